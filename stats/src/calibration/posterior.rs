//! The unnormalised log posterior in unconstrained space,
//! log p(z | y) = log p(y | theta(z)) + log p_z(z), the target of BBVI and MCMC.

use super::{CalibError, Likelihood, UniformBox};

/// An unnormalised log density on R^d.
pub trait LogDensity: Sync {
    /// Dimension d.
    fn dim(&self) -> usize;
    /// log density at z (d); −inf where the model fails.
    fn log_density(&self, z: &[f64]) -> f64;
    /// Gradient into `grad` (d) and the log density; central differences by default.
    fn gradient(&self, z: &[f64], grad: &mut [f64]) -> f64 {
        fd_gradient(self, z, grad)
    }
}

/// Prior box plus likelihood: the calibration posterior.
pub struct Posterior<L> {
    prior: UniformBox,
    lik: L,
}

impl<L: Likelihood> Posterior<L> {
    /// Joins a prior over all parameters (simulator then extras) with a likelihood.
    pub fn new(prior: UniformBox, lik: L) -> Result<Self, CalibError> {
        CalibError::check_len("prior parameters", prior.dim(), lik.n_params())?;
        Ok(Self { prior, lik })
    }

    /// The prior box.
    pub fn prior(&self) -> &UniformBox {
        &self.prior
    }

    /// The likelihood.
    pub fn likelihood(&self) -> &L {
        &self.lik
    }

    /// Physical parameters of unconstrained z.
    pub fn to_physical(&self, z: &[f64]) -> Vec<f64> {
        self.prior.to_physical(z)
    }
}

impl<L: Likelihood> LogDensity for Posterior<L> {
    fn dim(&self) -> usize {
        self.prior.dim()
    }
    fn log_density(&self, z: &[f64]) -> f64 {
        if z.iter().any(|v| !v.is_finite()) {
            return f64::NEG_INFINITY;
        }
        let theta = self.prior.to_physical(z);
        match self.lik.log_likelihood(&theta) {
            Ok(ll) if ll.is_finite() => ll + self.prior.log_density_unconstrained(z),
            _ => f64::NEG_INFINITY,
        }
    }
    /// The likelihood's own gradient through theta = a + (b − a) sigmoid(z)
    /// when it has one; central differences otherwise.
    fn gradient(&self, z: &[f64], grad: &mut [f64]) -> f64 {
        if z.iter().any(|v| !v.is_finite()) {
            return f64::NEG_INFINITY;
        }
        let theta = self.prior.to_physical(z);
        match self.lik.log_likelihood_gradient(&theta, grad) {
            None => fd_gradient(self, z, grad),
            Some(Ok(ll)) if ll.is_finite() => {
                for (i, g) in grad.iter_mut().enumerate() {
                    let s = super::prior::sigmoid(z[i]);
                    let width = self.prior.upper[i] - self.prior.lower[i];
                    *g = *g * width * s * (1.0 - s) + 1.0 - 2.0 * s;
                }
                ll + self.prior.log_density_unconstrained(z)
            }
            Some(_) => f64::NEG_INFINITY,
        }
    }
}

/// Central-difference gradient of `t` (the trait's default).
pub fn fd_gradient<T: LogDensity + ?Sized>(t: &T, z: &[f64], grad: &mut [f64]) -> f64 {
    let mut zz = z.to_vec();
    for i in 0..z.len() {
        let h = 1e-5 * (1.0 + z[i].abs());
        zz[i] = z[i] + h;
        let up = t.log_density(&zz);
        zz[i] = z[i] - h;
        let down = t.log_density(&zz);
        zz[i] = z[i];
        grad[i] = (up - down) / (2.0 * h);
    }
    t.log_density(z)
}

impl<T: LogDensity + ?Sized> LogDensity for &T {
    fn dim(&self) -> usize {
        (**self).dim()
    }
    fn log_density(&self, z: &[f64]) -> f64 {
        (**self).log_density(z)
    }
    fn gradient(&self, z: &[f64], grad: &mut [f64]) -> f64 {
        (**self).gradient(z, grad)
    }
}
