//! In-process transport: N worker threads in this process, each with its own
//! task channel, reporting on one shared channel. The local two-core mode;
//! the farm cannot tell it from a networked transport. Tasks and results
//! travel sealed under the sweep's key ([`crate::seal`]) as on the other
//! transports, so one code path checks every message; here it guards
//! against nothing outside the process.

use crate::seal::{Direction, SweepKey, SweepMac};
use crate::transport::{Transport, TransportError, TransportEvent, WorkerId};
use crate::{FromWorker, ModelSpec, Task, TaskId, TaskResult, ToWorker};
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError, Sender};
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

/// What arrives on the shared channel: a transport event, or a worker's
/// sealed message to open.
enum Inbound {
    Event(TransportEvent),
    Sealed(WorkerId, Vec<u8>),
}

struct LocalWorker {
    tasks: Sender<Vec<u8>>,
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
    events_tx: Sender<Inbound>,
    events_rx: Receiver<Inbound>,
    mac: Option<Arc<SweepMac>>,
    next_seq: u64,
    leases: HashMap<u64, (WorkerId, TaskId)>,
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
            mac: None,
            next_seq: 1,
            leases: HashMap::new(),
        }
    }

    /// The event a worker's sealed message stands for.
    fn open(&mut self, worker: WorkerId, bytes: &[u8]) -> TransportEvent {
        let Some(mac) = &self.mac else {
            return TransportEvent::Rejected { reason: "not started".into() };
        };
        match mac.open::<FromWorker>(Direction::FromWorker, bytes) {
            Ok((seq, FromWorker::Result(result)))
                if self.leases.get(&seq) == Some(&(worker, result.id)) =>
            {
                self.leases.remove(&seq);
                TransportEvent::Result { worker, result }
            }
            Ok((seq, _)) => TransportEvent::Rejected {
                reason: format!("{worker}: a message for lease {seq} it does not hold; dropped"),
            },
            Err(e) => TransportEvent::Rejected { reason: format!("{worker}: {e}; dropped") },
        }
    }

    fn spawn_worker(&mut self) -> Result<(), TransportError> {
        let model =
            self.model.as_ref().ok_or_else(|| TransportError::Setup("not started".into()))?;
        let mut runner = (self.factory)(model).map_err(TransportError::Setup)?;
        let mac = self.mac.clone().ok_or_else(|| TransportError::Setup("not started".into()))?;
        let id = WorkerId(self.next_id);
        self.next_id += 1;
        let (tx, rx) = channel::<Vec<u8>>();
        let cancel = Arc::new(AtomicBool::new(false));
        let events = self.events_tx.clone();
        let flag = cancel.clone();
        let handle = std::thread::Builder::new()
            .name(format!("ceilfarm-worker-{}", id.0))
            .spawn(move || {
                while let Ok(bytes) = rx.recv() {
                    if flag.load(Ordering::Relaxed) {
                        break;
                    }
                    let (seq, task) = match mac.open::<ToWorker>(Direction::ToWorker, &bytes) {
                        Ok((seq, ToWorker::Task(task))) => (seq, task),
                        _ => continue,
                    };
                    let result = runner.run(&task, &flag);
                    let Ok(sealed) =
                        mac.seal(Direction::FromWorker, seq, &FromWorker::Result(result))
                    else {
                        continue;
                    };
                    if flag.load(Ordering::Relaxed)
                        || events.send(Inbound::Sealed(id, sealed)).is_err()
                    {
                        break;
                    }
                }
            })
            .map_err(|e| TransportError::Setup(format!("cannot start a worker thread: {e}")))?;
        self.workers.insert(id, LocalWorker { tasks: tx, cancel, handle: Some(handle) });
        let name = format!("in-process #{}", id.0);
        let joined = TransportEvent::Joined { worker: id, name, slots: 1 };
        let _ = self.events_tx.send(Inbound::Event(joined));
        Ok(())
    }
}

impl Transport for InProcess {
    fn name(&self) -> &'static str {
        "in-process"
    }

    fn start(&mut self, study_hash: &str, model: &ModelSpec) -> Result<(), TransportError> {
        self.model = Some(model.clone());
        self.mac = Some(Arc::new(SweepMac::new(SweepKey::random(), study_hash)));
        for _ in 0..self.n_workers {
            self.spawn_worker()?;
        }
        Ok(())
    }

    fn send(&mut self, worker: WorkerId, task: Task) -> Result<(), TransportError> {
        let w = self.workers.get(&worker).ok_or(TransportError::UnknownWorker(worker))?;
        let mac = self.mac.as_ref().ok_or_else(|| TransportError::Closed("not started".into()))?;
        let (seq, id) = (self.next_seq, task.id);
        let bytes = mac
            .seal(Direction::ToWorker, seq, &ToWorker::Task(task))
            .map_err(|e| TransportError::Setup(e.to_string()))?;
        w.tasks.send(bytes).map_err(|_| TransportError::UnknownWorker(worker))?;
        self.next_seq += 1;
        self.leases.insert(seq, (worker, id));
        Ok(())
    }

    fn next_event(&mut self, timeout: Duration) -> Result<Option<TransportEvent>, TransportError> {
        match self.events_rx.recv_timeout(timeout) {
            Ok(Inbound::Event(ev)) => Ok(Some(ev)),
            Ok(Inbound::Sealed(worker, bytes)) => Ok(Some(self.open(worker, &bytes))),
            Err(RecvTimeoutError::Timeout) => Ok(None),
            Err(RecvTimeoutError::Disconnected) => {
                Err(TransportError::Closed("event channel".into()))
            }
        }
    }

    fn abandon(&mut self, worker: WorkerId, _reason: &str) {
        self.leases.retain(|_, (w, _)| *w != worker);
        if let Some(mut w) = self.workers.remove(&worker) {
            // The thread may be stuck in a model; it stops at its next check
            // and its late result is never sent. A fresh thread replaces it.
            w.cancel.store(true, Ordering::Relaxed);
            drop(w.handle.take());
            if let Err(e) = self.spawn_worker() {
                let rejected = TransportEvent::Rejected { reason: e.to_string() };
                let _ = self.events_tx.send(Inbound::Event(rejected));
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
