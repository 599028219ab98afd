//! Stage 4: Kennedy–O'Hagan calibration of the kept parameters against the
//! measured values (seed eqs. 6.3–6.11):
//! y_i = alpha eta_i(theta) + delta(i) + eps_i, eta the GP emulators (their
//! predictive variance enters the covariance), delta a squared-exponential
//! GP over the observation index, eps_i ~ N(0, sd_i²) with the measured sds;
//! dropped parameters sit at their prior centres. The emulators' predictive
//! variance enters as extra noise, taken at the prior centre (constant, so
//! that the gradient through the emulator means is exact). Solved by BBVI
//! (or MCMC) in the unconstrained space of the uniform prior box.

use super::config::{CalibrationSection, ObservationsSection};
use anyhow::{anyhow, bail, Result};
use serde::Serialize;
use stats::calibration::{
    calibrate, CalibrationResult, GpEmulator, Hyper, KohLikelihood, KohSettings, Likelihood,
    Method, Posterior, RunSettings, Simulator, SubsetSimulator, UniformBox,
};

/// The emulators with the dropped parameters held at their centres.
type Sim<'a> = SubsetSimulator<&'a GpEmulator>;

/// One parameter's prior and posterior.
#[derive(Debug, Clone, Serialize)]
pub struct ParameterRow {
    /// Name.
    pub name: String,
    /// Prior bounds.
    pub prior: [f64; 2],
    /// Posterior mean, sd and quantiles.
    #[serde(flatten)]
    pub posterior: stats::calibration::Marginal,
    /// Posterior sd over the prior sd (width / sqrt 12): near 1, the data say little.
    pub sd_ratio: f64,
}

/// Predicted against measured at one observation.
#[derive(Debug, Clone, Serialize)]
pub struct PredictiveRow {
    /// Output name.
    pub output: String,
    /// Measured value.
    pub measured: f64,
    /// Measurement sd.
    pub sd: f64,
    /// Simulator (alpha eta) at the posterior draws: mean, 5 %, 95 %.
    pub simulator: [f64; 3],
    /// Discrepancy mean at the posterior mean.
    pub discrepancy: f64,
    /// Simulator plus discrepancy at the posterior mean.
    pub corrected: f64,
}

/// The calibrated error model at the posterior means: y − alpha eta ~ N(0, C),
/// C = K_delta(index) + diag(noise²).
#[derive(Debug, Clone, Serialize)]
pub struct ErrorModel {
    /// Scale on the simulator.
    pub alpha: f64,
    /// Discrepancy sd (output units).
    pub disc_sd: f64,
    /// Discrepancy length scale (observation-index units).
    pub disc_length: f64,
    /// Noise sd per observation: measurement and emulator at the prior centre.
    pub noise_sd: Vec<f64>,
}

impl ErrorModel {
    /// The covariance C of y − alpha eta.
    pub fn covariance(&self) -> nalgebra::DMatrix<f64> {
        let x: Vec<Vec<f64>> = (1..=self.noise_sd.len()).map(|i| vec![i as f64]).collect();
        let k =
            stats::calibration::SquaredExponential { sd: self.disc_sd, length: self.disc_length };
        let mut c = k.matrix(&x);
        for (i, s) in self.noise_sd.iter().enumerate() {
            c[(i, i)] += s * s;
        }
        c
    }
}

/// The calibration stage's result.
pub struct Calibration {
    /// Error model at the posterior means.
    pub error_model: ErrorModel,
    /// The run (draws in physical units: kept parameters then hyperparameters).
    pub result: CalibrationResult,
    /// Prior and posterior per parameter and hyperparameter.
    pub rows: Vec<ParameterRow>,
    /// Posterior predictive at each observation.
    pub predictive: Vec<PredictiveRow>,
}

/// Calibrates `keep` (indices into the study parameters) with the others at
/// their prior centres; `emulator` in its means-only mode.
pub fn run(
    emulator: &GpEmulator,
    names: &[String],
    bounds: &[(f64, f64)],
    keep: &[usize],
    obs: &ObservationsSection,
    cfg: &CalibrationSection,
) -> Result<Calibration> {
    let centre: Vec<f64> = bounds.iter().map(|(l, h)| 0.5 * (l + h)).collect();
    let sim = SubsetSimulator::new(emulator, keep.to_vec(), centre.clone())?;
    let Some(disc_sd) = cfg.discrepancy_sd_range else {
        bail!("calibration.discrepancy_sd_range is required (KOH with a GP discrepancy)");
    };
    let settings = KohSettings {
        alpha: if cfg.alpha_range.is_some() { Hyper::Inferred } else { Hyper::Fixed(1.0) },
        noise_sd: Hyper::Fixed(1.0),
        disc_sd: Hyper::Inferred,
        disc_length: Hyper::Inferred,
    };
    let x: Vec<Vec<f64>> = (1..=obs.values.len()).map(|i| vec![i as f64]).collect();
    let emulator_var = emulator.variance_at(&centre)?;
    let scale: Vec<f64> =
        obs.sd.iter().zip(&emulator_var).map(|(s, v)| (s * s + v).sqrt()).collect();
    let lik = KohLikelihood::new(&sim, x, obs.values.clone(), settings)?
        .with_noise_scale(scale.clone())?;
    let mut pnames: Vec<String> = keep.iter().map(|&i| names[i].clone()).collect();
    let mut lo: Vec<f64> = keep.iter().map(|&i| bounds[i].0).collect();
    let mut hi: Vec<f64> = keep.iter().map(|&i| bounds[i].1).collect();
    let extra = cfg.alpha_range.into_iter().chain([disc_sd, cfg.discrepancy_length_range]);
    for (name, r) in lik.extra_names().into_iter().zip(extra) {
        pnames.push(name);
        lo.push(r[0]);
        hi.push(r[1]);
    }
    let prior = UniformBox::new(pnames, lo, hi)?;
    let post = Posterior::new(prior.clone(), lik)?;
    let method = Method::from_name(&cfg.method, cfg.seed)
        .ok_or_else(|| anyhow!("calibration.method = {:?}", cfg.method))?;
    let s = RunSettings { method, draws: cfg.draws.max(10), map_starts: 8, seed: cfg.seed };
    let result = calibrate(&post, &s, &mut [])?;
    let rows = parameter_rows(&prior, &result);
    let predictive = predictive(&post, &sim, obs, &result)?;
    let mean_of = |name: &str| rows.iter().find(|r| r.name == name).map(|r| r.posterior.mean);
    let error_model = ErrorModel {
        alpha: mean_of("alpha").unwrap_or(1.0),
        disc_sd: mean_of("disc_sd").unwrap_or(disc_sd[0]),
        disc_length: mean_of("disc_length").unwrap_or(cfg.discrepancy_length_range[0]),
        noise_sd: scale,
    };
    Ok(Calibration { error_model, result, rows, predictive })
}

fn parameter_rows(prior: &UniformBox, r: &CalibrationResult) -> Vec<ParameterRow> {
    (0..prior.dim())
        .map(|j| {
            let m = r.summary.marginals[j].clone();
            let width = prior.upper[j] - prior.lower[j];
            ParameterRow {
                name: prior.names[j].clone(),
                prior: [prior.lower[j], prior.upper[j]],
                sd_ratio: m.sd / (width / 12f64.sqrt()),
                posterior: m,
            }
        })
        .collect()
}

/// Posterior predictive of alpha eta at up to 500 draws, and the discrepancy
/// mean at the posterior mean.
fn predictive(
    post: &Posterior<KohLikelihood<&Sim<'_>>>,
    sim: &Sim<'_>,
    obs: &ObservationsSection,
    r: &CalibrationResult,
) -> Result<Vec<PredictiveRow>> {
    let k = sim.n_params();
    let names = &r.summary.names;
    let alpha_at = |t: &[f64]| names.iter().position(|n| n == "alpha").map_or(1.0, |i| t[i]);
    let step = (r.draws.len() / 500).max(1);
    let preds: Vec<Vec<f64>> = r
        .draws
        .iter()
        .step_by(step)
        .map(|t| sim.predict(&t[..k]).map(|p| p.mean.iter().map(|m| alpha_at(t) * m).collect()))
        .collect::<Result<_, _>>()?;
    let mean: Vec<f64> = r.summary.marginals.iter().map(|m| m.mean).collect();
    let delta = post.likelihood().discrepancy_mean(&mean)?;
    let at_mean = sim.predict(&mean[..k])?.mean;
    Ok((0..obs.values.len())
        .map(|i| {
            let mut v: Vec<f64> = preds.iter().map(|p| p[i]).collect();
            v.sort_by(f64::total_cmp);
            let q = |p| stats::calibration::summary::quantile_sorted(&v, p);
            let eta = alpha_at(&mean) * at_mean[i];
            PredictiveRow {
                output: obs.outputs[i].clone(),
                measured: obs.values[i],
                sd: obs.sd[i],
                simulator: [v.iter().sum::<f64>() / v.len() as f64, q(0.05), q(0.95)],
                discrepancy: delta[i],
                corrected: eta + delta[i],
            }
        })
        .collect())
}

/// posterior.json (as `ceilfarm calibrate` writes it, each parameter with
/// its prior range and sd ratio, plus the predictive), samples.csv and
/// elbo.csv (BBVI).
pub fn write_posterior(out: &std::path::Path, method: &str, cal: &Calibration) -> Result<()> {
    let params = cal
        .rows
        .iter()
        .map(|row| Ok((row.name.clone(), serde_json::to_value(row)?)))
        .collect::<Result<_, serde_json::Error>>()?;
    let mut extra = serde_json::Map::new();
    extra.insert("predictive".into(), serde_json::to_value(&cal.predictive)?);
    crate::commands::calibrate::write_posterior(out, method, params, &cal.result, extra)
}
