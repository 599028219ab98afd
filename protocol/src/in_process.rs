//! In-process transport: N worker threads in this process, each with its own
//! task channel, reporting on one shared event channel. The local two-core
//! mode; the farm cannot tell it from a networked transport.

use crate::transport::{recv_event, Transport, TransportError, TransportEvent, WorkerId};
use crate::{ModelSpec, Task, TaskResult};
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// Runs tasks of one model inside a worker thread.
pub trait TaskRunner: Send {
    /// Runs one task; `cancel` turns true when the coordinator gave up on it.
    fn run(&mut self, task: &Task, cancel: &Arc<AtomicBool>) -> TaskResult;
}

/// Builds a runner for a model; called once per worker thread.
pub type RunnerFactory =
    Arc<dyn Fn(&ModelSpec) -> Result<Box<dyn TaskRunner>, String> + Send + Sync>;

struct LocalWorker {
    tasks: Sender<Task>,
    cancel: Arc<AtomicBool>,
    handle: Option<JoinHandle<()>>,
}

/// Worker threads in this process.
pub struct InProcess {
    n_workers: usize,
    factory: RunnerFactory,
    model: Option<ModelSpec>,
    workers: HashMap<WorkerId, LocalWorker>,
    next_id: u64,
    events_tx: Sender<TransportEvent>,
    events_rx: Receiver<TransportEvent>,
}

impl InProcess {
    /// A transport that will run `n_workers` threads, each with a runner from `factory`.
    pub fn new(n_workers: usize, factory: RunnerFactory) -> Self {
        let (events_tx, events_rx) = channel();
        Self {
            n_workers: n_workers.max(1),
            factory,
            model: None,
            workers: HashMap::new(),
            next_id: 0,
            events_tx,
            events_rx,
        }
    }

    fn spawn_worker(&mut self) -> Result<(), TransportError> {
        let model =
            self.model.as_ref().ok_or_else(|| TransportError::Setup("not started".into()))?;
        let mut runner = (self.factory)(model).map_err(TransportError::Setup)?;
        let id = WorkerId(self.next_id);
        self.next_id += 1;
        let (tx, rx) = channel::<Task>();
        let cancel = Arc::new(AtomicBool::new(false));
        let events = self.events_tx.clone();
        let flag = cancel.clone();
        let handle = std::thread::Builder::new()
            .name(format!("ceilfarm-worker-{}", id.0))
            .spawn(move || {
                while let Ok(task) = rx.recv() {
                    if flag.load(Ordering::Relaxed) {
                        break;
                    }
                    let result = runner.run(&task, &flag);
                    if flag.load(Ordering::Relaxed)
                        || events.send(TransportEvent::Result { worker: id, result }).is_err()
                    {
                        break;
                    }
                }
            })
            .map_err(|e| TransportError::Setup(format!("cannot start a worker thread: {e}")))?;
        self.workers.insert(id, LocalWorker { tasks: tx, cancel, handle: Some(handle) });
        let name = format!("in-process #{}", id.0);
        let _ = self.events_tx.send(TransportEvent::Joined { worker: id, name, slots: 1 });
        Ok(())
    }
}

impl Transport for InProcess {
    fn name(&self) -> &'static str {
        "in-process"
    }

    fn start(&mut self, _study_hash: &str, model: &ModelSpec) -> Result<(), TransportError> {
        self.model = Some(model.clone());
        for _ in 0..self.n_workers {
            self.spawn_worker()?;
        }
        Ok(())
    }

    fn send(&mut self, worker: WorkerId, task: Task) -> Result<(), TransportError> {
        let w = self.workers.get(&worker).ok_or(TransportError::UnknownWorker(worker))?;
        w.tasks.send(task).map_err(|_| TransportError::UnknownWorker(worker))
    }

    fn next_event(&mut self, timeout: Duration) -> Result<Option<TransportEvent>, TransportError> {
        recv_event(&self.events_rx, timeout)
    }

    fn abandon(&mut self, worker: WorkerId, _reason: &str) {
        if let Some(mut w) = self.workers.remove(&worker) {
            // The thread may be stuck in a model; it stops at its next check
            // and its late result is never sent. A fresh thread replaces it.
            w.cancel.store(true, Ordering::Relaxed);
            drop(w.handle.take());
            if let Err(e) = self.spawn_worker() {
                let _ = self.events_tx.send(TransportEvent::Rejected { reason: e.to_string() });
            }
        }
    }

    fn shutdown(&mut self) {
        let workers: Vec<_> = self.workers.drain().collect();
        for (_, w) in &workers {
            w.cancel.store(true, Ordering::Relaxed);
        }
        for (_, mut w) in workers {
            drop(w.tasks);
            if let Some(h) = w.handle.take() {
                let _ = h.join();
            }
        }
    }
}

impl Drop for InProcess {
    fn drop(&mut self) {
        self.shutdown();
    }
}
