//! Why a bundle was refused: always the file, then the line or key.

use std::path::PathBuf;

/// A refused bundle.
#[derive(Debug, thiserror::Error)]
pub enum BundleError {
    /// A file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A required file is missing.
    #[error("{path}: missing ({what})")]
    Missing {
        /// The file.
        path: PathBuf,
        /// Why it is needed.
        what: String,
    },
    /// A key of `bundle.toml` is wrong.
    #[error("{path}: {key}: {message}")]
    Key {
        /// The file.
        path: PathBuf,
        /// The key, e.g. `sensors[3].x_m`.
        key: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A line of a CSV file is wrong.
    #[error("{path}:{line}: {message}")]
    Line {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A whole-file problem (size, encoding, structure).
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}
