//! Priors the tempered sampler draws its first population from.

use crate::calibration::UniformBox;
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand_distr::StandardNormal;

/// A proper prior: draws and a normalised log density (−∞ outside its support).
pub trait Prior {
    /// Number of parameters.
    fn dim(&self) -> usize;
    /// One draw.
    fn sample(&self, rng: &mut dyn rand::RngCore) -> Vec<f64>;
    /// Normalised log density at `x`; −∞ outside the support.
    fn ln_density(&self, x: &[f64]) -> f64;
}

impl Prior for UniformBox {
    fn dim(&self) -> usize {
        self.names.len()
    }

    fn sample(&self, rng: &mut dyn rand::RngCore) -> Vec<f64> {
        (0..self.dim())
            .map(|i| self.lower[i] + (self.upper[i] - self.lower[i]) * rng.random::<f64>())
            .collect()
    }

    fn ln_density(&self, x: &[f64]) -> f64 {
        if self.contains(x) {
            -self.log_volume()
        } else {
            f64::NEG_INFINITY
        }
    }
}

/// A multivariate normal prior N(mean, L Lᵀ) given by its Cholesky factor.
#[derive(Debug, Clone)]
pub struct GaussianPrior {
    mean: DVector<f64>,
    chol: DMatrix<f64>,
    ln_norm: f64,
}

impl GaussianPrior {
    /// N(mean, cov); None unless `cov` is symmetric positive definite of the mean's size.
    pub fn new(mean: Vec<f64>, cov: DMatrix<f64>) -> Option<Self> {
        let d = mean.len();
        if cov.nrows() != d || cov.ncols() != d {
            return None;
        }
        let chol = cov.cholesky()?.l();
        let ln_det: f64 = (0..d).map(|i| chol[(i, i)].ln()).sum::<f64>() * 2.0;
        let ln_norm = -0.5 * (d as f64 * (2.0 * std::f64::consts::PI).ln() + ln_det);
        Some(Self { mean: DVector::from_vec(mean), chol, ln_norm })
    }
}

impl Prior for GaussianPrior {
    fn dim(&self) -> usize {
        self.mean.len()
    }

    fn sample(&self, rng: &mut dyn rand::RngCore) -> Vec<f64> {
        let z = DVector::from_iterator(
            self.dim(),
            (0..self.dim()).map(|_| rng.sample::<f64, _>(StandardNormal)),
        );
        (&self.mean + &self.chol * z).iter().copied().collect()
    }

    fn ln_density(&self, x: &[f64]) -> f64 {
        let r = DVector::from_column_slice(x) - &self.mean;
        match self.chol.solve_lower_triangular(&r) {
            Some(z) => self.ln_norm - 0.5 * z.norm_squared(),
            None => f64::NEG_INFINITY,
        }
    }
}
