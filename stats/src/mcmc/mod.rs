//! MCMC reference sampler and diagnostics for checking variational fits.
//!
//! Roles: [`AdaptiveMetropolis`] (Haario, Saksman & Tamminen 2001) runs
//! several independent chains on a [`LogDensity`](crate::calibration::LogDensity),
//! adapting its Gaussian proposal during warm-up and freezing it afterwards;
//! [`split_rhat`] and [`ess`] (Gelman et al., BDA3 §11.4–11.5) judge the
//! chains; [`psis`] (Vehtari, Simpson, Gelman, Yao & Gabry 2024) gives the
//! Pareto k-hat of importance weights p/q, the reliability of a VI fit.
//!
//! ```
//! use stats::mcmc::{AdaptiveMetropolis, McmcSettings};
//! use stats::calibration::LogDensity;
//! struct Normal;
//! impl LogDensity for Normal {
//!     fn dim(&self) -> usize { 1 }
//!     fn log_density(&self, z: &[f64]) -> f64 { -0.5 * z[0] * z[0] }
//! }
//! let run = AdaptiveMetropolis::new(McmcSettings { iters: 4000, warmup: 1000, ..McmcSettings::default() })
//!     .run(&Normal, &[0.0]).unwrap();
//! assert!(run.rhat[0] < 1.05);
//! ```

pub mod adaptive_metropolis;
pub mod diagnostics;
pub mod psis;

pub use adaptive_metropolis::{AdaptiveMetropolis, McmcError, McmcRun, McmcSettings};
pub use diagnostics::{ess, split_rhat};
pub use psis::{psis, PsisResult};
