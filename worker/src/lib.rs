//! The stateless side of the farm: a registry of model kinds and the loop
//! that runs tasks.
//!
//! A [`Model`] maps a parameter set to [`protocol::Outputs`]. Analytic models
//! (Ishigami, Sobol' G, borehole, oscillator, no-op) and the ceiling models are
//! peers in the [`registry`]; the coordinator names one by its study's
//! `[model] kind`.
//!
//! ```
//! use protocol::{ModelSpec, TaskId};
//! let spec = ModelSpec {
//!     kind: "ishigami".into(),
//!     options_json: "{}".into(),
//!     param_names: vec!["x1".into(), "x2".into(), "x3".into()],
//!     outputs: vec![],
//! };
//! let model = worker::registry::build(&spec).unwrap();
//! let out = worker::run_task(model.as_ref(), &spec.param_names, TaskId(0), &[0.0, 0.0, 0.0]);
//! assert!(matches!(out, protocol::Outcome::Ok(_)));
//! ```

pub mod ceiling;
pub mod ceiling_campaign;
pub mod ceiling_modal;
pub mod csv_rows;
pub mod exact_json;
pub mod model;
pub mod models;
pub mod registry;
pub mod remote;
pub mod run;
pub mod specimen;

pub use model::{Model, ModelError, ParamSet, RunContext, RunError};
pub use run::{run_task, LocalRunner};
