//! Independent Gaussian noise likelihood y_i = eta_i(theta) + eps_i,
//! eps_i ~ N(0, (sigma c_i)² + v_i), v_i the emulator variance (0 for a
//! direct model), c_i a per-observation scale (1 unless given).

use super::{CalibError, Hyper, Likelihood, Simulator};
use std::f64::consts::PI;

/// Plain Gaussian likelihood with known or inferred noise sd.
pub struct GaussianLikelihood<S> {
    sim: S,
    y: Vec<f64>,
    noise_sd: Hyper,
    noise_scale: Vec<f64>,
}

impl<S: Simulator> GaussianLikelihood<S> {
    /// Observations `y` (n_obs) of `sim`; noise sd in units of y.
    pub fn new(sim: S, y: Vec<f64>, noise_sd: Hyper) -> Result<Self, CalibError> {
        CalibError::check_len("observations", y.len(), sim.n_outputs())?;
        noise_sd.check_positive("noise_sd")?;
        if let Some(v) = y.iter().find(|v| !v.is_finite()) {
            return Err(CalibError::invalid("y", v, "finite observations"));
        }
        let noise_scale = vec![1.0; y.len()];
        Ok(Self { sim, y, noise_sd, noise_scale })
    }

    /// Observation i gets noise sd `noise_sd * scale[i]` (e.g. noise_sd
    /// fixed at 1 and `scale` the measured sds).
    pub fn with_noise_scale(mut self, scale: Vec<f64>) -> Result<Self, CalibError> {
        CalibError::check_len("noise scales", scale.len(), self.y.len())?;
        if let Some(s) = scale.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
            return Err(CalibError::invalid("noise scale", s, "a finite value > 0"));
        }
        self.noise_scale = scale;
        Ok(self)
    }

    /// Total variance of each observation for noise sd `s` and emulator variance `v`.
    fn variances(&self, s: f64, v: Option<&[f64]>) -> Vec<f64> {
        let c = &self.noise_scale;
        (0..self.y.len()).map(|i| (s * c[i]).powi(2) + v.map_or(0.0, |v| v[i])).collect()
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
        let s = self.noise_sd.value(params, &mut next);
        let resid: Vec<f64> = self.y.iter().zip(&pred.mean).map(|(y, m)| y - m).collect();
        Ok(gaussian_log_density(&resid, self.variances(s, pred.variance.as_deref()).into_iter()))
    }
    /// From the simulator's Jacobian: sum_i r_i / v_i J_i in the simulator
    /// parameters, sum_i s (r_i² / v_i² − 1 / v_i) in an inferred noise sd s.
    fn log_likelihood_gradient(
        &self,
        params: &[f64],
        grad: &mut [f64],
    ) -> Option<Result<f64, CalibError>> {
        if let Err(e) = CalibError::check_len("parameters", params.len(), self.n_params()) {
            return Some(Err(e));
        }
        let np = self.sim.n_params();
        let (pred, jac) = match self.sim.jacobian(&params[..np])? {
            Ok(v) => v,
            Err(e) => return Some(Err(e)),
        };
        let mut next = np;
        let s = self.noise_sd.value(params, &mut next);
        let var = self.variances(s, pred.variance.as_deref());
        let resid: Vec<f64> = self.y.iter().zip(&pred.mean).map(|(y, m)| y - m).collect();
        grad.iter_mut().for_each(|g| *g = 0.0);
        for (i, (r, v)) in resid.iter().zip(&var).enumerate() {
            for j in 0..np {
                grad[j] += r / v * jac[(i, j)];
            }
            if self.noise_sd.is_inferred() {
                let c2 = self.noise_scale[i] * self.noise_scale[i];
                grad[np] += s * c2 * (r * r / (v * v) - 1.0 / v);
            }
        }
        Some(Ok(gaussian_log_density(&resid, var.into_iter())))
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

#[cfg(test)]
mod gradient_tests {
    use super::*;
    use crate::calibration::posterior::fd_gradient;
    use crate::calibration::simulator::test_support::Smooth;
    use crate::calibration::{LogDensity, Posterior, UniformBox};

    #[test]
    fn analytic_gradient_matches_central_differences() {
        for noise in [Hyper::Fixed(0.3), Hyper::Inferred] {
            let lik = GaussianLikelihood::new(Smooth(true), vec![1.1, 0.4, 0.8], noise)
                .unwrap()
                .with_noise_scale(vec![1.0, 0.5, 2.0])
                .unwrap();
            let d = lik.n_params();
            let names: Vec<String> = ["a", "b", "s"][..d].iter().map(|s| s.to_string()).collect();
            let prior = UniformBox::new(
                names,
                vec![0.0, 0.0, 0.05][..d].to_vec(),
                vec![2.0, 2.0, 1.0][..d].to_vec(),
            )
            .unwrap();
            let post = Posterior::new(prior, lik).unwrap();
            let z = [0.3, -0.7, 0.2];
            let theta = post.to_physical(&z[..d]);
            assert!(post
                .likelihood()
                .log_likelihood_gradient(&theta, &mut [0.0; 3][..d])
                .is_some());
            let (mut g, mut f) = (vec![0.0; d], vec![0.0; d]);
            let v = post.gradient(&z[..d], &mut g);
            let w = fd_gradient(&post, &z[..d], &mut f);
            assert!((v - w).abs() < 1e-12 * w.abs(), "{v} vs {w}");
            for i in 0..d {
                assert!(
                    (g[i] - f[i]).abs() < 1e-5 * (1.0 + f[i].abs()),
                    "{i}: {} vs {}",
                    g[i],
                    f[i]
                );
            }
        }
    }
}

#[cfg(test)]
mod scale_tests {
    use super::*;
    use crate::calibration::FnSimulator;

    #[test]
    fn noise_scale_gives_each_observation_its_sd() {
        let sim = FnSimulator::new(1, 2, |t: &[f64]| Ok(vec![t[0], 1.0]));
        let lik = GaussianLikelihood::new(sim, vec![0.5, 1.6], Hyper::Fixed(1.0))
            .unwrap()
            .with_noise_scale(vec![0.1, 0.3])
            .unwrap();
        let want = [(0.2f64, 0.1f64), (0.6, 0.3)]
            .iter()
            .map(|(r, s)| -0.5 * (r * r / (s * s) + (2.0 * PI * s * s).ln()))
            .sum::<f64>();
        assert!((lik.log_likelihood(&[0.3]).unwrap() - want).abs() < 1e-12);
    }
}
