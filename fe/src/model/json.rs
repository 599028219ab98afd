//! Reading and writing `ceiling-fe-model` JSON; reading validates.

use std::path::{Path, PathBuf};

use super::ir::Model;
use super::validate::{validate, ModelError};

/// Why a model file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The text is not a model in the format's shape.
    #[error("{path}:{line}:{column}: {message}")]
    Json {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What serde expected.
        message: String,
    },
    /// The model parsed but breaks a rule of the format.
    #[error("{path}: {source}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The broken rule.
        source: ModelError,
    },
}

/// Parses and validates a model from JSON text; `path` names it in errors.
pub fn parse_model(text: &str, path: &Path) -> Result<Model, ReadError> {
    let model: Model = serde_json::from_str(text).map_err(|e| ReadError::Json {
        path: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    validate(&model).map_err(|source| ReadError::Invalid { path: path.to_path_buf(), source })?;
    Ok(model)
}

/// Reads and validates a model file.
pub fn read_model(path: &Path) -> Result<Model, ReadError> {
    let text = std::fs::read_to_string(path)
        .map_err(|source| ReadError::Io { path: path.to_path_buf(), source })?;
    parse_model(&text, path)
}

/// Writes a model as pretty JSON.
pub fn write_model(model: &Model, path: &Path) -> Result<(), ReadError> {
    let text = serde_json::to_string_pretty(model).map_err(|e| ReadError::Json {
        path: path.to_path_buf(),
        line: 0,
        column: 0,
        message: e.to_string(),
    })?;
    std::fs::write(path, text + "\n")
        .map_err(|source| ReadError::Io { path: path.to_path_buf(), source })
}
