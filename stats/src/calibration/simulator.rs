//! The simulator seen by calibration: physical parameters in, predictions at
//! the observation points out, with an optional predictive variance (a GP
//! emulator supplies one; a direct model does not).

use super::CalibError;

/// Predictions at the observation points, (n_obs) each.
#[derive(Debug, Clone, PartialEq)]
pub struct Prediction {
    /// Predicted mean at each observation point.
    pub mean: Vec<f64>,
    /// Predictive variance at each point, if the simulator is an emulator.
    pub variance: Option<Vec<f64>>,
}

/// A simulator with optional predictive variance.
pub trait Simulator: Send + Sync {
    /// Number of calibration parameters it takes.
    fn n_params(&self) -> usize;
    /// Number of predictions it returns (one per observation).
    fn n_outputs(&self) -> usize;
    /// Predicts at physical parameters `theta` (n_params).
    fn predict(&self, theta: &[f64]) -> Result<Prediction, CalibError>;
}

/// A cheap simulator given as a closure returning the mean predictions.
pub struct FnSimulator<F> {
    n_params: usize,
    n_outputs: usize,
    f: F,
}

impl<F> FnSimulator<F>
where
    F: Fn(&[f64]) -> Result<Vec<f64>, String> + Send + Sync,
{
    /// Wraps `f`, which maps (n_params) to (n_outputs).
    pub fn new(n_params: usize, n_outputs: usize, f: F) -> Self {
        Self { n_params, n_outputs, f }
    }
}

impl<F> Simulator for FnSimulator<F>
where
    F: Fn(&[f64]) -> Result<Vec<f64>, String> + Send + Sync,
{
    fn n_params(&self) -> usize {
        self.n_params
    }
    fn n_outputs(&self) -> usize {
        self.n_outputs
    }
    fn predict(&self, theta: &[f64]) -> Result<Prediction, CalibError> {
        let mean = (self.f)(theta)
            .map_err(|message| CalibError::Simulator { theta: theta.to_vec(), message })?;
        CalibError::check_len("simulator outputs", mean.len(), self.n_outputs)?;
        Ok(Prediction { mean, variance: None })
    }
}

impl<S: Simulator + ?Sized> Simulator for Box<S> {
    fn n_params(&self) -> usize {
        (**self).n_params()
    }
    fn n_outputs(&self) -> usize {
        (**self).n_outputs()
    }
    fn predict(&self, theta: &[f64]) -> Result<Prediction, CalibError> {
        (**self).predict(theta)
    }
}

impl<S: Simulator + ?Sized> Simulator for std::sync::Arc<S> {
    fn n_params(&self) -> usize {
        (**self).n_params()
    }
    fn n_outputs(&self) -> usize {
        (**self).n_outputs()
    }
    fn predict(&self, theta: &[f64]) -> Result<Prediction, CalibError> {
        (**self).predict(theta)
    }
}
