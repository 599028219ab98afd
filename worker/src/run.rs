//! Running one task: the model call, with panics caught and kept as data.

use crate::model::{Model, ParamSet, RunContext};
use protocol::{Outcome, TaskId};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Runs one task to an [`Outcome`]; errors and panics become `Failed`.
pub fn run_task(model: &dyn Model, names: &[String], id: TaskId, params: &[f64]) -> Outcome {
    run_task_with(model, names, &RunContext::new(id, Arc::new(AtomicBool::new(false))), params)
}

/// As [`run_task`], with a caller-owned context (for cancellation).
pub fn run_task_with(model: &dyn Model, names: &[String], ctx: &RunContext, params: &[f64]) -> Outcome {
    let result = catch_unwind(AssertUnwindSafe(|| {
        let p = ParamSet::new(names, params)?;
        model.run(&p, ctx)
    }));
    match result {
        Ok(Ok(out)) => Outcome::Ok(out),
        Ok(Err(e)) => Outcome::Failed { reason: e.to_string() },
        Err(payload) => Outcome::Failed { reason: format!("panic: {}", panic_message(&payload)) },
    }
}

fn panic_message(payload: &Box<dyn std::any::Any + Send>) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown payload".into()
    }
}

/// Host name of this machine, for provenance.
pub fn host_name() -> String {
    gethostname::gethostname().to_string_lossy().into_owned()
}
