//! Multi-start maximum-likelihood fit inside a prior box from the centre and
//! scrambled-Sobol' starting points: bounded L-BFGS in the box scaled to the
//! unit cube when the likelihood gives its gradient, else Nelder–Mead in the
//! logit coordinates of the box.

use super::nelder_mead::nelder_mead;
use crate::calibration::{Likelihood, UniformBox};
use crate::gp::lbfgs::{minimise, LbfgsSettings};

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
        let (x, f) = match gradient_fit(lik, prior, &prior.to_physical(&z0)) {
            Some((theta, f)) => (prior.to_unconstrained(&theta).unwrap_or(z0), f),
            None => {
                let m = nelder_mead(&nll, &z0, 0.5, 1e-10, 4000);
                let m = nelder_mead(&nll, &m.x, 0.05, 1e-12, 4000);
                (m.x, m.f)
            }
        };
        per_start.push(f);
        if best.as_ref().is_none_or(|b| f < b.1) {
            best = Some((x, f));
        }
    }
    let (z, f) = best.unwrap_or((vec![0.0; prior.dim()], f64::INFINITY));
    MlFit { theta: prior.to_physical(&z), neg_log_likelihood: f, per_start }
}

/// Bounded L-BFGS on u in the unit cube, theta = lower + u (upper − lower),
/// from `theta0`; None when the likelihood has no gradient or fails there.
/// The optimum may lie on the box boundary; it is pulled inside by 1e-9 of
/// the width so that it maps to finite logit coordinates.
fn gradient_fit<L: Likelihood>(
    lik: &L,
    prior: &UniformBox,
    theta0: &[f64],
) -> Option<(Vec<f64>, f64)> {
    let d = prior.dim();
    let width: Vec<f64> = (0..d).map(|j| prior.upper[j] - prior.lower[j]).collect();
    let theta_of = |u: &[f64]| -> Vec<f64> {
        (0..d).map(|j| prior.lower[j] + width[j] * u[j].clamp(1e-9, 1.0 - 1e-9)).collect()
    };
    let mut grad = vec![0.0; d];
    lik.log_likelihood_gradient(theta0, &mut grad)?.ok()?;
    let f = |u: &[f64]| -> Option<(f64, Vec<f64>)> {
        let mut g = vec![0.0; d];
        let ll = lik.log_likelihood_gradient(&theta_of(u), &mut g)?.ok()?;
        ll.is_finite().then(|| (-ll, (0..d).map(|j| -g[j] * width[j]).collect()))
    };
    let u0: Vec<f64> = (0..d).map(|j| (theta0[j] - prior.lower[j]) / width[j]).collect();
    let set = LbfgsSettings { max_iter: 500, gtol: 1e-8, ftol: 1e-12, ..LbfgsSettings::default() };
    let r = minimise(f, &u0, &vec![0.0; d], &vec![1.0; d], &set)?;
    Some((theta_of(&r.x), r.f))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibration::simulator::test_support::Smooth;
    use crate::calibration::{Hyper, KohLikelihood, KohSettings};

    fn lik(with_jacobian: bool) -> KohLikelihood<Smooth> {
        let s = KohSettings {
            alpha: Hyper::Fixed(1.0),
            noise_sd: Hyper::Fixed(0.1),
            disc_sd: Hyper::Fixed(0.2),
            disc_length: Hyper::Fixed(1.0),
        };
        let x = vec![vec![1.0], vec![2.0], vec![3.0]];
        KohLikelihood::new(Smooth(with_jacobian), x, vec![1.3, 0.7, 0.75], s).unwrap()
    }

    /// L-BFGS on the gradient finds the Nelder–Mead optimum, inside the box
    /// and on its boundary.
    #[test]
    fn gradient_fit_agrees_with_nelder_mead() {
        for upper_b in [2.0, 0.6] {
            let prior =
                UniformBox::new(vec!["a".into(), "b".into()], vec![0.0, 0.0], vec![2.0, upper_b])
                    .unwrap();
            let (g, n) = (fit_ml(&lik(true), &prior, 4, 3), fit_ml(&lik(false), &prior, 4, 3));
            assert!(gradient_fit(&lik(true), &prior, &[1.0, 0.3]).is_some());
            assert!(gradient_fit(&lik(false), &prior, &[1.0, 0.3]).is_none());
            assert!((g.neg_log_likelihood - n.neg_log_likelihood).abs() < 1e-7, "{g:?} {n:?}");
            for j in 0..2 {
                assert!((g.theta[j] - n.theta[j]).abs() < 1e-4, "{g:?} {n:?}");
            }
        }
    }
}
