//! Reading another simulator's histories of exported runs (`ceilfarm synth
//! --histories MDIR`): `MDIR/<run>.history.csv` (header `t_s`, then at
//! least the run's recorder columns; one row per input sample from t = 0)
//! and, for modal data, `MDIR/modal.json` with the simulator's `freq_hz`.
//! The run's model file `MDIR/<run>.json` must be the one this campaign
//! exports now, so histories of another campaign or seed are refused.
//!
//! History files are read through the shared CSV reader
//! ([`worker::csv_rows`]: quotes, a byte-order mark, CRLF; no comment lines).
//!
//! Units: recorder columns in mm/s² and mm, as exported.

use super::export::model_text;
use super::spec::SynthSpec;
use fe::ceiling::PreparedRun;
use fe::transient::History;
use std::path::{Path, PathBuf};
use worker::csv_rows::{CsvError, CsvLimits, CsvRows};

/// Why a history (or modal) file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum HistoryError {
    /// The file could not be read.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        message: String,
    },
    /// A recorder column is absent.
    #[error(
        "{path}: no column {column:?}: expected t_s and the recorders of {model} ({expected})"
    )]
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// The column.
        column: String,
        /// The model file naming the recorders.
        model: String,
        /// The columns expected.
        expected: String,
    },
    /// Too few or too many rows.
    #[error("{path}: {rows} rows, expected {expected} (t = 0 to {end_s} s every {dt_s} s); the simulation stopped early or is of another run")]
    Rows {
        /// The file.
        path: PathBuf,
        /// Rows found.
        rows: usize,
        /// Rows expected.
        expected: usize,
        /// Last time expected (s).
        end_s: f64,
        /// Interval (s).
        dt_s: f64,
    },
    /// A value is not a finite number or a time is off the grid.
    #[error("{path}:{line}: column {column:?}: {message}")]
    Value {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// The column.
        column: String,
        /// What is wrong.
        message: String,
    },
    /// The model file differs from the one this campaign exports.
    #[error("{path}: differs from the model this campaign exports for run {run}; re-export with --export-models (other campaign, seed or ceilfarm version?)")]
    Model {
        /// The model file.
        path: PathBuf,
        /// Run id.
        run: String,
    },
    /// `modal.json` or `simulator.json` lacks what is needed.
    #[error("{path}: {message}")]
    Meta {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// A shared-reader error as a history error naming the file (and line).
fn csv_error(path: &Path, e: CsvError) -> HistoryError {
    let message = match e.line() {
        Some(line) => format!("line {line}: {e}"),
        None => e.to_string(),
    };
    HistoryError::Io { path: path.to_path_buf(), message }
}

fn read(path: &Path) -> Result<String, HistoryError> {
    std::fs::read_to_string(path)
        .map_err(|e| HistoryError::Io { path: path.to_path_buf(), message: e.to_string() })
}

/// Checks that `dir/<run>.json` is the model this campaign exports.
pub fn check_model(
    dir: &Path,
    spec: &SynthSpec,
    run_id: &str,
    prep: &PreparedRun,
) -> Result<(), HistoryError> {
    let path = dir.join(format!("{run_id}.json"));
    let text = read(&path)?;
    if text != model_text(spec, run_id, prep, spec.truth.damping_ratio) {
        return Err(HistoryError::Model { path, run: run_id.into() });
    }
    Ok(())
}

/// Reads `dir/<run>.history.csv` as a history whose columns are `t_s`
/// followed by the run's recorders in order (what `read_history` takes).
pub fn read_run_history(
    dir: &Path,
    run_id: &str,
    prep: &PreparedRun,
) -> Result<History, HistoryError> {
    let path = dir.join(format!("{run_id}.history.csv"));
    let text = read(&path)?;
    let mut csv = CsvRows::new(text.as_bytes(), CsvLimits::default(), false);
    let header: Vec<String> = match csv.next_row().map_err(|e| csv_error(&path, e))? {
        Some((_, record)) => record.iter().map(str::to_string).collect(),
        None => Vec::new(),
    };
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    let names = recorder_names(prep);
    let idx = recorder_columns(&path, run_id, &header, &names)?;
    let layout = HistoryLayout { path: &path, header, idx, dt: prep.input_dt_s };
    let mut rows = Vec::new();
    while let Some((line, record)) = csv.next_row().map_err(|e| csv_error(&path, e))? {
        let cells: Vec<&str> = record.iter().collect();
        let row = layout.row(line, &cells, rows.len())?;
        rows.push(row);
    }
    check_row_count(&path, rows.len(), prep.output_rows(), layout.dt)?;
    let mut columns = vec!["t_s".to_string()];
    columns.extend(names);
    Ok(History { columns, rows })
}

/// The run's recorder names in order (empty for an unnamed recorder).
fn recorder_names(prep: &PreparedRun) -> Vec<String> {
    prep.recorders.iter().map(|r| r.name.clone().unwrap_or_default()).collect()
}

/// The header positions of the recorder columns `names`, after a first `t_s`.
fn recorder_columns(
    path: &Path,
    run_id: &str,
    header: &[&str],
    names: &[String],
) -> Result<Vec<usize>, HistoryError> {
    let missing = |column: &str| HistoryError::MissingColumn {
        path: path.to_path_buf(),
        column: column.into(),
        model: format!("{run_id}.json"),
        expected: format!("{} recorder columns: {}", names.len(), names.join(", ")),
    };
    if header.first() != Some(&"t_s") {
        return Err(missing("t_s"));
    }
    names.iter().map(|n| header.iter().position(|h| h == n).ok_or_else(|| missing(n))).collect()
}

/// Where a history file's columns are and the time grid (step `dt` s) its rows follow.
struct HistoryLayout<'a> {
    /// The file.
    path: &'a Path,
    /// Header cells, trimmed.
    header: Vec<&'a str>,
    /// Header positions of the recorder columns.
    idx: Vec<usize>,
    /// Input sample interval (s).
    dt: f64,
}

impl HistoryLayout<'_> {
    /// Row number `row` (0-based) from file line `line` (1-based): `t`, then the recorders.
    fn row(&self, line: usize, cells: &[&str], row: usize) -> Result<Vec<f64>, HistoryError> {
        let t = self.value(line, cells, 0)?;
        self.check_time(line, t, row)?;
        let mut values = vec![t];
        for c in &self.idx {
            values.push(self.value(line, cells, *c)?);
        }
        Ok(values)
    }

    /// Refuses a time `t` (s) off the grid point of row `row`.
    fn check_time(&self, line: usize, t: f64, row: usize) -> Result<(), HistoryError> {
        let dt = self.dt;
        let want = row as f64 * dt;
        if (t - want).abs() > 1e-6 * dt.max(want.abs() * 1e-3) + 1e-9 {
            return Err(HistoryError::Value {
                path: self.path.to_path_buf(),
                line,
                column: "t_s".into(),
                message: format!("t = {t} s, expected {want} s (row {row} at {dt} s)"),
            });
        }
        Ok(())
    }

    /// The finite number in header column `c` of a line's `cells`.
    fn value(&self, line: usize, cells: &[&str], c: usize) -> Result<f64, HistoryError> {
        let bad = |message: String| HistoryError::Value {
            path: self.path.to_path_buf(),
            line,
            column: self.header.get(c).map_or(String::new(), |h| h.to_string()),
            message,
        };
        let s = cells
            .get(c)
            .ok_or_else(|| bad(format!("{} cells, expected {}", cells.len(), self.header.len())))?;
        let v: f64 = s.parse().map_err(|_| bad(format!("{s:?} is not a number")))?;
        if !v.is_finite() {
            return Err(bad(format!("{s}: expected a finite number")));
        }
        Ok(v)
    }
}

/// Refuses a history of `rows` rows when the run has `expected` (step `dt` s).
fn check_row_count(path: &Path, rows: usize, expected: usize, dt: f64) -> Result<(), HistoryError> {
    if rows != expected {
        return Err(HistoryError::Rows {
            path: path.to_path_buf(),
            rows,
            expected,
            end_s: (expected - 1) as f64 * dt,
            dt_s: dt,
        });
    }
    Ok(())
}

/// The simulator's lowest `modes` frequencies (Hz) from `dir/modal.json`.
pub fn read_modal(dir: &Path, modes: usize) -> Result<Vec<f64>, HistoryError> {
    let path = dir.join("modal.json");
    let text = read(&path)?;
    let bad = |message: String| HistoryError::Meta { path: path.clone(), message };
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
    let freq: Vec<f64> = v
        .get("freq_hz")
        .and_then(|f| f.as_array())
        .ok_or_else(|| bad("no freq_hz: expected the simulator's frequencies (run scripts/opensees/run_campaign.py)".into()))?
        .iter()
        .map(|f| f.as_f64().filter(|x| x.is_finite() && *x > 0.0))
        .collect::<Option<_>>()
        .ok_or_else(|| bad("freq_hz: expected positive finite numbers".into()))?;
    if freq.len() < modes {
        return Err(bad(format!("freq_hz has {} values, expected at least {modes}", freq.len())));
    }
    Ok(freq[..modes].to_vec())
}

/// The simulator named in `dir/simulator.json` (`{"simulator": NAME, ...}`).
pub fn read_simulator(dir: &Path) -> Result<String, HistoryError> {
    let path = dir.join("simulator.json");
    let text = read(&path)?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| HistoryError::Meta { path: path.clone(), message: e.to_string() })?;
    v.get("simulator").and_then(|s| s.as_str()).map(str::to_string).ok_or(HistoryError::Meta {
        path,
        message: "no \"simulator\": expected the name of the code that wrote the histories".into(),
    })
}
