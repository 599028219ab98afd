//! A fitted GP: the self-describing model (kernel, hyperparameters,
//! scaling, training data) and its Cholesky factor, with predictions of the
//! mean, sd and full covariance in physical output units.

use super::error::GpError;
use super::kernel::Kernel;
use super::likelihood::{factor, Factor};
use super::mean::{MeanKind, Trend};
use super::scaling::{InputScaling, OutputScaling};
use super::warp::InputWarp;
use faer::Mat;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// How the hyperparameter search went.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitReport {
    /// Number of optimiser starts.
    pub starts: usize,
    /// Index of the winning start (0 = default start).
    pub best_start: usize,
    /// Maximised log marginal likelihood (standardised outputs).
    pub lml: f64,
    /// Final LML of each start (None where it failed).
    pub start_lmls: Vec<Option<f64>>,
    /// Total LML evaluations over all starts.
    pub evaluations: usize,
    /// Jitter added to the diagonal of the final factor.
    pub jitter: f64,
}

/// Everything needed to rebuild a fitted GP (serialisable).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GpModel {
    /// Kernel with fitted hyperparameters.
    pub kernel: Kernel,
    /// Input warps applied to the scaled inputs before the kernel.
    #[serde(default)]
    pub warp: InputWarp,
    /// White-noise variance (standardised output units).
    pub noise_var: f64,
    /// Prior mean kind.
    pub mean: MeanKind,
    /// Linear trend when `mean` is linear.
    pub trend: Option<Trend>,
    /// Input scaling to [0, 1].
    pub input_scaling: InputScaling,
    /// Output standardisation of the residual.
    pub output_scaling: OutputScaling,
    /// Scaled (unwarped) training inputs, (n, d) row-major.
    pub x: Vec<f64>,
    /// Standardised training residuals, (n).
    pub y: Vec<f64>,
    /// Number of inputs d.
    pub dim: usize,
    /// Optimiser report.
    pub report: FitReport,
}

/// Prediction points as scaled and as warped, with K(X, x*).
struct Cross {
    /// Scaled points, (m, d) row-major.
    xs: Vec<f64>,
    /// Warped scaled points, (m, d) row-major.
    xw: Vec<f64>,
    /// Cross-covariance with the training points, (n, m).
    ks: Mat<f64>,
}

/// A fitted GP ready to predict.
pub struct Gp {
    /// The model description.
    pub model: GpModel,
    /// Warped scaled training inputs (the kernel's coordinates).
    xw: Vec<f64>,
    factor: Factor,
}

/// Predictive mean and sd at a set of points (physical output units).
#[derive(Debug, Clone, PartialEq)]
pub struct Prediction {
    /// Predictive means, (m).
    pub mean: Vec<f64>,
    /// Predictive sds, (m).
    pub sd: Vec<f64>,
}

impl Gp {
    /// Factor the covariance of a model description.
    pub fn from_model(mut model: GpModel) -> Result<Self, GpError> {
        let xw = model.warp.apply(&model.x, model.dim);
        let factor = factor(&model.kernel, model.noise_var, &xw, model.dim, &model.y)?;
        model.report.jitter = factor.jitter;
        Ok(Gp { model, xw, factor })
    }

    /// Number of training points.
    pub fn n_train(&self) -> usize {
        self.model.y.len()
    }

    /// Scaled points, warped points and the (n, m) cross-covariance K(X, x*).
    fn cross(&self, x: &[f64]) -> Result<Cross, GpError> {
        let d = self.model.dim;
        if !x.len().is_multiple_of(d) {
            return Err(GpError::Shape {
                what: "prediction points",
                expected: d,
                found: x.len() % d,
            });
        }
        let xs = self.model.input_scaling.apply(x);
        let xw = self.model.warp.apply(&xs, d);
        let m = xs.len() / d;
        let n = self.n_train();
        let tx = &self.xw;
        let k = &self.model.kernel;
        let ks = Mat::<f64>::from_fn(n, m, |i, j| {
            k.eval(&tx[i * d..(i + 1) * d], &xw[j * d..(j + 1) * d])
        });
        Ok(Cross { xs, xw, ks })
    }

    /// Means in physical units from scaled points and cross-covariance.
    fn means(&self, xs: &[f64], ks: &Mat<f64>) -> Vec<f64> {
        let d = self.model.dim;
        let out = self.model.output_scaling;
        (0..ks.ncols())
            .map(|j| {
                let f: f64 = (0..ks.nrows()).map(|i| ks[(i, j)] * self.factor.alpha[i]).sum();
                let trend =
                    self.model.trend.as_ref().map_or(0.0, |t| t.eval(&xs[j * d..(j + 1) * d]));
                trend + out.mean + out.sd * f
            })
            .collect()
    }

    /// V = L⁻¹ K(X, x*), (n, m).
    fn whitened(&self, mut ks: Mat<f64>) -> Mat<f64> {
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(
            self.factor.llt.L(),
            ks.as_mut(),
            faer::Par::Seq,
        );
        ks
    }

    /// Predictive means only at the (m, d) physical points (no triangular
    /// solve: O(n m d), in blocks of 512 points to bound memory; for
    /// Sobol' samples and Jacobians).
    pub fn predict_mean(&self, x: &[f64]) -> Result<Vec<f64>, GpError> {
        let block = 512 * self.model.dim.max(1);
        let mut out = Vec::with_capacity(x.len() / self.model.dim.max(1));
        for chunk in x.chunks(block) {
            let c = self.cross(chunk)?;
            out.extend(self.means(&c.xs, &c.ks));
        }
        Ok(out)
    }

    /// Predictive mean at one physical point and its gradient with respect
    /// to the physical inputs (d).
    pub fn predict_mean_grad(&self, x: &[f64]) -> Result<(f64, Vec<f64>), GpError> {
        let d = self.model.dim;
        if x.len() != d {
            return Err(GpError::Shape { what: "prediction point", expected: d, found: x.len() });
        }
        let xs = self.model.input_scaling.apply(x);
        let xw = self.model.warp.apply(&xs, d);
        let k = &self.model.kernel;
        let (mut f, mut g) = (0.0, vec![0.0; d]);
        for (i, row) in self.xw.chunks(d).enumerate() {
            let (shape, minus_2_dg, _) = k.shape(k.scaled_dist2(row, &xw));
            f += k.variance * shape * self.factor.alpha[i];
            let a = self.factor.alpha[i] * k.variance;
            for j in 0..d {
                let l = k.lengths[j];
                g[j] -= a * minus_2_dg * (xw[j] - row[j]) / (l * l);
            }
        }
        let out = self.model.output_scaling;
        let sc = &self.model.input_scaling;
        let trend = self.model.trend.as_ref();
        let mean = trend.map_or(0.0, |t| t.eval(&xs)) + out.mean + out.sd * f;
        let grad = (0..d)
            .map(|j| {
                let slope = trend.map_or(0.0, |t| t.beta[j + 1]);
                let dw = self.model.warp.slope(j, xs[j]);
                (slope + out.sd * g[j] * dw) / (sc.hi[j] - sc.lo[j])
            })
            .collect();
        Ok((mean, grad))
    }

    /// Predictive mean and sd at the (m, d) physical points; `with_noise`
    /// adds the fitted white-noise variance (prediction of an observation).
    pub fn predict(&self, x: &[f64], with_noise: bool) -> Result<Prediction, GpError> {
        let Cross { xs, ks, .. } = self.cross(x)?;
        let mean = self.means(&xs, &ks);
        let v = self.whitened(ks);
        let out = self.model.output_scaling;
        let extra = if with_noise { self.model.noise_var } else { 0.0 };
        let sd = (0..v.ncols())
            .map(|j| {
                let q: f64 = (0..v.nrows()).map(|i| v[(i, j)] * v[(i, j)]).sum();
                out.sd * ((self.model.kernel.variance - q).max(0.0) + extra).sqrt()
            })
            .collect();
        Ok(Prediction { mean, sd })
    }

    /// Predictive mean and full (m, m) latent covariance (physical units).
    pub fn predict_cov(&self, x: &[f64]) -> Result<(Vec<f64>, DMatrix<f64>), GpError> {
        let Cross { xs, xw, ks } = self.cross(x)?;
        let mean = self.means(&xs, &ks);
        let v = self.whitened(ks);
        let d = self.model.dim;
        let m = mean.len();
        let s2 = self.model.output_scaling.sd.powi(2);
        let k = &self.model.kernel;
        let cov = DMatrix::from_fn(m, m, |a, b| {
            let prior = k.eval(&xw[a * d..(a + 1) * d], &xw[b * d..(b + 1) * d]);
            let q: f64 = (0..v.nrows()).map(|i| v[(i, a)] * v[(i, b)]).sum();
            s2 * (prior - q)
        });
        Ok((mean, cov))
    }

    /// Leave-one-out predictive means and sds at the training points
    /// (Rasmussen and Williams 2006, eq. 5.12): μ_i = y_i − α_i / [K⁻¹]_ii,
    /// σ²_i = 1 / [K⁻¹]_ii, in physical units (sds of observations).
    pub fn loo(&self) -> Prediction {
        use faer::linalg::solvers::DenseSolveCore;
        let kinv = self.factor.llt.inverse();
        let out = self.model.output_scaling;
        let d = self.model.dim;
        let n = self.n_train();
        let mut mean = Vec::with_capacity(n);
        let mut sd = Vec::with_capacity(n);
        for i in 0..n {
            let kii = kinv[(i, i)];
            let mu_s = self.model.y[i] - self.factor.alpha[i] / kii;
            let trend = self
                .model
                .trend
                .as_ref()
                .map_or(0.0, |t| t.eval(&self.model.x[i * d..(i + 1) * d]));
            mean.push(trend + out.mean + out.sd * mu_s);
            sd.push(out.sd / kii.sqrt());
        }
        Prediction { mean, sd }
    }
}
