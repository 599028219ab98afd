//! Export of a synthetic campaign's true models (`ceilfarm synth
//! --export-models MDIR`) so that another FE code can simulate the runs:
//! per run `<run>.json`, the exact model ceilfarm integrates (hidden effect,
//! fitted Rayleigh coefficients, flagged springs) in the `ceiling-fe-model`
//! format with a transient stanza; its base records `<run>.base_x.csv` /
//! `<run>.base_y.csv` (mm/s²); a sidecar `<run>.sensors.json` saying how
//! recorder columns make each bundle sensor; ceilfarm's own recorder history
//! `<run>.ceilfarm.csv` for comparison; and `modal.json` when the campaign
//! writes modal data.
//!
//! The transient stanza lists its base records under `excitations` (one per
//! shaken direction, each a format-v1 `excitation` block); a single-direction
//! run also carries it as `excitation`, so v1 readers run it unchanged.
//! Recorder columns are mm/s² (absolute acceleration) or mm (displacement
//! relative to the base); a bundle sensor is Σ wᵢ·columnᵢ × `to_bundle`
//! (m/s² or mm).

use super::spec::SynthSpec;
use crate::bundle::{self, SensorKind};
use fe::ceiling::PreparedRun;
use fe::transient::{write_history_csv, History};
use serde::{Deserialize, Serialize};
use serde_json::{json, Map, Value};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// `format` of a sensors sidecar.
pub const SENSORS_FORMAT: &str = "ceiling-synth-sensors/1";
/// `format` of `modal.json`.
pub const MODAL_FORMAT: &str = "ceiling-synth-modal/1";

/// Why an export could not be written.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {message}")]
pub struct ExportError {
    /// The file.
    pub path: PathBuf,
    /// What went wrong.
    pub message: String,
}

/// How one bundle sensor is made from recorder columns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorRecipe {
    /// Sensor id (its bundle column).
    pub id: String,
    /// `acceleration` or `displacement`.
    pub kind: String,
    /// `x` or `y`.
    pub direction: String,
    /// Recorder response: `accel_abs` (mm/s²) or `disp` (mm).
    pub response: String,
    /// Recorder columns of the history file.
    pub columns: Vec<String>,
    /// Interpolation weight of each column (summing to 1).
    pub weights: Vec<f64>,
    /// Factor from the weighted sum to the bundle's unit.
    pub to_bundle: f64,
    /// The bundle's unit (`m/s2` or `mm`).
    pub bundle_units: String,
}

/// The sidecar `<run>.sensors.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorsSidecar {
    /// [`SENSORS_FORMAT`].
    pub format: String,
    /// Run id.
    pub run: String,
    /// The model file.
    pub model: String,
    /// SHA-256 of the model file.
    pub model_sha256: String,
    /// The history file a simulator writes: header `t_s`, then recorder columns.
    pub history_csv: String,
    /// Output interval (s).
    pub dt_s: f64,
    /// Rows expected in the history file (t = 0 included).
    pub n_rows: usize,
    /// One recipe per bundle sensor, in bundle order.
    pub sensors: Vec<SensorRecipe>,
}

/// The text of a run's model file.
pub fn model_text(spec: &SynthSpec, run_id: &str, prep: &PreparedRun, zeta: f64) -> String {
    let mut model = prep.model.clone();
    model.name = format!("{}-{run_id}", spec.name);
    model.description =
        format!("synthetic campaign {} run {run_id}: the true model ceilfarm simulates", spec.name);
    if let Some(d) = model.damping.as_mut() {
        d.extra.insert("stiffness".into(), json!("initial"));
        d.extra.insert(
            "target".into(),
            json!({"zeta": zeta, "f_hz": [prep.rayleigh.fx_hz, prep.rayleigh.fy_hz],
                   "modes": "first x and first y"}),
        );
    }
    model.analysis = Some(fe::model::Analysis::Transient(transient_stanza(run_id, prep)));
    let text = serde_json::to_string_pretty(&model).unwrap_or_default();
    text + "\n"
}

fn record_name(run_id: &str, dof: u8) -> String {
    format!("{run_id}.base_{}.csv", if dof == 1 { "x" } else { "y" })
}

fn record_text(dt_s: f64, accel_mm_s2: &[f64]) -> String {
    let mut h = History { columns: vec!["t_s".into(), "ag_mm_s2".into()], rows: vec![] };
    h.rows = accel_mm_s2.iter().enumerate().map(|(k, a)| vec![k as f64 * dt_s, *a]).collect();
    let mut out = Vec::new();
    let _ = fe::transient::write_history(&h, &mut out);
    String::from_utf8_lossy(&out).into_owned()
}

fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
}

fn transient_stanza(run_id: &str, prep: &PreparedRun) -> Map<String, Value> {
    let excitations: Vec<Value> = prep
        .base
        .components
        .iter()
        .map(|g| {
            let text = record_text(g.dt_s, &g.accel_mm_s2);
            json!({"type": "uniform_base_acceleration", "dof": g.dof,
                   "record_csv": record_name(run_id, g.dof), "dt": g.dt_s,
                   "npts": g.accel_mm_s2.len(), "units": "mm/s^2", "scale": 1.0,
                   "interpolation": "linear between samples",
                   "sha256": sha256_hex(text.as_bytes())})
        })
        .collect();
    // `"type": "transient"` comes from the Analysis enum's tag.
    let mut m = Map::new();
    m.insert(
        "initial_state".into(),
        json!("at rest and undeformed at t = 0; no gravity load; small displacements"),
    );
    if excitations.len() == 1 {
        m.insert("excitation".into(), excitations[0].clone());
    }
    m.insert("excitations".into(), Value::Array(excitations));
    m.insert("integrator".into(), json!({"type": "Newmark", "gamma": 0.5, "beta": 0.25}));
    m.insert("dt".into(), json!(prep.dt_s));
    m.insert("n_steps".into(), json!(prep.n_steps));
    m.insert("output_every_n_steps".into(), json!(prep.output_every_n_steps));
    m.insert("recorders".into(), json!(prep.recorders));
    m
}

/// The sidecar of a run.
pub fn sidecar(
    run_id: &str,
    sensors: &[bundle::Sensor],
    prep: &PreparedRun,
    model_text: &str,
) -> SensorsSidecar {
    let mut recipes = Vec::new();
    let mut col = 0;
    for (s, p) in sensors.iter().zip(&prep.placements) {
        let n = p.nodes.len();
        let recs = &prep.recorders[col..col + n];
        col += n;
        let (to_bundle, units) = match s.kind {
            SensorKind::Acceleration => (1e-3, "m/s2"),
            SensorKind::Displacement => (1.0, "mm"),
        };
        recipes.push(SensorRecipe {
            id: s.id.clone(),
            kind: s.kind.as_str().into(),
            direction: s.direction.as_str().into(),
            response: recs.first().map(|r| r.response.clone()).unwrap_or_default(),
            columns: recs.iter().map(|r| r.name.clone().unwrap_or_default()).collect(),
            weights: p.nodes.iter().map(|(_, w)| *w).collect(),
            to_bundle,
            bundle_units: units.into(),
        });
    }
    SensorsSidecar {
        format: SENSORS_FORMAT.into(),
        run: run_id.into(),
        model: format!("{run_id}.json"),
        model_sha256: sha256_hex(model_text.as_bytes()),
        history_csv: format!("{run_id}.history.csv"),
        dt_s: prep.input_dt_s,
        n_rows: prep.output_rows(),
        sensors: recipes,
    }
}

fn write(path: &Path, text: &str) -> Result<(), ExportError> {
    std::fs::write(path, text)
        .map_err(|e| ExportError { path: path.to_path_buf(), message: e.to_string() })
}

/// Writes a run's model, records and sidecar into `dir`.
pub fn write_run(
    dir: &Path,
    spec: &SynthSpec,
    run_id: &str,
    prep: &PreparedRun,
) -> Result<(), ExportError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| ExportError { path: dir.to_path_buf(), message: e.to_string() })?;
    let text = model_text(spec, run_id, prep, spec.truth.damping_ratio);
    write(&dir.join(format!("{run_id}.json")), &text)?;
    for g in &prep.base.components {
        write(&dir.join(record_name(run_id, g.dof)), &record_text(g.dt_s, &g.accel_mm_s2))?;
    }
    let side = sidecar(run_id, &spec.sensors, prep, &text);
    let side_text = serde_json::to_string_pretty(&side).unwrap_or_default() + "\n";
    write(&dir.join(format!("{run_id}.sensors.json")), &side_text)
}

/// Writes ceilfarm's own recorder history of a run (`<run>.ceilfarm.csv`:
/// `t_s`, then the recorder columns, as a simulator's history file).
pub fn write_ceilfarm_history(
    dir: &Path,
    run_id: &str,
    prep: &PreparedRun,
    hist: &History,
) -> Result<(), ExportError> {
    let first = hist.columns.len() - prep.recorders.len();
    let mut columns = vec!["t_s".to_string()];
    columns.extend(hist.columns[first..].iter().cloned());
    let rows = hist
        .rows
        .iter()
        .map(|r| std::iter::once(r[0]).chain(r[first..].iter().copied()).collect())
        .collect();
    let path = dir.join(format!("{run_id}.ceilfarm.csv"));
    write_history_csv(&History { columns, rows }, &path)
        .map_err(|e| ExportError { path, message: e.to_string() })
}

/// Writes `modal.json`: the model to analyse, the modes wanted and
/// ceilfarm's frequencies; a simulator adds `freq_hz` and `simulator`.
pub fn write_modal(
    dir: &Path,
    run_id: &str,
    n_modes: usize,
    prep: &PreparedRun,
) -> Result<(), ExportError> {
    let v = json!({"format": MODAL_FORMAT, "model": format!("{run_id}.json"),
                   "n_modes": n_modes, "ceilfarm_freq_hz": prep.freq_hz,
                   "ceilfarm_mode_dir": prep.mode_dir.iter().map(|c| c.to_string()).collect::<Vec<_>>()});
    write(&dir.join("modal.json"), &(serde_json::to_string_pretty(&v).unwrap_or_default() + "\n"))
}
