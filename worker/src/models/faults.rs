//! `test-faults`: a model that fails on purpose, to exercise how the farm
//! records errors, panics, timeouts and non-finite outputs. Output `y` =
//! sum of the parameters.

use crate::model::{Model, ModelError, ParamSet, RunContext, RunError};
use protocol::Outputs;
use serde::Deserialize;
use std::time::Duration;

/// Which task ids misbehave and how.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct FaultOptions {
    /// Task ids whose run panics.
    #[serde(default)]
    pub panic_on: Vec<u64>,
    /// Task ids whose run returns an error.
    #[serde(default)]
    pub error_on: Vec<u64>,
    /// Task ids whose run never finishes until cancelled.
    #[serde(default)]
    pub hang_on: Vec<u64>,
    /// Task ids whose output `y` is NaN.
    #[serde(default)]
    pub nan_on: Vec<u64>,
    /// Task ids whose output `y` is +infinity.
    #[serde(default)]
    pub inf_on: Vec<u64>,
}

/// The fault-injecting model.
pub struct Faults {
    opts: FaultOptions,
}

impl Faults {
    /// Builds it; any parameters are accepted.
    pub fn new(opts: FaultOptions, _names: &[String]) -> Result<Self, ModelError> {
        Ok(Self { opts })
    }
}

impl Model for Faults {
    fn output_names(&self) -> Vec<String> {
        vec!["y".into()]
    }
    fn run(&self, p: &ParamSet<'_>, ctx: &RunContext) -> Result<Outputs, RunError> {
        let id = ctx.task.map(|t| t.0).unwrap_or(u64::MAX);
        if self.opts.panic_on.contains(&id) {
            panic!("injected panic in task {id}");
        }
        if self.opts.error_on.contains(&id) {
            return Err(RunError::Failed(format!("injected error in task {id}")));
        }
        if self.opts.hang_on.contains(&id) {
            while !ctx.cancelled() {
                std::thread::sleep(Duration::from_millis(5));
            }
            return Err(RunError::Cancelled);
        }
        let y = if self.opts.nan_on.contains(&id) {
            f64::NAN
        } else if self.opts.inf_on.contains(&id) {
            f64::INFINITY
        } else {
            p.values().iter().sum()
        };
        Ok(Outputs { scalars: vec![("y".into(), y)], histories: vec![] })
    }
}
