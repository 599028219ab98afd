//! Errors of calibration: bad settings or data, and failed simulator runs.

/// What went wrong while building or evaluating a calibration problem.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibError {
    /// A setting or input has a value outside what is allowed.
    #[error("{key} = {value}: expected {expected}")]
    Invalid {
        /// The offending key.
        key: String,
        /// Its value, printed.
        value: String,
        /// What was expected.
        expected: String,
    },
    /// Two inputs disagree in length.
    #[error("{what}: {found} values, expected {expected}")]
    Length {
        /// Which input.
        what: String,
        /// Its length.
        found: usize,
        /// The required length.
        expected: usize,
    },
    /// The simulator failed at these parameters.
    #[error("simulator failed at {theta:?}: {message}")]
    Simulator {
        /// Physical parameter values.
        theta: Vec<f64>,
        /// The simulator's reason.
        message: String,
    },
    /// A covariance matrix was not positive definite.
    #[error("covariance not positive definite ({what})")]
    NotPositiveDefinite {
        /// Which matrix.
        what: String,
    },
}

impl CalibError {
    /// Shorthand for [`CalibError::Invalid`].
    pub fn invalid(key: &str, value: impl std::fmt::Display, expected: &str) -> Self {
        Self::Invalid { key: key.into(), value: value.to_string(), expected: expected.into() }
    }

    /// Checks a length, naming the input.
    pub fn check_len(what: &str, found: usize, expected: usize) -> Result<(), Self> {
        if found == expected {
            Ok(())
        } else {
            Err(Self::Length { what: what.into(), found, expected })
        }
    }
}
