//! Bayesian calibration of a simulator against observations.
//!
//! Roles: a [`Simulator`] maps physical parameters to predictions (optionally
//! with a predictive variance, as a GP emulator gives); a [`Likelihood`]
//! scores observations given parameters — [`GaussianLikelihood`] (known or
//! inferred noise) or [`KohLikelihood`] (Kennedy–O'Hagan with a marginalised
//! squared-exponential GP discrepancy, seed eqs. 6.3–6.11); a [`UniformBox`]
//! prior maps the bounded box to unconstrained space by a logit transform;
//! [`Posterior`] joins them into the [`LogDensity`] that BBVI and MCMC use.
//!
//! ```
//! use stats::calibration::{FnSimulator, GaussianLikelihood, Hyper, Posterior, UniformBox, LogDensity};
//! let sim = FnSimulator::new(1, 2, |t: &[f64]| Ok(vec![t[0], 2.0 * t[0]]));
//! let lik = GaussianLikelihood::new(sim, vec![1.0, 2.0], Hyper::Fixed(0.1)).unwrap();
//! let prior = UniformBox::new(vec!["a".into()], vec![0.0], vec![2.0]).unwrap();
//! let post = Posterior::new(prior, lik).unwrap();
//! assert!(post.log_density(&[0.0]).is_finite());
//! ```

pub mod emulator;
pub mod error;
pub mod gaussian;
pub mod kernel;
pub mod koh;
pub mod likelihood;
pub mod posterior;
pub mod prior;
pub mod run;
pub mod simulator;
pub mod summary;

pub use emulator::GpEmulator;
pub use error::CalibError;
pub use gaussian::GaussianLikelihood;
pub use kernel::SquaredExponential;
pub use koh::{KohLikelihood, KohSettings};
pub use likelihood::{Hyper, Likelihood};
pub use posterior::{LogDensity, Posterior};
pub use prior::UniformBox;
pub use run::{calibrate, CalibrationResult, Diagnostics, Method, RunError, RunSettings};
pub use simulator::{FnSimulator, LinearMap, Prediction, Simulator, SubsetSimulator, Whitened};
pub use summary::{Marginal, PosteriorSummary};
