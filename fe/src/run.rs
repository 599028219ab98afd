//! Running a model file's own analysis (`ceilfarm fe run`).

use std::path::{Path, PathBuf};

use crate::eigen::output::{write_modal, WriteError};
use crate::eigen::{modal_analysis, EigenError, LanczosSettings, ModalResult};
use crate::model::{read_model, Analysis, ReadError};

/// Why a model file could not be run.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The file could not be read or is invalid.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// The eigen solver failed.
    #[error("{path}: {source}")]
    Eigen {
        /// The model file.
        path: PathBuf,
        /// The cause.
        source: EigenError,
    },
    /// Results could not be written.
    #[error(transparent)]
    Write(#[from] WriteError),
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
}

/// Runs the file's analysis (or eigen with `modes_override` modes) into `out_dir`.
pub fn run_model_file(
    path: &Path,
    out_dir: &Path,
    modes_override: Option<usize>,
) -> Result<RunSummary, RunError> {
    let model = read_model(path)?;
    let n_modes = match (&model.analysis, modes_override) {
        (_, Some(n)) => n,
        (Some(Analysis::Eigen { n_modes, .. }), None) => *n_modes,
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
        .map_err(|source| RunError::Eigen { path: path.to_path_buf(), source })?;
    write_modal(out_dir, &s, &res)?;
    Ok(RunSummary::Eigen(res))
}
