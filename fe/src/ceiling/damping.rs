//! Rayleigh damping C = αM + βK with ratio ζ on two modes (seed eqs 5.1–5.3:
//! 5 % on the first x and y modes): α = 2ζωᵢωⱼ/(ωᵢ+ωⱼ), β = 2ζ/(ωᵢ+ωⱼ)
//! (Chopra, *Dynamics of Structures*, 11.4).

use crate::eigen::ModalResult;

/// Rayleigh coefficients and the two modes they were fitted on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayleighFit {
    /// Mass coefficient α (1/s).
    pub alpha_m_per_s: f64,
    /// Stiffness coefficient β (s).
    pub beta_k_s: f64,
    /// Frequency of the x mode used (Hz).
    pub fx_hz: f64,
    /// Frequency of the y mode used (Hz).
    pub fy_hz: f64,
}

/// α and β giving ratio `zeta` at frequencies `f1_hz` and `f2_hz`.
pub fn rayleigh_coefficients(zeta: f64, f1_hz: f64, f2_hz: f64) -> (f64, f64) {
    let (w1, w2) = (2.0 * std::f64::consts::PI * f1_hz, 2.0 * std::f64::consts::PI * f2_hz);
    (2.0 * zeta * w1 * w2 / (w1 + w2), 2.0 * zeta / (w1 + w2))
}

/// Rayleigh damping with ratio `zeta` on the modes of largest effective
/// mass in x and in y; `None` when no mode moves mass in x or y.
pub fn rayleigh_on_first_modes(res: &ModalResult, zeta: f64) -> Option<RayleighFit> {
    let best = |d: usize| {
        (0..res.freq_hz.len())
            .filter(|k| res.effective_mass_t[*k][d] > 0.0)
            .max_by(|a, b| res.effective_mass_t[*a][d].total_cmp(&res.effective_mass_t[*b][d]))
    };
    let (kx, ky) = match (best(0), best(1)) {
        (Some(x), Some(y)) => (x, y),
        (Some(x), None) => (x, x),
        (None, Some(y)) => (y, y),
        (None, None) => return None,
    };
    let (fx_hz, fy_hz) = (res.freq_hz[kx], res.freq_hz[ky]);
    let (alpha_m_per_s, beta_k_s) = rayleigh_coefficients(zeta, fx_hz, fy_hz);
    Some(RayleighFit { alpha_m_per_s, beta_k_s, fx_hz, fy_hz })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ζ(ω) = α/2ω + βω/2 equals the target at both fitted frequencies.
    #[test]
    fn ratio_is_exact_at_both_frequencies() {
        let (a, b) = rayleigh_coefficients(0.05, 2.0, 7.0);
        for f in [2.0, 7.0] {
            let w = 2.0 * std::f64::consts::PI * f;
            let zeta = a / (2.0 * w) + b * w / 2.0;
            assert!((zeta - 0.05).abs() < 1e-14, "{zeta}");
        }
        let w = 2.0 * std::f64::consts::PI * 4.0;
        assert!(a / (2.0 * w) + b * w / 2.0 < 0.05);
    }
}
