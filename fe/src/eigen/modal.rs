//! Modal analysis of a model: frequencies (Hz), mass-normalised shapes,
//! participation factors Γ = φᵀ M r and effective masses Γ² (t) in x, y, z
//! (Chopra, *Dynamics of Structures*, 13.1).

use super::lanczos::{shift_invert_lanczos, LanczosSettings};
use super::ritz::ritz_pairs;
use super::{EigenError, Eigenpairs};
use crate::assembly::Structure;
use crate::model::Model;

/// The lowest modes of a model.
#[derive(Debug, Clone)]
pub struct ModalResult {
    /// Frequencies (Hz), ascending.
    pub freq_hz: Vec<f64>,
    /// Eigenvalues ω² (rad²/s²).
    pub omega2: Vec<f64>,
    /// Mass-normalised shapes on the free DOFs.
    pub shapes: Vec<Vec<f64>>,
    /// Participation factors Γ (t^½) per mode in x, y, z.
    pub participation: Vec<[f64; 3]>,
    /// Effective modal masses Γ² (t) per mode in x, y, z.
    pub effective_mass_t: Vec<[f64; 3]>,
    /// Total translational mass (t) on free DOFs in x, y, z.
    pub total_mass_t: [f64; 3],
}

impl ModalResult {
    /// Direction ('x', 'y' or 'z') of the largest effective mass of `mode` (0-based).
    pub fn dominant(&self, mode: usize) -> char {
        let m = self.effective_mass_t[mode];
        let k = (0..3).max_by(|a, b| m[*a].total_cmp(&m[*b])).unwrap_or(0);
        ['x', 'y', 'z'][k]
    }
}

/// Frequency (Hz) of an eigenvalue ω² (negative round-off clipped to 0).
pub fn freq_hz(omega2: f64) -> f64 {
    omega2.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)
}

/// The lowest `n_modes` modes of a validated model (initial stiffness).
pub fn modal_analysis(
    model: &Model,
    n_modes: usize,
    settings: &LanczosSettings,
) -> Result<(Structure, ModalResult), EigenError> {
    let s = Structure::new(model)?;
    let k = s.initial_stiffness();
    let pairs = shift_invert_lanczos(&s.pattern, &k, &s.mass, n_modes, settings)?;
    let result = modal_quantities(&s, pairs);
    Ok((s, result))
}

/// [`modal_analysis`], by Rayleigh–Ritz on `basis` ([`super::ritz`]) when
/// one is given and it can carry the model (a model near the one whose
/// modes it holds: the same mesh, at least `n_modes` vectors independent
/// under its mass); by Lanczos otherwise.
pub fn modal_analysis_on(
    model: &Model,
    basis: Option<&[Vec<f64>]>,
    n_modes: usize,
    settings: &LanczosSettings,
) -> Result<(Structure, ModalResult), EigenError> {
    let s = Structure::new(model)?;
    let k = s.initial_stiffness();
    let ritz = basis.and_then(|b| ritz_pairs(&s.pattern, &k, &s.mass, b, n_modes).ok());
    let pairs = match ritz {
        Some(pairs) => pairs,
        None => shift_invert_lanczos(&s.pattern, &k, &s.mass, n_modes, settings)?,
    };
    let result = modal_quantities(&s, pairs);
    Ok((s, result))
}

/// Each mode's share of its kinetic energy (Σ m φ² over the translations)
/// in the horizontal translations x and y: near 1 for the sway modes a
/// shaking table's horizontal sensors identify, near 0 for a vertical mode.
pub fn horizontal_share(s: &Structure, modal: &ModalResult) -> Vec<f64> {
    modal
        .shapes
        .iter()
        .map(|phi| {
            let energy = |dofs: &[usize]| -> f64 {
                (s.dofs.eqs.iter())
                    .flat_map(|eqs| dofs.iter().filter_map(move |d| eqs[*d]))
                    .map(|e| s.mass[e] * phi[e] * phi[e])
                    .sum()
            };
            let (horizontal, all) = (energy(&[0, 1]), energy(&[0, 1, 2]));
            if all > 0.0 {
                horizontal / all
            } else {
                0.0
            }
        })
        .collect()
}

/// Participation factors and effective masses of eigenpairs of `s`.
pub fn modal_quantities(s: &Structure, pairs: Eigenpairs) -> ModalResult {
    let influence = |d: usize| {
        let mut r = vec![0.0; s.dofs.n_free];
        for eqs in &s.dofs.eqs {
            if let Some(e) = eqs[d] {
                r[e] = 1.0;
            }
        }
        r
    };
    let r = [influence(0), influence(1), influence(2)];
    let total_mass_t = r.each_ref().map(|r| r.iter().zip(&s.mass).map(|(a, m)| a * m).sum());
    let participation: Vec<[f64; 3]> = pairs
        .vectors
        .iter()
        .map(|phi| {
            r.each_ref().map(|r| phi.iter().zip(r).zip(&s.mass).map(|((p, a), m)| p * a * m).sum())
        })
        .collect();
    ModalResult {
        freq_hz: pairs.omega2.iter().map(|w| freq_hz(*w)).collect(),
        effective_mass_t: participation.iter().map(|g| g.map(|v| v * v)).collect(),
        participation,
        omega2: pairs.omega2,
        shapes: pairs.vectors,
        total_mass_t,
    }
}
