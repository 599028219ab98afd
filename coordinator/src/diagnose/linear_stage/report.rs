//! The linear stage's fit as `diagnosis.json` and the report state it: the
//! parameters with their Laplace intervals, the frequencies measured
//! against the model's, and each linear run's channels.

use super::LinearStage;
use serde::Serialize;

/// One calibrated parameter of the linear form.
#[derive(Debug, Clone, Serialize)]
pub struct ParameterJson {
    /// Name (an FE parameter or solver option).
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Estimate.
    pub value: f64,
    /// Approximate 68 % interval (Laplace, clamped to the prior).
    pub interval: [f64; 2],
}

/// The frequencies against `modal.csv`.
#[derive(Debug, Clone, Serialize)]
pub struct FrequenciesJson {
    /// Mode numbers.
    pub modes: Vec<u32>,
    /// Measured (Hz).
    pub measured_hz: Vec<f64>,
    /// The lab's one-sigma uncertainty (Hz; 0 unknown).
    pub std_hz: Vec<f64>,
    /// The fitted linear model's, as integrated at `step_s` (Hz;
    /// [`crate::diagnose::modal_fit::as_integrated_hz`]).
    pub model_hz: Vec<f64>,
    /// The fitted linear model's eigenfrequencies (Hz).
    pub eigen_hz: Vec<f64>,
    /// The step the runs are integrated at (s).
    pub step_s: f64,
    /// The profiled discrepancy's standard deviation (Hz).
    pub discrepancy_sd_hz: f64,
}

/// One channel of a linear run at the estimate.
#[derive(Debug, Clone, Serialize)]
pub struct ChannelJson {
    /// Run id.
    pub run: String,
    /// Sensor id.
    pub sensor: String,
    /// RMS(residual) / RMS(measurement).
    pub nrmse: f64,
}

/// The linear stage in `diagnosis.json`.
#[derive(Debug, Clone, Serialize)]
pub struct LinearJson {
    /// The runs taken as linear.
    pub runs: Vec<String>,
    /// The linear form found.
    pub parameters: Vec<ParameterJson>,
    /// The frequencies (None: no `modal.csv`).
    pub frequencies: Option<FrequenciesJson>,
    /// The lowest frequencies of the fitted model (Hz).
    pub model_modes_hz: Vec<f64>,
    /// Each linear run's channels.
    pub channels: Vec<ChannelJson>,
    /// Mean normalised error over the linear runs' channels.
    pub nrmse: f64,
    /// −log L at the estimate (nats).
    pub neg_log_lik: f64,
    /// Linear evaluations (modal superpositions) spent.
    pub evaluations: usize,
}

/// Modes listed beside the measured ones.
const LISTED_MODES: usize = 12;

impl LinearJson {
    /// The stage's fit, the bundle's runs named by `run_ids`.
    pub fn of(run_ids: &[String], s: &LinearStage) -> Self {
        let parameters = s
            .priors
            .iter()
            .zip(s.u.iter().zip(&s.sd_unit))
            .map(|(p, (u, sd))| {
                let sd = if sd.is_finite() { *sd } else { 0.5 };
                let at = |v: f64| p.at(v.clamp(0.0, 1.0));
                ParameterJson {
                    name: p.name.into(),
                    unit: p.unit.into(),
                    value: p.at(*u),
                    interval: [at(u - sd), at(u + sd)],
                }
            })
            .collect();
        let frequencies = s.judged.modal.as_ref().map(|m| FrequenciesJson {
            modes: m.modes.clone(),
            measured_hz: m.measured_hz.clone(),
            std_hz: m.lab_var_hz2.iter().map(|v| v.sqrt()).collect(),
            model_hz: m.model_hz.clone(),
            eigen_hz: m.eigen_hz.clone(),
            step_s: m.step_s,
            discrepancy_sd_hz: m.discrepancy_var_hz2.sqrt(),
        });
        let channels = s
            .judged
            .channels
            .iter()
            .map(|c| ChannelJson { run: c.run.clone(), sensor: c.sensor.clone(), nrmse: c.nrmse() })
            .collect();
        LinearJson {
            runs: s.runs.iter().map(|k| run_ids[*k].clone()).collect(),
            parameters,
            frequencies,
            model_modes_hz: s.judged.modes_hz.iter().take(LISTED_MODES).copied().collect(),
            channels,
            nrmse: s.nrmse(),
            neg_log_lik: s.neg_log_lik,
            evaluations: s.evaluations,
        }
    }

    /// A few lines for a terminal.
    pub fn summary(&self) -> String {
        let mut out = format!("linear stage on runs {}:\n", self.runs.join(", "));
        for p in &self.parameters {
            out += &format!(
                "  {:<20} {:>10.4} {:<5} [{:.4}, {:.4}]\n",
                p.name, p.value, p.unit, p.interval[0], p.interval[1]
            );
        }
        if let Some(f) = &self.frequencies {
            let list =
                |v: &[f64]| v.iter().map(|x| format!("{x:.2}")).collect::<Vec<_>>().join(" ");
            out += &format!("  measured Hz: {}\n", list(&f.measured_hz));
            out += &format!(
                "  model Hz:    {} (as integrated at {} ms)\n",
                list(&f.model_hz),
                f.step_s * 1e3
            );
            out += &format!("  eigen Hz:    {}\n", list(&f.eigen_hz));
        }
        for c in &self.channels {
            out += &format!("  {} {}: NRMSE {:.3}\n", c.run, c.sensor, c.nrmse);
        }
        out + &format!("  mean NRMSE {:.3}, -log L {:.1}\n", self.nrmse, self.neg_log_lik)
    }
}
