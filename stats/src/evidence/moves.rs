//! Random-walk Metropolis moves of a whole population at one temperature,
//! every proposal's likelihood asked for in one batch.

use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand_distr::StandardNormal;

/// Weighted mean and covariance of a population (weights normalised here).
pub fn weighted_covariance(x: &[Vec<f64>], w: &[f64]) -> DMatrix<f64> {
    let d = x.first().map_or(0, Vec::len);
    let total: f64 = w.iter().sum();
    let mut mean = DVector::zeros(d);
    for (xi, wi) in x.iter().zip(w) {
        mean += DVector::from_column_slice(xi) * (wi / total);
    }
    let mut cov = DMatrix::zeros(d, d);
    for (xi, wi) in x.iter().zip(w) {
        let r = DVector::from_column_slice(xi) - &mean;
        cov += &r * r.transpose() * (wi / total);
    }
    cov
}

/// The lower Cholesky factor of `cov`, with diagonal jitter grown until it
/// factors (a population on a lower-dimensional set, or a single point).
pub fn proposal_factor(cov: &DMatrix<f64>) -> DMatrix<f64> {
    let d = cov.nrows();
    let scale = (0..d).map(|i| cov[(i, i)].abs()).fold(0.0, f64::max).max(1e-300);
    let mut jitter = 1e-10 * scale;
    loop {
        let c = cov + DMatrix::identity(d, d) * jitter;
        if let Some(ch) = c.cholesky() {
            return ch.l();
        }
        jitter *= 10.0;
    }
}

/// One population's state at a temperature.
pub struct Population<'a> {
    /// Particles.
    pub x: &'a mut [Vec<f64>],
    /// Their log-likelihoods.
    pub ln_l: &'a mut [f64],
    /// Their log prior densities.
    pub ln_p: &'a mut [f64],
}

/// Proposes x + scale · L z for every particle; returns the proposals and
/// which of them lie in the prior's support (the others are rejected
/// without a likelihood evaluation).
pub fn propose(
    x: &[Vec<f64>],
    factor: &DMatrix<f64>,
    scale: f64,
    rng: &mut dyn rand::RngCore,
) -> Vec<Vec<f64>> {
    let d = factor.nrows();
    x.iter()
        .map(|xi| {
            let z = DVector::from_iterator(d, (0..d).map(|_| rng.sample::<f64, _>(StandardNormal)));
            let step = factor * z * scale;
            xi.iter().zip(step.iter()).map(|(a, b)| a + b).collect()
        })
        .collect()
}

/// Metropolis accept/reject at temperature β of proposals `y` with prior
/// log densities `ln_p_y` and log-likelihoods `ln_l_y`; returns the number
/// accepted.
pub fn accept(
    pop: &mut Population<'_>,
    y: Vec<Vec<f64>>,
    ln_p_y: &[f64],
    ln_l_y: &[f64],
    beta: f64,
    rng: &mut dyn rand::RngCore,
) -> usize {
    let mut accepted = 0;
    for (i, yi) in y.into_iter().enumerate() {
        if !ln_p_y[i].is_finite() || ln_l_y[i] == f64::NEG_INFINITY {
            continue;
        }
        let ln_ratio = ln_p_y[i] - pop.ln_p[i] + beta * (ln_l_y[i] - pop.ln_l[i]);
        if ln_ratio >= 0.0 || rng.random::<f64>().ln() < ln_ratio {
            pop.x[i] = yi;
            pop.ln_l[i] = ln_l_y[i];
            pop.ln_p[i] = ln_p_y[i];
            accepted += 1;
        }
    }
    accepted
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn covariance_of_two_points() {
        let c = weighted_covariance(&[vec![0.0, 0.0], vec![2.0, 4.0]], &[1.0, 1.0]);
        assert!((c[(0, 0)] - 1.0).abs() < 1e-12 && (c[(1, 1)] - 4.0).abs() < 1e-12);
        assert!((c[(0, 1)] - 2.0).abs() < 1e-12);
    }

    #[test]
    fn a_degenerate_population_still_factors() {
        let c = weighted_covariance(&[vec![1.0, 1.0], vec![1.0, 1.0]], &[1.0, 1.0]);
        let l = proposal_factor(&c);
        assert!(l.iter().all(|v| v.is_finite()));
    }
}
