//! Fisher information of a Gaussian-noise simulator and its geometric
//! complexity term ln ∫_box sqrt(det I1(θ)) dθ (seed eq. 3.63).
//!
//! I1(θ) = J^T J / sigma² / n, J = d eta / d theta (n_obs, k) from the
//! simulator when it can differentiate itself, else by central differences
//! with step 1e-6 of each box width. The integral is the box
//! volume times the mean of sqrt(det I1) over R Owen-scrambled Sobol'
//! replicates of N points; the replicate spread gives the standard error.

use crate::calibration::{CalibError, Simulator, UniformBox};
use nalgebra::DMatrix;

/// ln ∫ sqrt(det I1) and its standard error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FisherIntegral {
    /// ln of the integral.
    pub log_value: f64,
    /// Standard error of `log_value` (delta method over replicates).
    pub log_se: f64,
    /// Evaluation points used (N R).
    pub points: usize,
}

/// Jacobian d eta / d theta (n_obs, k): the simulator's own if it has one,
/// else central differences with step 1e-6 × width.
pub fn jacobian<S: Simulator + ?Sized>(
    sim: &S,
    theta: &[f64],
    width: &[f64],
) -> Result<DMatrix<f64>, CalibError> {
    if let Some(r) = sim.jacobian(theta) {
        return r.map(|(_, j)| j);
    }
    let k = theta.len();
    let mut j = DMatrix::zeros(sim.n_outputs(), k);
    let mut t = theta.to_vec();
    for p in 0..k {
        let h = 1e-6 * width[p];
        t[p] = theta[p] + h;
        let up = sim.predict(&t)?.mean;
        t[p] = theta[p] - h;
        let down = sim.predict(&t)?.mean;
        t[p] = theta[p];
        for i in 0..up.len() {
            j[(i, p)] = (up[i] - down[i]) / (2.0 * h);
        }
    }
    Ok(j)
}

/// Total Fisher information J^T J / sigma² (k, k).
pub fn fisher_total(j: &DMatrix<f64>, noise_sd: f64) -> DMatrix<f64> {
    j.transpose() * j / (noise_sd * noise_sd)
}

/// sqrt(det I1) at theta; 0 where I1 is singular.
pub fn sqrt_det_i1<S: Simulator + ?Sized>(
    sim: &S,
    theta: &[f64],
    width: &[f64],
    noise_sd: f64,
) -> Result<f64, CalibError> {
    let j = jacobian(sim, theta, width)?;
    let i1 = fisher_total(&j, noise_sd) / sim.n_outputs() as f64;
    Ok(i1.determinant().max(0.0).sqrt())
}

/// ln ∫_box sqrt(det I1) dθ from `replicates` scrambles of `points` Sobol' points.
pub fn log_fisher_integral<S: Simulator + ?Sized>(
    sim: &S,
    prior: &UniformBox,
    noise_sd: f64,
    points: usize,
    replicates: usize,
    seed: u32,
) -> Result<FisherIntegral, CalibError> {
    if points == 0 || replicates < 2 {
        return Err(CalibError::invalid(
            "qmc points x replicates",
            format!("{points} x {replicates}"),
            "points >= 1 and replicates >= 2",
        ));
    }
    let d = prior.dim();
    let width: Vec<f64> = (0..d).map(|j| prior.upper[j] - prior.lower[j]).collect();
    let mut means = Vec::with_capacity(replicates);
    for r in 0..replicates {
        let rseed = seed.wrapping_mul(7919).wrapping_add(r as u32);
        let mut sum = 0.0;
        for i in 0..points {
            let theta: Vec<f64> = (0..d)
                .map(|j| {
                    prior.lower[j]
                        + width[j] * sobol_burley::sample(i as u32, j as u32, rseed) as f64
                })
                .collect();
            sum += sqrt_det_i1(sim, &theta, &width, noise_sd)?;
        }
        means.push(sum / points as f64);
    }
    let r = replicates as f64;
    let mean = means.iter().sum::<f64>() / r;
    let sd = (means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (r - 1.0)).sqrt();
    Ok(FisherIntegral {
        log_value: prior.log_volume() + mean.ln(),
        log_se: sd / r.sqrt() / mean,
        points: points * replicates,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibration::FnSimulator;

    /// Linear model eta = a x_i + b: I1 is constant, so the integral is
    /// sqrt(det I1) times the box volume exactly.
    #[test]
    fn linear_model_integral_is_exact() {
        let x = [0.0, 1.0, 2.0, 3.0];
        let sim = FnSimulator::new(2, 4, move |t: &[f64]| {
            Ok(x.iter().map(|x| t[0] * x + t[1]).collect())
        });
        let prior =
            UniformBox::new(vec!["a".into(), "b".into()], vec![0.0, -1.0], vec![2.0, 2.0]).unwrap();
        let fi = log_fisher_integral(&sim, &prior, 0.5, 64, 4, 1).unwrap();
        // J^T J = [[14, 6], [6, 4]], det = 20; I1 = J^T J / 0.25 / 4.
        let expected = (20.0f64.sqrt() / 0.25 / 4.0 * 6.0).ln();
        assert!((fi.log_value - expected).abs() < 1e-6, "{} vs {expected}", fi.log_value);
    }
}
