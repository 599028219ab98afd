//! Gaussian-process regression: ARD kernels (squared exponential, Matérn
//! 3/2 and 5/2, rational quadratic) plus white noise, zero/constant/linear
//! mean, hyperparameters by maximising the log marginal likelihood with
//! analytic gradients (bounded L-BFGS, parallel multi-start, jitter
//! escalation), inputs scaled to [0, 1] and power-warped (identity to log
//! scale, learned with the kernel; positive inputs only), outputs
//! standardised.
//!
//! Roles: [`GpSettings`] configure, [`fit`] returns a [`Gp`] whose
//! [`GpModel`] is serialisable (the model file) and whose `predict`
//! gives means and sds in physical units.
//!
//! ```
//! use stats::gp::{fit, GpSettings};
//! let x: Vec<f64> = (0..20).map(|i| i as f64 / 19.0).collect();
//! let y: Vec<f64> = x.iter().map(|v| (6.0 * v).sin()).collect();
//! let gp = fit(&x, 1, &y, None, &GpSettings::default()).unwrap();
//! let p = gp.predict(&[0.5], false).unwrap();
//! assert!((p.mean[0] - 3.0f64.sin()).abs() < 1e-3);
//! ```

pub mod error;
pub mod exp_kernel;
pub mod fit;
pub mod kernel;
pub mod lbfgs;
pub mod likelihood;
pub mod line_search;
pub mod lml_workspace;
pub mod mean;
pub mod model;
pub mod pca;
pub mod scaling;
pub mod warp;

pub use error::GpError;
pub use fit::{fit, fit_shared, GpSettings};
pub use kernel::{Kernel, KernelKind};
pub use mean::MeanKind;
pub use model::{FitReport, Gp, GpModel, Prediction};
pub use scaling::{InputScaling, OutputScaling};
pub use warp::{InputWarp, PowerWarp};
