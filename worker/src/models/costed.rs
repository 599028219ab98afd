//! `cost_ms`: an artificial cost per run that stands in for an expensive
//! simulation in tests and demos. It sleeps and changes no result.

use crate::model::{Model, ParamSet, RunContext, RunError};
use protocol::Outputs;
use std::time::{Duration, Instant};

/// Wraps a model so that each run takes at least `cost`.
pub struct Costed {
    /// The real model.
    pub inner: Box<dyn Model>,
    /// Minimum wall time per run.
    pub cost: Duration,
}

impl Model for Costed {
    fn output_names(&self) -> Vec<String> {
        self.inner.output_names()
    }
    fn run(&self, p: &ParamSet<'_>, ctx: &RunContext) -> Result<Outputs, RunError> {
        let start = Instant::now();
        let out = self.inner.run(p, ctx)?;
        // Sleep in short slices so a cancelled run stops promptly.
        while let Some(left) = self.cost.checked_sub(start.elapsed()) {
            if ctx.cancelled() {
                return Err(RunError::Cancelled);
            }
            std::thread::sleep(left.min(Duration::from_millis(5)));
        }
        Ok(out)
    }
}
