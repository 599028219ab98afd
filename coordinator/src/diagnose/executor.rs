//! Who runs a diagnosis's FE simulations: the [`FeExecutor`] trait, and its
//! plain-thread implementation ([`ThreadExecutor`]). The farm's is in
//! [`super::farm_executor`]. Residuals, fits and every decision stay with
//! the caller: an executor only turns parameter points into simulated runs
//! (bundle units) or spring-group demands, the same numbers whoever runs them.

use super::cause::Demand;
use super::fit::{Evaluation, Simulated};

/// Why an executor could not deliver (never a failed simulation: those are
/// results).
#[derive(Debug, thiserror::Error)]
pub enum ExecutorError {
    /// The farm stopped.
    #[error(transparent)]
    Farm(#[from] crate::farm::FarmError),
    /// The transport is not available.
    #[error(transparent)]
    Transport(#[from] crate::transports::TransportChoiceError),
    /// The evaluation store refused.
    #[error(transparent)]
    Store(#[from] crate::evaluations::EvaluationStoreError),
    /// A worker's outputs do not have the expected shape.
    #[error("outputs of {what}: {message}")]
    Outputs {
        /// Which evaluation.
        what: String,
        /// What is wrong.
        message: String,
    },
    /// The study could not be described to the workers.
    #[error("model: {0}")]
    Model(String),
    /// Stopped on request.
    #[error("stopped: {0}")]
    Stopped(String),
}

/// The simulated runs at one point, or why the simulation failed.
pub type Sims = Result<Vec<Simulated>, String>;

/// Runs FE simulations for a diagnosis.
pub trait FeExecutor {
    /// Simulates `ev`'s runs at each point `thetas[k]` (physical values in
    /// prior order); one entry per point, in order.
    fn simulate(
        &mut self,
        ev: &Evaluation<'_>,
        thetas: &[Vec<f64>],
    ) -> Result<Vec<Sims>, ExecutorError>;

    /// The spring-group demand of `ev`'s runs at `theta`.
    fn demand(
        &mut self,
        ev: &Evaluation<'_>,
        theta: &[f64],
    ) -> Result<Result<Demand, String>, ExecutorError>;

    /// FE evaluations (parameter points) this executor has simulated.
    fn simulated(&self) -> usize;
}

/// Plain threads in this process, no store.
pub struct ThreadExecutor {
    threads: usize,
    simulated: usize,
}

impl ThreadExecutor {
    /// An executor on `threads` threads (at least one).
    pub fn new(threads: usize) -> Self {
        ThreadExecutor { threads: threads.max(1), simulated: 0 }
    }
}

impl FeExecutor for ThreadExecutor {
    fn simulate(
        &mut self,
        ev: &Evaluation<'_>,
        thetas: &[Vec<f64>],
    ) -> Result<Vec<Sims>, ExecutorError> {
        self.simulated += thetas.len();
        Ok(on_threads(thetas, self.threads, |theta| ev.simulate(theta)))
    }

    fn demand(
        &mut self,
        ev: &Evaluation<'_>,
        theta: &[f64],
    ) -> Result<Result<Demand, String>, ExecutorError> {
        self.simulated += 1;
        Ok(ev.demand_at(theta))
    }

    fn simulated(&self) -> usize {
        self.simulated
    }
}

/// `f` at every item on up to `threads` threads, results in item order (a
/// panicking call becomes an error).
pub(crate) fn on_threads<T: Sync, R: Send>(
    items: &[T],
    threads: usize,
    f: impl Fn(&T) -> Result<R, String> + Sync,
) -> Vec<Result<R, String>> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    type Slot<R> = std::sync::Mutex<Option<Result<R, String>>>;
    let slots: Vec<Slot<R>> = items.iter().map(|_| std::sync::Mutex::new(None)).collect();
    std::thread::scope(|s| {
        for _ in 0..threads.max(1).min(items.len().max(1)) {
            s.spawn(|| loop {
                let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                if k >= items.len() {
                    break;
                }
                let out = f(&items[k]);
                if let Ok(mut slot) = slots[k].lock() {
                    *slot = Some(out);
                }
            });
        }
    });
    slots
        .into_iter()
        .map(|m| {
            m.into_inner()
                .ok()
                .flatten()
                .unwrap_or_else(|| Err("evaluation thread panicked".into()))
        })
        .collect()
}
