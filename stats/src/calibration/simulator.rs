//! The simulator seen by calibration: physical parameters in, predictions at
//! the observation points out, with an optional predictive variance (a GP
//! emulator supplies one; a direct model does not).

use super::CalibError;
use nalgebra::DMatrix;

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
    /// The prediction and d mean / d theta (n_outputs, n_params), when the
    /// simulator can differentiate itself and its variance does not depend
    /// on theta (None otherwise).
    fn jacobian(&self, _theta: &[f64]) -> Option<Result<(Prediction, DMatrix<f64>), CalibError>> {
        None
    }
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
    fn jacobian(&self, theta: &[f64]) -> Option<Result<(Prediction, DMatrix<f64>), CalibError>> {
        (**self).jacobian(theta)
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
    fn jacobian(&self, theta: &[f64]) -> Option<Result<(Prediction, DMatrix<f64>), CalibError>> {
        (**self).jacobian(theta)
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
    fn jacobian(&self, theta: &[f64]) -> Option<Result<(Prediction, DMatrix<f64>), CalibError>> {
        (**self).jacobian(theta)
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
    fn jacobian(&self, theta: &[f64]) -> Option<Result<(Prediction, DMatrix<f64>), CalibError>> {
        if let Err(e) = CalibError::check_len("free parameters", theta.len(), self.free.len()) {
            return Some(Err(e));
        }
        let (p, j) = match self.inner.jacobian(&self.full(theta))? {
            Ok(v) => v,
            Err(e) => return Some(Err(e)),
        };
        Some(Ok((p, j.select_columns(self.free.iter()))))
    }
}

/// A simulator whose outputs are divided by a per-observation scale (the
/// observation sds): with observations divided the same way, unit noise
/// stands for independent noise of sd `scale[i]` at observation i.
pub struct Whitened<S> {
    inner: S,
    scale: Vec<f64>,
}

impl<S: Simulator> Whitened<S> {
    /// Divides output i of `inner` by `scale[i]` (finite, > 0).
    pub fn new(inner: S, scale: Vec<f64>) -> Result<Self, CalibError> {
        CalibError::check_len("output scales", scale.len(), inner.n_outputs())?;
        if let Some(s) = scale.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
            return Err(CalibError::invalid("output scale", s, "a finite value > 0"));
        }
        Ok(Self { inner, scale })
    }

    /// Observations divided by the same scales.
    pub fn whiten(&self, y: &[f64]) -> Vec<f64> {
        y.iter().zip(&self.scale).map(|(v, s)| v / s).collect()
    }
}

impl<S: Simulator> Simulator for Whitened<S> {
    fn n_params(&self) -> usize {
        self.inner.n_params()
    }
    fn n_outputs(&self) -> usize {
        self.inner.n_outputs()
    }
    fn predict(&self, theta: &[f64]) -> Result<Prediction, CalibError> {
        let p = self.inner.predict(theta)?;
        let s = &self.scale;
        Ok(Prediction {
            mean: p.mean.iter().zip(s).map(|(m, s)| m / s).collect(),
            variance: p.variance.map(|v| v.iter().zip(s).map(|(v, s)| v / (s * s)).collect()),
        })
    }
}

#[cfg(test)]
mod whitened_tests {
    use super::*;

    #[test]
    fn divides_means_and_variances() {
        struct Two;
        impl Simulator for Two {
            fn n_params(&self) -> usize {
                1
            }
            fn n_outputs(&self) -> usize {
                2
            }
            fn predict(&self, t: &[f64]) -> Result<Prediction, CalibError> {
                Ok(Prediction { mean: vec![t[0], 4.0], variance: Some(vec![1.0, 8.0]) })
            }
        }
        let w = Whitened::new(Two, vec![2.0, 4.0]).unwrap();
        let p = w.predict(&[3.0]).unwrap();
        assert_eq!(p.mean, vec![1.5, 1.0]);
        assert_eq!(p.variance.unwrap(), vec![0.25, 0.5]);
        assert_eq!(w.whiten(&[2.0, 2.0]), vec![1.0, 0.5]);
        assert!(Whitened::new(Two, vec![1.0, 0.0]).is_err());
        assert!(Whitened::new(Two, vec![1.0]).is_err());
    }
}
