//! Black-box variational inference (Ranganath, Gerrish & Blei 2014; seed
//! Algorithm 6.2) with a Gaussian family in unconstrained space.
//!
//! Roles: [`GaussianQ`] is the variational family (mean-field or full-rank
//! with a Cholesky factor); [`Estimator`] picks the ELBO gradient — the
//! score-function estimator with control variates and Rao–Blackwellisation,
//! or the reparameterisation estimator; [`StepRule`] turns gradients into
//! steps (Robbins–Monro, AdaGrad, Adam); [`Bbvi`] holds the settings and
//! advances a [`BbviState`] one [`Bbvi::step`] at a time, and [`Bbvi::run`]
//! drives it to convergence (relative change of window-averaged parameters)
//! while [`Observer`]s watch.
//!
//! ```
//! use stats::bbvi::{Bbvi, BbviSettings, FamilyKind};
//! use stats::calibration::LogDensity;
//! struct Normal;
//! impl LogDensity for Normal {
//!     fn dim(&self) -> usize { 1 }
//!     fn log_density(&self, z: &[f64]) -> f64 { -0.5 * (z[0] - 3.0).powi(2) / 4.0 }
//! }
//! let fit = Bbvi::new(&Normal, BbviSettings::reparam(FamilyKind::FullRank, 7)).run(&[0.0], &mut []).unwrap();
//! assert!((fit.q.mean()[0] - 3.0).abs() < 0.1);
//! ```

pub mod driver;
pub mod estimator;
pub mod family;
pub mod step_size;

pub use driver::{Bbvi, BbviError, BbviFit, BbviSettings, BbviState, Observer};
pub use estimator::{Estimator, GradientEstimate};
pub use family::{FamilyKind, GaussianQ};
pub use step_size::{StepRule, StepState};
