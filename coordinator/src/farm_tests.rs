//! The farm's rules for what a worker's word counts for (issue 56), driven
//! by a scripted network that maps replies and liveliness tokens to events
//! through the same code the zenoh transport uses
//! ([`protocol::task_reply`], [`protocol::membership`]).

use super::*;
use protocol::membership::Members;
use protocol::seal::{Direction, SweepKey, SweepMac};
use protocol::task_reply::{Reply, ReplyGate};
use protocol::{FromWorker, Outputs, TransportError};
use std::sync::Arc;

/// One reply a scripted worker sends to a task query.
#[derive(Debug, Clone)]
enum Wire {
    /// A result with scalar `y`.
    Value(f64),
    /// A result with this wall time (y = 1).
    WallTime(f64),
    /// The model's own failure.
    ModelFailure(&'static str),
    /// An error reply with this text.
    Error(&'static str),
    /// A hand-back with this reason.
    HandBack(&'static str),
    /// Bytes that decode to nothing.
    Junk,
    /// This reply, sent on the same query when the worker gets its next task.
    Later(Box<Wire>),
}

type Behaviour = Box<dyn FnMut(&Task) -> Vec<Wire> + Send>;

/// A network of scripted workers (no threads, no sockets).
struct FakeNet {
    members: Members,
    scripts: Vec<(String, usize, Behaviour)>,
    tokens_without_hello: usize,
    events: VecDeque<TransportEvent>,
    gates: Vec<ReplyGate>,
    mac: Arc<SweepMac>,
    stale: HashMap<WorkerId, Vec<(usize, Wire)>>,
    sends: Vec<(WorkerId, TaskId)>,
    idle_polls: u32,
}

/// Most sends a test allows before calling the farm endless.
const MAX_SENDS: usize = 5000;
/// Consecutive polls without an event before calling the farm stalled.
const MAX_IDLE_POLLS: u32 = 50;

impl FakeNet {
    fn new() -> Self {
        FakeNet {
            members: Members::default(),
            scripts: Vec::new(),
            tokens_without_hello: 0,
            events: VecDeque::new(),
            gates: Vec::new(),
            mac: Arc::new(SweepMac::new(SweepKey::random(), "fake")),
            stale: HashMap::new(),
            sends: Vec::new(),
            idle_polls: 0,
        }
    }

    /// Adds a worker that says Hello and then shows its liveliness token.
    fn worker(
        mut self,
        name: &str,
        slots: usize,
        b: impl FnMut(&Task) -> Vec<Wire> + Send + 'static,
    ) -> Self {
        self.scripts.push((name.to_string(), slots, Box::new(b)));
        self
    }

    fn deliver(&mut self, gate: usize, wire: Wire, task: TaskId) {
        let (mac, seq) = (self.mac.clone(), self.gates[gate].seq());
        let seal = |msg: FromWorker| mac.seal(Direction::FromWorker, seq, &msg).unwrap();
        let bytes = |outcome| {
            let r = TaskResult { id: task, outcome, wall_s: 0.01, host: "h".into() };
            seal(FromWorker::Result(r))
        };
        let ok = |y| Outcome::Ok(Outputs { scalars: vec![("y".into(), y)], histories: vec![] });
        let event = match wire {
            Wire::Value(y) => self.gates[gate].on_reply(Reply::Answer(&bytes(ok(y)))),
            Wire::WallTime(wall_s) => {
                let r = TaskResult { id: task, outcome: ok(1.0), wall_s, host: "h".into() };
                let b = seal(FromWorker::Result(r));
                self.gates[gate].on_reply(Reply::Answer(&b))
            }
            Wire::ModelFailure(why) => {
                let b = bytes(Outcome::Failed { reason: why.into() });
                self.gates[gate].on_reply(Reply::Answer(&b))
            }
            Wire::Error(text) => self.gates[gate].on_reply(Reply::Error(text.as_bytes())),
            Wire::HandBack(why) => {
                let b = seal(FromWorker::HandBack { id: task, reason: why.into() });
                self.gates[gate].on_reply(Reply::Answer(&b))
            }
            Wire::Junk => self.gates[gate].on_reply(Reply::Answer(b"\x07junk")),
            Wire::Later(_) => unreachable!("held back by the caller"),
        };
        self.events.push_back(event);
    }
}

impl Transport for FakeNet {
    fn name(&self) -> &'static str {
        "fake"
    }

    fn start(&mut self, _hash: &str, _model: &ModelSpec) -> Result<(), TransportError> {
        for i in 0..self.tokens_without_hello {
            let ev = self.members.appeared(&format!("intruder{i}/1"));
            self.events.extend(ev);
        }
        for (name, slots, _) in &self.scripts {
            self.members.admit(name).unwrap();
            self.events.extend(self.members.appeared(&format!("{name}/{slots}")));
        }
        Ok(())
    }

    fn send(&mut self, worker: WorkerId, task: Task) -> Result<(), TransportError> {
        let name = self.members.name(worker).ok_or(TransportError::UnknownWorker(worker))?;
        let name = name.to_string();
        self.sends.push((worker, task.id));
        for (gate, wire) in self.stale.remove(&worker).unwrap_or_default() {
            let task = self.gates[gate].task();
            self.deliver(gate, wire, task);
        }
        let gate = self.gates.len();
        let seq = gate as u64 + 1;
        self.gates.push(ReplyGate::new(worker, task.id, seq, self.mac.clone()));
        let script = self.scripts.iter_mut().find(|(n, _, _)| *n == name).expect("scripted");
        let mut held = false;
        for wire in (script.2)(&task) {
            match wire {
                Wire::Later(w) => {
                    held = true;
                    self.stale.entry(worker).or_default().push((gate, *w));
                }
                w => self.deliver(gate, w, task.id),
            }
        }
        if !held {
            self.events.extend(self.gates[gate].on_close());
        }
        Ok(())
    }

    fn next_event(&mut self, _timeout: Duration) -> Result<Option<TransportEvent>, TransportError> {
        if self.sends.len() > MAX_SENDS {
            return Err(TransportError::Closed(format!("endless: {} sends", self.sends.len())));
        }
        let ev = self.events.pop_front();
        self.idle_polls = if ev.is_some() { 0 } else { self.idle_polls + 1 };
        if self.idle_polls > MAX_IDLE_POLLS {
            return Err(TransportError::Closed("stalled: no event".into()));
        }
        Ok(ev)
    }

    fn abandon(&mut self, worker: WorkerId, _reason: &str) {
        self.members.forget(worker);
    }

    fn shutdown(&mut self) {}
}

#[derive(Default)]
struct Kept(Vec<TaskResult>);

impl ResultSink for Kept {
    /// Refuses what the store's NOT NULL constraints refuse (a NaN wall time).
    fn accept(&mut self, results: &[TaskResult]) -> Result<(), String> {
        if let Some(r) = results.iter().find(|r| r.wall_s.is_nan()) {
            return Err(format!("NOT NULL constraint failed: wall_s of {}", r.id));
        }
        self.0.extend_from_slice(results);
        Ok(())
    }
}

impl Kept {
    fn y(&self, id: u64) -> Option<f64> {
        let r = self.0.iter().find(|r| r.id == TaskId(id))?;
        match &r.outcome {
            Outcome::Ok(out) => out.scalar("y"),
            Outcome::Failed { .. } => None,
        }
    }

    fn reason(&self, id: u64) -> Option<&str> {
        match &self.0.iter().find(|r| r.id == TaskId(id))?.outcome {
            Outcome::Failed { reason } => Some(reason),
            Outcome::Ok(_) => None,
        }
    }
}

fn tasks(n: u64) -> Vec<Task> {
    (0..n).map(|i| Task { id: TaskId(i), params: vec![i as f64] }).collect()
}

/// One task per worker at a time (so the order of sends is known), one retry.
fn settings() -> FarmSettings {
    FarmSettings {
        task_timeout: Duration::from_secs(60),
        window_per_slot: 1,
        max_retries: 1,
        ..FarmSettings::default()
    }
}

/// A farm over tasks `0..n` (queued when `queued`), driven event by event.
fn farm(settings: &FarmSettings, n: u64, queued: bool) -> Farm<'_> {
    Farm {
        settings,
        remaining: n as usize,
        pending: if queued { tasks(n).into() } else { VecDeque::new() },
        tasks: tasks(n).into_iter().map(|t| (t.id, t)).collect(),
        leases: HashMap::new(),
        workers: BTreeMap::new(),
        tries: HashMap::new(),
        losses: HashMap::new(),
        hand_backs: HandBacks::default(),
        summary: FarmSummary::default(),
        last_starved_warning: None,
    }
}

fn run(net: &mut FakeNet, n: u64) -> Result<(FarmSummary, Kept), FarmError> {
    let model = ModelSpec {
        kind: "fake".into(),
        options_json: "{}".into(),
        param_names: vec!["x".into()],
        outputs: vec![],
    };
    let mut kept = Kept::default();
    let summary =
        run_farm(net, "0123456789abcdef", &model, tasks(n), &settings(), &mut kept, &mut Silent)?;
    Ok((summary, kept))
}

fn honest(t: &Task) -> Vec<Wire> {
    vec![Wire::Value(t.params[0])]
}

// Rule 1: a result counts only from the lease holder, once.

#[test]
fn a_second_reply_to_one_query_never_counts_for_the_next_lease() {
    // The first attempt fails (the model's verdict), and a forged second
    // reply on the same query arrives once the task is leased to the same
    // worker again: it must not be taken as the new attempt's answer.
    let mut first = true;
    let mut net = FakeNet::new().worker("w", 1, move |t| {
        if t.id == TaskId(0) && std::mem::take(&mut first) {
            vec![Wire::ModelFailure("diverged"), Wire::Later(Box::new(Wire::Value(12345.0)))]
        } else {
            honest(t)
        }
    });
    let (summary, kept) = run(&mut net, 2).unwrap();
    assert_eq!(kept.y(0), Some(0.0));
    assert_eq!((summary.ok, summary.failed), (2, 0));
}

#[test]
fn a_malformed_reply_is_dropped_and_the_worker_keeps_working() {
    let mut net = FakeNet::new().worker("w", 1, |t| {
        if t.id == TaskId(1) {
            vec![Wire::Junk, Wire::Value(t.params[0])]
        } else {
            honest(t)
        }
    });
    let (summary, kept) = run(&mut net, 3).unwrap();
    assert_eq!((summary.ok, summary.failed), (3, 0));
    assert_eq!(kept.y(1), Some(1.0));
}

#[test]
fn a_result_with_a_nan_wall_time_fails_its_attempt_not_the_sweep() {
    let mut bad = true;
    let mut net = FakeNet::new().worker("w", 1, move |t| {
        if t.id == TaskId(2) && std::mem::take(&mut bad) {
            vec![Wire::WallTime(f64::NAN)]
        } else {
            honest(t)
        }
    });
    let (summary, kept) = run(&mut net, 4).unwrap();
    assert_eq!((summary.ok, summary.failed, summary.reissued), (4, 0, 1));
    assert_eq!(kept.y(2), Some(2.0));
}

#[test]
fn foreign_late_and_duplicate_results_are_dropped() {
    let settings = settings();
    let mut f = farm(&settings, 3, false);
    let (a, b) = (WorkerId(0), WorkerId(1));
    let mut done = Vec::new();
    for w in [a, b] {
        f.handle(
            TransportEvent::Joined { worker: w, name: "w".into(), slots: 1 },
            &mut Silent,
            &mut done,
        );
    }
    let deadline = Instant::now() + Duration::from_secs(60);
    f.leases.insert(TaskId(0), Lease { worker: a, deadline });
    f.workers.get_mut(&a).unwrap().held.push(TaskId(0));
    let result = |y: f64| TaskResult {
        id: TaskId(0),
        outcome: Outcome::Ok(Outputs { scalars: vec![("y".into(), y)], histories: vec![] }),
        wall_s: 0.0,
        host: "h".into(),
    };
    let ev = |worker, y| TransportEvent::Result { worker, result: result(y) };
    f.handle(ev(b, 12345.0), &mut Silent, &mut done); // foreign
    f.handle(
        TransportEvent::Failed { worker: b, task: TaskId(0), reason: "x".into() },
        &mut Silent,
        &mut done,
    );
    f.handle(TransportEvent::HandedBack { worker: b, task: TaskId(0) }, &mut Silent, &mut done);
    assert!(f.holds(a, TaskId(0)), "the lease holder keeps its lease");
    f.handle(ev(a, 1.0), &mut Silent, &mut done);
    f.handle(ev(a, 2.0), &mut Silent, &mut done); // duplicate, task done
    f.handle(ev(b, 3.0), &mut Silent, &mut done); // late
    assert_eq!(done, vec![result(1.0)]);
    assert_eq!(f.summary.duplicates, 5);
}

// Rule 2: an error reply (which carries no MAC, so never counts) fails
// that attempt when nothing valid came, never the worker.

#[test]
fn one_error_reply_fails_one_attempt_and_the_sweep_completes() {
    let mut once = true;
    let mut net = FakeNet::new().worker("w", 1, move |t| {
        if t.id == TaskId(5) && std::mem::take(&mut once) {
            vec![Wire::Error("model refused")]
        } else {
            honest(t)
        }
    });
    let (summary, kept) = run(&mut net, 13).unwrap();
    assert_eq!((summary.ok, summary.failed, summary.reissued), (13, 0, 1));
    assert_eq!(kept.y(5), Some(5.0));
}

#[test]
fn error_replies_past_the_retry_limit_record_the_failure_with_its_reason() {
    let mut net = FakeNet::new().worker("w", 1, |t| {
        if t.id == TaskId(1) {
            vec![Wire::Error("no licence")]
        } else {
            honest(t)
        }
    });
    let (summary, kept) = run(&mut net, 3).unwrap();
    assert_eq!((summary.ok, summary.failed), (2, 1));
    assert!(kept.reason(1).unwrap().contains("no licence"), "{:?}", kept.reason(1));
    assert_eq!(net.sends.iter().filter(|(_, t)| *t == TaskId(1)).count(), 2);
}

// Rule 3: hand-backs are bounded.

#[test]
fn a_worker_handing_everything_back_costs_each_task_a_bounded_number_of_sends() {
    let mut net = FakeNet::new().worker("w", 1, |_| vec![Wire::HandBack("stopping")]);
    let (summary, kept) = run(&mut net, 5).unwrap();
    assert_eq!((summary.ok, summary.failed), (0, 5));
    assert!(kept.reason(0).unwrap().contains("handed"), "{:?}", kept.reason(0));
    let bound = (crate::farm_hand_backs::MAX_FREE_HAND_BACKS_PER_TASK + 1) * 2;
    assert!(net.sends.len() <= 5 * bound, "{} sends", net.sends.len());
}

#[test]
fn an_honest_hand_back_costs_no_try() {
    let mut once = true;
    let mut net = FakeNet::new().worker("w", 1, move |t| {
        if std::mem::take(&mut once) {
            vec![Wire::HandBack("worker stopping")]
        } else {
            honest(t)
        }
    });
    let (summary, _) = run(&mut net, 2).unwrap();
    assert_eq!((summary.ok, summary.failed, summary.reissued), (2, 0, 1));
}

// Rule 4: liveliness alone cannot fail tasks.

#[test]
fn fake_liveliness_tokens_never_get_or_lose_a_task() {
    let mut net = FakeNet::new().worker("real", 1, honest);
    net.tokens_without_hello = 50;
    let (summary, _) = run(&mut net, 40).unwrap();
    assert_eq!((summary.ok, summary.failed, summary.reissued), (40, 0, 0));
    assert_eq!(net.sends.len(), 40);
}

#[test]
fn a_worker_without_leases_leaving_loses_nothing() {
    let settings = settings();
    let mut f = farm(&settings, 2, true);
    let mut done = Vec::new();
    let joined = TransportEvent::Joined { worker: WorkerId(4), name: "idle".into(), slots: 1 };
    f.handle(joined, &mut Silent, &mut done);
    for w in [WorkerId(4), WorkerId(9), WorkerId(4)] {
        let left = TransportEvent::Left { worker: w, reason: "liveliness lost".into() };
        f.handle(left, &mut Silent, &mut done);
    }
    assert!(f.losses.is_empty());
    assert_eq!((f.pending.len(), f.summary.reissued), (2, 0));
}

#[test]
fn a_worker_lost_with_leases_re_queues_only_its_own() {
    let mut net = FakeNet::new().worker("a", 1, honest).worker("b", 1, |t| {
        if t.id == TaskId(1) {
            vec![]
        } else {
            honest(t)
        }
    });
    let (summary, kept) = run(&mut net, 4).unwrap();
    assert_eq!((summary.ok, summary.failed, summary.reissued), (4, 0, 1));
    assert_eq!(kept.y(1), Some(1.0));
    let sends_of = |id| net.sends.iter().filter(|(_, t)| *t == TaskId(id)).count();
    assert_eq!((sends_of(0), sends_of(1)), (1, 2), "{:?}", net.sends);
}
