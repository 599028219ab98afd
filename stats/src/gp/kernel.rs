//! Stationary ARD covariance functions on inputs scaled to [0, 1]:
//! k(x, x') = s² g(u) with u = Σ_k ((x_k − x'_k) / l_k)² the squared scaled
//! distance. Families: squared exponential g = exp(−u/2); Matérn 3/2
//! g = (1 + √3 r) e^(−√3 r); Matérn 5/2 g = (1 + √5 r + 5u/3) e^(−√5 r)
//! (r = √u); rational quadratic g = (1 + u / (2α))^(−α) (Rasmussen and
//! Williams, *Gaussian Processes for Machine Learning*, 2006, ch. 4).
//! Hyperparameters live in log space: θ = [ln l_1..ln l_d, ln s², (ln α)].

use super::exp_kernel::exp_nonpositive;
use serde::{Deserialize, Serialize};

/// Which stationary covariance family.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum KernelKind {
    /// Squared exponential (RBF) with one length scale per input.
    SquaredExponential,
    /// Matérn ν = 3/2 with one length scale per input.
    Matern32,
    /// Matérn ν = 5/2 with one length scale per input.
    Matern52,
    /// Rational quadratic with one length scale per input and shape α.
    RationalQuadratic,
}

impl KernelKind {
    /// All families, in the order they are tried by kernel selection.
    pub const ALL: [KernelKind; 4] = [
        KernelKind::SquaredExponential,
        KernelKind::Matern32,
        KernelKind::Matern52,
        KernelKind::RationalQuadratic,
    ];

    /// Parse a command-line name (`se`, `rbf`, `matern32`, `matern52`, `rq`).
    pub fn parse(name: &str) -> Option<Self> {
        match name.to_ascii_lowercase().as_str() {
            "se" | "rbf" | "squared-exponential" | "squared_exponential" => {
                Some(Self::SquaredExponential)
            }
            "matern32" | "matern-32" | "matern3/2" => Some(Self::Matern32),
            "matern52" | "matern-52" | "matern5/2" => Some(Self::Matern52),
            "rq" | "rational-quadratic" | "rational_quadratic" => Some(Self::RationalQuadratic),
            _ => None,
        }
    }

    /// Short name used in model files and reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::SquaredExponential => "se",
            Self::Matern32 => "matern32",
            Self::Matern52 => "matern52",
            Self::RationalQuadratic => "rq",
        }
    }

    /// Number of kernel hyperparameters for `dim` inputs (lengths, s², α).
    pub fn n_params(self, dim: usize) -> usize {
        match self {
            Self::RationalQuadratic => dim + 2,
            _ => dim + 1,
        }
    }
}

/// A kernel family with its hyperparameters on the natural scale.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Kernel {
    /// The family.
    pub kind: KernelKind,
    /// Length scales l_k, one per input (scaled input units).
    pub lengths: Vec<f64>,
    /// Signal variance s² (standardised output units squared).
    pub variance: f64,
    /// Shape α of the rational quadratic (ignored by the other families).
    pub alpha: f64,
}

impl Kernel {
    /// Kernel from log-space parameters θ = [ln l.., ln s², (ln α)].
    pub fn from_log(kind: KernelKind, theta: &[f64]) -> Self {
        let d = match kind {
            KernelKind::RationalQuadratic => theta.len() - 2,
            _ => theta.len() - 1,
        };
        let alpha = if kind == KernelKind::RationalQuadratic { theta[d + 1].exp() } else { 1.0 };
        Kernel {
            kind,
            lengths: theta[..d].iter().map(|t| t.exp()).collect(),
            variance: theta[d].exp(),
            alpha,
        }
    }

    /// Log-space parameter vector θ.
    pub fn to_log(&self) -> Vec<f64> {
        let mut theta: Vec<f64> = self.lengths.iter().map(|l| l.ln()).collect();
        theta.push(self.variance.ln());
        if self.kind == KernelKind::RationalQuadratic {
            theta.push(self.alpha.ln());
        }
        theta
    }

    /// Squared scaled distance u between two points.
    pub fn scaled_dist2(&self, a: &[f64], b: &[f64]) -> f64 {
        let mut u = 0.0;
        for ((p, q), l) in a.iter().zip(b).zip(&self.lengths) {
            let t = (p - q) / l;
            u += t * t;
        }
        u
    }

    /// k(a, b).
    pub fn eval(&self, a: &[f64], b: &[f64]) -> f64 {
        self.variance * self.shape(self.scaled_dist2(a, b)).0
    }

    /// (g(u), −2 g'(u), ∂g/∂ln α) for squared scaled distance u.
    #[inline(always)]
    pub fn shape(&self, u: f64) -> (f64, f64, f64) {
        match self.kind {
            KernelKind::SquaredExponential => squared_exponential(u),
            KernelKind::Matern32 => matern32(u),
            KernelKind::Matern52 => matern52(u),
            KernelKind::RationalQuadratic => rational_quadratic(self.alpha, u),
        }
    }
}

/// Squared-exponential shape: (g, −2g', 0) at squared scaled distance u.
#[inline(always)]
pub fn squared_exponential(u: f64) -> (f64, f64, f64) {
    let g = exp_nonpositive(-0.5 * u);
    (g, g, 0.0)
}

/// Matérn 3/2 shape: (g, −2g', 0) at squared scaled distance u.
#[inline(always)]
pub fn matern32(u: f64) -> (f64, f64, f64) {
    let r = (3.0 * u).sqrt();
    let e = exp_nonpositive(-r);
    ((1.0 + r) * e, 3.0 * e, 0.0)
}

/// Matérn 5/2 shape: (g, −2g', 0) at squared scaled distance u.
#[inline(always)]
pub fn matern52(u: f64) -> (f64, f64, f64) {
    let r = (5.0 * u).sqrt();
    let e = exp_nonpositive(-r);
    ((1.0 + r + 5.0 * u / 3.0) * e, 5.0 / 3.0 * (1.0 + r) * e, 0.0)
}

/// Rational-quadratic shape of exponent `a`: (g, −2g', ∂g/∂ln a).
#[inline(always)]
pub fn rational_quadratic(a: f64, u: f64) -> (f64, f64, f64) {
    let b = 1.0 + u / (2.0 * a);
    let g = b.powf(-a);
    let h = g / b;
    let dg_dlna = a * g * (-b.ln() + u / (2.0 * a * b));
    (g, h, dg_dlna)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn kernel(kind: KernelKind) -> Kernel {
        Kernel { kind, lengths: vec![0.3, 0.7], variance: 1.7, alpha: 2.5 }
    }

    proptest! {
        #[test]
        fn derivative_factor_matches_finite_difference(u in 0.01..5.0f64) {
            for kind in KernelKind::ALL {
                let k = kernel(kind);
                let h = 1e-6;
                let fd = -2.0 * (k.shape(u + h).0 - k.shape(u - h).0) / (2.0 * h);
                prop_assert!((fd - k.shape(u).1).abs() < 1e-6, "{kind:?}");
            }
        }

        #[test]
        fn symmetric_and_bounded_by_variance(a in 0.0..1.0f64, b in 0.0..1.0f64) {
            for kind in KernelKind::ALL {
                let k = kernel(kind);
                let (p, q) = ([a, b], [b, a]);
                prop_assert!((k.eval(&p, &q) - k.eval(&q, &p)).abs() < 1e-14);
                prop_assert!(k.eval(&p, &q) <= k.variance + 1e-14);
                prop_assert!((k.eval(&p, &p) - k.variance).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn rational_quadratic_tends_to_squared_exponential() {
        let mut rq = kernel(KernelKind::RationalQuadratic);
        rq.alpha = 1e7;
        let se = kernel(KernelKind::SquaredExponential);
        let (a, b) = ([0.1, 0.2], [0.5, 0.9]);
        assert!((rq.eval(&a, &b) - se.eval(&a, &b)).abs() < 1e-6);
    }

    #[test]
    fn log_round_trip() {
        let k = kernel(KernelKind::RationalQuadratic);
        let back = Kernel::from_log(k.kind, &k.to_log());
        assert!((back.alpha - k.alpha).abs() < 1e-12);
        assert!((back.lengths[1] - k.lengths[1]).abs() < 1e-12);
    }
}
