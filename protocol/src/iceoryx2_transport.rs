//! iceoryx2 transport: worker processes on one host, over shared memory.
//!
//! Neither publish-subscribe nor request-response in iceoryx2 offers
//! competing consumers, so the layout is a work queue built by hand, under a
//! service root `R` (default `ceilfarm`):
//! - `R/welcome`: the coordinator publishes the sweep (history 1): the sweep
//!   id in plain bytes, the coordinator's node id, then the Welcome message;
//!   joining workers read it, and join only if that node is alive;
//! - `R/<sweep>/result`: every worker publishes its Hello (with its node
//!   id), results, hand-backs and Goodbye; the coordinator subscribes before
//!   it publishes the welcome, so no Hello goes out unread;
//! - `R/<sweep>/task/<worker>`: one per worker, the coordinator publishes.
//!
//! Overwriting of unread samples is off and buffers exceed the farm's
//! window, so no task or result is dropped. Liveness is iceoryx2's node
//! monitoring, by node id (names may repeat; a restarted process has a new
//! id). Waiting sides sleep on event services (`R/<sweep>/result-ready`,
//! `R/<sweep>/task-ready/<worker>`) that the sending side notifies, so a
//! round trip costs no polling delay. The coordinator lists nodes every
//! 100 ms, reports workers whose process died, and removes their stale
//! resources. Messages are bincode with the version header; a worker of
//! another protocol version (or pinned to another study) still finds the
//! sweep id, announces itself on the result channel and leaves, so both
//! sides log the refusal.

use crate::codec;
use crate::link::{study_refusal, JoinRequest, Joined, LinkEvent, Ticket, WorkerLink};
use crate::seal::{Direction, SweepKey, SweepMac};
use crate::transport::{Transport, TransportError, TransportEvent, WorkerId};
use crate::{FromWorker, ModelSpec, Task, TaskId, TaskResult, ToWorker, PROTOCOL_VERSION};
use iceoryx2::node::NodeView;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::{HashMap, HashSet};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

type Svc = ipc_threadsafe::Service;
type Pub = Publisher<Svc, [u8], ()>;
type Sub = Subscriber<Svc, [u8], ()>;
type Ntf = iceoryx2::port::notifier::Notifier<Svc>;
type Lst = iceoryx2::port::listener::Listener<Svc>;
type Keep = Box<dyn std::any::Any + Send>;

/// Default service root.
pub const DEFAULT_ROOT: &str = "ceilfarm";
/// Tasks one worker may hold unread (above the farm's window).
const TASK_BUFFER: usize = 64;
/// Results the coordinator may hold unread (above workers x window).
const RESULT_BUFFER: usize = 1024;
/// How long a refused worker keeps its announcement readable.
const REFUSAL_LINGER: Duration = Duration::from_millis(500);
/// Most worker processes per sweep on one host.
const MAX_WORKERS: usize = 64;

fn err(context: &str) -> impl Fn(&dyn std::fmt::Debug) -> TransportError + '_ {
    move |e| TransportError::Setup(format!("iceoryx2 {context}: {e:?}"))
}

fn quiet_logs() {
    set_log_level(LogLevel::Error);
}

fn node(name: &str) -> Result<Node<Svc>, TransportError> {
    quiet_logs();
    let n = NodeName::new(name).map_err(|e| err("node name")(&e))?;
    NodeBuilder::new().name(&n).create::<Svc>().map_err(|e| err("node")(&e))
}

fn service_name(s: &str) -> Result<ServiceName, TransportError> {
    ServiceName::new(s).map_err(|e| err("service name")(&e))
}

/// Opens (or creates) a byte-slice pub/sub service with the farm's settings.
fn channel(
    node: &Node<Svc>,
    name: &str,
    buffer: usize,
    publishers: usize,
    history: usize,
    overwrite: bool,
    subscribers: usize,
) -> Result<
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<Svc, [u8], ()>,
    TransportError,
> {
    let builder = node
        .service_builder(&service_name(name)?)
        .publish_subscribe::<[u8]>()
        .enable_safe_overflow(overwrite)
        .subscriber_max_buffer_size(buffer)
        .history_size(history)
        .max_publishers(publishers)
        .max_subscribers(subscribers)
        .max_nodes(publishers.max(subscribers) + 2);
    builder.open_or_create().map_err(|e| {
        TransportError::Setup(format!("iceoryx2 service {name}: {e:?} (another ceilfarm build?)"))
    })
}

/// Opens (or creates) an event service that wakes a waiting side.
fn event_service(
    node: &Node<Svc>,
    name: &str,
    notifiers: usize,
    listeners: usize,
) -> Result<iceoryx2::service::port_factory::event::PortFactory<Svc>, TransportError> {
    node.service_builder(&service_name(name)?)
        .event()
        .max_notifiers(notifiers)
        .max_listeners(listeners)
        .max_nodes(notifiers.max(listeners) + 2)
        .open_or_create()
        .map_err(|e| TransportError::Setup(format!("iceoryx2 event service {name}: {e:?}")))
}

/// A listener on an event service, with the service kept open.
fn listener(node: &Node<Svc>, name: &str, notifiers: usize) -> Result<(Lst, Keep), TransportError> {
    let f = event_service(node, name, notifiers, 1)?;
    let l = f.listener_builder().create().map_err(|e| err("listener")(&e))?;
    Ok((l, Box::new(f)))
}

/// A notifier on an event service, with the service kept open.
fn notifier(node: &Node<Svc>, name: &str, notifiers: usize) -> Result<(Ntf, Keep), TransportError> {
    let f = event_service(node, name, notifiers, 1)?;
    let n = f.notifier_builder().create().map_err(|e| err("notifier")(&e))?;
    Ok((n, Box::new(f)))
}

/// Shortest wait handed to a listener. iceoryx2 0.10 turns the timeout into
/// a socket `timeval` by truncation, and a zero `timeval` waits forever: a
/// remainder under a microsecond would sleep until the next notification.
const MIN_NAP: Duration = Duration::from_micros(1);

/// Sleeps until notified or `timeout`, consuming pending notifications.
fn nap(l: &Lst, timeout: Duration) {
    let _ = l.timed_wait(|_| {}, timeout.max(MIN_NAP));
}

fn publisher(
    f: &iceoryx2::service::port_factory::publish_subscribe::PortFactory<Svc, [u8], ()>,
) -> Result<Pub, TransportError> {
    // With overwriting off (tasks, results) a full buffer waits for the reader
    // rather than dropping; the welcome channel overwrites instead.
    f.publisher_builder()
        .initial_max_slice_len(2048)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .backpressure_strategy(BackpressureStrategy::RetryUntilDelivered)
        .create()
        .map_err(|e| err("publisher")(&e))
}

fn subscriber(
    f: &iceoryx2::service::port_factory::publish_subscribe::PortFactory<Svc, [u8], ()>,
    buffer: usize,
) -> Result<Sub, TransportError> {
    f.subscriber_builder().buffer_size(buffer).create().map_err(|e| err("subscriber")(&e))
}

fn send(p: &Pub, bytes: &[u8]) -> Result<(), TransportError> {
    let sample = p
        .loan_slice_uninit(bytes.len())
        .map_err(|e| TransportError::Closed(format!("iceoryx2 loan: {e:?}")))?;
    let sample = sample.write_from_slice(bytes);
    sample.send().map(|_| ()).map_err(|e| TransportError::Closed(format!("iceoryx2 send: {e:?}")))
}

/// Copies the next sample into `into` (its bytes replaced) and says whether
/// there was one. The tag is checked on this private copy, never on the
/// shared memory, which another local process could change between the
/// check and the decoding; the buffer is kept across messages, so a
/// megabyte result costs one copy and no fresh allocation (whose pages the
/// kernel would map and zero anew each time), unless it grew past
/// [`INBOX_KEEP_BYTES`].
fn receive_into(s: &Sub, into: &mut Vec<u8>) -> Result<bool, TransportError> {
    if into.capacity() > INBOX_KEEP_BYTES {
        *into = Vec::new();
    }
    into.clear();
    match s.receive() {
        Ok(Some(sample)) => {
            into.extend_from_slice(sample.payload());
            Ok(true)
        }
        Ok(None) => Ok(false),
        Err(e) => Err(TransportError::Closed(format!("iceoryx2 receive: {e:?}"))),
    }
}

/// The largest receive buffer kept from one message to the next (bytes).
const INBOX_KEEP_BYTES: usize = 8 << 20;

/// Publishes `msg` sealed for lease `seq`, written and tagged straight in a
/// loan of shared memory ([`SweepMac::seal_into`]): no copy of the message
/// in between.
fn send_sealed<T: Serialize>(
    p: &Pub,
    mac: &SweepMac,
    direction: Direction,
    seq: u64,
    msg: &T,
) -> Result<(), TransportError> {
    let len = crate::seal::sealed_len(msg).map_err(|e| TransportError::Setup(e.to_string()))?;
    let mut sample = p
        .loan_slice_uninit(len)
        .map_err(|e| TransportError::Closed(format!("iceoryx2 loan: {e:?}")))?;
    mac.seal_into(direction, seq, msg, sample.payload_mut())
        .map_err(|e| TransportError::Setup(e.to_string()))?;
    // SAFETY: `seal_into` returned `Ok`, so it wrote every byte of the payload.
    let sample = unsafe { sample.assume_init() };
    sample.send().map(|_| ()).map_err(|e| TransportError::Closed(format!("iceoryx2 send: {e:?}")))
}

fn receive(s: &Sub) -> Result<Option<Vec<u8>>, TransportError> {
    match s.receive() {
        Ok(Some(sample)) => Ok(Some(sample.payload().to_vec())),
        Ok(None) => Ok(None),
        Err(e) => Err(TransportError::Closed(format!("iceoryx2 receive: {e:?}"))),
    }
}

/// Ids of the nodes whose processes are alive (a restarted process has a
/// new id; names may repeat); removes dead nodes' resources.
fn alive_node_ids() -> HashSet<u128> {
    let mut alive = HashSet::new();
    let _ = Node::<Svc>::list(Config::global_config(), |state| {
        match state {
            NodeState::Alive(view) => {
                alive.insert(view.id().value());
            }
            NodeState::Dead(view) => {
                let _ = view.try_remove_stale_resources();
            }
            _ => {}
        }
        CallbackProgression::Continue
    });
    alive
}

fn coordinator_node_name(sweep: &str) -> String {
    format!("ceilfarm-c-{sweep}")
}

fn worker_node_name(name: &str) -> String {
    format!("ceilfarm-w-{name}")
}

fn sweep_of(hash: &str) -> String {
    hash[..hash.len().min(16)].to_string()
}

/// A welcome sample: the sweep id's length, the id, the coordinator's node
/// id (16 bytes, little-endian), then the message.
fn frame_welcome(sweep: &str, coordinator: u128, message: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(17 + sweep.len() + message.len());
    out.push(sweep.len() as u8);
    out.extend_from_slice(sweep.as_bytes());
    out.extend_from_slice(&coordinator.to_le_bytes());
    out.extend_from_slice(message);
    out
}

/// A welcome sample taken apart.
#[derive(Debug, PartialEq)]
struct Welcome<'a> {
    /// The sweep id (names the sweep's services).
    sweep: String,
    /// The node id of the coordinator that published it.
    coordinator: u128,
    /// The encoded [`ToWorker::Welcome`].
    message: &'a [u8],
}

/// Splits a welcome sample into the sweep id, the coordinator and the message.
fn split_welcome(bytes: &[u8]) -> Option<Welcome<'_>> {
    let (&len, rest) = bytes.split_first()?;
    let len = len as usize;
    let sweep = std::str::from_utf8(rest.get(..len)?).ok()?;
    let id: [u8; 16] = rest.get(len..len + 16)?.try_into().ok()?;
    let valid = sweep.chars().all(|c| c.is_ascii_alphanumeric());
    valid.then(|| Welcome {
        sweep: sweep.to_string(),
        coordinator: u128::from_le_bytes(id),
        message: &rest[len + 16..],
    })
}

/// A worker message on the shared result channel, with its sender.
#[derive(Debug, Serialize, Deserialize)]
struct Envelope {
    /// The worker's name.
    from: String,
    /// The worker's node id, by which the coordinator watches its liveness.
    node: u128,
    /// The message.
    msg: FromWorker,
}

struct RemoteWorker {
    name: String,
    node: u128,
    tasks: Pub,
    wake: Ntf,
    _keep: (Keep, Keep),
}

/// The coordinator's end: implements [`Transport`].
pub struct IceoryxCoordinator {
    root: String,
    sweep: String,
    study_hash: String,
    node: Option<Node<Svc>>,
    welcome: Option<(Pub, Box<dyn std::any::Any + Send>)>,
    welcome_bytes: Vec<u8>,
    results: Option<(Sub, Box<dyn std::any::Any + Send>)>,
    ready: Option<(Lst, Keep)>,
    workers: HashMap<WorkerId, RemoteWorker>,
    by_name: HashMap<String, WorkerId>,
    next_id: u64,
    last_liveness: Instant,
    pending: std::collections::VecDeque<TransportEvent>,
    mac: Option<SweepMac>,
    next_seq: u64,
    /// Tasks sent and not answered, by lease sequence number.
    leases: HashMap<u64, (WorkerId, TaskId)>,
    /// The last message read off the result channel: one buffer kept
    /// from message to message (see [`receive_into`]).
    inbox: Vec<u8>,
}

impl IceoryxCoordinator {
    /// A coordinator under service root `root` (default `ceilfarm`).
    pub fn new(root: Option<&str>) -> Self {
        Self {
            root: root.unwrap_or(DEFAULT_ROOT).to_string(),
            sweep: String::new(),
            study_hash: String::new(),
            node: None,
            welcome: None,
            welcome_bytes: Vec::new(),
            results: None,
            ready: None,
            workers: HashMap::new(),
            by_name: HashMap::new(),
            next_id: 0,
            last_liveness: Instant::now(),
            pending: Default::default(),
            mac: None,
            next_seq: 1,
            leases: HashMap::new(),
            inbox: Vec::new(),
        }
    }

    /// Whether lease `seq` is `task` held by `worker`; consumes it if so.
    fn take_lease(&mut self, seq: u64, worker: WorkerId, task: TaskId) -> bool {
        let held = self.leases.get(&seq) == Some(&(worker, task));
        if held {
            self.leases.remove(&seq);
        }
        held
    }

    fn forget_leases(&mut self, worker: WorkerId) {
        self.leases.retain(|_, (w, _)| *w != worker);
    }

    fn on_message(&mut self, bytes: &[u8]) -> Result<(), TransportError> {
        let Some(mac) = &self.mac else {
            return Err(TransportError::Closed("not started".into()));
        };
        let (seq, Envelope { from, node, msg }) =
            match mac.open::<Envelope>(Direction::FromWorker, bytes) {
                Ok(e) => e,
                Err(e) => {
                    let reason = format!("message on the result channel: {e}");
                    self.pending.push_back(TransportEvent::Rejected { reason });
                    return Ok(());
                }
            };
        let worker = self.by_name.get(&from).copied();
        match (msg, worker) {
            (FromWorker::Hello { threads, study, .. }, _) => {
                match study_refusal(study.as_deref(), &self.study_hash) {
                    None => self.on_hello(&from, node, threads)?,
                    Some(why) => {
                        let reason = format!("worker {from} refused: {why}");
                        self.pending.push_back(TransportEvent::Rejected { reason });
                    }
                }
            }
            (FromWorker::Result(result), Some(worker))
                if self.take_lease(seq, worker, result.id) =>
            {
                self.pending.push_back(TransportEvent::Result { worker, result })
            }
            (FromWorker::HandBack { id, .. }, Some(worker)) if self.take_lease(seq, worker, id) => {
                self.pending.push_back(TransportEvent::HandedBack { worker, task: id })
            }
            (FromWorker::Result(_) | FromWorker::HandBack { .. }, Some(worker)) => {
                let reason = format!("{worker}: an answer for lease {seq} it does not hold (replayed or foreign); dropped");
                self.pending.push_back(TransportEvent::Rejected { reason });
            }
            (FromWorker::Goodbye, Some(worker)) => {
                self.forget_leases(worker);
                self.workers.remove(&worker);
                self.by_name.remove(&from);
                self.pending.push_back(TransportEvent::Left {
                    worker,
                    reason: "worker said goodbye".into(),
                });
            }
            (_, None) => {
                let reason = format!("message from unknown worker {from:?}");
                self.pending.push_back(TransportEvent::Rejected { reason });
            }
        }
        Ok(())
    }

    fn on_hello(&mut self, name: &str, node_id: u128, threads: u32) -> Result<(), TransportError> {
        if self.by_name.contains_key(name) {
            return Ok(());
        }
        let node =
            self.node.as_ref().ok_or_else(|| TransportError::Closed("not started".into()))?;
        let factory = channel(
            node,
            &format!("{}/{}/task/{name}", self.root, self.sweep),
            TASK_BUFFER,
            1,
            0,
            false,
            1,
        )?;
        let tasks = publisher(&factory)?;
        let (wake, wake_keep) =
            notifier(node, &format!("{}/{}/task-ready/{name}", self.root, self.sweep), 1)?;
        let id = WorkerId(self.next_id);
        self.next_id += 1;
        let _keep = (Box::new(factory) as Keep, wake_keep);
        let worker = RemoteWorker { name: name.to_string(), node: node_id, tasks, wake, _keep };
        self.workers.insert(id, worker);
        self.by_name.insert(name.to_string(), id);
        self.pending.push_back(TransportEvent::Joined {
            worker: id,
            name: name.to_string(),
            slots: threads.max(1) as usize,
        });
        Ok(())
    }

    fn check_liveness(&mut self) {
        if self.last_liveness.elapsed() < Duration::from_millis(100) {
            return;
        }
        self.last_liveness = Instant::now();
        let alive = alive_node_ids();
        let gone: Vec<(WorkerId, String)> = self
            .workers
            .iter()
            .filter(|(_, w)| !alive.contains(&w.node))
            .map(|(id, w)| (*id, w.name.clone()))
            .collect();
        for (id, name) in gone {
            self.forget_leases(id);
            self.workers.remove(&id);
            self.by_name.remove(&name);
            self.pending.push_back(TransportEvent::Left {
                worker: id,
                reason: "worker process is gone".into(),
            });
        }
        // Re-announce the sweep so workers that arrive later see it.
        if let Some((p, _)) = &self.welcome {
            let _ = p.update_connections();
            let _ = send(p, &self.welcome_bytes);
        }
    }
}

impl Transport for IceoryxCoordinator {
    fn name(&self) -> &'static str {
        "iceoryx2"
    }

    fn start(&mut self, study_hash: &str, model: &ModelSpec) -> Result<(), TransportError> {
        self.sweep = sweep_of(study_hash);
        self.study_hash = study_hash.to_string();
        let node = node(&coordinator_node_name(&self.sweep))?;
        // The result subscriber and its wake-up exist before any worker can
        // read the welcome: a Hello sent with no subscriber would be lost.
        let results_factory = channel(
            &node,
            &format!("{}/{}/result", self.root, self.sweep),
            RESULT_BUFFER,
            MAX_WORKERS,
            0,
            false,
            1,
        )?;
        let results = subscriber(&results_factory, RESULT_BUFFER)?;
        let ready_name = format!("{}/{}/result-ready", self.root, self.sweep);
        self.ready = Some(listener(&node, &ready_name, MAX_WORKERS)?);
        self.results = Some((results, Box::new(results_factory)));
        let welcome_factory =
            channel(&node, &format!("{}/welcome", self.root), 1, 1, 1, true, MAX_WORKERS)?;
        let welcome = publisher(&welcome_factory)?;
        let mac = SweepMac::new(SweepKey::random(), study_hash);
        let bytes = codec::encode(&ToWorker::Welcome {
            study_hash: study_hash.to_string(),
            model: model.clone(),
            key: mac.key().clone(),
        })
        .map_err(|e| TransportError::Setup(e.to_string()))?;
        self.mac = Some(mac);
        let bytes = frame_welcome(&self.sweep, node.id().value(), &bytes);
        send(&welcome, &bytes)?;
        self.welcome_bytes = bytes;
        self.welcome = Some((welcome, Box::new(welcome_factory)));
        self.node = Some(node);
        Ok(())
    }

    fn send(&mut self, worker: WorkerId, task: Task) -> Result<(), TransportError> {
        let w = self.workers.get(&worker).ok_or(TransportError::UnknownWorker(worker))?;
        let mac = self.mac.as_ref().ok_or_else(|| TransportError::Closed("not started".into()))?;
        let seq = self.next_seq;
        let id = task.id;
        send_sealed(&w.tasks, mac, Direction::ToWorker, seq, &ToWorker::Task(task))?;
        self.next_seq += 1;
        self.leases.insert(seq, (worker, id));
        let _ = w.wake.notify();
        Ok(())
    }

    fn next_event(&mut self, timeout: Duration) -> Result<Option<TransportEvent>, TransportError> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(ev) = self.pending.pop_front() {
                return Ok(Some(ev));
            }
            let got = match &self.results {
                Some((sub, _)) => receive_into(sub, &mut self.inbox)?,
                None => return Err(TransportError::Closed("not started".into())),
            };
            match got {
                true => {
                    let bytes = std::mem::take(&mut self.inbox);
                    let handled = self.on_message(&bytes);
                    self.inbox = bytes;
                    handled?
                }
                false => {
                    self.check_liveness();
                    if !self.pending.is_empty() {
                        continue;
                    }
                    let now = Instant::now();
                    if now >= deadline {
                        return Ok(None);
                    }
                    // Wake on a worker's notification; look at liveness at least every 100 ms.
                    let wait = (deadline - now).min(Duration::from_millis(100));
                    match &self.ready {
                        Some((l, _)) => nap(l, wait),
                        None => std::thread::sleep(wait),
                    }
                }
            }
        }
    }

    fn abandon(&mut self, worker: WorkerId, _reason: &str) {
        self.forget_leases(worker);
        if let Some(w) = self.workers.remove(&worker) {
            self.by_name.remove(&w.name);
        }
    }

    fn shutdown(&mut self) {
        self.workers.clear();
        self.results = None;
        self.ready = None;
        self.welcome = None;
        self.node = None;
    }
}

/// The worker's end: implements [`WorkerLink`].
pub struct IceoryxWorker {
    root: String,
    name: String,
    threads: u32,
    node: Option<Node<Svc>>,
    sweep: String,
    welcome: Option<(Sub, Box<dyn std::any::Any + Send>)>,
    tasks: Option<(Sub, Lst, Keep, Keep)>,
    results: Option<Arc<Mutex<ResultPort>>>,
    coordinator: Option<u128>,
    last_liveness: Instant,
    mac: Option<SweepMac>,
}

/// A worker's way back: the shared result channel and its wake-up, usable
/// from the pool threads.
struct ResultPort {
    from: String,
    node: u128,
    publisher: Pub,
    wake: Ntf,
    _keep: (Keep, Keep),
    /// The sweep's sealer; `None` only for a refused worker's last Hello.
    mac: Option<SweepMac>,
}

impl ResultPort {
    /// Publishes `msg`, sealed for lease `seq` (0: not about a task).
    fn publish(&self, seq: u64, msg: FromWorker) -> Result<(), TransportError> {
        let env = Envelope { from: self.from.clone(), node: self.node, msg };
        match &self.mac {
            Some(mac) => send_sealed(&self.publisher, mac, Direction::FromWorker, seq, &env)?,
            None => send(
                &self.publisher,
                &codec::encode(&env).map_err(|e| TransportError::Setup(e.to_string()))?,
            )?,
        }
        let _ = self.wake.notify();
        Ok(())
    }
}

impl IceoryxWorker {
    /// A worker under service root `root` (default `ceilfarm`).
    pub fn new(root: Option<&str>) -> Result<Self, TransportError> {
        quiet_logs();
        Ok(Self {
            root: root.unwrap_or(DEFAULT_ROOT).to_string(),
            name: String::new(),
            threads: 1,
            node: None,
            sweep: String::new(),
            welcome: None,
            tasks: None,
            results: None,
            coordinator: None,
            last_liveness: Instant::now(),
            mac: None,
        })
    }

    fn hello(&self, request: &JoinRequest) -> FromWorker {
        FromWorker::Hello {
            proto: PROTOCOL_VERSION,
            name: self.name.clone(),
            threads: self.threads,
            study: request.study.clone(),
        }
    }

    fn node(&mut self) -> Result<&Node<Svc>, TransportError> {
        if self.node.is_none() {
            self.node = Some(node(&worker_node_name(&self.name))?);
        }
        Ok(self.node.as_ref().expect("just set"))
    }

    /// The newest welcome sample, waiting up to `timeout` for one.
    fn latest_welcome(&mut self, timeout: Duration) -> Result<Option<Vec<u8>>, TransportError> {
        if self.welcome.is_none() {
            let root = self.root.clone();
            let node = self.node()?;
            let f = channel(node, &format!("{root}/welcome"), 1, 1, 1, true, MAX_WORKERS)?;
            let s = f
                .subscriber_builder()
                .buffer_size(1)
                .history_request(1)
                .create()
                .map_err(|e| err("subscriber")(&e))?;
            self.welcome = Some((s, Box::new(f)));
        }
        let deadline = Instant::now() + timeout;
        let mut latest = None;
        while Instant::now() < deadline {
            while let Some(bytes) = receive(&self.welcome.as_ref().expect("set").0)? {
                latest = Some(bytes);
            }
            if latest.is_some() {
                break;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        Ok(latest)
    }

    fn open_results(&mut self) -> Result<(), TransportError> {
        let (root, sweep, from) = (self.root.clone(), self.sweep.clone(), self.name.clone());
        let node = self.node()?;
        let node_id = node.id().value();
        let rf = channel(
            node,
            &format!("{root}/{sweep}/result"),
            RESULT_BUFFER,
            MAX_WORKERS,
            0,
            false,
            1,
        )?;
        let publisher = publisher(&rf)?;
        let (wake, keep) = notifier(node, &format!("{root}/{sweep}/result-ready"), MAX_WORKERS)?;
        let mac = self.mac.clone();
        let port =
            ResultPort { from, node: node_id, publisher, wake, _keep: (Box::new(rf), keep), mac };
        self.results = Some(Arc::new(Mutex::new(port)));
        Ok(())
    }

    fn open_tasks(&mut self) -> Result<(), TransportError> {
        let (root, sweep, name) = (self.root.clone(), self.sweep.clone(), self.name.clone());
        let node = self.node()?;
        let tf =
            channel(node, &format!("{root}/{sweep}/task/{name}"), TASK_BUFFER, 1, 0, false, 1)?;
        let (wake, keep) = listener(node, &format!("{root}/{sweep}/task-ready/{name}"), 1)?;
        self.tasks = Some((subscriber(&tf, TASK_BUFFER)?, wake, Box::new(tf), keep));
        Ok(())
    }

    fn publish(&self, seq: u64, msg: FromWorker) -> Result<(), TransportError> {
        let port =
            self.results.as_ref().ok_or_else(|| TransportError::Closed("not joined".into()))?;
        let port =
            port.lock().map_err(|_| TransportError::Closed("result port poisoned".into()))?;
        port.publish(seq, msg)
    }
}

impl WorkerLink for IceoryxWorker {
    fn join(
        &mut self,
        request: &JoinRequest,
        timeout: Duration,
    ) -> Result<Option<Joined>, TransportError> {
        self.name = request
            .name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' })
            .collect();
        self.threads = request.threads.max(1);
        let Some(bytes) = self.latest_welcome(timeout)? else { return Ok(None) };
        let Some(Welcome { sweep, coordinator, message }) = split_welcome(&bytes) else {
            tracing::warn!(len = bytes.len(), "dropped a malformed welcome");
            return Ok(None);
        };
        if !alive_node_ids().contains(&coordinator) {
            // A welcome left by a coordinator that is gone (maybe of the same
            // sweep, before a resume): its result channel may have no reader.
            return Ok(None);
        }
        self.coordinator = Some(coordinator);
        self.sweep = sweep;
        let welcome = codec::decode::<ToWorker>(message);
        self.mac = match &welcome {
            Ok(ToWorker::Welcome { study_hash, key, .. }) => {
                Some(SweepMac::new(key.clone(), study_hash))
            }
            _ => None,
        };
        self.open_results()?;
        let refusal = match welcome {
            Ok(ToWorker::Welcome { study_hash, model, .. }) => {
                match study_refusal(request.study.as_deref(), &study_hash) {
                    None => {
                        self.open_tasks()?;
                        return Ok(Some(Joined { study_hash, model }));
                    }
                    Some(why) => why,
                }
            }
            Ok(_) => return Ok(None),
            Err(e) => format!("the coordinator speaks another protocol: {e}"),
        };
        // Announce ourselves anyway, so that the coordinator logs the refusal too.
        // Samples go with their publisher: give the coordinator time to read it.
        let _ = self.publish(0, self.hello(request));
        std::thread::sleep(REFUSAL_LINGER);
        self.results = None;
        Err(TransportError::Setup(format!("coordinator refused this worker: {refusal}")))
    }

    fn serve(&mut self) -> Result<(), TransportError> {
        // The task subscriber exists: announce ourselves.
        self.publish(
            0,
            FromWorker::Hello {
                proto: PROTOCOL_VERSION,
                name: self.name.clone(),
                threads: self.threads,
                study: None,
            },
        )
    }

    fn next(&mut self, timeout: Duration) -> Result<LinkEvent, TransportError> {
        let deadline = Instant::now() + timeout;
        loop {
            let (sub, wake, _, _) =
                self.tasks.as_ref().ok_or_else(|| TransportError::Closed("not serving".into()))?;
            if let Some(bytes) = receive(sub)? {
                let mac =
                    self.mac.as_ref().ok_or_else(|| TransportError::Closed("not joined".into()))?;
                match mac.open::<ToWorker>(Direction::ToWorker, &bytes) {
                    Ok((seq, ToWorker::Task(task))) => {
                        let route = Box::new((task.id, seq));
                        return Ok(LinkEvent::Task(Ticket { task, route }));
                    }
                    Ok(_) => {}
                    Err(e) => tracing::warn!(error = %e, "dropped a task message"),
                }
                continue;
            }
            if self.last_liveness.elapsed() > Duration::from_millis(200) {
                self.last_liveness = Instant::now();
                // Gone, or restarted under the same name (a new node id).
                let alive = alive_node_ids();
                if !self.coordinator.is_some_and(|id| alive.contains(&id)) {
                    return Ok(LinkEvent::CoordinatorGone);
                }
            }
            let now = Instant::now();
            if now >= deadline {
                return Ok(LinkEvent::Idle);
            }
            // Wake on the coordinator's notification; check on it every 200 ms.
            nap(wake, (deadline - now).min(Duration::from_millis(200)));
        }
    }

    fn reply(
        &mut self,
        route: Box<dyn std::any::Any + Send>,
        result: TaskResult,
    ) -> Result<(), TransportError> {
        self.publish(lease_seq(&route)?, FromWorker::Result(result))
    }

    fn replier(&self) -> Option<crate::link::Replier> {
        let port = self.results.clone()?;
        Some(Arc::new(move |route, result| {
            let seq = lease_seq(&route)?;
            let port =
                port.lock().map_err(|_| TransportError::Closed("result port poisoned".into()))?;
            port.publish(seq, FromWorker::Result(result))
        }))
    }

    fn hand_back(&mut self, route: Box<dyn std::any::Any + Send>, reason: &str) {
        if let Ok(lease) = route.downcast::<(TaskId, u64)>() {
            let (id, seq) = *lease;
            let _ = self.publish(seq, FromWorker::HandBack { id, reason: reason.to_string() });
        }
    }

    fn leave(&mut self) {
        let _ = self.publish(0, FromWorker::Goodbye);
        self.tasks = None;
        self.results = None;
    }
}

/// The lease sequence number a task's route carries.
fn lease_seq(route: &Box<dyn std::any::Any + Send>) -> Result<u64, TransportError> {
    match route.downcast_ref::<(TaskId, u64)>() {
        Some((_, seq)) => Ok(*seq),
        None => Err(TransportError::Closed("foreign route".into())),
    }
}

#[cfg(test)]
#[path = "iceoryx2_refusals_tests.rs"]
mod refusals_tests;

#[cfg(test)]
#[path = "iceoryx2_join_tests.rs"]
mod join_tests;
