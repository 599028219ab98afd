//! Errors of GP fitting and prediction.

use thiserror::Error;

/// What went wrong while fitting or using a Gaussian process.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum GpError {
    /// The covariance matrix stayed indefinite after the largest jitter.
    #[error("covariance not positive definite even with jitter {jitter:e} (n = {n})")]
    NotPositiveDefinite {
        /// Largest jitter tried (added to the diagonal).
        jitter: f64,
        /// Number of training points.
        n: usize,
    },
    /// Training data are empty or inconsistent in shape.
    #[error("training data: {what}: expected {expected}, found {found}")]
    Shape {
        /// Which array.
        what: &'static str,
        /// Expected size.
        expected: usize,
        /// Size found.
        found: usize,
    },
    /// A value that must be finite is not.
    #[error("{what}: non-finite value at row {row}")]
    NonFinite {
        /// Which array.
        what: &'static str,
        /// Row of the offending value.
        row: usize,
    },
    /// A bad setting.
    #[error("setting {key} = {value}: expected {expected}")]
    Setting {
        /// Setting name.
        key: &'static str,
        /// Value given.
        value: String,
        /// What is allowed.
        expected: &'static str,
    },
    /// The optimiser found no start with a finite likelihood.
    #[error("no start gave a finite log marginal likelihood ({starts} starts)")]
    NoFiniteStart {
        /// Number of starts tried.
        starts: usize,
    },
}
