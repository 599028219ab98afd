//! How well one model variant at one parameter point reproduces measured
//! runs: per channel (run × sensor) the residual sum of squares against the
//! offset-corrected measurement, its lag-one autocorrelation and the
//! effective sample size n(1−ρ)/(1+ρ); the profiled Gaussian log-likelihood
//! −log L = Σ n_eff/2 · log(SSR/n); and the normalised error RMS(res)/RMS(meas).
//! Missing readings (NaN) are skipped, never read as zero.

use super::cause::{Cause, Prior};
use crate::bundle::{Bundle, RunData};
use crate::specimen::{base_input, fe_spec, simulate_run};
use fe::ceiling::SimOptions;
use fe::generator::Parameters;

/// The fit of one channel.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelFit {
    /// Run id.
    pub run: String,
    /// Sensor id.
    pub sensor: String,
    /// Σ residual² over the samples present.
    pub ssr: f64,
    /// Samples present.
    pub n: usize,
    /// Lag-one autocorrelation of the residual.
    pub rho: f64,
    /// RMS of the (offset-corrected) measurement.
    pub rms_meas: f64,
}

impl ChannelFit {
    /// RMS(residual) / RMS(measurement).
    pub fn nrmse(&self) -> f64 {
        (self.ssr / self.n.max(1) as f64).sqrt() / self.rms_meas.max(1e-300)
    }
}

/// One simulated run at a parameter point: (sensor id, samples) in bundle units.
pub type Simulated = Vec<(String, Vec<f64>)>;

/// Model variant, parameter point and the data it is judged on.
pub struct Evaluation<'a> {
    /// The bundle.
    pub bundle: &'a Bundle,
    /// The variant.
    pub cause: Cause,
    /// Its priors (parameter order).
    pub priors: &'a [Prior],
    /// Indices of the runs used.
    pub runs: &'a [usize],
}

impl Evaluation<'_> {
    /// Simulates the runs at `theta` (physical values in prior order).
    pub fn simulate(&self, theta: &[f64]) -> Result<Vec<Simulated>, String> {
        let spec = fe_spec(&self.bundle.manifest.structure, self.cause.model_options())
            .map_err(|e| e.to_string())?;
        let mut params = Parameters::prior_midpoints_for(&spec);
        let mut opts = SimOptions::default();
        for (p, v) in self.priors.iter().zip(theta) {
            if p.name == "damping_ratio" {
                opts.damping_ratio = *v;
            } else {
                params.set(p.name, *v).map_err(|e| e.to_string())?;
            }
        }
        self.runs
            .iter()
            .map(|&k| {
                let run = &self.bundle.runs[k];
                let sensors = measured_sensors(self.bundle, run);
                simulate_run(&spec, &params, &sensors, &base_input(run), &opts)
                    .map(|(series, _)| series)
                    .map_err(|e| format!("run {}: {e}", run.id))
            })
            .collect()
    }

    /// Channel fits of simulated runs against the measured ones.
    pub fn channels(&self, sims: &[Simulated]) -> Vec<ChannelFit> {
        let mut out = Vec::new();
        for (&k, sim) in self.runs.iter().zip(sims) {
            let run = &self.bundle.runs[k];
            for (id, s) in sim {
                if let Some(m) = run.sensor(id) {
                    out.push(channel_fit(run, id, m, s));
                }
            }
        }
        out
    }
}

/// The listed sensors a run measured.
pub fn measured_sensors(b: &Bundle, run: &RunData) -> Vec<crate::bundle::Sensor> {
    b.manifest.sensors.iter().filter(|s| run.sensor(&s.id).is_some()).cloned().collect()
}

/// Offset of a measured channel: median of its first 0.5 s (at least 5 samples).
pub fn pre_event_offset(m: &[f64], dt_s: f64) -> f64 {
    let n = ((0.5 / dt_s) as usize).max(5).min(m.len());
    let mut head: Vec<f64> = m[..n].iter().copied().filter(|v| v.is_finite()).collect();
    if head.is_empty() {
        return 0.0;
    }
    head.sort_by(f64::total_cmp);
    head[head.len() / 2]
}

fn channel_fit(run: &RunData, id: &str, m: &[f64], s: &[f64]) -> ChannelFit {
    let off = pre_event_offset(m, run.dt_s);
    let (mut ssr, mut n, mut mm) = (0.0, 0usize, 0.0);
    let (mut c0, mut c1, mut prev) = (0.0, 0.0, None::<f64>);
    for (a, b) in m.iter().zip(s) {
        let a = a - off;
        if !a.is_finite() || !b.is_finite() {
            prev = None;
            continue;
        }
        let r = b - a;
        ssr += r * r;
        mm += a * a;
        n += 1;
        c0 += r * r;
        if let Some(p) = prev {
            c1 += r * p;
        }
        prev = Some(r);
    }
    let rho = if c0 > 0.0 { (c1 / c0).clamp(0.0, 0.995) } else { 0.0 };
    ChannelFit {
        run: run.id.clone(),
        sensor: id.into(),
        ssr,
        n,
        rho,
        rms_meas: (mm / n.max(1) as f64).sqrt(),
    }
}

/// Effective sample sizes n(1−ρ)/(1+ρ) of channels.
pub fn effective_sizes(ch: &[ChannelFit]) -> Vec<f64> {
    ch.iter().map(|c| c.n as f64 * (1.0 - c.rho) / (1.0 + c.rho)).collect()
}

/// −log L with the noise variance of each channel profiled out, each
/// channel counting `n_eff` independent samples (constants dropped).
pub fn neg_log_lik(ch: &[ChannelFit], n_eff: &[f64]) -> f64 {
    ch.iter()
        .zip(n_eff)
        .map(|(c, ne)| 0.5 * ne * (c.ssr / c.n.max(1) as f64).max(1e-300).ln())
        .sum()
}

/// Mean normalised error over channels.
pub fn mean_nrmse(ch: &[ChannelFit]) -> f64 {
    if ch.is_empty() {
        return f64::NAN;
    }
    ch.iter().map(ChannelFit::nrmse).sum::<f64>() / ch.len() as f64
}
