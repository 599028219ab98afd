//! iceoryx2 transport: worker processes on one host, over shared memory.
//!
//! Neither publish-subscribe nor request-response in iceoryx2 offers
//! competing consumers, so the layout is a work queue built by hand, under a
//! service root `R` (default `ceilfarm`):
//! - `R/welcome`: the coordinator publishes the sweep (history 1); joining
//!   workers read it;
//! - `R/<sweep>/result`: every worker publishes its Hello, results,
//!   hand-backs and Goodbye; the coordinator subscribes;
//! - `R/<sweep>/task/<worker>`: one per worker, the coordinator publishes.
//! Overwriting of unread samples is off and buffers exceed the farm's
//! window, so no task or result is dropped. Liveness is iceoryx2's node
//! monitoring: the coordinator lists nodes every 100 ms, reports workers
//! whose process died, and removes their stale resources. Every service
//! carries the attribute `proto = <version>`: a worker of another version
//! cannot open it. Messages are bincode with the version header.

use crate::codec;
use crate::link::{Joined, LinkEvent, Ticket, WorkerLink};
use crate::transport::{Transport, TransportError, TransportEvent, WorkerId};
use crate::{FromWorker, ModelSpec, Task, TaskId, TaskResult, ToWorker, PROTOCOL_VERSION};
use iceoryx2::node::NodeView;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::time::{Duration, Instant};

type Svc = ipc_threadsafe::Service;
type Pub = Publisher<Svc, [u8], ()>;
type Sub = Subscriber<Svc, [u8], ()>;

/// Default service root.
pub const DEFAULT_ROOT: &str = "ceilfarm";
/// Tasks one worker may hold unread (above the farm's window).
const TASK_BUFFER: usize = 64;
/// Results the coordinator may hold unread (above workers x window).
const RESULT_BUFFER: usize = 1024;
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

fn proto_attr() -> (AttributeSpecifier, AttributeVerifier) {
    let v = PROTOCOL_VERSION.to_string();
    let spec = AttributeSpecifier::new()
        .define(&"proto".try_into().expect("key"), &v.as_str().try_into().expect("value"));
    let verify = AttributeVerifier::new()
        .require(&"proto".try_into().expect("key"), &v.as_str().try_into().expect("value"));
    (spec.expect("attribute"), verify.expect("attribute"))
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
    let (spec, verify) = proto_attr();
    let builder = node
        .service_builder(&service_name(name)?)
        .publish_subscribe::<[u8]>()
        .enable_safe_overflow(overwrite)
        .subscriber_max_buffer_size(buffer)
        .history_size(history)
        .max_publishers(publishers)
        .max_subscribers(subscribers)
        .max_nodes(publishers.max(subscribers) + 2);
    match builder.open_or_create_with_attributes(&verify) {
        Ok(s) => Ok(s),
        Err(e) => {
            let _ = spec;
            Err(TransportError::Setup(format!(
                "iceoryx2 service {name}: {e:?} (another protocol version?)"
            )))
        }
    }
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

fn receive(s: &Sub) -> Result<Option<Vec<u8>>, TransportError> {
    match s.receive() {
        Ok(Some(sample)) => Ok(Some(sample.payload().to_vec())),
        Ok(None) => Ok(None),
        Err(e) => Err(TransportError::Closed(format!("iceoryx2 receive: {e:?}"))),
    }
}

/// Names of the nodes whose processes are alive; removes dead nodes' resources.
fn alive_nodes() -> Vec<String> {
    let mut alive = Vec::new();
    let _ = Node::<Svc>::list(Config::global_config(), |state| {
        match state {
            NodeState::Alive(view) => {
                if let Some(d) = view.details() {
                    alive.push(d.name().as_str().to_string());
                }
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

/// A worker message on the shared result channel, with its sender.
#[derive(Debug, Serialize, Deserialize)]
struct Envelope {
    from: String,
    msg: FromWorker,
}

struct RemoteWorker {
    name: String,
    tasks: Pub,
    _factory: Box<dyn std::any::Any + Send>,
}

/// The coordinator's end: implements [`Transport`].
pub struct IceoryxCoordinator {
    root: String,
    sweep: String,
    node: Option<Node<Svc>>,
    welcome: Option<(Pub, Box<dyn std::any::Any + Send>)>,
    welcome_bytes: Vec<u8>,
    results: Option<(Sub, Box<dyn std::any::Any + Send>)>,
    workers: HashMap<WorkerId, RemoteWorker>,
    by_name: HashMap<String, WorkerId>,
    next_id: u64,
    last_liveness: Instant,
    pending: std::collections::VecDeque<TransportEvent>,
}

impl IceoryxCoordinator {
    /// A coordinator under service root `root` (default `ceilfarm`).
    pub fn new(root: Option<&str>) -> Self {
        Self {
            root: root.unwrap_or(DEFAULT_ROOT).to_string(),
            sweep: String::new(),
            node: None,
            welcome: None,
            welcome_bytes: Vec::new(),
            results: None,
            workers: HashMap::new(),
            by_name: HashMap::new(),
            next_id: 0,
            last_liveness: Instant::now(),
            pending: Default::default(),
        }
    }

    fn on_message(&mut self, bytes: &[u8]) -> Result<(), TransportError> {
        let Envelope { from, msg } = match codec::decode::<Envelope>(bytes) {
            Ok(e) => e,
            Err(e) => {
                let reason = format!("message on the result channel: {e}");
                self.pending.push_back(TransportEvent::Rejected { reason });
                return Ok(());
            }
        };
        let worker = self.by_name.get(&from).copied();
        match (msg, worker) {
            (FromWorker::Hello { threads, .. }, _) => self.on_hello(&from, threads)?,
            (FromWorker::Result(result), Some(worker)) => {
                self.pending.push_back(TransportEvent::Result { worker, result })
            }
            (FromWorker::HandBack { id, .. }, Some(worker)) => {
                self.pending.push_back(TransportEvent::HandedBack { worker, task: id })
            }
            (FromWorker::Goodbye, Some(worker)) => {
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

    fn on_hello(&mut self, name: &str, threads: u32) -> Result<(), TransportError> {
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
        let id = WorkerId(self.next_id);
        self.next_id += 1;
        self.workers.insert(
            id,
            RemoteWorker { name: name.to_string(), tasks, _factory: Box::new(factory) },
        );
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
        let alive = alive_nodes();
        let gone: Vec<(WorkerId, String)> = self
            .workers
            .iter()
            .filter(|(_, w)| !alive.contains(&worker_node_name(&w.name)))
            .map(|(id, w)| (*id, w.name.clone()))
            .collect();
        for (id, name) in gone {
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
        let node = node(&coordinator_node_name(&self.sweep))?;
        let welcome_factory =
            channel(&node, &format!("{}/welcome", self.root), 1, 1, 1, true, MAX_WORKERS)?;
        let welcome = publisher(&welcome_factory)?;
        let bytes = codec::encode(&ToWorker::Welcome {
            study_hash: study_hash.to_string(),
            model: model.clone(),
        })
        .map_err(|e| TransportError::Setup(e.to_string()))?;
        send(&welcome, &bytes)?;
        self.welcome_bytes = bytes;
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
        self.welcome = Some((welcome, Box::new(welcome_factory)));
        self.results = Some((results, Box::new(results_factory)));
        self.node = Some(node);
        Ok(())
    }

    fn send(&mut self, worker: WorkerId, task: Task) -> Result<(), TransportError> {
        let w = self.workers.get(&worker).ok_or(TransportError::UnknownWorker(worker))?;
        let bytes = codec::encode(&ToWorker::Task(task))
            .map_err(|e| TransportError::Setup(e.to_string()))?;
        send(&w.tasks, &bytes)
    }

    fn next_event(&mut self, timeout: Duration) -> Result<Option<TransportEvent>, TransportError> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(ev) = self.pending.pop_front() {
                return Ok(Some(ev));
            }
            let msg = match &self.results {
                Some((sub, _)) => receive(sub)?,
                None => return Err(TransportError::Closed("not started".into())),
            };
            match msg {
                Some(bytes) => self.on_message(&bytes)?,
                None => {
                    self.check_liveness();
                    if !self.pending.is_empty() {
                        continue;
                    }
                    if Instant::now() >= deadline {
                        return Ok(None);
                    }
                    std::thread::sleep(Duration::from_micros(50));
                }
            }
        }
    }

    fn abandon(&mut self, worker: WorkerId, _reason: &str) {
        if let Some(w) = self.workers.remove(&worker) {
            self.by_name.remove(&w.name);
        }
    }

    fn shutdown(&mut self) {
        self.workers.clear();
        self.results = None;
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
    tasks: Option<(Sub, Box<dyn std::any::Any + Send>)>,
    results: Option<(Pub, Box<dyn std::any::Any + Send>)>,
    last_liveness: Instant,
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
            last_liveness: Instant::now(),
        })
    }

    fn publish(&self, msg: FromWorker) -> Result<(), TransportError> {
        let (p, _) =
            self.results.as_ref().ok_or_else(|| TransportError::Closed("not joined".into()))?;
        let env = Envelope { from: self.name.clone(), msg };
        send(p, &codec::encode(&env).map_err(|e| TransportError::Setup(e.to_string()))?)
    }
}

impl WorkerLink for IceoryxWorker {
    fn join(
        &mut self,
        name: &str,
        threads: u32,
        timeout: Duration,
    ) -> Result<Option<Joined>, TransportError> {
        self.name = name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' })
            .collect();
        if self.node.is_none() {
            self.node = Some(node(&worker_node_name(&self.name))?);
        }
        let node = self.node.as_ref().expect("just set");
        if self.welcome.is_none() {
            let f = channel(node, &format!("{}/welcome", self.root), 1, 1, 1, true, MAX_WORKERS)?;
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
        let Some(bytes) = latest else { return Ok(None) };
        let (study_hash, model) = match codec::decode::<ToWorker>(&bytes) {
            Ok(ToWorker::Welcome { study_hash, model }) => (study_hash, model),
            Ok(_) => return Ok(None),
            Err(e) => {
                return Err(TransportError::Setup(format!(
                    "coordinator speaks another protocol: {e}"
                )))
            }
        };
        let sweep = sweep_of(&study_hash);
        if !alive_nodes().contains(&coordinator_node_name(&sweep)) {
            // A welcome left by a coordinator that is gone.
            return Ok(None);
        }
        self.sweep = sweep;
        let tf = channel(
            node,
            &format!("{}/{}/task/{}", self.root, self.sweep, self.name),
            TASK_BUFFER,
            1,
            0,
            false,
            1,
        )?;
        let tasks = subscriber(&tf, TASK_BUFFER)?;
        self.tasks = Some((tasks, Box::new(tf)));
        let rf = channel(
            node,
            &format!("{}/{}/result", self.root, self.sweep),
            RESULT_BUFFER,
            MAX_WORKERS,
            0,
            false,
            1,
        )?;
        let results = publisher(&rf)?;
        self.results = Some((results, Box::new(rf)));
        self.threads = threads.max(1);
        Ok(Some(Joined { study_hash, model }))
    }

    fn serve(&mut self) -> Result<(), TransportError> {
        // The task subscriber exists: announce ourselves.
        self.publish(FromWorker::Hello {
            proto: PROTOCOL_VERSION,
            name: self.name.clone(),
            threads: self.threads,
        })
    }

    fn next(&mut self, timeout: Duration) -> Result<LinkEvent, TransportError> {
        let deadline = Instant::now() + timeout;
        loop {
            let (sub, _) =
                self.tasks.as_ref().ok_or_else(|| TransportError::Closed("not serving".into()))?;
            if let Some(bytes) = receive(sub)? {
                match codec::decode::<ToWorker>(&bytes) {
                    Ok(ToWorker::Task(task)) => {
                        let id = task.id;
                        return Ok(LinkEvent::Task(Ticket { task, route: Box::new(id) }));
                    }
                    Ok(_) => {}
                    Err(e) => tracing::warn!(error = %e, "dropped a malformed task message"),
                }
                continue;
            }
            if self.last_liveness.elapsed() > Duration::from_millis(200) {
                self.last_liveness = Instant::now();
                if !alive_nodes().contains(&coordinator_node_name(&self.sweep)) {
                    return Ok(LinkEvent::CoordinatorGone);
                }
            }
            if Instant::now() >= deadline {
                return Ok(LinkEvent::Idle);
            }
            std::thread::sleep(Duration::from_micros(50));
        }
    }

    fn reply(
        &mut self,
        _route: Box<dyn std::any::Any + Send>,
        result: TaskResult,
    ) -> Result<(), TransportError> {
        self.publish(FromWorker::Result(result))
    }

    fn hand_back(&mut self, route: Box<dyn std::any::Any + Send>, reason: &str) {
        if let Ok(id) = route.downcast::<TaskId>() {
            let _ = self.publish(FromWorker::HandBack { id: *id, reason: reason.to_string() });
        }
    }

    fn leave(&mut self) {
        let _ = self.publish(FromWorker::Goodbye);
        self.tasks = None;
        self.results = None;
    }
}
