//! The pipeline file: a study (the sweep: `[study]`, `[model]`,
//! `[[parameters]]`, `[design]`, `[outputs]`, `[farm]`) plus the sections of
//! the analysis that follows it: `[emulator]`, `[sensitivity]`,
//! `[observations]`, `[calibration]` and `[selection]`.

use anyhow::{bail, Context, Result};
use coordinator::study::Study;
use serde::Deserialize;
use std::path::Path;

/// Keys of the file that belong to the analysis, not to the study.
const SECTIONS: [&str; 5] = ["emulator", "sensitivity", "observations", "calibration", "selection"];

/// GP emulators of the sweep's outputs (seed 6.5: 70/20/10 split, kernel by validation).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EmulatorSection {
    /// Fractions of the runs for training, validation (kernel choice) and test.
    #[serde(default = "default_split")]
    pub split: [f64; 3],
    /// Kernels tried (se, matern32, matern52, rq); the lowest validation RMSE wins.
    #[serde(default = "default_kernels")]
    pub kernels: Vec<String>,
    /// Extra optimiser starts per fit.
    #[serde(default)]
    pub restarts: usize,
    /// Learn a power warp of each input with the kernel (as `gp fit` does).
    #[serde(default = "yes")]
    pub warp: bool,
    /// Seed of the split and of the optimiser starts.
    #[serde(default = "one")]
    pub seed: u64,
}

/// Sobol' indices on each emulator and the screening threshold (seed: 1 %).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensitivitySection {
    /// Saltelli base sample size N (N (d + 2) emulator evaluations per output).
    #[serde(default = "default_sobol_n")]
    pub n: usize,
    /// A parameter is dropped when its total index is below this for every output.
    #[serde(default = "default_threshold")]
    pub threshold: f64,
    /// Seed of the Sobol' sequence scramble and the bootstrap.
    #[serde(default = "one")]
    pub seed: u64,
}

/// The measured values the model is calibrated against.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObservationsSection {
    /// Output names of the sweep, one per measured value.
    pub outputs: Vec<String>,
    /// Measured values (same units as the outputs, Hz for frequencies).
    pub values: Vec<f64>,
    /// Measurement sds (same units).
    pub sd: Vec<f64>,
}

/// Kennedy–O'Hagan calibration of the kept parameters (seed eqs. 6.3–6.11).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationSection {
    /// bbvi-fullrank, bbvi-meanfield, bbvi-score or mcmc.
    #[serde(default = "default_method")]
    pub method: String,
    /// Seed of the fit and the draws.
    #[serde(default = "one")]
    pub seed: u64,
    /// Posterior draws written to samples.csv.
    #[serde(default = "default_draws")]
    pub draws: usize,
    /// Prior range of the scale alpha on the simulator; absent: alpha = 1.
    #[serde(default)]
    pub alpha_range: Option<[f64; 2]>,
    /// Prior range of the discrepancy sd (output units); absent: no discrepancy.
    #[serde(default)]
    pub discrepancy_sd_range: Option<[f64; 2]>,
    /// Prior range of the discrepancy length scale, in observation-index units.
    #[serde(default = "default_length_range")]
    pub discrepancy_length_range: [f64; 2],
}

/// Candidate parameter subsets scored by AIC, BIC, DIC, ICOMP and MDL.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SelectionSection {
    /// Named subsets (free parameters); the others sit at their prior centres.
    #[serde(default)]
    pub candidates: Vec<CandidateSection>,
    /// Also score the nested subsets of the kept parameters ranked by total
    /// index, of sizes 1 up to the number of observations.
    #[serde(default = "yes")]
    pub nested_by_sensitivity: bool,
    /// Starts of each maximum-likelihood fit.
    #[serde(default = "default_starts")]
    pub starts: usize,
    /// Quasi-Monte Carlo points per replicate of the Fisher integral.
    #[serde(default = "default_qmc")]
    pub qmc_points: usize,
    /// Replicates of the Fisher integral (its error estimate).
    #[serde(default = "default_replicates")]
    pub qmc_replicates: usize,
    /// Seed of starts, scrambles and the DIC sampler.
    #[serde(default = "one")]
    pub seed: u64,
}

/// One named candidate.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CandidateSection {
    /// Name in the table.
    pub name: String,
    /// Free parameters.
    pub free: Vec<String>,
}

/// The analysis sections.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Analysis {
    /// Emulators.
    #[serde(default = "default_emulator")]
    pub emulator: EmulatorSection,
    /// Sensitivity.
    #[serde(default = "default_sensitivity")]
    pub sensitivity: SensitivitySection,
    /// Measured values.
    pub observations: ObservationsSection,
    /// Calibration.
    pub calibration: CalibrationSection,
    /// Selection.
    pub selection: SelectionSection,
}

/// A parsed pipeline file.
pub struct PipelineConfig {
    /// The sweep.
    pub study: Study,
    /// The analysis.
    pub analysis: Analysis,
}

fn default_split() -> [f64; 3] {
    [0.7, 0.2, 0.1]
}
fn default_kernels() -> Vec<String> {
    vec!["se".into(), "matern52".into()]
}
fn one() -> u64 {
    1
}
fn yes() -> bool {
    true
}
fn default_sobol_n() -> usize {
    4096
}
fn default_threshold() -> f64 {
    0.01
}
fn default_method() -> String {
    "bbvi-fullrank".into()
}
fn default_draws() -> usize {
    4000
}
fn default_length_range() -> [f64; 2] {
    [0.5, 6.0]
}
fn default_starts() -> usize {
    8
}
fn default_qmc() -> usize {
    1024
}
fn default_replicates() -> usize {
    4
}
fn default_emulator() -> EmulatorSection {
    EmulatorSection {
        split: default_split(),
        kernels: default_kernels(),
        restarts: 0,
        warp: true,
        seed: 1,
    }
}
fn default_sensitivity() -> SensitivitySection {
    SensitivitySection { n: default_sobol_n(), threshold: default_threshold(), seed: 1 }
}

impl PipelineConfig {
    /// Reads the file, splits it into study and analysis, checks both.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("{}: cannot read", path.display()))?;
        let mut table: toml::Table =
            toml::from_str(&text).with_context(|| format!("{}: not valid TOML", path.display()))?;
        let mut analysis = toml::Table::new();
        for key in SECTIONS {
            if let Some(v) = table.remove(key) {
                analysis.insert(key.into(), v);
            }
        }
        let analysis: Analysis = analysis
            .try_into()
            .with_context(|| format!("{}: analysis sections", path.display()))?;
        let study = Study::parse(&toml::to_string(&table)?, path)?;
        check(&analysis, &study, path)?;
        Ok(PipelineConfig { study, analysis })
    }
}

/// Consistency of the analysis with the study, each failure naming the key.
#[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN must fail the check
fn check(a: &Analysis, study: &Study, path: &Path) -> Result<()> {
    let file = path.display();
    let s = a.emulator.split;
    if s.iter().any(|v| !(*v > 0.0)) || (s.iter().sum::<f64>() - 1.0).abs() > 1e-9 {
        bail!("{file}: emulator.split = {s:?}: expected three positive fractions summing to 1");
    }
    for k in &a.emulator.kernels {
        if stats::gp::KernelKind::parse(k).is_none() {
            bail!("{file}: emulator.kernels: {k:?}: expected se, matern32, matern52 or rq");
        }
    }
    if a.emulator.kernels.is_empty() {
        bail!("{file}: emulator.kernels is empty: expected at least one kernel");
    }
    let o = &a.observations;
    if o.values.len() != o.outputs.len() || o.sd.len() != o.outputs.len() {
        bail!(
            "{file}: observations: {} outputs, {} values, {} sds: expected equal lengths",
            o.outputs.len(),
            o.values.len(),
            o.sd.len()
        );
    }
    if let Some(v) = o.sd.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
        bail!("{file}: observations.sd: {v}: expected finite values > 0");
    }
    if !study.outputs.is_empty() {
        if let Some(name) = o.outputs.iter().find(|n| !study.outputs.contains(n)) {
            bail!(
                "{file}: observations.outputs: {name:?} is not a study output (outputs.scalars: {})",
                study.outputs.join(", ")
            );
        }
    }
    let names: Vec<&str> = study.parameters.iter().map(|p| p.name.as_str()).collect();
    for c in &a.selection.candidates {
        if let Some(p) = c.free.iter().find(|p| !names.contains(&p.as_str())) {
            bail!(
                "{file}: selection.candidates `{}`: {p:?} is not a study parameter ({})",
                c.name,
                names.join(", ")
            );
        }
    }
    if stats::calibration::Method::from_name(&a.calibration.method, 0).is_none() {
        bail!(
            "{file}: calibration.method = {:?}: expected one of {}",
            a.calibration.method,
            stats::calibration::Method::NAMES.join(", ")
        );
    }
    Ok(())
}
