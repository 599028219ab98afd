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

impl<S: Simulator + ?Sized> Simulator for &S {
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

/// A simulator with some parameters held fixed: the free ones, by index
/// into the full vector, are the only inputs.
pub struct SubsetSimulator<S> {
    inner: S,
    free: Vec<usize>,
    base: Vec<f64>,
}

impl<S: Simulator> SubsetSimulator<S> {
    /// Frees the parameters at `free` of `inner`; the rest take their value in `base` (n_params).
    pub fn new(inner: S, free: Vec<usize>, base: Vec<f64>) -> Result<Self, CalibError> {
        CalibError::check_len("full parameter vector", base.len(), inner.n_params())?;
        if let Some(&i) = free.iter().find(|&&i| i >= base.len()) {
            return Err(CalibError::invalid("free parameter index", i, "an index below n_params"));
        }
        Ok(Self { inner, free, base })
    }

    /// The full parameter vector for free values `theta`.
    pub fn full(&self, theta: &[f64]) -> Vec<f64> {
        let mut full = self.base.clone();
        self.free.iter().zip(theta).for_each(|(&i, &v)| full[i] = v);
        full
    }
}

impl<S: Simulator> Simulator for SubsetSimulator<S> {
    fn n_params(&self) -> usize {
        self.free.len()
    }
    fn n_outputs(&self) -> usize {
        self.inner.n_outputs()
    }
    fn predict(&self, theta: &[f64]) -> Result<Prediction, CalibError> {
        CalibError::check_len("free parameters", theta.len(), self.free.len())?;
        self.inner.predict(&self.full(theta))
    }
}
