//! Kennedy–O'Hagan likelihood (seed eqs. 6.3–6.11, Kennedy & O'Hagan 2001):
//! y = alpha eta(x, theta) + delta(x) + eps, delta ~ GP(0, k_SE), eps ~ N(0, sigma² I).
//! The discrepancy is marginalised: y − alpha eta ~ N(0, C) with
//! C = sigma² I + K_delta + alpha² diag(v), v the emulator's predictive
//! variance when there is one.
//! With every hyperparameter fixed and no emulator variance the Cholesky
//! factor is computed once.

use super::gaussian::gaussian_log_density;
use super::{CalibError, Hyper, Likelihood, Prediction, Simulator, SquaredExponential};
use nalgebra::{Cholesky, DMatrix, DVector, Dyn};
use std::f64::consts::PI;

/// Hyperparameters of the KOH likelihood, each fixed or inferred.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KohSettings {
    /// Scale alpha on the simulator (seed eq. 6.4); usually fixed at 1.
    pub alpha: Hyper,
    /// Observation noise sd sigma (units of y).
    pub noise_sd: Hyper,
    /// Discrepancy sd s (units of y).
    pub disc_sd: Hyper,
    /// Discrepancy length scale l (units of x).
    pub disc_length: Hyper,
}

/// Residual, alpha, noise sd, discrepancy kernel and emulator variance at one point.
type Parts = (Vec<f64>, f64, f64, SquaredExponential, Option<Vec<f64>>);

/// KOH likelihood with a squared-exponential GP discrepancy.
pub struct KohLikelihood<S> {
    sim: S,
    x: Vec<Vec<f64>>,
    y: Vec<f64>,
    settings: KohSettings,
    noise_scale: Vec<f64>,
    fixed_chol: Option<Cholesky<f64, Dyn>>,
}

impl<S: Simulator> KohLikelihood<S> {
    /// Observations `y` at input points `x` (n_obs, each of dimension D).
    pub fn new(
        sim: S,
        x: Vec<Vec<f64>>,
        y: Vec<f64>,
        settings: KohSettings,
    ) -> Result<Self, CalibError> {
        CalibError::check_len("observations", y.len(), sim.n_outputs())?;
        CalibError::check_len("input points", x.len(), y.len())?;
        settings.noise_sd.check_positive("noise_sd")?;
        settings.disc_sd.check_positive("discrepancy sd")?;
        settings.disc_length.check_positive("discrepancy length")?;
        let noise_scale = vec![1.0; y.len()];
        let mut me = Self { sim, x, y, settings, noise_scale, fixed_chol: None };
        me.refactor_fixed()?;
        Ok(me)
    }

    /// Observation i gets noise sd `noise_sd * scale[i]` (e.g. noise_sd fixed
    /// at 1 and `scale` the measured sds).
    pub fn with_noise_scale(mut self, scale: Vec<f64>) -> Result<Self, CalibError> {
        CalibError::check_len("noise scales", scale.len(), self.y.len())?;
        if let Some(s) = scale.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
            return Err(CalibError::invalid("noise scale", s, "a finite value > 0"));
        }
        self.noise_scale = scale;
        self.refactor_fixed()?;
        Ok(self)
    }

    /// Factors the covariance once when every hyperparameter is fixed.
    fn refactor_fixed(&mut self) -> Result<(), CalibError> {
        if let KohSettings {
            noise_sd: Hyper::Fixed(s),
            disc_sd: Hyper::Fixed(d),
            disc_length: Hyper::Fixed(l),
            ..
        } = self.settings
        {
            self.fixed_chol =
                Some(self.factor(s, SquaredExponential { sd: d, length: l }, None, 1.0)?);
        }
        Ok(())
    }

    fn factor(
        &self,
        noise_sd: f64,
        k: SquaredExponential,
        emu_var: Option<&[f64]>,
        alpha: f64,
    ) -> Result<Cholesky<f64, Dyn>, CalibError> {
        let mut c = k.matrix(&self.x);
        for i in 0..self.y.len() {
            let s = noise_sd * self.noise_scale[i];
            c[(i, i)] += s * s + emu_var.map_or(0.0, |v| alpha * alpha * v[i]);
        }
        Cholesky::new(c).ok_or(CalibError::NotPositiveDefinite { what: "KOH covariance".into() })
    }

    /// Residual y − alpha eta(theta) and the hyperparameters, from `params`.
    fn parts(&self, params: &[f64]) -> Result<Parts, CalibError> {
        CalibError::check_len("parameters", params.len(), self.n_params())?;
        let pred = self.sim.predict(&params[..self.sim.n_params()])?;
        Ok(self.parts_of(&pred, params))
    }

    /// As [`Self::parts`] for a given prediction.
    fn parts_of(&self, pred: &Prediction, params: &[f64]) -> Parts {
        let mut next = self.sim.n_params();
        let s = &self.settings;
        let alpha = s.alpha.value(params, &mut next);
        let noise = s.noise_sd.value(params, &mut next);
        let sd = s.disc_sd.value(params, &mut next);
        let length = s.disc_length.value(params, &mut next);
        let r = self.y.iter().zip(&pred.mean).map(|(y, m)| y - alpha * m).collect();
        (r, alpha, noise, SquaredExponential { sd, length }, pred.variance.clone())
    }

    /// log p(y | params) from its parts.
    fn log_likelihood_of(&self, parts: Parts) -> Result<f64, CalibError> {
        let (r, alpha, noise, k, var) = parts;
        if k.sd == 0.0 && var.is_none() {
            let var = self.noise_scale.iter().map(|s| (noise * s).powi(2));
            return Ok(gaussian_log_density(&r, var));
        }
        match (&self.fixed_chol, &var) {
            (Some(chol), None) => Ok(mvn_log_density(chol, &r)),
            _ => Ok(mvn_log_density(&self.factor(noise, k, var.as_deref(), alpha)?, &r)),
        }
    }

    /// Gradient from the simulator's Jacobian: d/dtheta = alpha J^T C^-1 r
    /// (C does not depend on theta); central differences in the few
    /// hyperparameters, with the prediction held.
    fn gradient_with(
        &self,
        pred: &Prediction,
        jac: &DMatrix<f64>,
        params: &[f64],
        grad: &mut [f64],
    ) -> Result<f64, CalibError> {
        let (r, alpha, noise, k, var) = self.parts_of(pred, params);
        let chol = self.factor(noise, k, var.as_deref(), alpha)?;
        let w = chol.solve(&DVector::from_column_slice(&r));
        let np = self.sim.n_params();
        let g = jac.transpose() * &w * alpha;
        grad[..np].copy_from_slice(g.as_slice());
        let mut p = params.to_vec();
        for i in np..params.len() {
            let h = 1e-6 * (1.0 + params[i].abs());
            p[i] = params[i] + h;
            let up = self.log_likelihood_of(self.parts_of(pred, &p))?;
            p[i] = params[i] - h;
            let down = self.log_likelihood_of(self.parts_of(pred, &p))?;
            p[i] = params[i];
            grad[i] = (up - down) / (2.0 * h);
        }
        Ok(mvn_log_density(&chol, &r))
    }

    /// Posterior mean of the discrepancy delta at the observation points given `params`.
    pub fn discrepancy_mean(&self, params: &[f64]) -> Result<Vec<f64>, CalibError> {
        let (r, alpha, noise, k, var) = self.parts(params)?;
        let chol = self.factor(noise, k, var.as_deref(), alpha)?;
        let w = chol.solve(&DVector::from_vec(r));
        Ok((k.matrix(&self.x) * w).iter().copied().collect())
    }
}

/// log N(r; 0, C) from the Cholesky factor of C.
pub fn mvn_log_density(chol: &Cholesky<f64, Dyn>, r: &[f64]) -> f64 {
    let n = r.len();
    let l: DMatrix<f64> = chol.l();
    let Some(z) = l.solve_lower_triangular(&DVector::from_column_slice(r)) else {
        return f64::NAN;
    };
    let log_det: f64 = (0..n).map(|i| l[(i, i)].ln()).sum();
    -0.5 * z.norm_squared() - log_det - 0.5 * n as f64 * (2.0 * PI).ln()
}

impl<S: Simulator> Likelihood for KohLikelihood<S> {
    fn n_sim_params(&self) -> usize {
        self.sim.n_params()
    }
    fn extra_names(&self) -> Vec<String> {
        let s = &self.settings;
        [
            (s.alpha, "alpha"),
            (s.noise_sd, "noise_sd"),
            (s.disc_sd, "disc_sd"),
            (s.disc_length, "disc_length"),
        ]
        .iter()
        .filter(|(h, _)| h.is_inferred())
        .map(|(_, n)| n.to_string())
        .collect()
    }
    fn n_obs(&self) -> usize {
        self.y.len()
    }
    fn log_likelihood(&self, params: &[f64]) -> Result<f64, CalibError> {
        self.log_likelihood_of(self.parts(params)?)
    }
    fn log_likelihood_gradient(
        &self,
        params: &[f64],
        grad: &mut [f64],
    ) -> Option<Result<f64, CalibError>> {
        if let Err(e) = CalibError::check_len("parameters", params.len(), self.n_params()) {
            return Some(Err(e));
        }
        Some(match self.sim.jacobian(&params[..self.sim.n_params()])? {
            Ok((pred, jac)) => self.gradient_with(&pred, &jac, params, grad),
            Err(e) => Err(e),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibration::simulator::test_support::Smooth;
    use crate::calibration::{FnSimulator, GaussianLikelihood};

    fn settings(d: f64) -> KohSettings {
        KohSettings {
            alpha: Hyper::Fixed(1.0),
            noise_sd: Hyper::Fixed(0.3),
            disc_sd: Hyper::Fixed(d),
            disc_length: Hyper::Fixed(0.5),
        }
    }

    #[test]
    fn analytic_gradient_matches_central_differences() {
        use crate::calibration::posterior::fd_gradient;
        use crate::calibration::{LogDensity, Posterior, UniformBox};
        let s = KohSettings {
            alpha: Hyper::Inferred,
            noise_sd: Hyper::Fixed(1.0),
            disc_sd: Hyper::Inferred,
            disc_length: Hyper::Inferred,
        };
        let x = vec![vec![1.0], vec![2.0], vec![3.0]];
        let lik = KohLikelihood::new(Smooth(true), x, vec![1.1, 0.4, 0.8], s)
            .unwrap()
            .with_noise_scale(vec![0.1, 0.05, 0.2])
            .unwrap();
        let names = ["a", "b", "alpha", "sd", "l"].map(String::from).to_vec();
        let prior =
            UniformBox::new(names, vec![0.0, 0.0, 0.5, 0.01, 0.5], vec![2.0, 2.0, 2.0, 1.0, 4.0])
                .unwrap();
        let post = Posterior::new(prior, lik).unwrap();
        let z = [0.3, -0.7, 0.2, -0.4, 0.9];
        let (mut g, mut f) = ([0.0; 5], [0.0; 5]);
        let theta = post.to_physical(&z);
        assert!(post.likelihood().log_likelihood_gradient(&theta, &mut [0.0; 5]).is_some());
        let v = post.gradient(&z, &mut g);
        let w = fd_gradient(&post, &z, &mut f);
        assert!((v - w).abs() < 1e-12 * w.abs(), "{v} vs {w}");
        for i in 0..5 {
            assert!((g[i] - f[i]).abs() < 1e-5 * (1.0 + f[i].abs()), "{i}: {} vs {}", g[i], f[i]);
        }
    }

    #[test]
    fn tiny_discrepancy_reduces_to_gaussian() {
        let sim = || FnSimulator::new(1, 3, |t: &[f64]| Ok(vec![t[0], 2.0 * t[0], 0.5]));
        let x = vec![vec![0.0], vec![0.5], vec![1.0]];
        let y = vec![0.9, 2.2, 0.4];
        let koh = KohLikelihood::new(sim(), x, y.clone(), settings(1e-9)).unwrap();
        let g = GaussianLikelihood::new(sim(), y, Hyper::Fixed(0.3)).unwrap();
        let (a, b) = (koh.log_likelihood(&[1.1]).unwrap(), g.log_likelihood(&[1.1]).unwrap());
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }

    #[test]
    fn noise_scale_gives_each_observation_its_sd() {
        let sim = || FnSimulator::new(1, 3, |t: &[f64]| Ok(vec![t[0], 2.0 * t[0], 0.5]));
        let x = vec![vec![0.0], vec![0.5], vec![1.0]];
        let y = vec![0.9, 2.2, 0.4];
        let sds = vec![0.1, 0.3, 0.05];
        let mut s = settings(1e-9);
        s.noise_sd = Hyper::Fixed(1.0);
        let koh = KohLikelihood::new(sim(), x, y.clone(), s).unwrap();
        let koh = koh.with_noise_scale(sds.clone()).unwrap();
        let m = [1.1, 2.2, 0.5];
        let want: f64 = (0..3)
            .map(|i| {
                let r: f64 = y[i] - m[i];
                -0.5 * (r * r / (sds[i] * sds[i]) + (2.0 * PI * sds[i] * sds[i]).ln())
            })
            .sum();
        let got = koh.log_likelihood(&[1.1]).unwrap();
        assert!((got - want).abs() < 1e-6, "{got} vs {want}");
    }

    /// A GP emulator's predictive variance v adds alpha² v to the diagonal.
    struct Emulator;
    impl Simulator for Emulator {
        fn n_params(&self) -> usize {
            1
        }
        fn n_outputs(&self) -> usize {
            2
        }
        fn predict(&self, t: &[f64]) -> Result<crate::calibration::Prediction, CalibError> {
            Ok(crate::calibration::Prediction {
                mean: vec![t[0], 2.0 * t[0]],
                variance: Some(vec![0.01, 0.04]),
            })
        }
    }

    #[test]
    fn emulator_variance_enters_the_covariance() {
        let x = vec![vec![0.0], vec![1.0]];
        let s = KohSettings { alpha: Hyper::Fixed(2.0), ..settings(1e-9) };
        let koh = KohLikelihood::new(Emulator, x, vec![1.0, 1.5], s).unwrap();
        // Residuals y − 2 eta = (0.2, −0.1); variances 0.09 + 4 v = (0.13, 0.25).
        let expected = gaussian_log_density(&[0.2, -0.1], [0.13, 0.25].into_iter());
        assert!((koh.log_likelihood(&[0.4]).unwrap() - expected).abs() < 1e-9);
        let g = GaussianLikelihood::new(Emulator, vec![0.4, 0.7], Hyper::Fixed(0.3)).unwrap();
        let expected = gaussian_log_density(&[0.0, -0.1], [0.1, 0.13].into_iter());
        assert!((g.log_likelihood(&[0.4]).unwrap() - expected).abs() < 1e-12);
    }

    #[test]
    fn inferred_matches_fixed() {
        let sim = || FnSimulator::new(1, 2, |t: &[f64]| Ok(vec![t[0], -t[0]]));
        let x = vec![vec![0.0], vec![0.2]];
        let fixed = KohLikelihood::new(sim(), x.clone(), vec![0.1, 0.3], settings(0.2)).unwrap();
        let inf = KohSettings { disc_sd: Hyper::Inferred, ..settings(0.2) };
        let inferred = KohLikelihood::new(sim(), x, vec![0.1, 0.3], inf).unwrap();
        assert_eq!(inferred.extra_names(), vec!["disc_sd".to_string()]);
        let (a, b) =
            (fixed.log_likelihood(&[0.4]).unwrap(), inferred.log_likelihood(&[0.4, 0.2]).unwrap());
        assert!((a - b).abs() < 1e-12);
    }
}
