//! The farm: hands tasks to workers through any [`Transport`], keeps a lease
//! on each task, retries failures, re-issues the tasks of workers that leave,
//! drops late duplicates, and passes each result exactly once to a sink.
//!
//! A worker's word counts for its own tasks only: a result, error reply or
//! hand-back is taken only from the worker that holds the task's lease, once
//! (late, duplicate, foreign and malformed replies are logged and dropped);
//! an error reply fails that attempt, never the worker; hand-backs are
//! bounded ([`crate::farm_hand_backs`]); and a worker's loss re-queues only
//! the leases it held, so a worker never leased a task cannot lose one.

use crate::farm_hand_backs::{HandBackVerdict, HandBacks};
use protocol::{ModelSpec, Outcome, Task, TaskId, TaskResult, Transport, TransportEvent, WorkerId};
use std::collections::{BTreeMap, HashMap, VecDeque};
use std::time::{Duration, Instant};

/// Farm settings (none of them changes results).
#[derive(Debug, Clone)]
pub struct FarmSettings {
    /// Time one task may take before it is given up.
    pub task_timeout: Duration,
    /// How often a failed or timed-out task is tried again.
    pub max_retries: u32,
    /// Tasks a worker may hold per slot (1 = no prefetch).
    pub window_per_slot: usize,
    /// How many times a task may be lost with its worker before it counts as failed.
    pub max_worker_losses: u32,
}

impl Default for FarmSettings {
    fn default() -> Self {
        Self {
            task_timeout: Duration::from_secs(3600),
            max_retries: 1,
            window_per_slot: 2,
            max_worker_losses: 3,
        }
    }
}

/// Why the farm stopped before finishing.
#[derive(Debug, thiserror::Error)]
pub enum FarmError {
    /// The transport failed.
    #[error(transparent)]
    Transport(#[from] protocol::TransportError),
    /// The sink (store) refused a result.
    #[error("recording results: {0}")]
    Sink(String),
}

/// Where finished tasks go (the store); called with batches of final results.
pub trait ResultSink {
    /// Keeps these final results; an error stops the farm.
    fn accept(&mut self, results: &[TaskResult]) -> Result<(), String>;
}

/// Watches a sweep (progress bars, logs); never changes the numbers.
pub trait FarmObserver {
    /// A task reached its final result.
    fn finished(&mut self, _result: &TaskResult) {}
    /// A task failed and will be tried again.
    fn retrying(&mut self, _task: TaskId, _reason: &str) {}
    /// A worker joined or left.
    fn membership(&mut self, _joined: bool, _worker: WorkerId, _detail: &str) {}
    /// A message was rejected by the transport.
    fn rejected(&mut self, _reason: &str) {}
}

/// An observer that does nothing.
pub struct Silent;
impl FarmObserver for Silent {}

/// What the farm did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FarmSummary {
    /// Tasks finished with outputs.
    pub ok: usize,
    /// Tasks recorded as failed.
    pub failed: usize,
    /// Tries beyond the first (failures, timeouts, lost workers).
    pub reissued: usize,
    /// Late, duplicate or foreign replies dropped (results, error replies, hand-backs).
    pub duplicates: usize,
}

struct Lease {
    worker: WorkerId,
    deadline: Instant,
}

struct WorkerState {
    capacity: usize,
    held: Vec<TaskId>,
    last_deadline: Instant,
}

/// One sweep's bookkeeping.
struct Farm<'a> {
    settings: &'a FarmSettings,
    pending: VecDeque<Task>,
    tasks: HashMap<TaskId, Task>,
    leases: HashMap<TaskId, Lease>,
    workers: BTreeMap<WorkerId, WorkerState>,
    tries: HashMap<TaskId, u32>,
    losses: HashMap<TaskId, u32>,
    hand_backs: HandBacks,
    summary: FarmSummary,
    remaining: usize,
    last_starved_warning: Option<Instant>,
}

/// How often the farm says that tasks wait with no worker connected.
const STARVED_WARNING_EVERY: Duration = Duration::from_secs(30);

/// Runs `tasks` to completion on the transport, feeding final results to `sink`.
pub fn run_farm(
    transport: &mut dyn Transport,
    study_hash: &str,
    model: &ModelSpec,
    tasks: Vec<Task>,
    settings: &FarmSettings,
    sink: &mut dyn ResultSink,
    observer: &mut dyn FarmObserver,
) -> Result<FarmSummary, FarmError> {
    if tasks.is_empty() {
        return Ok(FarmSummary::default());
    }
    transport.start(study_hash, model)?;
    let mut workers = BTreeMap::new();
    let result = run_batch(transport, &mut workers, tasks, settings, sink, observer);
    transport.shutdown();
    result
}

/// One study served over several batches of tasks: the transport starts
/// once and the workers stay joined between batches (for callers that
/// choose each batch from the results of the last).
pub struct FarmSession {
    transport: Box<dyn Transport>,
    workers: BTreeMap<WorkerId, WorkerState>,
    settings: FarmSettings,
}

impl FarmSession {
    /// Starts serving the study on `transport`.
    pub fn start(
        mut transport: Box<dyn Transport>,
        study_hash: &str,
        model: &ModelSpec,
        settings: FarmSettings,
    ) -> Result<Self, FarmError> {
        transport.start(study_hash, model)?;
        Ok(FarmSession { transport, workers: BTreeMap::new(), settings })
    }

    /// Runs one batch to completion, feeding final results to `sink`.
    pub fn run(
        &mut self,
        tasks: Vec<Task>,
        sink: &mut dyn ResultSink,
        observer: &mut dyn FarmObserver,
    ) -> Result<FarmSummary, FarmError> {
        let t = self.transport.as_mut();
        run_batch(t, &mut self.workers, tasks, &self.settings, sink, observer)
    }
}

impl Drop for FarmSession {
    fn drop(&mut self) {
        self.transport.shutdown();
    }
}

/// Runs `tasks` on a started transport with the workers known so far
/// (updated as they join and leave).
fn run_batch(
    transport: &mut dyn Transport,
    workers: &mut BTreeMap<WorkerId, WorkerState>,
    tasks: Vec<Task>,
    settings: &FarmSettings,
    sink: &mut dyn ResultSink,
    observer: &mut dyn FarmObserver,
) -> Result<FarmSummary, FarmError> {
    let mut farm = Farm {
        settings,
        remaining: tasks.len(),
        tasks: tasks.iter().map(|t| (t.id, t.clone())).collect(),
        pending: tasks.into(),
        leases: HashMap::new(),
        workers: std::mem::take(workers),
        tries: HashMap::new(),
        losses: HashMap::new(),
        hand_backs: HandBacks::default(),
        summary: FarmSummary::default(),
        last_starved_warning: None,
    };
    let result = if farm.remaining == 0 { Ok(()) } else { farm.drive(transport, sink, observer) };
    // Tasks still held (a failed batch) are forgotten with the batch.
    for w in farm.workers.values_mut() {
        w.held.clear();
    }
    *workers = farm.workers;
    result.map(|()| farm.summary)
}

impl Farm<'_> {
    fn drive(
        &mut self,
        t: &mut dyn Transport,
        sink: &mut dyn ResultSink,
        obs: &mut dyn FarmObserver,
    ) -> Result<(), FarmError> {
        let mut done = Vec::new();
        while self.remaining > 0 {
            self.dispatch(t)?;
            self.warn_if_starved();
            let wait = self.next_deadline().map(|d| d.saturating_duration_since(Instant::now()));
            let wait = wait.unwrap_or(Duration::from_millis(200)).min(Duration::from_millis(200));
            if let Some(ev) = t.next_event(wait)? {
                self.handle(ev, obs, &mut done);
                // Drain whatever else is already there, then record in one transaction.
                while let Some(ev) = t.next_event(Duration::ZERO)? {
                    self.handle(ev, obs, &mut done);
                    if done.len() >= 256 {
                        break;
                    }
                }
            }
            self.expire(t, obs, &mut done);
            if !done.is_empty() {
                sink.accept(&done).map_err(FarmError::Sink)?;
                done.clear();
            }
        }
        Ok(())
    }

    /// Says so (every [`STARVED_WARNING_EVERY`]) while tasks wait and no worker is connected.
    fn warn_if_starved(&mut self) {
        if !self.workers.is_empty() {
            self.last_starved_warning = None;
            return;
        }
        let now = Instant::now();
        let first = *self.last_starved_warning.get_or_insert(now);
        if now.duration_since(first) >= STARVED_WARNING_EVERY {
            tracing::warn!(waiting = self.remaining, "no worker connected: tasks wait");
            self.last_starved_warning = Some(now);
        }
    }

    fn next_deadline(&self) -> Option<Instant> {
        self.leases.values().map(|l| l.deadline).min()
    }

    /// Hands pending tasks to workers with free room, least-loaded first.
    fn dispatch(&mut self, t: &mut dyn Transport) -> Result<(), FarmError> {
        while !self.pending.is_empty() {
            let Some((&id, _)) = self
                .workers
                .iter()
                .filter(|(_, w)| w.held.len() < w.capacity)
                .min_by_key(|(_, w)| w.held.len() * 1000 / w.capacity.max(1))
            else {
                return Ok(());
            };
            let task = self.pending.pop_front().expect("checked non-empty");
            let w = self.workers.get_mut(&id).expect("chosen from the map");
            let deadline = w.last_deadline.max(Instant::now()) + self.settings.task_timeout;
            match t.send(id, task.clone()) {
                Ok(()) => {
                    w.last_deadline = deadline;
                    w.held.push(task.id);
                    self.leases.insert(task.id, Lease { worker: id, deadline });
                }
                Err(_) => {
                    self.pending.push_front(task);
                    self.drop_worker(id);
                }
            }
        }
        Ok(())
    }

    fn handle(
        &mut self,
        ev: TransportEvent,
        obs: &mut dyn FarmObserver,
        done: &mut Vec<TaskResult>,
    ) {
        match ev {
            TransportEvent::Joined { worker, name, slots } => {
                self.on_joined(worker, &name, slots, obs)
            }
            TransportEvent::Left { worker, reason } => self.on_left(worker, &reason, obs),
            TransportEvent::Rejected { reason } => {
                tracing::warn!(%reason, "message rejected");
                obs.rejected(&reason)
            }
            TransportEvent::HandedBack { worker, task } => {
                self.on_hand_back(worker, task, obs, done)
            }
            TransportEvent::Failed { worker, task, reason } => {
                self.on_failed(worker, task, reason, obs, done)
            }
            TransportEvent::Result { worker, result } => self.on_result(worker, result, obs, done),
        }
    }

    fn on_joined(
        &mut self,
        worker: WorkerId,
        name: &str,
        slots: usize,
        obs: &mut dyn FarmObserver,
    ) {
        if self.workers.contains_key(&worker) {
            tracing::warn!(%worker, name, "joined twice: ignored");
            return;
        }
        let capacity = slots.max(1) * self.settings.window_per_slot.max(1);
        let state = WorkerState { capacity, held: Vec::new(), last_deadline: Instant::now() };
        self.workers.insert(worker, state);
        obs.membership(true, worker, name);
    }

    fn on_left(&mut self, worker: WorkerId, reason: &str, obs: &mut dyn FarmObserver) {
        if !self.workers.contains_key(&worker) {
            // Its other task queries closing, or a stranger's token: nothing to re-queue.
            tracing::debug!(%worker, reason, "leave of a worker the farm does not know: ignored");
            return;
        }
        obs.membership(false, worker, reason);
        self.drop_worker(worker);
    }

    /// Whether `worker` holds the lease of `task` now.
    fn holds(&self, worker: WorkerId, task: TaskId) -> bool {
        self.leases.get(&task).is_some_and(|l| l.worker == worker)
    }

    /// Logs and drops a reply from a worker that does not hold the task's lease.
    fn drop_reply(&mut self, worker: WorkerId, task: TaskId, what: &str) {
        self.summary.duplicates += 1;
        let why = match self.leases.get(&task) {
            _ if !self.tasks.contains_key(&task) => "late: the task is done or not in this batch",
            Some(_) => "foreign: the task is leased to another worker",
            None => "late: the task was given up and re-queued",
        };
        tracing::warn!(%worker, %task, why, "{what} dropped");
    }

    fn on_result(
        &mut self,
        worker: WorkerId,
        result: TaskResult,
        obs: &mut dyn FarmObserver,
        done: &mut Vec<TaskResult>,
    ) {
        if !self.holds(worker, result.id) {
            return self.drop_reply(worker, result.id, "result");
        }
        self.release(result.id);
        if let Some(why) = malformed(&result) {
            tracing::warn!(%worker, task = %result.id, why, "malformed result dropped");
            let reason = format!("malformed result from {worker}: {why}");
            return self.fail_attempt(result.id, reason, 0.0, obs, done);
        }
        // A NaN from any worker is that run's failure, never a number to keep.
        let result = TaskResult { outcome: result.outcome.finite_or_failed(), ..result };
        match &result.outcome {
            Outcome::Failed { reason } if self.retry_allowed(result.id) => {
                obs.retrying(result.id, reason);
                self.requeue(result.id);
            }
            _ => self.finish(result, obs, done),
        }
    }

    /// An error reply: that attempt failed; the worker keeps its other tasks.
    fn on_failed(
        &mut self,
        worker: WorkerId,
        task: TaskId,
        reason: String,
        obs: &mut dyn FarmObserver,
        done: &mut Vec<TaskResult>,
    ) {
        if !self.holds(worker, task) {
            return self.drop_reply(worker, task, "error reply");
        }
        tracing::warn!(%worker, %task, %reason, "attempt failed");
        self.release(task);
        self.fail_attempt(task, reason, 0.0, obs, done);
    }

    /// A task given back unrun: re-queued free within the bound, else a failed attempt.
    fn on_hand_back(
        &mut self,
        worker: WorkerId,
        task: TaskId,
        obs: &mut dyn FarmObserver,
        done: &mut Vec<TaskResult>,
    ) {
        if !self.holds(worker, task) {
            return self.drop_reply(worker, task, "hand-back");
        }
        self.release(task);
        match self.hand_backs.record(task, worker) {
            HandBackVerdict::Free => self.requeue(task),
            HandBackVerdict::FailedAttempt(reason) => {
                tracing::warn!(%worker, %task, %reason, "hand-back counted as a failed attempt");
                self.fail_attempt(task, reason, 0.0, obs, done)
            }
        }
    }

    /// One attempt of a task ended without a result: try again or record the failure.
    fn fail_attempt(
        &mut self,
        id: TaskId,
        reason: String,
        wall_s: f64,
        obs: &mut dyn FarmObserver,
        done: &mut Vec<TaskResult>,
    ) {
        if self.retry_allowed(id) {
            obs.retrying(id, &reason);
            self.requeue(id);
        } else {
            let outcome = Outcome::Failed { reason };
            self.finish(TaskResult { id, outcome, wall_s, host: String::new() }, obs, done);
        }
    }

    fn retry_allowed(&mut self, id: TaskId) -> bool {
        let tries = self.tries.entry(id).or_insert(0);
        *tries += 1;
        *tries <= self.settings.max_retries
    }

    fn requeue(&mut self, id: TaskId) {
        self.summary.reissued += 1;
        if let Some(task) = self.tasks.get(&id) {
            self.pending.push_front(task.clone());
        }
    }

    fn finish(
        &mut self,
        result: TaskResult,
        obs: &mut dyn FarmObserver,
        done: &mut Vec<TaskResult>,
    ) {
        if self.tasks.remove(&result.id).is_none() {
            self.summary.duplicates += 1;
            return;
        }
        match result.outcome {
            Outcome::Ok(_) => self.summary.ok += 1,
            Outcome::Failed { .. } => self.summary.failed += 1,
        }
        self.remaining -= 1;
        obs.finished(&result);
        done.push(result);
    }

    fn release(&mut self, id: TaskId) {
        if let Some(lease) = self.leases.remove(&id) {
            if let Some(w) = self.workers.get_mut(&lease.worker) {
                w.held.retain(|t| *t != id);
            }
        }
    }

    /// Forgets a worker and re-issues the leases it held (and only those).
    fn drop_worker(&mut self, id: WorkerId) {
        let Some(w) = self.workers.remove(&id) else { return };
        for task in w.held.into_iter().rev() {
            if !self.holds(id, task) {
                continue;
            }
            self.leases.remove(&task);
            *self.losses.entry(task).or_insert(0) += 1;
            self.requeue(task);
        }
    }

    /// Gives up on tasks whose lease expired: failure or retry.
    fn expire(
        &mut self,
        t: &mut dyn Transport,
        obs: &mut dyn FarmObserver,
        done: &mut Vec<TaskResult>,
    ) {
        let now = Instant::now();
        let expired: Vec<(TaskId, WorkerId)> = self
            .leases
            .iter()
            .filter(|(_, l)| l.deadline <= now)
            .map(|(id, l)| (*id, l.worker))
            .collect();
        for (id, worker) in expired {
            if !self.leases.contains_key(&id) {
                continue;
            }
            let secs = self.settings.task_timeout.as_secs_f64();
            let reason = format!("timeout: no result after {secs} s");
            self.release(id);
            // The worker is stuck in this task: replace it; its other tasks go back to the queue.
            t.abandon(worker, &reason);
            obs.membership(false, worker, &reason);
            self.drop_worker(worker);
            self.fail_attempt(id, reason, secs, obs, done);
        }
        self.fail_lost_tasks(obs, done);
    }

    /// Tasks lost with too many workers fail rather than kill the whole farm.
    fn fail_lost_tasks(&mut self, obs: &mut dyn FarmObserver, done: &mut Vec<TaskResult>) {
        let limit = self.settings.max_worker_losses;
        let lost: Vec<TaskId> =
            self.losses.iter().filter(|(_, n)| **n >= limit).map(|(id, _)| *id).collect();
        for id in lost {
            self.losses.remove(&id);
            if self.leases.contains_key(&id) || !self.tasks.contains_key(&id) {
                continue;
            }
            self.pending.retain(|t| t.id != id);
            let reason = format!("lost with its worker {limit} times");
            self.finish(
                TaskResult {
                    id,
                    outcome: Outcome::Failed { reason },
                    wall_s: 0.0,
                    host: String::new(),
                },
                obs,
                done,
            );
        }
    }
}

/// Why a result cannot be kept as it came (its wall time is not a
/// non-negative finite number of seconds), or `None` when it can.
fn malformed(r: &TaskResult) -> Option<String> {
    let ok = r.wall_s.is_finite() && r.wall_s >= 0.0;
    (!ok).then(|| format!("wall time {} s", r.wall_s))
}

/// Whether a result is a failure the farm recorded itself (a timeout, a
/// task lost with too many workers: these carry no host) rather than the
/// model's own verdict; such a failure says nothing about the parameters
/// and is worth trying again on the next run.
pub fn farm_failure(r: &TaskResult) -> bool {
    matches!(r.outcome, Outcome::Failed { .. }) && r.host.is_empty()
}

#[cfg(test)]
#[path = "farm_tests.rs"]
mod farm_tests;

#[cfg(test)]
mod farm_failure_tests {
    use super::*;
    use protocol::{Outputs, TaskId};

    fn result(outcome: Outcome, host: &str) -> TaskResult {
        TaskResult { id: TaskId(1), outcome, wall_s: 0.0, host: host.into() }
    }

    #[test]
    fn only_failures_without_a_host_are_the_farms_own() {
        let failed = || Outcome::Failed { reason: "timeout: no result after 3600 s".into() };
        assert!(farm_failure(&result(failed(), "")));
        assert!(!farm_failure(&result(failed(), "node-3")));
        let ok = Outcome::Ok(Outputs { scalars: vec![], histories: vec![] });
        assert!(!farm_failure(&result(ok, "")));
    }
}
