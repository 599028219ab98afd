//! Independent Gaussian noise likelihood y_i = eta_i(theta) + eps_i,
//! eps_i ~ N(0, sigma² + v_i), v_i the emulator variance (0 for a direct model).

use super::{CalibError, Hyper, Likelihood, Simulator};
use std::f64::consts::PI;

/// Plain Gaussian likelihood with known or inferred noise sd.
pub struct GaussianLikelihood<S> {
    sim: S,
    y: Vec<f64>,
    noise_sd: Hyper,
}

impl<S: Simulator> GaussianLikelihood<S> {
    /// Observations `y` (n_obs) of `sim`; noise sd in units of y.
    pub fn new(sim: S, y: Vec<f64>, noise_sd: Hyper) -> Result<Self, CalibError> {
        CalibError::check_len("observations", y.len(), sim.n_outputs())?;
        noise_sd.check_positive("noise_sd")?;
        if let Some(v) = y.iter().find(|v| !v.is_finite()) {
            return Err(CalibError::invalid("y", v, "finite observations"));
        }
        Ok(Self { sim, y, noise_sd })
    }

    /// The simulator.
    pub fn simulator(&self) -> &S {
        &self.sim
    }

    /// The observations.
    pub fn observations(&self) -> &[f64] {
        &self.y
    }
}

/// Sum of log N(r_i; 0, var_i).
pub fn gaussian_log_density(resid: &[f64], var: impl Iterator<Item = f64>) -> f64 {
    resid.iter().zip(var).map(|(r, v)| -0.5 * (r * r / v + (2.0 * PI * v).ln())).sum()
}

impl<S: Simulator> Likelihood for GaussianLikelihood<S> {
    fn n_sim_params(&self) -> usize {
        self.sim.n_params()
    }
    fn extra_names(&self) -> Vec<String> {
        if self.noise_sd.is_inferred() {
            vec!["noise_sd".into()]
        } else {
            vec![]
        }
    }
    fn n_obs(&self) -> usize {
        self.y.len()
    }
    fn log_likelihood(&self, params: &[f64]) -> Result<f64, CalibError> {
        CalibError::check_len("parameters", params.len(), self.n_params())?;
        let np = self.sim.n_params();
        let pred = self.sim.predict(&params[..np])?;
        let mut next = np;
        let s2 = self.noise_sd.value(params, &mut next).powi(2);
        let resid: Vec<f64> = self.y.iter().zip(&pred.mean).map(|(y, m)| y - m).collect();
        Ok(match &pred.variance {
            None => gaussian_log_density(&resid, std::iter::repeat(s2)),
            Some(v) => gaussian_log_density(&resid, v.iter().map(|v| s2 + v)),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibration::FnSimulator;

    #[test]
    fn standard_normal_at_zero_residual() {
        let sim = FnSimulator::new(1, 1, |t: &[f64]| Ok(vec![t[0]]));
        let lik = GaussianLikelihood::new(sim, vec![0.0], Hyper::Fixed(1.0)).unwrap();
        let ll = lik.log_likelihood(&[0.0]).unwrap();
        assert!((ll + 0.5 * (2.0 * PI).ln()).abs() < 1e-14);
    }

    #[test]
    fn inferred_noise_is_the_last_parameter() {
        let sim = FnSimulator::new(1, 1, |t: &[f64]| Ok(vec![t[0]]));
        let lik = GaussianLikelihood::new(sim, vec![1.0], Hyper::Inferred).unwrap();
        assert_eq!(lik.extra_names(), vec!["noise_sd".to_string()]);
        let ll = lik.log_likelihood(&[0.0, 2.0]).unwrap();
        assert!((ll - (-0.5 * (0.25 + (2.0 * PI * 4.0).ln()))).abs() < 1e-14);
    }

    #[test]
    fn wrong_length_is_refused() {
        let sim = FnSimulator::new(1, 2, |t: &[f64]| Ok(vec![t[0], t[0]]));
        assert!(GaussianLikelihood::new(sim, vec![1.0], Hyper::Fixed(1.0)).is_err());
    }
}
