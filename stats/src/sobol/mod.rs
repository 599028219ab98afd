//! Variance-based sensitivity: Saltelli sampling, Jansen and Saltelli-2010
//! estimators of first- and total-order Sobol' indices with bootstrap
//! intervals, screening of inert inputs, and analytic test functions.
//! Sampling and analysis are pure (SALib's `sample` / `analyze`); the
//! caller evaluates the model in between.
//!
//! ```
//! use stats::sobol::{analyze, functions, saltelli_sample, AnalyzeSettings};
//! let p = functions::problem("ishigami").unwrap();
//! let x = saltelli_sample(&p, 1024, 0);
//! let y: Vec<f64> = x.chunks(3).map(functions::ishigami).collect();
//! let s = analyze(3, &y, &AnalyzeSettings::default()).unwrap();
//! assert!((s.st[0] - 0.5576).abs() < 0.02);
//! ```

pub mod analyze;
pub mod functions;
pub mod problem;
pub mod sample;
pub mod screening;

pub use analyze::{analyze, AnalyzeSettings, FirstOrder, Indices, SobolError};
pub use problem::Problem;
pub use sample::saltelli_sample;
pub use screening::screen;
