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
    fn jacobian(&self, theta: &[f64]) -> Option<Result<(Prediction, DMatrix<f64>), CalibError>> {
        let (p, mut j) = match self.inner.jacobian(theta)? {
            Ok(v) => v,
            Err(e) => return Some(Err(e)),
        };
        for (i, s) in self.scale.iter().enumerate() {
            j.row_mut(i).scale_mut(1.0 / s);
        }
        let s = &self.scale;
        Some(Ok((
            Prediction {
                mean: p.mean.iter().zip(s).map(|(m, s)| m / s).collect(),
                variance: p.variance.map(|v| v.iter().zip(s).map(|(v, s)| v / (s * s)).collect()),
            },
            j,
        )))
    }
}

/// A simulator whose outputs are mapped by a fixed matrix: A (alpha eta).
/// With A = L^-1, L the Cholesky factor of a fixed covariance C of
/// y - alpha eta, and observations mapped the same way, unit white noise
/// stands for N(0, C) (e.g. a Kennedy–O'Hagan discrepancy plus noise at
/// fixed hyperparameters).
pub struct LinearMap<S> {
    inner: S,
    a: DMatrix<f64>,
}

impl<S: Simulator> LinearMap<S> {
    /// Outputs `a` (m, n_outputs) times `alpha` times those of `inner`.
    pub fn new(inner: S, a: DMatrix<f64>, alpha: f64) -> Result<Self, CalibError> {
        CalibError::check_len("map columns", a.ncols(), inner.n_outputs())?;
        if !alpha.is_finite() || a.iter().any(|v| !v.is_finite()) {
            return Err(CalibError::invalid("linear map", alpha, "finite entries"));
        }
        Ok(Self { inner, a: a * alpha })
    }

    /// Whitening by the Cholesky factor of `cov`: A = L^-1.
    pub fn whitening(inner: S, cov: DMatrix<f64>, alpha: f64) -> Result<Self, CalibError> {
        let n = cov.nrows();
        let chol = cov
            .cholesky()
            .ok_or(CalibError::NotPositiveDefinite { what: "covariance to whiten by".into() })?;
        let l_inv = chol
            .l()
            .solve_lower_triangular(&DMatrix::identity(n, n))
            .ok_or(CalibError::NotPositiveDefinite { what: "covariance to whiten by".into() })?;
        Self::new(inner, l_inv, alpha)
    }

    /// Observations mapped by the matrix without alpha: y -> L^-1 y when
    /// whitening (the caller divides alpha back out).
    pub fn map_observations(&self, y: &[f64], alpha: f64) -> Vec<f64> {
        (&self.a * nalgebra::DVector::from_column_slice(y) / alpha).as_slice().to_vec()
    }
}

impl<S: Simulator> Simulator for LinearMap<S> {
    fn n_params(&self) -> usize {
        self.inner.n_params()
    }
    fn n_outputs(&self) -> usize {
        self.a.nrows()
    }
    fn predict(&self, theta: &[f64]) -> Result<Prediction, CalibError> {
        let p = self.inner.predict(theta)?;
        let mean = &self.a * nalgebra::DVector::from_column_slice(&p.mean);
        let variance = p.variance.map(|v| {
            let a2 = self.a.map(|x| x * x);
            (a2 * nalgebra::DVector::from_column_slice(&v)).as_slice().to_vec()
        });
        Ok(Prediction { mean: mean.as_slice().to_vec(), variance })
    }
    fn jacobian(&self, theta: &[f64]) -> Option<Result<(Prediction, DMatrix<f64>), CalibError>> {
        let (p, j) = match self.inner.jacobian(theta)? {
            Ok(v) => v,
            Err(e) => return Some(Err(e)),
        };
        let mean = &self.a * nalgebra::DVector::from_column_slice(&p.mean);
        Some(Ok((Prediction { mean: mean.as_slice().to_vec(), variance: None }, &self.a * j)))
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
        assert!(w.jacobian(&[3.0]).is_none());
        assert!(Whitened::new(Two, vec![1.0, 0.0]).is_err());
        assert!(Whitened::new(Two, vec![1.0]).is_err());
    }
}

#[cfg(test)]
mod linear_map_tests {
    use super::*;
    use crate::calibration::gaussian::gaussian_log_density;
    use crate::calibration::koh::mvn_log_density;

    /// Unit white noise on whitened values equals N(0, C) on the original
    /// ones up to the constant log det L.
    #[test]
    fn whitening_turns_a_covariance_into_unit_noise() {
        let sim = FnSimulator::new(1, 3, |t: &[f64]| Ok(vec![t[0], 2.0 * t[0], 1.0]));
        let cov = DMatrix::from_row_slice(3, 3, &[1.0, 0.5, 0.1, 0.5, 2.0, 0.3, 0.1, 0.3, 0.5]);
        let alpha = 1.3;
        let y = [0.9, 2.5, 1.2];
        let map = LinearMap::whitening(sim, cov.clone(), alpha).unwrap();
        let yw = map.map_observations(&y, alpha);
        let eta = map.predict(&[0.8]).unwrap().mean;
        let r: Vec<f64> = yw.iter().zip(&eta).map(|(a, b)| a - b).collect();
        let white = gaussian_log_density(&r, std::iter::repeat(1.0));
        let raw: Vec<f64> = [0.8, 1.6, 1.0].iter().zip(&y).map(|(m, y)| y - alpha * m).collect();
        let chol = cov.clone().cholesky().unwrap();
        let log_det_l: f64 = (0..3).map(|i| chol.l()[(i, i)].ln()).sum();
        let full = mvn_log_density(&chol, &raw);
        assert!((white - log_det_l - full).abs() < 1e-12, "{white} {full}");
    }
}

/// Test simulators shared by the likelihood and selection tests.
#[cfg(test)]
pub mod test_support {
    use super::*;

    /// eta(a, b) = (a + b/2, a b, sin a), with its exact Jacobian when the flag is set.
    pub struct Smooth(pub bool);

    impl Simulator for Smooth {
        fn n_params(&self) -> usize {
            2
        }
        fn n_outputs(&self) -> usize {
            3
        }
        fn predict(&self, t: &[f64]) -> Result<Prediction, CalibError> {
            Ok(Prediction {
                mean: vec![t[0] + 0.5 * t[1], t[0] * t[1], t[0].sin()],
                variance: None,
            })
        }
        fn jacobian(&self, t: &[f64]) -> Option<Result<(Prediction, DMatrix<f64>), CalibError>> {
            let j = DMatrix::from_row_slice(3, 2, &[1.0, 0.5, t[1], t[0], t[0].cos(), 0.0]);
            self.0.then(|| self.predict(t).map(|p| (p, j)))
        }
    }
}
