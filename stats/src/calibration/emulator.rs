//! GP emulators as a calibration simulator: one fitted GP per observation,
//! all over the same physical parameters, each giving the predictive mean
//! and (optionally) its variance, which the likelihoods add to the noise.

use super::{CalibError, Prediction, Simulator};
use crate::gp::Gp;
use nalgebra::DMatrix;

/// One GP per observation over the same parameters.
pub struct GpEmulator {
    gps: Vec<Gp>,
    with_variance: bool,
}

impl GpEmulator {
    /// Emulators in observation order; `with_variance` passes each GP's
    /// latent predictive variance on to the likelihood.
    pub fn new(gps: Vec<Gp>, with_variance: bool) -> Result<Self, CalibError> {
        let Some(first) = gps.first() else {
            return Err(CalibError::invalid("emulators", 0, "at least one GP"));
        };
        let d = first.model.dim;
        if let Some((i, g)) = gps.iter().enumerate().find(|(_, g)| g.model.dim != d) {
            return Err(CalibError::invalid(
                &format!("emulator {i} inputs"),
                g.model.dim,
                &format!("{d} inputs like emulator 0"),
            ));
        }
        Ok(Self { gps, with_variance })
    }

    /// Each GP's latent predictive variance at `theta`.
    pub fn variance_at(&self, theta: &[f64]) -> Result<Vec<f64>, CalibError> {
        self.gps
            .iter()
            .map(|g| g.predict(theta, false).map(|p| p.sd[0] * p.sd[0]))
            .collect::<Result<_, _>>()
            .map_err(|e| CalibError::Simulator { theta: theta.to_vec(), message: e.to_string() })
    }

    /// The same emulators with the variance switched on or off.
    pub fn with_variance(mut self, on: bool) -> Self {
        self.with_variance = on;
        self
    }
}

impl Simulator for GpEmulator {
    fn n_params(&self) -> usize {
        self.gps[0].model.dim
    }
    fn n_outputs(&self) -> usize {
        self.gps.len()
    }
    fn predict(&self, theta: &[f64]) -> Result<Prediction, CalibError> {
        CalibError::check_len("emulator parameters", theta.len(), self.n_params())?;
        let fail = |e: crate::gp::GpError| CalibError::Simulator {
            theta: theta.to_vec(),
            message: e.to_string(),
        };
        if !self.with_variance {
            let mean = self
                .gps
                .iter()
                .map(|g| g.predict_mean(theta).map(|m| m[0]))
                .collect::<Result<Vec<_>, _>>()
                .map_err(fail)?;
            return Ok(Prediction { mean, variance: None });
        }
        let (mut mean, mut var) = (Vec::new(), Vec::new());
        for g in &self.gps {
            let p = g.predict(theta, false).map_err(fail)?;
            mean.push(p.mean[0]);
            var.push(p.sd[0] * p.sd[0]);
        }
        Ok(Prediction { mean, variance: Some(var) })
    }
    /// Analytic, in the means-only mode (the variance would depend on theta).
    fn jacobian(&self, theta: &[f64]) -> Option<Result<(Prediction, DMatrix<f64>), CalibError>> {
        if self.with_variance {
            return None;
        }
        if let Err(e) = CalibError::check_len("emulator parameters", theta.len(), self.n_params()) {
            return Some(Err(e));
        }
        let mut j = DMatrix::zeros(self.gps.len(), theta.len());
        let mut mean = Vec::with_capacity(self.gps.len());
        for (i, g) in self.gps.iter().enumerate() {
            match g.predict_mean_grad(theta) {
                Ok((m, grad)) => {
                    mean.push(m);
                    j.row_mut(i).copy_from_slice(&grad);
                }
                Err(e) => {
                    return Some(Err(CalibError::Simulator {
                        theta: theta.to_vec(),
                        message: e.to_string(),
                    }))
                }
            }
        }
        Some(Ok((Prediction { mean, variance: None }, j)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gp::mean::Trend;
    use crate::gp::warp::InputWarp;
    use crate::gp::{
        fit, FitReport, GpModel, GpSettings, InputScaling, Kernel, KernelKind, MeanKind,
        OutputScaling,
    };

    fn gps() -> Vec<Gp> {
        let x: Vec<f64> = (0..12).map(|i| i as f64 / 11.0).collect();
        let ya: Vec<f64> = x.iter().map(|v| (3.0 * v).sin()).collect();
        let yb: Vec<f64> = x.iter().map(|v| v * v).collect();
        let set = GpSettings::default();
        vec![fit(&x, 1, &ya, None, &set).unwrap(), fit(&x, 1, &yb, None, &set).unwrap()]
    }

    #[test]
    fn means_match_each_gp_and_variance_is_optional() {
        let gps = gps();
        let want: Vec<f64> =
            gps.iter().map(|g| g.predict(&[0.37], false).unwrap().mean[0]).collect();
        let sd: Vec<f64> = gps.iter().map(|g| g.predict(&[0.37], false).unwrap().sd[0]).collect();
        let emu = GpEmulator::new(gps, true).unwrap();
        let p = emu.predict(&[0.37]).unwrap();
        assert_eq!(p.mean, want);
        let var = p.variance.unwrap();
        assert!((var[0] - sd[0] * sd[0]).abs() < 1e-15 && (var[1] - sd[1] * sd[1]).abs() < 1e-15);
        let q = emu.with_variance(false).predict(&[0.37]).unwrap();
        assert!(q.variance.is_none());
        for (a, b) in q.mean.iter().zip(&want) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
        assert!((want[0] - (3.0f64 * 0.37).sin()).abs() < 1e-3);
    }

    /// A GP with set hyperparameters and noise (well conditioned, so that
    /// central differences are accurate).
    fn noisy_gp(kind: KernelKind, trend: Option<Trend>, warp: InputWarp) -> Gp {
        let x: Vec<f64> = (0..40)
            .flat_map(|i| [((i * 7) % 40) as f64 / 39.0, ((i * 13) % 40) as f64 / 39.0])
            .collect();
        let y: Vec<f64> = x.chunks(2).map(|p| (3.0 * p[0]).sin() + p[1] * p[1] - 0.5).collect();
        let model = GpModel {
            kernel: Kernel { kind, lengths: vec![0.3, 0.5], variance: 1.3, alpha: 1.5 },
            noise_var: 0.01,
            mean: if trend.is_some() { MeanKind::Linear } else { MeanKind::Constant },
            trend,
            input_scaling: InputScaling { lo: vec![0.2, 1.0], hi: vec![2.0, 3.0] },
            warp,
            output_scaling: OutputScaling { mean: 8.0, sd: 0.7 },
            x,
            y,
            dim: 2,
            report: FitReport {
                starts: 1,
                best_start: 0,
                lml: 0.0,
                start_lmls: vec![],
                evaluations: 0,
                jitter: 0.0,
            },
        };
        Gp::from_model(model).unwrap()
    }

    #[test]
    fn jacobian_matches_central_differences() {
        let kinds =
            [KernelKind::SquaredExponential, KernelKind::Matern52, KernelKind::RationalQuadratic];
        for kind in kinds {
            let warped = InputWarp::from_parts(&[Some(10.0), Some(3.0)], &[0.3, 1.7]);
            let cases = [
                (None, InputWarp::default()),
                (Some(Trend { beta: vec![0.2, -0.4, 0.9] }), InputWarp::default()),
                (None, warped),
            ];
            for (trend, warp) in cases {
                let emu = GpEmulator::new(vec![noisy_gp(kind, trend, warp)], false).unwrap();
                let t = [0.83, 0.61];
                let (p, j) = emu.jacobian(&t).unwrap().unwrap();
                let pm = emu.predict(&t).unwrap().mean[0];
                assert!(
                    (p.mean[0] - pm).abs() < 1e-12 * pm.abs(),
                    "{kind:?}: {} vs {pm}",
                    p.mean[0]
                );
                for k in 0..2 {
                    let h = 1e-5;
                    let (mut a, mut b) = (t, t);
                    a[k] += h;
                    b[k] -= h;
                    let fd = (emu.predict(&a).unwrap().mean[0] - emu.predict(&b).unwrap().mean[0])
                        / (2.0 * h);
                    let got = j[(0, k)];
                    assert!(
                        (got - fd).abs() < 1e-6 * (1.0 + fd.abs()),
                        "{kind:?} {k}: {got} vs {fd}"
                    );
                }
            }
        }
        assert!(GpEmulator::new(gps(), true).unwrap().jacobian(&[0.3]).is_none());
    }

    #[test]
    fn wrong_parameter_count_is_an_error() {
        let emu = GpEmulator::new(gps(), false).unwrap();
        assert!(emu.predict(&[0.1, 0.2]).is_err());
        assert!(GpEmulator::new(vec![], false).is_err());
    }
}
