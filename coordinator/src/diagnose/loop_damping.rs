//! Equivalent viscous damping from hysteresis loops (Chopra, Dynamics of
//! Structures, §3.9): per full cycle of relative displacement u, the energy
//! dissipated E_D = ∮ F du and the strain energy E_S = ¼ (F(u_max) u_max +
//! F(u_min) u_min), with F the restoring force per unit mass, here minus
//! the absolute acceleration at the same point (m/s²); ζ_eq = ΣE_D / (4π ΣE_S)
//! over the cycles large enough to count.
//!
//! For a linear oscillator (ω_n, ζ) in steady harmonic motion at ω,
//! ζ_eq = ζ ω/ω_n: ζ itself at resonance. Friction and hysteretic
//! connections raise ζ_eq with amplitude. Units: displacement in m, force
//! per unit mass in m/s², energies in J/kg. Cycles with a missing reading
//! (NaN) are left out, never read as zero.

/// Loop energy of a record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopDamping {
    /// Equivalent viscous damping ratio ζ_eq (-).
    pub zeta_eq: f64,
    /// Cycles counted.
    pub cycles: usize,
    /// Mean energy dissipated per counted cycle (J/kg).
    pub energy_per_cycle_j_kg: f64,
}

/// One full cycle's energies and amplitude.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cycle {
    /// Half the peak-to-peak displacement (m).
    pub amplitude_m: f64,
    /// ∮ F du (J/kg).
    pub dissipated_j_kg: f64,
    /// ¼ (F(u_max) u_max + F(u_min) u_min) (J/kg).
    pub strain_j_kg: f64,
}

/// Full cycles between upward zero crossings of `disp_m`; a crossing counts
/// only after the record went below −5 % of its largest |value| (noise
/// near zero does not split cycles). Cycles with a missing reading are skipped.
pub fn cycles(force_per_mass: &[f64], disp_m: &[f64]) -> Vec<Cycle> {
    let n = force_per_mass.len().min(disp_m.len());
    let top = disp_m[..n].iter().filter(|v| v.is_finite()).fold(0.0f64, |m, v| m.max(v.abs()));
    if top <= 0.0 {
        return vec![];
    }
    let mut starts = Vec::new();
    let mut armed = false;
    for i in 1..n {
        let (a, b) = (disp_m[i - 1], disp_m[i]);
        if a < -0.05 * top {
            armed = true;
        }
        if armed && a < 0.0 && b >= 0.0 {
            starts.push(i);
            armed = false;
        }
    }
    starts
        .windows(2)
        .filter_map(|w| cycle(&force_per_mass[w[0]..=w[1]], &disp_m[w[0]..=w[1]]))
        .collect()
}

/// The energies of one cycle (samples from one upward crossing to the next).
fn cycle(f: &[f64], u: &[f64]) -> Option<Cycle> {
    if f.iter().chain(u).any(|v| !v.is_finite()) {
        return None;
    }
    let dissipated: f64 = (1..u.len()).map(|i| 0.5 * (f[i] + f[i - 1]) * (u[i] - u[i - 1])).sum();
    let hi = (0..u.len()).max_by(|a, b| u[*a].total_cmp(&u[*b]))?;
    let lo = (0..u.len()).min_by(|a, b| u[*a].total_cmp(&u[*b]))?;
    let strain = 0.25 * (f[hi] * u[hi] + f[lo] * u[lo]);
    Some(Cycle {
        amplitude_m: 0.5 * (u[hi] - u[lo]),
        dissipated_j_kg: dissipated,
        strain_j_kg: strain,
    })
}

/// ζ_eq over the cycles whose amplitude is at least `min_share` of the
/// largest; `None` without such a cycle or with no strain energy.
pub fn loop_damping(force_per_mass: &[f64], disp_m: &[f64], min_share: f64) -> Option<LoopDamping> {
    let all = cycles(force_per_mass, disp_m);
    let top = all.iter().map(|c| c.amplitude_m).fold(0.0f64, f64::max);
    let used: Vec<&Cycle> = all.iter().filter(|c| c.amplitude_m >= min_share * top).collect();
    let ed: f64 = used.iter().map(|c| c.dissipated_j_kg).sum();
    let es: f64 = used.iter().map(|c| c.strain_j_kg).sum();
    if used.is_empty() || es.is_nan() || es <= 0.0 {
        return None;
    }
    Some(LoopDamping {
        zeta_eq: ed / (4.0 * std::f64::consts::PI * es),
        cycles: used.len(),
        energy_per_cycle_j_kg: ed / used.len() as f64,
    })
}

#[cfg(test)]
#[path = "loop_damping_tests.rs"]
mod tests;
