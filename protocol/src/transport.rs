//! The one interface every transport implements: send tasks to workers,
//! receive results, see workers come and go.
//!
//! The coordinator's farm does the scheduling (which worker gets which task,
//! leases, retries); a transport only moves messages and reports membership.

use crate::{ModelSpec, Task, TaskResult};
#[cfg(feature = "zenoh")]
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::Duration;

/// A worker as the transport knows it; never reused within one transport.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct WorkerId(pub u64);

impl std::fmt::Display for WorkerId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "worker {}", self.0)
    }
}

/// Something that happened on the transport.
#[derive(Debug, Clone, PartialEq)]
pub enum TransportEvent {
    /// A worker was accepted and can hold up to `slots` tasks.
    Joined {
        /// The new worker.
        worker: WorkerId,
        /// Its name (host and process).
        name: String,
        /// How many tasks it may hold at once.
        slots: usize,
    },
    /// A worker is gone; the tasks it held must be handed to others.
    Left {
        /// The worker that left.
        worker: WorkerId,
        /// Why (exit, crash, lost liveliness).
        reason: String,
    },
    /// A worker answered a task.
    Result {
        /// Who answered.
        worker: WorkerId,
        /// The answer.
        result: TaskResult,
    },
    /// A worker could not run a task (an error reply): that attempt failed,
    /// the worker stays.
    Failed {
        /// Who answered.
        worker: WorkerId,
        /// The task whose attempt failed.
        task: crate::TaskId,
        /// Why.
        reason: String,
    },
    /// A worker gave a task back unrun; it goes to another worker, no try
    /// counted (within the farm's bound on hand-backs).
    HandedBack {
        /// Who gave it back.
        worker: WorkerId,
        /// The task.
        task: crate::TaskId,
    },
    /// A message was refused (malformed, wrong version, other study); logged, no state change.
    Rejected {
        /// What was wrong.
        reason: String,
    },
}

/// Why a transport operation failed.
#[derive(Debug, thiserror::Error)]
pub enum TransportError {
    /// The worker is not (or no longer) known.
    #[error("{0} is not connected")]
    UnknownWorker(WorkerId),
    /// The transport cannot go on (its session or channels are closed).
    #[error("transport closed: {0}")]
    Closed(String),
    /// Setting up the transport failed.
    #[error("transport setup failed: {0}")]
    Setup(String),
}

/// Moves tasks and results between the farm and its workers.
pub trait Transport: Send {
    /// Short name for logs and provenance (`"in-process"`, `"zenoh"`, ...).
    fn name(&self) -> &'static str;
    /// Starts serving one sweep; joining workers get `model` and `study_hash`.
    fn start(&mut self, study_hash: &str, model: &ModelSpec) -> Result<(), TransportError>;
    /// Hands one task to one worker; must not block on the worker's progress.
    fn send(&mut self, worker: WorkerId, task: Task) -> Result<(), TransportError>;
    /// Waits up to `timeout` for the next event; `Ok(None)` when none came.
    fn next_event(&mut self, timeout: Duration) -> Result<Option<TransportEvent>, TransportError>;
    /// Gives up on a worker whose task overran its lease; a transport that
    /// can, replaces it (in-process starts a fresh thread).
    fn abandon(&mut self, worker: WorkerId, reason: &str);
    /// Tells every worker to stop and releases the transport's resources.
    fn shutdown(&mut self);
}

/// The next event of a transport that gathers its events on a channel.
#[cfg(feature = "zenoh")]
pub(crate) fn recv_event(
    events: &Receiver<TransportEvent>,
    timeout: Duration,
) -> Result<Option<TransportEvent>, TransportError> {
    match events.recv_timeout(timeout) {
        Ok(ev) => Ok(Some(ev)),
        Err(RecvTimeoutError::Timeout) => Ok(None),
        Err(RecvTimeoutError::Disconnected) => Err(TransportError::Closed("event channel".into())),
    }
}
