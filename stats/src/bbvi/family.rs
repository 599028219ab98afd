//! Gaussian variational family q(z) = N(mu, L L^T) on R^d.
//!
//! Flat parameters lambda = [mu (d), omega (d), off-diagonal of L (d(d−1)/2,
//! full-rank only, row by row)], with L_ii = exp(omega_i) so L stays a valid
//! Cholesky factor.

use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand_distr::StandardNormal;
use std::f64::consts::PI;

/// Mean-field (diagonal) or full-rank covariance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FamilyKind {
    /// Independent coordinates.
    MeanField,
    /// Dense covariance through a Cholesky factor.
    FullRank,
}

/// A member of the Gaussian family.
#[derive(Debug, Clone, PartialEq)]
pub struct GaussianQ {
    /// Mean-field or full-rank.
    pub kind: FamilyKind,
    /// Dimension d.
    pub dim: usize,
    /// Flat variational parameters lambda.
    pub lambda: Vec<f64>,
}

impl GaussianQ {
    /// Number of flat parameters for `kind` in dimension `d`.
    pub fn n_lambda(kind: FamilyKind, d: usize) -> usize {
        match kind {
            FamilyKind::MeanField => 2 * d,
            FamilyKind::FullRank => 2 * d + d * (d - 1) / 2,
        }
    }

    /// Independent N(mean_i, sd_i²) as a member of `kind`.
    pub fn new(kind: FamilyKind, mean: &[f64], sd: &[f64]) -> Self {
        let d = mean.len();
        let mut lambda = vec![0.0; Self::n_lambda(kind, d)];
        lambda[..d].copy_from_slice(mean);
        for i in 0..d {
            lambda[d + i] = sd[i].ln();
        }
        Self { kind, dim: d, lambda }
    }

    /// Mean mu (d).
    pub fn mean(&self) -> &[f64] {
        &self.lambda[..self.dim]
    }

    /// Index of L_ij (i > j) in lambda.
    pub fn off_index(&self, i: usize, j: usize) -> usize {
        2 * self.dim + i * (i - 1) / 2 + j
    }

    /// The Cholesky factor L (d, d).
    pub fn cholesky(&self) -> DMatrix<f64> {
        let d = self.dim;
        let mut l = DMatrix::zeros(d, d);
        for i in 0..d {
            l[(i, i)] = self.lambda[d + i].exp();
            if self.kind == FamilyKind::FullRank {
                for j in 0..i {
                    l[(i, j)] = self.lambda[self.off_index(i, j)];
                }
            }
        }
        l
    }

    /// Covariance L L^T (d, d).
    pub fn covariance(&self) -> DMatrix<f64> {
        let l = self.cholesky();
        &l * l.transpose()
    }

    /// z = mu + L eps.
    pub fn transform(&self, l: &DMatrix<f64>, eps: &[f64]) -> Vec<f64> {
        let z = l * DVector::from_column_slice(eps);
        (0..self.dim).map(|i| self.lambda[i] + z[i]).collect()
    }

    /// Draws eps ~ N(0, I) and returns (eps, z).
    pub fn sample<R: Rng>(&self, l: &DMatrix<f64>, rng: &mut R) -> (Vec<f64>, Vec<f64>) {
        let eps: Vec<f64> = (0..self.dim).map(|_| rng.sample(StandardNormal)).collect();
        let z = self.transform(l, &eps);
        (eps, z)
    }

    /// Differential entropy sum omega + d/2 (1 + ln 2 pi).
    pub fn entropy(&self) -> f64 {
        let d = self.dim;
        self.lambda[d..2 * d].iter().sum::<f64>() + 0.5 * d as f64 * (1.0 + (2.0 * PI).ln())
    }

    /// log q(z) given eps = L^−1 (z − mu).
    pub fn log_q_of_eps(&self, eps: &[f64]) -> f64 {
        let d = self.dim;
        let omega: f64 = self.lambda[d..2 * d].iter().sum();
        -0.5 * eps.iter().map(|e| e * e).sum::<f64>() - omega - 0.5 * d as f64 * (2.0 * PI).ln()
    }

    /// log q(z) for any z (d).
    pub fn log_q(&self, z: &[f64]) -> f64 {
        let l = self.cholesky();
        let r = DVector::from_iterator(self.dim, (0..self.dim).map(|i| z[i] - self.lambda[i]));
        match l.solve_lower_triangular(&r) {
            Some(eps) => self.log_q_of_eps(eps.as_slice()),
            None => f64::NEG_INFINITY,
        }
    }

    /// Marginal standard deviations (d).
    pub fn sd(&self) -> Vec<f64> {
        let c = self.covariance();
        (0..self.dim).map(|i| c[(i, i)].sqrt()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn log_q_of_mean_is_normaliser() {
        let q = GaussianQ::new(FamilyKind::FullRank, &[1.0, 2.0], &[0.5, 2.0]);
        let lq = q.log_q(&[1.0, 2.0]);
        assert!((lq - (-(2.0 * PI).ln() - 1.0f64.ln())).abs() < 1e-12, "{lq}");
    }

    #[test]
    fn sample_covariance_matches() {
        let mut q = GaussianQ::new(FamilyKind::FullRank, &[0.0, 0.0], &[1.0, 0.5]);
        let k = q.off_index(1, 0);
        q.lambda[k] = 0.8;
        let l = q.cholesky();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let n = 200_000;
        let mut c01 = 0.0;
        for _ in 0..n {
            let (_, z) = q.sample(&l, &mut rng);
            c01 += z[0] * z[1];
        }
        let c = q.covariance();
        assert!((c01 / n as f64 - c[(1, 0)]).abs() < 0.01, "{} vs {}", c01 / n as f64, c[(1, 0)]);
    }
}
