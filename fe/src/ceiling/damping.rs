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

impl RayleighFit {
    /// The same damping split differently between mass and stiffness:
    /// α and β scaled by 2·`mass_share` and 2·(1 − `mass_share`). The ratio
    /// where the two anchors coincide is kept; 0.5 returns the fit itself.
    pub fn with_mass_share(self, mass_share: f64) -> RayleighFit {
        RayleighFit {
            alpha_m_per_s: 2.0 * mass_share * self.alpha_m_per_s,
            beta_k_s: 2.0 * (1.0 - mass_share) * self.beta_k_s,
            ..self
        }
    }
}

/// `Ok` for a damping ratio 0 <= ratio < 1, else the value and what was
/// expected.
pub fn check_damping_ratio(ratio: f64) -> Result<(), String> {
    if (0.0..1.0).contains(&ratio) {
        Ok(())
    } else {
        Err(format!("{ratio}: expected 0 <= ratio < 1"))
    }
}

/// `Ok` for a share 0 <= share <= 1 (on the mass term,
/// [`RayleighFit::with_mass_share`], or of the stiffness term on the
/// committed tangent), else the value and what was expected.
pub fn check_share(share: f64) -> Result<(), String> {
    if (0.0..=1.0).contains(&share) {
        Ok(())
    } else {
        Err(format!("{share}: expected 0 <= share <= 1"))
    }
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

    /// The checks refuse NaN and each side of their range, naming the value.
    #[test]
    fn checks_refuse_values_outside_their_range() {
        assert!(check_damping_ratio(0.0).is_ok() && check_damping_ratio(0.99).is_ok());
        for bad in [-0.01, 1.0, f64::NAN] {
            let e = check_damping_ratio(bad).unwrap_err();
            assert_eq!(e, format!("{bad}: expected 0 <= ratio < 1"));
        }
        assert!(check_share(0.0).is_ok() && check_share(1.0).is_ok());
        for bad in [-0.01, 1.01, f64::NAN] {
            let e = check_share(bad).unwrap_err();
            assert_eq!(e, format!("{bad}: expected 0 <= share <= 1"));
        }
    }

    fn ratio_at(fit: &RayleighFit, f_hz: f64) -> f64 {
        let w = 2.0 * std::f64::consts::PI * f_hz;
        fit.alpha_m_per_s / (2.0 * w) + fit.beta_k_s * w / 2.0
    }

    fn fit_on(zeta: f64, fx_hz: f64, fy_hz: f64) -> RayleighFit {
        let (alpha_m_per_s, beta_k_s) = rayleigh_coefficients(zeta, fx_hz, fy_hz);
        RayleighFit { alpha_m_per_s, beta_k_s, fx_hz, fy_hz }
    }

    /// Share 0.5 is the fit itself, bit for bit; 1 and 0 leave one term.
    #[test]
    fn mass_share_bounds() {
        let fit = fit_on(0.05, 2.3, 3.1);
        assert_eq!(fit.with_mass_share(0.5), fit);
        let mass = fit.with_mass_share(1.0);
        assert_eq!((mass.beta_k_s, mass.alpha_m_per_s), (0.0, 2.0 * fit.alpha_m_per_s));
        let stiff = fit.with_mass_share(0.0);
        assert_eq!((stiff.alpha_m_per_s, stiff.beta_k_s), (0.0, 2.0 * fit.beta_k_s));
    }

    /// On one anchor frequency the ratio there is ζ for every share, and a
    /// larger share damps the frequencies above it less and below it more.
    #[test]
    fn mass_share_keeps_the_anchor_ratio() {
        for (zeta, f) in [(0.05, 2.0), (0.02, 7.5), (0.09, 0.8)] {
            let fit = fit_on(zeta, f, f);
            let mut last: Option<(f64, f64)> = None;
            for share in [0.0, 0.1, 0.3, 0.5, 0.7, 0.95, 1.0] {
                let s = fit.with_mass_share(share);
                assert!((ratio_at(&s, f) - zeta).abs() < 1e-14 * zeta.max(1.0), "{share}");
                let (hi, lo) = (ratio_at(&s, 4.0 * f), ratio_at(&s, 0.5 * f));
                if let Some((h, l)) = last {
                    assert!(hi < h && lo > l, "{share}: {hi} {lo} after {h} {l}");
                }
                last = Some((hi, lo));
            }
        }
    }
}
