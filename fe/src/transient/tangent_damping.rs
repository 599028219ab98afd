//! Stiffness-proportional damping on each flagged spring's last committed
//! tangent (OpenSees `rayleigh αM 0 0 βKcomm`), or on a share s of it
//! (K_R = (1 − s) K₀ + s K_comm). The structure's damping matrix keeps
//! β k₀ for every flagged spring ([`super::newton::Dynamics`]); here each
//! flagged nonlinear spring adds the rest,
//!
//!   f_c = c ḋ,  c = s β (k_comm − k₀),
//!
//! with k_comm its material tangent at the last commit, fixed for the step.
//! Within a Newmark step the spring's rate is affine in its deformation,
//! ḋ(d) = ḋ(0) + γ/(βΔt) d, so f_c joins the spring's force as a function of
//! its trial deformation and c γ/(βΔt) joins its tangent: both Newton paths
//! then see it like any other spring force.
//!
//! Units: deformation mm, rate mm/s, force N, damping coefficient N s/mm.

use super::low_rank::w_dot;
use super::newmark::NewmarkConstants;
use super::newton::Kinematics;
use crate::assembly::Structure;
use crate::materials::MaterialSpec;

/// The committed-tangent damping of the flagged nonlinear springs.
#[derive(Debug, Clone, PartialEq)]
pub struct CommittedTangentDamping {
    /// s β (s).
    beta_k_s: f64,
    /// Slot of each spring of the structure (`None`: not damped here).
    slot: Vec<Option<usize>>,
    /// Spring index of each slot.
    spring: Vec<usize>,
    /// Initial tangent per slot (N/mm).
    k0_n_mm: Vec<f64>,
    /// Material tangent per slot at the last commit (N/mm).
    committed_tangent_n_mm: Vec<f64>,
    /// Material tangent per slot at the last trial (N/mm).
    trial_tangent_n_mm: Vec<f64>,
    /// c = s β (k_comm − k₀) per slot for the current step (N s/mm).
    coefficient_n_s_mm: Vec<f64>,
    /// ḋ at zero trial deformation per slot for the current step (mm/s).
    rate_at_zero_mm_s: Vec<f64>,
    /// ∂ḋ/∂d = γ/(βΔt) of the current step (1/s).
    c_damp_per_s: f64,
}

impl CommittedTangentDamping {
    /// For the springs of `s` flagged `rayleigh` whose material is not
    /// elastic (an elastic spring's committed tangent is its initial one),
    /// with `beta_k_s` = s β; `None` when there are none or it is zero.
    pub fn of(s: &Structure, beta_k_s: f64) -> Option<Self> {
        let spring: Vec<usize> = (0..s.springs.len())
            .filter(|&k| {
                let sp = &s.springs[k];
                sp.rayleigh && !matches!(sp.material, MaterialSpec::Elastic { .. })
            })
            .collect();
        if spring.is_empty() || beta_k_s == 0.0 {
            return None;
        }
        let mut slot = vec![None; s.springs.len()];
        spring.iter().enumerate().for_each(|(i, &k)| slot[k] = Some(i));
        let k0_n_mm: Vec<f64> =
            spring.iter().map(|&k| s.springs[k].material.initial_tangent()).collect();
        let m = spring.len();
        Some(CommittedTangentDamping {
            beta_k_s,
            slot,
            spring,
            committed_tangent_n_mm: k0_n_mm.clone(),
            trial_tangent_n_mm: k0_n_mm.clone(),
            k0_n_mm,
            coefficient_n_s_mm: vec![0.0; m],
            rate_at_zero_mm_s: vec![0.0; m],
            c_damp_per_s: 0.0,
        })
    }

    /// Fixes the step's coefficients and rate map from the committed state
    /// (`deformation_mm` per spring, the committed kinematics).
    pub fn begin_step(
        &mut self,
        s: &Structure,
        nm: &NewmarkConstants,
        committed: &Kinematics,
        deformation_mm: &[f64],
    ) {
        self.c_damp_per_s = nm.c_damp;
        for (i, &k) in self.spring.iter().enumerate() {
            let eqs = &s.springs[k].eqs;
            let (v0, a0) = (w_dot(eqs, &committed.v), w_dot(eqs, &committed.a));
            self.rate_at_zero_mm_s[i] = nm.update(0.0, deformation_mm[k], v0, a0).0;
            self.coefficient_n_s_mm[i] =
                self.beta_k_s * (self.committed_tangent_n_mm[i] - self.k0_n_mm[i]);
        }
    }

    /// The damping force (N) and its tangent (N/mm) that spring `k` adds at
    /// trial deformation `d_mm`, whose material tangent is `kt_n_mm`
    /// (remembered for the next commit); zeros for a spring not damped here.
    pub fn trial(&mut self, k: usize, d_mm: f64, kt_n_mm: f64) -> (f64, f64) {
        let Some(i) = self.slot[k] else { return (0.0, 0.0) };
        self.trial_tangent_n_mm[i] = kt_n_mm;
        let c = self.coefficient_n_s_mm[i];
        (c * (self.rate_at_zero_mm_s[i] + self.c_damp_per_s * d_mm), c * self.c_damp_per_s)
    }

    /// Number of springs damped here.
    pub fn len(&self) -> usize {
        self.spring.len()
    }

    /// Whether no spring is damped here (never, once built).
    pub fn is_empty(&self) -> bool {
        self.spring.is_empty()
    }

    /// The structure's index of slot `i`'s spring.
    pub fn spring(&self, i: usize) -> usize {
        self.spring[i]
    }

    /// The material tangent of slot `i` at the last commit (N/mm).
    pub fn committed_tangent_n_mm(&self, i: usize) -> f64 {
        self.committed_tangent_n_mm[i]
    }

    /// Keeps the trial material tangents as the committed ones.
    pub fn commit(&mut self) {
        self.committed_tangent_n_mm.clone_from(&self.trial_tangent_n_mm);
    }

    /// Returns the trial material tangents to the committed ones.
    pub fn revert(&mut self) {
        self.trial_tangent_n_mm.clone_from(&self.committed_tangent_n_mm);
    }
}
