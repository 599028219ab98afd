//! zenoh transport: a coordinator and its workers across lab machines.
//!
//! zenoh has no work queue, so each worker serves a queryable of its own on
//! `ceilfarm/<sweep>/task/<worker>`; the coordinator sends each task as a
//! `get` to one worker and the reply carries the result. A query that closes
//! without a reply means the worker is gone: its tasks are re-issued.
//! Membership is zenoh liveliness (`ceilfarm/<sweep>/alive/<worker>/<slots>`,
//! declared after the queryable); joining is a `get` on
//! `ceilfarm/*/welcome` carrying the worker's Hello, which the coordinator
//! answers with the model or refuses with a reason (another protocol
//! version). A liveliness token counts only for a name that said Hello
//! first ([`crate::membership`]), and only the first valid reply to a task
//! query counts ([`crate::task_reply`]): an error reply fails that attempt,
//! never the worker. Keys carry the study hash, so two sweeps on one network never
//! mix. Multicast scouting is off: workers connect to the coordinator's
//! endpoint. The key layout and the patterns the access control grants
//! live in [`crate::zenoh_keys`].

use crate::codec;
use crate::link::{study_refusal, JoinRequest, Joined, LinkEvent, Ticket, WorkerLink};
pub use crate::membership::safe_name;
use crate::membership::Members;
use crate::seal::{Direction, SweepKey, SweepMac};
use crate::task_reply::{Reply, ReplyGate};
use crate::transport::{recv_event, Transport, TransportError, TransportEvent, WorkerId};
use crate::zenoh_config::session_config;
pub use crate::zenoh_config::{Role, ZenohSecurity, DEFAULT_ENDPOINT};
use crate::zenoh_keys as keys;
use crate::{FromWorker, ModelSpec, Task, TaskId, TaskResult, ToWorker, PROTOCOL_VERSION};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;
use zenoh::handlers::{CallbackDrop, FifoChannelHandler};
use zenoh::liveliness::LivelinessToken;
use zenoh::query::{ConsolidationMode, Query, QueryTarget, Queryable};
use zenoh::sample::SampleKind;
use zenoh::{Session, Wait};

/// Longest a single query may stay open (the farm's lease governs sooner).
const QUERY_TIMEOUT: Duration = Duration::from_secs(30 * 24 * 3600);

fn setup(e: impl std::fmt::Display) -> TransportError {
    TransportError::Setup(e.to_string())
}

pub use crate::zenoh_keys::sweep_prefix;

/// The lock's data even if a callback panicked while holding it.
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Opens a zenoh session: the coordinator listens (peer), workers connect
/// (client), under `security` ([`crate::zenoh_config`]); messages above
/// [`crate::codec::MAX_MESSAGE_BYTES`] are dropped by zenoh before they are
/// reassembled.
pub fn open_session(
    role: Role,
    endpoint: Option<&str>,
    security: &ZenohSecurity,
) -> Result<Session, TransportError> {
    let cfg = session_config(role, endpoint, security).map_err(setup)?;
    zenoh::open(cfg).wait().map_err(setup)
}

/// The coordinator's end: implements [`Transport`].
pub struct ZenohCoordinator {
    config: zenoh::Config,
    mac: Option<Arc<SweepMac>>,
    next_seq: u64,
    session: Option<Session>,
    prefix: String,
    members: Arc<Mutex<Members>>,
    events_tx: Sender<TransportEvent>,
    events_rx: Receiver<TransportEvent>,
    keep: Vec<Box<dyn std::any::Any + Send>>,
}

impl ZenohCoordinator {
    /// A coordinator that will listen on `endpoint` (e.g. `tls/0.0.0.0:7447`;
    /// `None`: the configuration file's, else [`DEFAULT_ENDPOINT`]); its
    /// configuration is read and checked here, before anything starts.
    pub fn new(endpoint: Option<&str>, security: &ZenohSecurity) -> Result<Self, TransportError> {
        let config = session_config(Role::Listen, endpoint, security).map_err(setup)?;
        let (events_tx, events_rx) = channel();
        Ok(Self {
            config,
            mac: None,
            next_seq: 1,
            session: None,
            prefix: String::new(),
            members: Arc::default(),
            events_tx,
            events_rx,
            keep: Vec::new(),
        })
    }

    fn declare_welcome(
        &mut self,
        session: &Session,
        study_hash: &str,
        model: &ModelSpec,
        key: &SweepKey,
    ) -> Result<(), TransportError> {
        let welcome = codec::encode(&ToWorker::Welcome {
            study_hash: study_hash.to_string(),
            model: model.clone(),
            key: key.clone(),
        })
        .map_err(setup)?;
        let (events, members) = (self.events_tx.clone(), self.members.clone());
        let hash = study_hash.to_string();
        let q = session
            .declare_queryable(keys::welcome_key(&self.prefix))
            .complete(true)
            .callback(move |query: Query| {
                let bytes = query.payload().map(|p| p.to_bytes().into_owned()).unwrap_or_default();
                match codec::decode::<FromWorker>(&bytes) {
                    Ok(FromWorker::Hello { name, study, .. }) => {
                        let refusal = study_refusal(study.as_deref(), &hash)
                            .or_else(|| lock(&members).admit(&name).err().map(|e| e.to_string()));
                        match refusal {
                            None => {
                                let _ =
                                    query.reply(query.key_expr().clone(), welcome.clone()).wait();
                            }
                            Some(why) => {
                                let _ = query.reply_err(why.clone()).wait();
                                let reason = format!("worker {name} refused: {why}");
                                let _ = events.send(TransportEvent::Rejected { reason });
                            }
                        }
                    }
                    Ok(_) => {
                        let _ = query.reply_err("expected a Hello").wait();
                    }
                    Err(e) => {
                        let reason = format!("worker refused: {e}");
                        let _ = query.reply_err(reason.clone()).wait();
                        let _ = events.send(TransportEvent::Rejected { reason });
                    }
                }
            })
            .wait()
            .map_err(setup)?;
        self.keep.push(Box::new(q));
        Ok(())
    }

    fn declare_membership(&mut self, session: &Session) -> Result<(), TransportError> {
        let (events, members) = (self.events_tx.clone(), self.members.clone());
        let base = keys::alive_key(&self.prefix, "");
        let sub = session
            .liveliness()
            .declare_subscriber(keys::alive_keys(&self.prefix))
            .history(true)
            .callback(move |sample| {
                let key = sample.key_expr().as_str().to_string();
                let rest = key.strip_prefix(&base).unwrap_or("");
                let event = match sample.kind() {
                    SampleKind::Put => lock(&members).appeared(rest),
                    SampleKind::Delete => lock(&members).vanished(rest),
                };
                if let Some(event) = event {
                    let _ = events.send(event);
                }
            })
            .wait()
            .map_err(setup)?;
        self.keep.push(Box::new(sub));
        let token: LivelinessToken = session
            .liveliness()
            .declare_token(keys::coordinator_key(&self.prefix))
            .wait()
            .map_err(setup)?;
        self.keep.push(Box::new(token));
        Ok(())
    }
}

impl Transport for ZenohCoordinator {
    fn name(&self) -> &'static str {
        "zenoh"
    }

    fn start(&mut self, study_hash: &str, model: &ModelSpec) -> Result<(), TransportError> {
        let session = zenoh::open(self.config.clone()).wait().map_err(setup)?;
        self.prefix = sweep_prefix(study_hash);
        let mac = Arc::new(SweepMac::new(SweepKey::random(), study_hash));
        self.declare_welcome(&session, study_hash, model, mac.key())?;
        self.mac = Some(mac);
        self.declare_membership(&session)?;
        self.session = Some(session);
        Ok(())
    }

    fn send(&mut self, worker: WorkerId, task: Task) -> Result<(), TransportError> {
        let session =
            self.session.as_ref().ok_or_else(|| TransportError::Closed("not started".into()))?;
        let name = lock(&self.members).name(worker).map(str::to_string);
        let name = name.ok_or(TransportError::UnknownWorker(worker))?;
        let mac = self.mac.clone().ok_or_else(|| TransportError::Closed("not started".into()))?;
        let seq = self.next_seq;
        self.next_seq += 1;
        let gate = Arc::new(Mutex::new(ReplyGate::new(worker, task.id, seq, mac.clone())));
        let payload = mac.seal(Direction::ToWorker, seq, &ToWorker::Task(task)).map_err(setup)?;
        let (ev1, ev2, gate2) = (self.events_tx.clone(), self.events_tx.clone(), gate.clone());
        let handler = CallbackDrop {
            callback: move |reply: zenoh::query::Reply| {
                let event = match reply.result() {
                    Ok(sample) => lock(&gate).on_reply(Reply::Answer(&sample.payload().to_bytes())),
                    Err(err) => lock(&gate).on_reply(Reply::Error(&err.payload().to_bytes())),
                };
                let _ = ev1.send(event);
            },
            drop: move || {
                if let Some(event) = lock(&gate2).on_close() {
                    let _ = ev2.send(event);
                }
            },
        };
        session
            .get(keys::task_key(&self.prefix, &name))
            .payload(payload)
            .target(QueryTarget::All)
            .consolidation(ConsolidationMode::None)
            .timeout(QUERY_TIMEOUT)
            .with(handler)
            .wait()
            .map_err(|e| TransportError::Closed(e.to_string()))
    }

    fn next_event(&mut self, timeout: Duration) -> Result<Option<TransportEvent>, TransportError> {
        recv_event(&self.events_rx, timeout)
    }

    fn abandon(&mut self, worker: WorkerId, _reason: &str) {
        // A remote worker cannot be stopped from here; forget it until it
        // announces itself again.
        lock(&self.members).forget(worker);
    }

    fn shutdown(&mut self) {
        self.keep.clear();
        if let Some(s) = self.session.take() {
            let _ = s.close().wait();
        }
    }
}

/// A task query with the lease's sequence number its answer is sealed for.
struct Lease {
    query: Query,
    seq: u64,
    task: TaskId,
}

/// Answers a task query with `msg`, sealed for its lease.
fn answer_lease(
    mac: &SweepMac,
    route: Box<dyn std::any::Any + Send>,
    msg: &FromWorker,
) -> Result<(), TransportError> {
    let lease =
        route.downcast::<Lease>().map_err(|_| TransportError::Closed("foreign route".into()))?;
    let bytes = mac.seal(Direction::FromWorker, lease.seq, msg).map_err(setup)?;
    let query = lease.query;
    query
        .reply(query.key_expr().clone(), bytes)
        .wait()
        .map_err(|e| TransportError::Closed(e.to_string()))
}

/// The worker's end: implements [`WorkerLink`].
pub struct ZenohWorker {
    session: Session,
    /// The common name of the certificate the session presents, if any: the
    /// only name the coordinator's access control lets it serve.
    certified: Option<(String, std::path::PathBuf)>,
    name: String,
    joined: Option<String>,
    mac: Option<Arc<SweepMac>>,
    queryable: Option<Queryable<FifoChannelHandler<Query>>>,
    token: Option<LivelinessToken>,
    coordinator_gone: Arc<AtomicBool>,
    watch: Option<Box<dyn std::any::Any + Send>>,
}

impl ZenohWorker {
    /// Connects to a coordinator's endpoint (e.g. `tls/10.0.0.5:7447`;
    /// `None`: the configuration file's, else [`DEFAULT_ENDPOINT`]). A
    /// configuration that presents a certificate fixes the worker's name
    /// ([`crate::zenoh_identity`]).
    pub fn connect(
        endpoint: Option<&str>,
        security: &ZenohSecurity,
    ) -> Result<Self, TransportError> {
        let certified = match &security.config {
            Some(path) => crate::zenoh_identity::certificate_name(path)
                .map_err(setup)?
                .map(|name| (name, path.clone())),
            None => None,
        };
        Ok(Self {
            session: open_session(Role::Connect, endpoint, security)?,
            certified,
            name: String::new(),
            joined: None,
            mac: None,
            queryable: None,
            token: None,
            coordinator_gone: Arc::new(AtomicBool::new(false)),
            watch: None,
        })
    }
}

impl WorkerLink for ZenohWorker {
    fn join(
        &mut self,
        request: &JoinRequest,
        timeout: Duration,
    ) -> Result<Option<Joined>, TransportError> {
        if let Some((certified, path)) = &self.certified {
            if request.name != *certified {
                return Err(setup(crate::zenoh_identity::IdentityError::NameMismatch {
                    requested: request.name.clone(),
                    certified: certified.clone(),
                    path: path.clone(),
                }));
            }
        }
        let threads = request.threads.max(1);
        self.name = format!("{}/{threads}", safe_name(&request.name));
        let hello = codec::encode(&FromWorker::Hello {
            proto: PROTOCOL_VERSION,
            name: request.name.clone(),
            threads,
            study: request.study.clone(),
        })
        .map_err(setup)?;
        let replies = self
            .session
            .get(keys::WELCOME_KEYS)
            .payload(hello)
            .target(QueryTarget::All)
            .timeout(timeout)
            .wait()
            .map_err(|e| TransportError::Closed(e.to_string()))?;
        // Several sweeps may answer: join the first that welcomes us, and
        // report refusals only when nobody did.
        let mut refusals = Vec::new();
        while let Ok(reply) = replies.recv() {
            match reply.result() {
                Ok(sample) => match codec::decode::<ToWorker>(&sample.payload().to_bytes()) {
                    Ok(ToWorker::Welcome { study_hash, model, key }) => {
                        self.joined = Some(sweep_prefix(&study_hash));
                        self.mac = Some(Arc::new(SweepMac::new(key, &study_hash)));
                        return Ok(Some(Joined { study_hash, model }));
                    }
                    Ok(other) => tracing::warn!(?other, "unexpected answer to Hello"),
                    Err(e) => refusals.push(format!("undecodable welcome: {e}")),
                },
                Err(err) => {
                    refusals.push(String::from_utf8_lossy(&err.payload().to_bytes()).into())
                }
            }
        }
        match refusals.is_empty() {
            true => Ok(None),
            false => Err(TransportError::Setup(format!(
                "coordinator refused this worker: {}",
                refusals.join("; ")
            ))),
        }
    }

    fn serve(&mut self) -> Result<(), TransportError> {
        let prefix =
            self.joined.clone().ok_or_else(|| TransportError::Closed("not joined".into()))?;
        let task_name = self.name.split('/').next().unwrap_or("w").to_string();
        // Queryable first, then liveliness: never be seen before being able to answer.
        let q = self
            .session
            .declare_queryable(keys::task_key(&prefix, &task_name))
            .complete(true)
            .wait()
            .map_err(setup)?;
        self.queryable = Some(q);
        self.coordinator_gone.store(false, Ordering::Relaxed);
        let gone = self.coordinator_gone.clone();
        let watch = self
            .session
            .liveliness()
            .declare_subscriber(keys::coordinator_key(&prefix))
            .history(true)
            .callback(move |s| {
                if s.kind() == SampleKind::Delete {
                    gone.store(true, Ordering::Relaxed);
                }
            })
            .wait()
            .map_err(setup)?;
        self.watch = Some(Box::new(watch));
        let token = self
            .session
            .liveliness()
            .declare_token(keys::alive_key(&prefix, &self.name))
            .wait()
            .map_err(setup)?;
        self.token = Some(token);
        Ok(())
    }

    fn next(&mut self, timeout: Duration) -> Result<LinkEvent, TransportError> {
        if self.coordinator_gone.load(Ordering::Relaxed) {
            return Ok(LinkEvent::CoordinatorGone);
        }
        let q =
            self.queryable.as_ref().ok_or_else(|| TransportError::Closed("not serving".into()))?;
        let Some(query) =
            q.recv_timeout(timeout).map_err(|e| TransportError::Closed(e.to_string()))?
        else {
            return Ok(LinkEvent::Idle);
        };
        let mac = self.mac.as_ref().ok_or_else(|| TransportError::Closed("not joined".into()))?;
        let bytes = query.payload().map(|p| p.to_bytes().into_owned()).unwrap_or_default();
        // A query that fails the MAC is the querier's problem only: it gets
        // an error reply, nothing else changes.
        match mac.open::<ToWorker>(Direction::ToWorker, &bytes) {
            Ok((seq, ToWorker::Task(task))) => {
                let lease = Lease { query, seq, task: task.id };
                Ok(LinkEvent::Task(Ticket { task, route: Box::new(lease) }))
            }
            Ok(_) => {
                let _ = query.reply_err("expected a task").wait();
                Ok(LinkEvent::Idle)
            }
            Err(e) => {
                tracing::warn!(error = %e, "dropped a task message");
                let _ = query.reply_err(format!("task refused: {e}")).wait();
                Ok(LinkEvent::Idle)
            }
        }
    }

    fn reply(
        &mut self,
        route: Box<dyn std::any::Any + Send>,
        result: TaskResult,
    ) -> Result<(), TransportError> {
        let mac = self.mac.as_ref().ok_or_else(|| TransportError::Closed("not joined".into()))?;
        answer_lease(mac, route, &FromWorker::Result(result))
    }

    fn replier(&self) -> Option<crate::link::Replier> {
        let mac = self.mac.clone()?;
        Some(Arc::new(move |route, result| answer_lease(&mac, route, &FromWorker::Result(result))))
    }

    fn hand_back(&mut self, route: Box<dyn std::any::Any + Send>, reason: &str) {
        let Some(mac) = &self.mac else { return };
        let Some(id) = route.downcast_ref::<Lease>().map(|lease| lease.task) else { return };
        let _ = answer_lease(mac, route, &FromWorker::HandBack { id, reason: reason.into() });
    }

    fn leave(&mut self) {
        self.token = None;
        self.watch = None;
        self.queryable = None;
        self.joined = None;
    }
}

#[cfg(test)]
#[path = "zenoh_trust_tests.rs"]
mod trust_tests;
