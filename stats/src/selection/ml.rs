//! Multi-start maximum-likelihood fit inside a prior box: Nelder–Mead in
//! the logit coordinates of the box from the centre and scrambled-Sobol'
//! starting points.

use super::nelder_mead::nelder_mead;
use crate::calibration::{Likelihood, UniformBox};

/// The maximum-likelihood fit.
#[derive(Debug, Clone, PartialEq)]
pub struct MlFit {
    /// theta-hat in physical units.
    pub theta: Vec<f64>,
    /// −log L(theta-hat).
    pub neg_log_likelihood: f64,
    /// −log L at the best point of each start.
    pub per_start: Vec<f64>,
}

/// Start points in the unconstrained space: the centre then `starts − 1` Sobol' points.
fn start_points(prior: &UniformBox, starts: usize, seed: u32) -> Vec<Vec<f64>> {
    let d = prior.dim();
    let mut pts = vec![vec![0.0; d]];
    for i in 1..starts {
        let u: Vec<f64> =
            (0..d).map(|j| sobol_burley::sample(i as u32, j as u32, seed) as f64).collect();
        pts.push(u.iter().map(|u| ((0.02 + 0.96 * u) / (1.0 - 0.02 - 0.96 * u)).ln()).collect());
    }
    pts
}

/// Maximises `lik` over `prior` from `starts` points (at least 1).
pub fn fit_ml<L: Likelihood>(lik: &L, prior: &UniformBox, starts: usize, seed: u32) -> MlFit {
    let nll = |z: &[f64]| -> f64 {
        match lik.log_likelihood(&prior.to_physical(z)) {
            Ok(v) if v.is_finite() => -v,
            _ => f64::INFINITY,
        }
    };
    let mut best: Option<(Vec<f64>, f64)> = None;
    let mut per_start = Vec::new();
    for z0 in start_points(prior, starts.max(1), seed) {
        let m = nelder_mead(&nll, &z0, 0.5, 1e-10, 4000);
        let m = nelder_mead(&nll, &m.x, 0.05, 1e-12, 4000);
        per_start.push(m.f);
        if best.as_ref().is_none_or(|b| m.f < b.1) {
            best = Some((m.x, m.f));
        }
    }
    let (z, f) = best.unwrap_or((vec![0.0; prior.dim()], f64::INFINITY));
    MlFit { theta: prior.to_physical(&z), neg_log_likelihood: f, per_start }
}
