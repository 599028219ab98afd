//! A worker process's loop over any [`WorkerLink`]: join a sweep, run its
//! tasks on a pool of threads, answer each, join again when the coordinator
//! goes, and on a stop request finish running tasks, hand queued ones back
//! and leave.

use crate::run::LocalRunner;
use protocol::in_process::TaskRunner;
use protocol::link::{JoinRequest, LinkEvent, Replier, WorkerLink};
use protocol::{Task, TaskResult, TransportError};
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::Arc;
use std::time::Duration;

/// How a remote worker runs.
#[derive(Debug, Clone)]
pub struct RemoteSettings {
    /// Name announced to the coordinator (unique per process).
    pub name: String,
    /// Tasks run at once.
    pub threads: usize,
    /// Serve only the study whose hash starts with this.
    pub study: Option<String>,
}

/// Why a remote worker stopped with an error.
#[derive(Debug, thiserror::Error)]
pub enum RemoteError {
    /// The coordinator refused this worker, or the link broke.
    #[error(transparent)]
    Link(#[from] TransportError),
}

/// What a pool thread reports for a task.
enum Done {
    /// Answered from the pool thread already.
    Replied,
    /// A result for the main loop to send.
    Result(TaskResult),
    /// Not run: the worker is stopping (with the route if the thread held it).
    HandBack(Option<Route>),
}

type Route = Box<dyn std::any::Any + Send>;

struct Pool {
    tasks: Sender<(u64, Task, Option<Route>)>,
    results: Receiver<(u64, Done)>,
    cancel: Arc<AtomicBool>,
    handles: Vec<std::thread::JoinHandle<()>>,
}

impl Pool {
    fn start(runners: Vec<LocalRunner>, stop: &Arc<AtomicBool>, replier: Option<Replier>) -> Pool {
        let (task_tx, task_rx) = channel::<(u64, Task, Option<Route>)>();
        let task_rx = Arc::new(std::sync::Mutex::new(task_rx));
        let (res_tx, res_rx) = channel();
        let cancel = Arc::new(AtomicBool::new(false));
        let handles = runners
            .into_iter()
            .map(|mut runner| {
                let (rx, tx, cancel, stop) =
                    (task_rx.clone(), res_tx.clone(), cancel.clone(), stop.clone());
                let replier = replier.clone();
                std::thread::spawn(move || loop {
                    let next = rx.lock().map(|r| r.recv());
                    let Ok(Ok((seq, task, route))) = next else { return };
                    // A stop request hands back what has not started yet.
                    let done = if stop.load(Ordering::Relaxed) {
                        Done::HandBack(route)
                    } else {
                        let result = runner.run(&task, &cancel);
                        match (&replier, route) {
                            (Some(reply), Some(route)) => match reply(route, result) {
                                Ok(()) => Done::Replied,
                                Err(e) => {
                                    tracing::warn!(error = %e, "could not send a result");
                                    Done::Replied
                                }
                            },
                            _ => Done::Result(result),
                        }
                    };
                    if tx.send((seq, done)).is_err() {
                        return;
                    }
                })
            })
            .collect();
        Pool { tasks: task_tx, results: res_rx, cancel, handles }
    }

    fn finish(self) {
        self.cancel.store(true, Ordering::Relaxed);
        drop(self.tasks);
        for h in self.handles {
            let _ = h.join();
        }
    }
}

/// Serves sweeps over `link` until `stop` is set; returns when stopped.
pub fn serve_remote(
    link: &mut dyn WorkerLink,
    s: &RemoteSettings,
    stop: &Arc<AtomicBool>,
) -> Result<(), RemoteError> {
    let request =
        JoinRequest { name: s.name.clone(), threads: s.threads as u32, study: s.study.clone() };
    while !stop.load(Ordering::Relaxed) {
        let Some(joined) = link.join(&request, Duration::from_secs(1))? else {
            std::thread::sleep(Duration::from_millis(200));
            continue;
        };
        let runners: Result<Vec<_>, _> =
            (0..s.threads.max(1)).map(|_| LocalRunner::remote(&joined.model)).collect();
        let runners = match runners {
            Ok(r) => r,
            Err(e) => {
                tracing::error!(error = %e, "cannot build the sweep's model; not joining");
                std::thread::sleep(Duration::from_secs(2));
                continue;
            }
        };
        tracing::info!(study = %joined.study_hash, kind = %joined.model.kind, "joined sweep");
        link.serve()?;
        let pool = Pool::start(runners, stop, link.replier());
        let outcome = serve_sweep(link, &pool, stop);
        link.leave();
        pool.finish();
        outcome?;
    }
    Ok(())
}

fn serve_sweep(
    link: &mut dyn WorkerLink,
    pool: &Pool,
    stop: &Arc<AtomicBool>,
) -> Result<(), RemoteError> {
    // Routes stay here unless the pool threads can answer themselves.
    let mut routes: HashMap<u64, Option<Route>> = HashMap::new();
    let direct = link.replier().is_some();
    let mut seq = 0u64;
    loop {
        let stopping = stop.load(Ordering::Relaxed);
        if !stopping {
            // Waiting long is fine when answers leave from the pool threads.
            let wait = if direct || routes.is_empty() {
                Duration::from_millis(20)
            } else {
                Duration::from_micros(200)
            };
            match link.next(wait)? {
                LinkEvent::Task(ticket) => {
                    seq += 1;
                    let (keep, send) = if direct {
                        (None, Some(ticket.route))
                    } else {
                        (Some(ticket.route), None)
                    };
                    routes.insert(seq, keep);
                    let _ = pool.tasks.send((seq, ticket.task, send));
                }
                LinkEvent::CoordinatorGone => {
                    tracing::info!("coordinator gone; joining again");
                    return Ok(());
                }
                LinkEvent::Idle => {}
            }
        } else if routes.is_empty() {
            return Ok(());
        }
        let wait = if stopping { Duration::from_millis(20) } else { Duration::ZERO };
        while let Ok((id, done)) = pool.results.recv_timeout(wait) {
            let route = routes.remove(&id).flatten();
            match (done, route) {
                (Done::Result(r), Some(route)) => link.reply(route, r)?,
                (Done::HandBack(Some(route)), _) | (Done::HandBack(None), Some(route)) => {
                    link.hand_back(route, "worker stopping")
                }
                _ => {}
            }
        }
    }
}
