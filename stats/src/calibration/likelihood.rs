//! The likelihood trait and the fixed-or-inferred hyperparameter switch.
//!
//! Parameter layout: the simulator's parameters first, then each inferred
//! hyperparameter in the order [`Likelihood::extra_names`] lists them.

use super::CalibError;

/// A hyperparameter (noise sd, discrepancy sd, ...) that is fixed or inferred.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Hyper {
    /// Known value.
    Fixed(f64),
    /// Inferred: an extra parameter appended to the parameter vector.
    Inferred,
}

impl Hyper {
    /// Value: the fixed one, or the next extra parameter (advancing `next`).
    pub fn value(&self, params: &[f64], next: &mut usize) -> f64 {
        match *self {
            Hyper::Fixed(v) => v,
            Hyper::Inferred => {
                let v = params[*next];
                *next += 1;
                v
            }
        }
    }

    /// True when inferred.
    pub fn is_inferred(&self) -> bool {
        matches!(self, Hyper::Inferred)
    }

    /// Checks a fixed value is finite and positive.
    pub fn check_positive(&self, key: &str) -> Result<(), CalibError> {
        match *self {
            Hyper::Fixed(v) if !(v.is_finite() && v > 0.0) => {
                Err(CalibError::invalid(key, v, "a finite value > 0"))
            }
            _ => Ok(()),
        }
    }
}

/// log p(y | params) for a calibration problem.
pub trait Likelihood: Send + Sync {
    /// Number of simulator parameters.
    fn n_sim_params(&self) -> usize;
    /// Names of the inferred hyperparameters appended after them.
    fn extra_names(&self) -> Vec<String>;
    /// Number of observations.
    fn n_obs(&self) -> usize;
    /// log p(y | params), params = simulator parameters then extras.
    fn log_likelihood(&self, params: &[f64]) -> Result<f64, CalibError>;
    /// Total number of parameters.
    fn n_params(&self) -> usize {
        self.n_sim_params() + self.extra_names().len()
    }
    /// log p(y | params) and its gradient into `grad`, when the likelihood
    /// can give it more cheaply than central differences (None otherwise).
    fn log_likelihood_gradient(
        &self,
        _params: &[f64],
        _grad: &mut [f64],
    ) -> Option<Result<f64, CalibError>> {
        None
    }
}

impl<L: Likelihood + ?Sized> Likelihood for &L {
    fn n_sim_params(&self) -> usize {
        (**self).n_sim_params()
    }
    fn extra_names(&self) -> Vec<String> {
        (**self).extra_names()
    }
    fn n_obs(&self) -> usize {
        (**self).n_obs()
    }
    fn log_likelihood(&self, params: &[f64]) -> Result<f64, CalibError> {
        (**self).log_likelihood(params)
    }
}
