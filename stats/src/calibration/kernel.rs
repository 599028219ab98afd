//! Squared-exponential covariance of a GP discrepancy:
//! k(x, x') = s² exp(−|x − x'|² / (2 l²)), x in the data's input units.

use nalgebra::DMatrix;

/// The squared-exponential kernel with sd `s` and length scale `l`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SquaredExponential {
    /// Marginal standard deviation s (units of y).
    pub sd: f64,
    /// Length scale l (units of x).
    pub length: f64,
}

impl SquaredExponential {
    /// k(a, b).
    pub fn eval(&self, a: &[f64], b: &[f64]) -> f64 {
        let d2: f64 = a.iter().zip(b).map(|(p, q)| (p - q) * (p - q)).sum();
        self.sd * self.sd * (-0.5 * d2 / (self.length * self.length)).exp()
    }

    /// The (n, n) covariance matrix of the points `x` (each of length D).
    pub fn matrix(&self, x: &[Vec<f64>]) -> DMatrix<f64> {
        let n = x.len();
        DMatrix::from_fn(n, n, |i, j| self.eval(&x[i], &x[j]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn symmetric_with_variance_on_diagonal(a in -3.0..3.0f64, b in -3.0..3.0f64, s in 0.01..2.0f64, l in 0.01..2.0f64) {
            let k = SquaredExponential { sd: s, length: l };
            prop_assert!((k.eval(&[a], &[b]) - k.eval(&[b], &[a])).abs() < 1e-15);
            prop_assert!((k.eval(&[a], &[a]) - s * s).abs() < 1e-12);
            prop_assert!(k.eval(&[a], &[b]) <= s * s + 1e-15);
        }
    }

    #[test]
    fn one_length_scale_apart_is_exp_minus_half() {
        let k = SquaredExponential { sd: 1.0, length: 0.3 };
        assert!((k.eval(&[0.0], &[0.3]) - (-0.5f64).exp()).abs() < 1e-15);
    }
}
