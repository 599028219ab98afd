//! The worker's side of a transport: join a sweep, take tasks, answer them.
//! A remote worker loop (in the worker crate) drives any [`WorkerLink`].

use crate::transport::TransportError;
use crate::{ModelSpec, Task, TaskResult};
use std::time::Duration;

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
    /// Waits (up to `timeout`) for a sweep to join, announcing `name` and `threads`.
    fn join(
        &mut self,
        name: &str,
        threads: u32,
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
