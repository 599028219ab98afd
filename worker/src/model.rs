//! The `Model` trait every model kind implements, and its inputs.

use protocol::{Outputs, TaskId};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Parameter values by name, in physical units.
#[derive(Debug, Clone, Copy)]
pub struct ParamSet<'a> {
    names: &'a [String],
    values: &'a [f64],
}

impl<'a> ParamSet<'a> {
    /// Pairs names with values; both must have the same length.
    pub fn new(names: &'a [String], values: &'a [f64]) -> Result<Self, RunError> {
        if names.len() != values.len() {
            return Err(RunError::Input(format!(
                "{} parameter values for {} names",
                values.len(),
                names.len()
            )));
        }
        Ok(Self { names, values })
    }

    /// Value of the named parameter.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.names.iter().position(|n| n == name).map(|i| self.values[i])
    }

    /// Value of the named parameter, or a [`RunError::Input`] naming it.
    pub fn require(&self, name: &str) -> Result<f64, RunError> {
        self.get(name).ok_or_else(|| RunError::Input(format!("parameter `{name}` is missing")))
    }

    /// All values, in order.
    pub fn values(&self) -> &'a [f64] {
        self.values
    }

    /// All names, in order.
    pub fn names(&self) -> &'a [String] {
        self.names
    }

    /// Iterates over (name, value) pairs.
    pub fn iter(&self) -> impl Iterator<Item = (&'a str, f64)> + 'a {
        self.names.iter().map(String::as_str).zip(self.values.iter().copied())
    }
}

/// Per-run context: which task, and a flag to stop early.
#[derive(Debug, Clone, Default)]
pub struct RunContext {
    /// The task being run.
    pub task: Option<TaskId>,
    cancel: Arc<AtomicBool>,
}

impl RunContext {
    /// A context for `task` with a shared cancellation flag.
    pub fn new(task: TaskId, cancel: Arc<AtomicBool>) -> Self {
        Self { task: Some(task), cancel }
    }

    /// True once the coordinator gave up on this run; long models check it.
    pub fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}

/// Why a run failed; recorded as data, never a crash.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// Bad parameter values or missing parameters.
    #[error("bad input: {0}")]
    Input(String),
    /// The model could not finish (no convergence, singular matrix, ...).
    #[error("{0}")]
    Failed(String),
    /// The run was cancelled.
    #[error("cancelled")]
    Cancelled,
}

/// Why a model could not be built from its spec.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// No model of that kind is registered.
    #[error("unknown model kind `{kind}` (known: {known})")]
    UnknownKind {
        /// The requested kind.
        kind: String,
        /// The registered kinds, comma-separated.
        known: String,
    },
    /// An option or parameter name is wrong for this kind.
    #[error("model `{kind}`: {message}")]
    Invalid {
        /// The model kind.
        kind: String,
        /// What is wrong.
        message: String,
    },
}

/// A simulator: parameters in, named outputs out. Pure: the same parameters
/// give the same outputs on any worker.
pub trait Model: Send + Sync {
    /// Names of the scalar outputs, in the order `run` returns them.
    fn output_names(&self) -> Vec<String>;
    /// Runs once.
    fn run(&self, params: &ParamSet<'_>, ctx: &RunContext) -> Result<Outputs, RunError>;
}
