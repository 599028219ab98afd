//! Running a model file's own analysis (`ceilfarm fe run`).

use std::path::{Path, PathBuf};

use crate::eigen::output::{write_modal, WriteError};
use crate::eigen::{modal_analysis, EigenError, LanczosSettings, ModalResult};
use crate::model::{read_model, Analysis, Model, ReadError};
use crate::transient::{
    run_model, write_history_csv, History, StepReport, TransientError, TransientOptions,
};

/// Why a model file could not be run.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The file could not be read or is invalid.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// The eigen solver failed.
    #[error("{path}: {error}")]
    Eigen {
        /// The model file.
        path: PathBuf,
        /// The cause (in the message, so not also a source to print twice).
        error: EigenError,
    },
    /// Results could not be written.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// The transient analysis failed; the rows up to the failure were written.
    #[error("{path}: {error}")]
    Transient {
        /// The model file.
        path: PathBuf,
        /// The cause (for a failed step: its time and reason).
        error: TransientError,
    },
    /// The file asks for no analysis, or one this build cannot run.
    #[error("{path}: analysis `{kind}`: {expected}")]
    Analysis {
        /// The model file.
        path: PathBuf,
        /// The analysis type found.
        kind: String,
        /// What is supported.
        expected: &'static str,
    },
}

/// What a run produced.
#[derive(Debug)]
pub enum RunSummary {
    /// An eigen analysis.
    Eigen(ModalResult),
    /// A transient analysis: the history written to `history.csv`.
    Transient(History),
}

/// Runs the file's analysis (or eigen with `modes_override` modes) into `out_dir`.
pub fn run_model_file(
    path: &Path,
    out_dir: &Path,
    modes_override: Option<usize>,
    observer: &mut dyn FnMut(&StepReport),
) -> Result<RunSummary, RunError> {
    let model = read_model(path)?;
    let n_modes = match (&model.analysis, modes_override) {
        (_, Some(n)) => n,
        (Some(Analysis::Eigen { n_modes, .. }), None) => *n_modes,
        (Some(Analysis::Transient(_)), None) => {
            return run_transient(&model, path, out_dir, observer).map(RunSummary::Transient)
        }
        (other, None) => {
            let kind = match other {
                Some(Analysis::Transient(_)) => "transient",
                _ => "none",
            };
            let expected = "expected `eigen` (or pass --modes N for an eigen analysis)";
            return Err(RunError::Analysis {
                path: path.to_path_buf(),
                kind: kind.into(),
                expected,
            });
        }
    };
    let (s, res) = modal_analysis(&model, n_modes, &LanczosSettings::default())
        .map_err(|error| RunError::Eigen { path: path.to_path_buf(), error })?;
    write_modal(out_dir, &s, &res)?;
    Ok(RunSummary::Eigen(res))
}

/// Runs a transient into `out_dir/history.csv`; a failed run still writes
/// the rows it reached before reporting the failure.
fn run_transient(
    model: &Model,
    path: &Path,
    out_dir: &Path,
    observer: &mut dyn FnMut(&StepReport),
) -> Result<History, RunError> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let fail = |error| RunError::Transient { path: path.to_path_buf(), error };
    std::fs::create_dir_all(out_dir).map_err(|e| {
        fail(TransientError::Io { path: out_dir.to_path_buf(), message: e.to_string() })
    })?;
    let out = out_dir.join("history.csv");
    match run_model(model, &TransientOptions::new(dir), observer) {
        Ok(h) => {
            write_history_csv(&h, &out).map_err(fail)?;
            Ok(h)
        }
        Err(TransientError::NoConvergence { t_s, dt_s, step, reason, history }) => {
            write_history_csv(&history, &out).map_err(fail)?;
            Err(fail(TransientError::NoConvergence { t_s, dt_s, step, reason, history }))
        }
        Err(e) => Err(fail(e)),
    }
}
