//! Frequency-response amplitude of a damped oscillator, the calibration
//! benchmark's simulator (shared benchmarks §3):
//! eta(x; k, c, m) = 1 / sqrt((k − m w²)² + (c w)²), w = 0.5 + 1.5 x.

use crate::model::{Model, ModelError, ParamSet, RunContext, RunError};
use crate::models::analytic::param_indices;
use protocol::Outputs;
use serde::Deserialize;

/// eta(x; k, c, m) of the benchmark.
pub fn oscillator_eta(x: f64, k: f64, c: f64, m: f64) -> f64 {
    let w = 0.5 + 1.5 * x;
    1.0 / ((k - m * w * w).powi(2) + (c * w).powi(2)).sqrt()
}

/// Options: the x locations at which to report eta.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OscillatorOptions {
    /// Observation points in [0, 1] (default: 0.025, 0.075, ..., 0.975).
    #[serde(default = "default_x")]
    pub x: Vec<f64>,
    /// Fixed values for k, c or m when they are not study parameters.
    #[serde(default)]
    pub fixed: std::collections::BTreeMap<String, f64>,
}

fn default_x() -> Vec<f64> {
    (0..20).map(|i| 0.025 + 0.05 * i as f64).collect()
}

/// The oscillator model; outputs `y1 .. yn` at the option's x points.
pub struct Oscillator {
    x: Vec<f64>,
    fixed: std::collections::BTreeMap<String, f64>,
}

impl Oscillator {
    /// Builds it; k, c and m must each be a parameter or a fixed option.
    pub fn new(opts: OscillatorOptions, names: &[String]) -> Result<Self, ModelError> {
        for p in ["k", "c", "m"] {
            if !opts.fixed.contains_key(p) {
                param_indices("oscillator", names, &[p])?;
            }
        }
        Ok(Self { x: opts.x, fixed: opts.fixed })
    }

    fn value(&self, p: &ParamSet<'_>, name: &str) -> Result<f64, RunError> {
        match p.get(name) {
            Some(v) => Ok(v),
            None => self
                .fixed
                .get(name)
                .copied()
                .ok_or_else(|| RunError::Input(format!("`{name}` missing"))),
        }
    }
}

impl Model for Oscillator {
    fn output_names(&self) -> Vec<String> {
        (1..=self.x.len()).map(|i| format!("y{i}")).collect()
    }
    fn run(&self, p: &ParamSet<'_>, _: &RunContext) -> Result<Outputs, RunError> {
        let (k, c, m) = (self.value(p, "k")?, self.value(p, "c")?, self.value(p, "m")?);
        let scalars = self
            .x
            .iter()
            .enumerate()
            .map(|(i, &x)| (format!("y{}", i + 1), oscillator_eta(x, k, c, m)))
            .collect();
        Ok(Outputs { scalars, histories: vec![] })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_benchmark_truth_column() {
        // calib_nodisc.csv row 1: x = 0.025, eta_true = 1.0807853013558071 at (1.2, 0.3, 1.0).
        let eta = oscillator_eta(0.025, 1.2, 0.3, 1.0);
        assert!((eta - 1.080785301355807).abs() < 1e-13, "{eta}");
    }
}
