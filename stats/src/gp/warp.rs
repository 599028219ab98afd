//! Box-Cox power warping of positive inputs, learned with the kernel by
//! maximising the log marginal likelihood. An input with physical range
//! [lo, hi], lo > 0, ratio ρ = hi / lo, scaled to u ∈ [0, 1], is warped to
//! w_λ(u) = ((1 + u (ρ − 1))^λ − 1) / (ρ^λ − 1) = ((x/lo)^λ − 1) / (ρ^λ − 1),
//! which keeps [0, 1] fixed, is the identity for λ = 1 and the log scale
//! ln(x/lo) / ln ρ for λ = 0 (Box and Cox 1964 applied to inputs; compare
//! the Beta-CDF input warping of Snoek et al., *Input warping for Bayesian
//! optimization of non-stationary functions*, ICML 2014). A stationary
//! kernel on w then models responses that vary on a log scale, such as
//! those of quantities spanning decades. Dimensionless.

use super::scaling::InputScaling;
use serde::{Deserialize, Serialize};

/// |λ| below which the series of w_λ about λ = 0 is used.
const SMALL_LAMBDA: f64 = 1e-4;

/// Bound on |w| for points whose physical value is not positive.
const FAR: f64 = 1e6;

/// Power warp of one input: its range ratio and exponent.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PowerWarp {
    /// ρ = hi / lo of the physical range (> 1).
    pub ratio: f64,
    /// Exponent λ (1 = identity, 0 = log scale).
    pub lambda: f64,
}

impl PowerWarp {
    /// (w_λ(u), ∂w/∂λ) at the scaled input u; far outside the range
    /// (x ≤ 0) w is held finite at ±`FAR`.
    pub fn eval(&self, u: f64) -> (f64, f64) {
        let (w, dw) = self.eval_raw(u);
        if w.is_finite() && dw.is_finite() {
            (w, dw)
        } else {
            (if w > 0.0 { FAR } else { -FAR }, 0.0)
        }
    }

    /// dw/du at the scaled input u (0 where w is held at ±`FAR`).
    pub fn slope(&self, u: f64) -> f64 {
        let base = 1.0 + u * (self.ratio - 1.0);
        let b = self.ratio.ln();
        let l = self.lambda;
        let c = if l == 0.0 { 1.0 / b } else { l / (l * b).exp_m1() };
        let s = (self.ratio - 1.0) * base.powf(l - 1.0) * c;
        if s.is_finite() && base > 0.0 {
            s
        } else {
            0.0
        }
    }

    fn eval_raw(&self, u: f64) -> (f64, f64) {
        let a = (1.0 + u * (self.ratio - 1.0)).max(f64::MIN_POSITIVE).ln();
        let b = self.ratio.ln();
        let l = self.lambda;
        if l.abs() < SMALL_LAMBDA {
            // w = (a/b) N/D, N and D the series of expm1(z)/z at z = λa, λb.
            let series = |c: f64| {
                let z = l * c;
                let value = 1.0 + z / 2.0 + z * z / 6.0 + z * z * z / 24.0;
                (value, c / 2.0 + z * c / 3.0 + z * z * c / 8.0)
            };
            let ((n, dn), (den, dd)) = (series(a), series(b));
            let r = a / b;
            (r * n / den, r * (dn * den - n * dd) / (den * den))
        } else {
            let (ea, eb) = ((l * a).exp_m1(), (l * b).exp_m1());
            let w = ea / eb;
            let dw = (a * (l * a).exp() * eb - b * (l * b).exp() * ea) / (eb * eb);
            (w, dw)
        }
    }
}

/// The warps of all inputs (None = input used as scaled).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct InputWarp {
    /// One entry per input; empty means no input is warped.
    pub inputs: Vec<Option<PowerWarp>>,
}

impl InputWarp {
    /// Ratios hi / lo of the inputs that can be warped (positive lower
    /// bound), None for the others.
    pub fn candidates(scaling: &InputScaling) -> Vec<Option<f64>> {
        scaling
            .lo
            .iter()
            .zip(&scaling.hi)
            .map(|(&lo, &hi)| (lo > 0.0 && hi > lo && (hi / lo).is_finite()).then(|| hi / lo))
            .collect()
    }

    /// Warp from the candidate ratios and one exponent per warped input.
    pub fn from_parts(ratios: &[Option<f64>], lambdas: &[f64]) -> Self {
        let mut next = lambdas.iter();
        let inputs = ratios
            .iter()
            .map(|r| r.map(|ratio| PowerWarp { ratio, lambda: *next.next().unwrap_or(&1.0) }))
            .collect();
        InputWarp { inputs }
    }

    /// Number of warped inputs.
    pub fn n_warped(&self) -> usize {
        self.inputs.iter().filter(|w| w.is_some()).count()
    }

    /// Warped (n, d) row-major scaled points.
    pub fn apply(&self, xs: &[f64], d: usize) -> Vec<f64> {
        self.apply_with_grad(xs, d).0
    }

    /// dw/du of input `k` at the scaled value u (1 when it is not warped).
    pub fn slope(&self, k: usize, u: f64) -> f64 {
        match self.inputs.get(k) {
            Some(Some(p)) => p.slope(u),
            _ => 1.0,
        }
    }

    /// Warped points and ∂w/∂λ at each (0 for inputs that are not warped).
    pub fn apply_with_grad(&self, xs: &[f64], d: usize) -> (Vec<f64>, Vec<f64>) {
        let mut w = xs.to_vec();
        let mut dw = vec![0.0; xs.len()];
        if self.inputs.is_empty() {
            return (w, dw);
        }
        for (i, v) in xs.iter().enumerate() {
            if let Some(Some(p)) = self.inputs.get(i % d) {
                (w[i], dw[i]) = p.eval(*v);
            }
        }
        (w, dw)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn fixes_the_ends_and_is_increasing(
            ratio in 1.01..1e4f64, lambda in -2.0..3.0f64, u in 0.0..0.99f64
        ) {
            let p = PowerWarp { ratio, lambda };
            prop_assert!(p.eval(0.0).0.abs() < 1e-12);
            prop_assert!((p.eval(1.0).0 - 1.0).abs() < 1e-12);
            prop_assert!(p.eval(u + 0.01).0 > p.eval(u).0);
        }

        #[test]
        fn lambda_derivative_matches_finite_difference(
            ratio in 1.1..1e3f64, lambda in -2.0..3.0f64, u in 0.0..1.0f64
        ) {
            let h = 1e-6;
            let at = |l: f64| PowerWarp { ratio, lambda: l }.eval(u).0;
            let fd = (at(lambda + h) - at(lambda - h)) / (2.0 * h);
            let dw = PowerWarp { ratio, lambda }.eval(u).1;
            prop_assert!((fd - dw).abs() < 1e-6 * (1.0 + dw.abs()), "fd {} vs {}", fd, dw);
        }
    }

    proptest! {
        #[test]
        fn slope_matches_finite_difference(
            ratio in 1.1..1e3f64, lambda in -2.0..3.0f64, u in 0.01..0.99f64
        ) {
            let p = PowerWarp { ratio, lambda };
            let h = 1e-6;
            let fd = (p.eval(u + h).0 - p.eval(u - h).0) / (2.0 * h);
            prop_assert!((fd - p.slope(u)).abs() < 1e-5 * (1.0 + fd.abs()), "fd {} vs {}", fd, p.slope(u));
        }
    }

    #[test]
    fn slope_at_lambda_zero_is_the_log_scale_slope() {
        let (ratio, u) = (500.0f64, 0.3);
        let want = (ratio - 1.0) / ((1.0 + u * (ratio - 1.0)) * ratio.ln());
        for lambda in [0.0, 1e-9, -1e-9] {
            let got = PowerWarp { ratio, lambda }.slope(u);
            assert!((got - want).abs() < 1e-6 * want, "{lambda}: {got} vs {want}");
        }
    }

    #[test]
    fn identity_at_one_and_log_scale_at_zero() {
        let (ratio, u) = (500.0, 0.3);
        assert!((PowerWarp { ratio, lambda: 1.0 }.eval(u).0 - u).abs() < 1e-14);
        let log = (1.0 + u * (ratio - 1.0)).ln() / ratio.ln();
        assert!((PowerWarp { ratio, lambda: 0.0 }.eval(u).0 - log).abs() < 1e-14);
    }

    #[test]
    fn continuous_across_the_series_switch() {
        let (ratio, u) = (500.0, 0.02);
        let below = PowerWarp { ratio, lambda: SMALL_LAMBDA * (1.0 - 1e-12) }.eval(u);
        let above = PowerWarp { ratio, lambda: SMALL_LAMBDA * (1.0 + 1e-12) }.eval(u);
        assert!((below.0 - above.0).abs() < 1e-13, "{below:?} {above:?}");
        assert!((below.1 - above.1).abs() < 1e-9, "{below:?} {above:?}");
    }

    #[test]
    fn finite_for_points_far_outside_the_range() {
        for lambda in [-2.0, -0.5, 0.0, 1e-5, 0.5, 3.0] {
            let p = PowerWarp { ratio: 500.0, lambda };
            for u in [-1.0, -1e-3, 1e3] {
                let (w, dw) = p.eval(u);
                assert!(w.is_finite() && dw.is_finite(), "λ {lambda}, u {u}: {w} {dw}");
            }
        }
    }

    #[test]
    fn only_positive_ranges_are_candidates() {
        let s = InputScaling { lo: vec![0.0, 100.0, -1.0], hi: vec![1.0, 5e4, 1.0] };
        assert_eq!(InputWarp::candidates(&s), vec![None, Some(500.0), None]);
    }
}
