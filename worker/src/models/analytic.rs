//! Analytic test functions with known answers: Ishigami, Sobol' G, borehole,
//! and a no-op model for measuring farm overhead.
//!
//! References: Ishigami & Homma (1990); Saltelli et al., *Global Sensitivity
//! Analysis: The Primer* (2008), G-function; Morris, Mitchell & Ylvisaker
//! (1993), borehole (flow rate in m³/yr).

use crate::model::{Model, ModelError, ParamSet, RunContext, RunError};
use protocol::Outputs;
use serde::Deserialize;

/// Ishigami function y = sin x1 + a sin² x2 + b x3⁴ sin x1.
pub fn ishigami(x: [f64; 3], a: f64, b: f64) -> f64 {
    x[0].sin() + a * x[1].sin().powi(2) + b * x[2].powi(4) * x[0].sin()
}

/// Sobol' G function Π (|4 x_i − 2| + a_i) / (1 + a_i), x in [0, 1]^d.
pub fn sobol_g(x: &[f64], a: &[f64]) -> f64 {
    x.iter().zip(a).map(|(xi, ai)| ((4.0 * xi - 2.0).abs() + ai) / (1.0 + ai)).product()
}

/// Borehole flow rate (m³/yr) from its eight inputs
/// `[rw, r, Tu, Hu, Tl, Hl, L, Kw]` (m, m, m²/yr, m, m²/yr, m, m, m/yr).
pub fn borehole(x: [f64; 8]) -> f64 {
    let [rw, r, tu, hu, tl, hl, l, kw] = x;
    let ln_r = (r / rw).ln();
    2.0 * std::f64::consts::PI * tu * (hu - hl)
        / (ln_r * (1.0 + 2.0 * l * tu / (ln_r * rw * rw * kw) + tu / tl))
}

fn invalid(kind: &str, message: String) -> ModelError {
    ModelError::Invalid { kind: kind.to_string(), message }
}

/// Indices of `wanted` parameters in `names`, or an error naming the first missing one.
pub fn param_indices(
    kind: &str,
    names: &[String],
    wanted: &[&str],
) -> Result<Vec<usize>, ModelError> {
    wanted
        .iter()
        .map(|w| {
            names.iter().position(|n| n == w).ok_or_else(|| {
                invalid(
                    kind,
                    format!("needs a parameter named `{w}` (study has: {})", names.join(", ")),
                )
            })
        })
        .collect()
}

/// Options of the Ishigami model.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IshigamiOptions {
    /// Coefficient a (default 7).
    #[serde(default = "seven")]
    pub a: f64,
    /// Coefficient b (default 0.1).
    #[serde(default = "tenth")]
    pub b: f64,
}

fn seven() -> f64 {
    7.0
}
fn tenth() -> f64 {
    0.1
}

/// The Ishigami model over parameters `x1, x2, x3`; output `y`.
pub struct Ishigami {
    opts: IshigamiOptions,
    idx: Vec<usize>,
}

impl Ishigami {
    /// Builds it from options and the study's parameter names.
    pub fn new(opts: IshigamiOptions, names: &[String]) -> Result<Self, ModelError> {
        Ok(Self { idx: param_indices("ishigami", names, &["x1", "x2", "x3"])?, opts })
    }
}

impl Model for Ishigami {
    fn output_names(&self) -> Vec<String> {
        vec!["y".into()]
    }
    fn run(&self, p: &ParamSet<'_>, _: &RunContext) -> Result<Outputs, RunError> {
        let v = p.values();
        let y =
            ishigami([v[self.idx[0]], v[self.idx[1]], v[self.idx[2]]], self.opts.a, self.opts.b);
        Ok(Outputs { scalars: vec![("y".into(), y)], histories: vec![] })
    }
}

/// Options of the Sobol' G model.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SobolGOptions {
    /// The a_i coefficients, one per input (default 0, 1, 4.5, 9, 99, 99, 99, 99).
    #[serde(default = "default_g_a")]
    pub a: Vec<f64>,
}

fn default_g_a() -> Vec<f64> {
    vec![0.0, 1.0, 4.5, 9.0, 99.0, 99.0, 99.0, 99.0]
}

/// The Sobol' G model over parameters `x1 .. xd`; output `y`.
pub struct SobolG {
    a: Vec<f64>,
    idx: Vec<usize>,
}

impl SobolG {
    /// Builds it; needs parameters `x1` to `x<len(a)>`.
    pub fn new(opts: SobolGOptions, names: &[String]) -> Result<Self, ModelError> {
        let wanted: Vec<String> = (1..=opts.a.len()).map(|i| format!("x{i}")).collect();
        let refs: Vec<&str> = wanted.iter().map(String::as_str).collect();
        Ok(Self { idx: param_indices("sobol-g", names, &refs)?, a: opts.a })
    }
}

impl Model for SobolG {
    fn output_names(&self) -> Vec<String> {
        vec!["y".into()]
    }
    fn run(&self, p: &ParamSet<'_>, _: &RunContext) -> Result<Outputs, RunError> {
        let x: Vec<f64> = self.idx.iter().map(|&i| p.values()[i]).collect();
        Ok(Outputs { scalars: vec![("y".into(), sobol_g(&x, &self.a))], histories: vec![] })
    }
}

/// The borehole model over `rw, r, Tu, Hu, Tl, Hl, L, Kw`; output `y` (m³/yr).
pub struct Borehole {
    idx: Vec<usize>,
}

/// Parameter names of the borehole function, in formula order.
pub const BOREHOLE_NAMES: [&str; 8] = ["rw", "r", "Tu", "Hu", "Tl", "Hl", "L", "Kw"];

impl Borehole {
    /// Builds it from the study's parameter names.
    pub fn new(names: &[String]) -> Result<Self, ModelError> {
        Ok(Self { idx: param_indices("borehole", names, &BOREHOLE_NAMES)? })
    }
}

impl Model for Borehole {
    fn output_names(&self) -> Vec<String> {
        vec!["y".into()]
    }
    fn run(&self, p: &ParamSet<'_>, _: &RunContext) -> Result<Outputs, RunError> {
        let v = p.values();
        let x: [f64; 8] = std::array::from_fn(|k| v[self.idx[k]]);
        if x[0] <= 0.0 || x[1] <= x[0] {
            return Err(RunError::Input(format!(
                "borehole needs 0 < rw < r, got rw = {}, r = {}",
                x[0], x[1]
            )));
        }
        Ok(Outputs { scalars: vec![("y".into(), borehole(x))], histories: vec![] })
    }
}

/// A model that does nothing: output `y = 0`; measures pure farm overhead.
/// With `history_samples = n` it also returns one history of `n` f64 samples
/// (e.g. 131072 for a 1 MiB result), to measure transports on large results.
#[derive(Debug, Default, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Noop {
    /// Samples in the returned history (0 = none).
    #[serde(default)]
    pub history_samples: usize,
}

impl Model for Noop {
    fn output_names(&self) -> Vec<String> {
        vec!["y".into()]
    }
    fn run(&self, p: &ParamSet<'_>, _: &RunContext) -> Result<Outputs, RunError> {
        let mut out = Outputs { scalars: vec![("y".into(), 0.0)], histories: vec![] };
        if self.history_samples > 0 {
            let x = p.values().first().copied().unwrap_or(0.0);
            out.histories.push(protocol::History {
                name: "noise".into(),
                dt_s: 0.01,
                channels: vec!["x".into()],
                data: (0..self.history_samples).map(|i| x + i as f64).collect(),
            });
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ishigami_known_values() {
        // y(pi/2, pi/2, 1) = 1 + 7 + 0.1 = 8.1
        let h = std::f64::consts::FRAC_PI_2;
        assert!((ishigami([h, h, 1.0], 7.0, 0.1) - 8.1).abs() < 1e-12);
        assert_eq!(ishigami([0.0, 0.0, 3.0], 7.0, 0.1), 0.0);
    }

    #[test]
    fn sobol_g_is_one_at_quarter_points() {
        // |4x - 2| = 1 at x = 1/4 and 3/4, so every factor is 1.
        assert!((sobol_g(&[0.25, 0.75, 0.25], &[0.0, 1.0, 99.0]) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn borehole_matches_benchmark_row() {
        // First row of shared/benchmarks/borehole_train_200.csv.
        let x = [
            0.12841052707124823,
            47047.235612218545,
            90750.79500961836,
            1042.116085266267,
            76.01843066970552,
            771.8973306090995,
            1488.1234596133354,
            10848.915569623276,
        ];
        let y = borehole(x);
        assert!((y - 101.02600695476211).abs() / y < 1e-12, "{y}");
    }
}
