//! Independent uniform priors on a box, mapped to unconstrained space by the
//! logit transform theta = a + (b − a) sigmoid(z). The log-Jacobian
//! log(b − a) + log sigmoid(z) + log(1 − sigmoid(z)) cancels the uniform
//! density 1/(b − a), so the prior in z has log density
//! sum_i [log sigmoid(z_i) + log(1 − sigmoid(z_i))].

use super::CalibError;

/// Bounded uniform priors, one per parameter (physical units).
#[derive(Debug, Clone, PartialEq)]
pub struct UniformBox {
    /// Parameter names.
    pub names: Vec<String>,
    /// Lower bounds a.
    pub lower: Vec<f64>,
    /// Upper bounds b.
    pub upper: Vec<f64>,
}

/// log(sigmoid(z)), stable for large |z|.
pub fn log_sigmoid(z: f64) -> f64 {
    if z >= 0.0 {
        -(-z).exp().ln_1p()
    } else {
        z - z.exp().ln_1p()
    }
}

/// sigmoid(z) = 1 / (1 + e^−z).
pub fn sigmoid(z: f64) -> f64 {
    if z >= 0.0 {
        1.0 / (1.0 + (-z).exp())
    } else {
        let e = z.exp();
        e / (1.0 + e)
    }
}

impl UniformBox {
    /// Checks the bounds: finite, lower < upper, one per name.
    pub fn new(names: Vec<String>, lower: Vec<f64>, upper: Vec<f64>) -> Result<Self, CalibError> {
        CalibError::check_len("lower bounds", lower.len(), names.len())?;
        CalibError::check_len("upper bounds", upper.len(), names.len())?;
        for ((n, a), b) in names.iter().zip(&lower).zip(&upper) {
            if !(a.is_finite() && b.is_finite() && a < b) {
                return Err(CalibError::invalid(
                    n,
                    format!("U({a}, {b})"),
                    "finite bounds with lower < upper",
                ));
            }
        }
        Ok(Self { names, lower, upper })
    }

    /// Number of parameters.
    pub fn dim(&self) -> usize {
        self.names.len()
    }

    /// theta = a + (b − a) sigmoid(z), elementwise.
    pub fn to_physical(&self, z: &[f64]) -> Vec<f64> {
        (0..self.dim())
            .map(|i| self.lower[i] + (self.upper[i] - self.lower[i]) * sigmoid(z[i]))
            .collect()
    }

    /// z = logit((theta − a) / (b − a)); None outside the open box.
    pub fn to_unconstrained(&self, theta: &[f64]) -> Option<Vec<f64>> {
        (0..self.dim())
            .map(|i| {
                let u = (theta[i] - self.lower[i]) / (self.upper[i] - self.lower[i]);
                (u > 0.0 && u < 1.0).then(|| (u / (1.0 - u)).ln())
            })
            .collect()
    }

    /// Log prior density of z in unconstrained space (uniform density times Jacobian).
    pub fn log_density_unconstrained(&self, z: &[f64]) -> f64 {
        z.iter().map(|&z| log_sigmoid(z) + log_sigmoid(-z)).sum()
    }

    /// Is theta inside the closed box?
    pub fn contains(&self, theta: &[f64]) -> bool {
        (0..self.dim()).all(|i| theta[i] >= self.lower[i] && theta[i] <= self.upper[i])
    }

    /// log of the box volume prod (b − a).
    pub fn log_volume(&self) -> f64 {
        (0..self.dim()).map(|i| (self.upper[i] - self.lower[i]).ln()).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn unit() -> UniformBox {
        UniformBox::new(vec!["k".into()], vec![0.5], vec![2.5]).unwrap()
    }

    proptest! {
        #[test]
        fn round_trip(t in 0.5001..2.4999f64) {
            let b = unit();
            let z = b.to_unconstrained(&[t]).unwrap();
            prop_assert!((b.to_physical(&z)[0] - t).abs() < 1e-10);
        }

        #[test]
        fn jacobian_matches_finite_difference(z in -6.0..6.0f64) {
            let b = unit();
            let h = 1e-5;
            let d = (b.to_physical(&[z + h])[0] - b.to_physical(&[z - h])[0]) / (2.0 * h);
            let expected = d.ln() - (2.0f64).ln();
            prop_assert!((b.log_density_unconstrained(&[z]) - expected).abs() < 1e-6);
        }
    }

    #[test]
    fn density_integrates_to_one() {
        let b = unit();
        let h = 0.01;
        let total: f64 =
            (-3000..3000).map(|i| b.log_density_unconstrained(&[i as f64 * h]).exp() * h).sum();
        assert!((total - 1.0).abs() < 1e-6, "{total}");
    }

    #[test]
    fn bad_bounds_named() {
        let e = UniformBox::new(vec!["c".into()], vec![1.0], vec![0.5]).unwrap_err().to_string();
        assert!(e.contains("c = U(1, 0.5)"), "{e}");
    }
}
