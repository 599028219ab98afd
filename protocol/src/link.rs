//! The worker's side of a transport: join a sweep, take tasks, answer them.
//! A remote worker loop (in the worker crate) drives any [`WorkerLink`].

use crate::transport::TransportError;
use crate::{ModelSpec, Task, TaskResult};
use std::time::Duration;

/// Who a joining worker is and what it agrees to serve.
#[derive(Debug, Clone, PartialEq)]
pub struct JoinRequest {
    /// Worker's name (unique per process).
    pub name: String,
    /// How many tasks it runs at once.
    pub threads: u32,
    /// Serve only the study whose hash starts with this (any study if `None`).
    pub study: Option<String>,
}

/// Why a worker pinned to `pin` may not serve the study `study_hash`, if so.
pub fn study_refusal(pin: Option<&str>, study_hash: &str) -> Option<String> {
    let pin = pin?;
    if !pin.is_empty() && study_hash.starts_with(pin) {
        return None;
    }
    let short = &study_hash[..study_hash.len().min(16)];
    Some(format!("the coordinator runs study {short}, the worker serves only study {pin}"))
}

/// What a coordinator told a joining worker.
#[derive(Debug, Clone, PartialEq)]
pub struct Joined {
    /// Hash of the sweep's study.
    pub study_hash: String,
    /// The model every task runs.
    pub model: ModelSpec,
}

/// A task with whatever the transport needs to route its answer.
pub struct Ticket {
    /// The task.
    pub task: Task,
    /// Transport-specific reply route.
    pub route: Box<dyn std::any::Any + Send>,
}

/// What a worker may see while serving.
pub enum LinkEvent {
    /// A task to run.
    Task(Ticket),
    /// The coordinator is gone; join again.
    CoordinatorGone,
    /// Nothing happened within the wait.
    Idle,
}

/// Answers a task from any thread, for transports whose routes allow it.
pub type Replier = std::sync::Arc<
    dyn Fn(Box<dyn std::any::Any + Send>, TaskResult) -> Result<(), TransportError> + Send + Sync,
>;

/// The worker's end of a transport.
pub trait WorkerLink {
    /// Waits (up to `timeout`) for a sweep to join; a refusal is an error
    /// carrying the coordinator's reason.
    fn join(
        &mut self,
        request: &JoinRequest,
        timeout: Duration,
    ) -> Result<Option<Joined>, TransportError>;
    /// Starts taking tasks for the joined sweep (declares itself alive).
    fn serve(&mut self) -> Result<(), TransportError>;
    /// Waits up to `timeout` for the next task or event.
    fn next(&mut self, timeout: Duration) -> Result<LinkEvent, TransportError>;
    /// Sends a task's result back.
    fn reply(
        &mut self,
        route: Box<dyn std::any::Any + Send>,
        result: TaskResult,
    ) -> Result<(), TransportError>;
    /// A thread-safe way to answer, if the transport has one (answers then
    /// leave the pool threads at once instead of waiting for this loop).
    fn replier(&self) -> Option<Replier> {
        None
    }
    /// Hands a task back unrun (the worker is stopping).
    fn hand_back(&mut self, route: Box<dyn std::any::Any + Send>, reason: &str);
    /// Stops serving: no longer alive to the coordinator.
    fn leave(&mut self);
}

#[cfg(test)]
mod tests {
    use super::study_refusal;

    #[test]
    fn an_unpinned_worker_serves_any_study() {
        assert_eq!(study_refusal(None, "abcdef"), None);
    }

    #[test]
    fn a_pinned_worker_serves_only_its_study() {
        assert_eq!(study_refusal(Some("abc"), "abcdef"), None);
        let why = study_refusal(Some("abd"), "abcdef").expect("refused");
        assert!(
            why.contains("runs study abcdef") && why.contains("serves only study abd"),
            "{why}"
        );
        assert!(study_refusal(Some(""), "abcdef").is_some());
    }
}
