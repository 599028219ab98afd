//! Running one task: the model call, with panics caught and non-finite
//! outputs kept as data (failures with their reason).

use crate::model::{Model, ParamSet, RunContext};
use protocol::{Outcome, TaskId};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Runs one task to an [`Outcome`]; errors, panics and NaN or infinite
/// outputs become `Failed`.
pub fn run_task(model: &dyn Model, names: &[String], id: TaskId, params: &[f64]) -> Outcome {
    run_task_with(model, names, &RunContext::new(id, Arc::new(AtomicBool::new(false))), params)
}

/// As [`run_task`], with a caller-owned context (for cancellation).
pub fn run_task_with(
    model: &dyn Model,
    names: &[String],
    ctx: &RunContext,
    params: &[f64],
) -> Outcome {
    let result = catch_unwind(AssertUnwindSafe(|| {
        let p = ParamSet::new(names, params)?;
        model.run(&p, ctx)
    }));
    match result {
        Ok(Ok(out)) => Outcome::Ok(out).finite_or_failed(),
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

/// Runs a built model for the in-process transport.
pub struct LocalRunner {
    model: Box<dyn Model>,
    names: Vec<String>,
    host: String,
}

impl LocalRunner {
    /// A runner for `spec`, or the reason the model cannot be built.
    pub fn new(spec: &protocol::ModelSpec) -> Result<Self, crate::ModelError> {
        Ok(Self {
            model: crate::registry::build(spec)?,
            names: spec.param_names.clone(),
            host: host_name(),
        })
    }

    /// A runner for a spec from another process: one naming a local file
    /// is refused ([`crate::registry::build_remote`]).
    pub fn remote(spec: &protocol::ModelSpec) -> Result<Self, crate::ModelError> {
        Ok(Self {
            model: crate::registry::build_remote(spec)?,
            names: spec.param_names.clone(),
            host: host_name(),
        })
    }

    /// A factory for [`protocol::in_process::InProcess`].
    pub fn factory() -> protocol::in_process::RunnerFactory {
        Arc::new(|spec| {
            LocalRunner::new(spec)
                .map(|r| Box::new(r) as Box<dyn protocol::in_process::TaskRunner>)
                .map_err(|e| e.to_string())
        })
    }
}

impl protocol::in_process::TaskRunner for LocalRunner {
    fn run(&mut self, task: &protocol::Task, cancel: &Arc<AtomicBool>) -> protocol::TaskResult {
        let start = std::time::Instant::now();
        let ctx = RunContext::new(task.id, cancel.clone());
        let outcome = run_task_with(self.model.as_ref(), &self.names, &ctx, &task.params);
        protocol::TaskResult {
            id: task.id,
            outcome,
            wall_s: start.elapsed().as_secs_f64(),
            host: self.host.clone(),
        }
    }
}
