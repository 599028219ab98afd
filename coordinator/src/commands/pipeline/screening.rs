//! Stage 3: Sobol' indices of every emulator over the prior box (Saltelli
//! sampling, Saltelli-2010 first order, Jansen total order, bootstrap
//! intervals) and the screening decision: a parameter is dropped when its
//! total index is below the threshold for every output (seed 6.4: J_cross
//! and J_main below 1 %).

use super::config::SensitivitySection;
use anyhow::Result;
use serde::Serialize;
use stats::gp::Gp;
use stats::sobol::analyze::{analyze, AnalyzeSettings, Indices};
use stats::sobol::problem::Problem;
use stats::sobol::sample::saltelli_sample;

/// Indices of one output.
#[derive(Debug, Clone, Serialize)]
pub struct OutputIndices {
    /// Output name.
    pub output: String,
    /// First-order indices, in parameter order.
    #[serde(rename = "S1")]
    pub s1: Vec<f64>,
    /// Total indices.
    #[serde(rename = "ST")]
    pub st: Vec<f64>,
    /// Half-widths of the 95 % bootstrap intervals of S1.
    #[serde(rename = "S1_conf")]
    pub s1_conf: Vec<f64>,
    /// Half-widths of the 95 % bootstrap intervals of ST.
    #[serde(rename = "ST_conf")]
    pub st_conf: Vec<f64>,
}

/// The sensitivity stage's result.
#[derive(Debug, Clone, Serialize)]
pub struct Sensitivity {
    /// Parameter names.
    pub names: Vec<String>,
    /// Per output.
    pub outputs: Vec<OutputIndices>,
    /// Largest total index of each parameter over the outputs.
    pub max_st: Vec<f64>,
    /// Threshold on `max_st`.
    pub threshold: f64,
    /// Parameters kept, by decreasing `max_st`.
    pub keep: Vec<String>,
    /// Parameters dropped (fixed at their prior centres from here on).
    pub drop: Vec<String>,
    /// Emulator evaluations per output.
    pub runs_per_output: usize,
}

/// Sobol' indices of each emulator's mean over the box `bounds`.
pub fn run(
    names: &[String],
    bounds: &[(f64, f64)],
    outputs: &[String],
    gps: &[Gp],
    cfg: &SensitivitySection,
) -> Result<Sensitivity> {
    let problem = Problem { names: names.to_vec(), bounds: bounds.to_vec() };
    let d = names.len();
    let x = saltelli_sample(&problem, cfg.n, cfg.seed as u32);
    let set = AnalyzeSettings { seed: cfg.seed, ..Default::default() };
    let mut per = Vec::new();
    for (name, gp) in outputs.iter().zip(gps) {
        let y = gp.predict_mean(&x)?;
        let Indices { s1, st, s1_conf, st_conf } = analyze(d, &y, &set)?;
        per.push(OutputIndices { output: name.clone(), s1, st, s1_conf, st_conf });
    }
    let max_st: Vec<f64> =
        (0..d).map(|j| per.iter().map(|o| o.st[j]).fold(f64::NEG_INFINITY, f64::max)).collect();
    let mut order: Vec<usize> = (0..d).collect();
    order.sort_by(|&a, &b| max_st[b].total_cmp(&max_st[a]));
    let keep = order.iter().filter(|&&j| max_st[j] >= cfg.threshold).map(|&j| names[j].clone());
    let drop = order.iter().filter(|&&j| max_st[j] < cfg.threshold).map(|&j| names[j].clone());
    Ok(Sensitivity {
        names: names.to_vec(),
        outputs: per,
        keep: keep.collect(),
        drop: drop.collect(),
        max_st,
        threshold: cfg.threshold,
        runs_per_output: x.len() / d,
    })
}
