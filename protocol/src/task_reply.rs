//! What the replies to one task query mean, decided once per query: the
//! first valid reply counts; later, malformed, unsealed or unexpected
//! replies are dropped as [`TransportEvent::Rejected`] and never touch the
//! worker. A valid reply is sealed under the sweep's key for this query's
//! lease ([`crate::seal`]): a result or a hand-back of this task. Error
//! replies carry no MAC and never count. Used by the zenoh transport (one
//! query may get several replies) and testable without a network.

use crate::seal::{Direction, SweepMac};
use crate::transport::{TransportEvent, WorkerId};
use crate::{FromWorker, TaskId};
use std::sync::Arc;

/// Longest part of an error reply's text kept as a reason, in bytes.
pub const MAX_REASON_BYTES: usize = 512;

/// One reply to a task query, as the transport received it.
#[derive(Debug, Clone, Copy)]
pub enum Reply<'a> {
    /// A reply sample: should be a sealed [`FromWorker::Result`] or
    /// [`FromWorker::HandBack`] for the task.
    Answer(&'a [u8]),
    /// An error reply: never counts (it carries no MAC).
    Error(&'a [u8]),
}

/// Decides what the replies to one task query (one lease) mean.
#[derive(Debug)]
pub struct ReplyGate {
    worker: WorkerId,
    task: TaskId,
    seq: u64,
    mac: Arc<SweepMac>,
    counted: bool,
    received: bool,
    /// Why the last reply was dropped (named when the attempt fails).
    last_dropped: Option<String>,
}

impl ReplyGate {
    /// A gate for the query that leased `task` to `worker` as lease `seq`
    /// of the sweep sealed by `mac`.
    pub fn new(worker: WorkerId, task: TaskId, seq: u64, mac: Arc<SweepMac>) -> Self {
        Self { worker, task, seq, mac, counted: false, received: false, last_dropped: None }
    }

    /// The task this query leased.
    pub fn task(&self) -> TaskId {
        self.task
    }

    /// The lease's sequence number a valid reply is sealed for.
    pub fn seq(&self) -> u64 {
        self.seq
    }

    /// The event for one reply: the first valid reply's meaning, a
    /// [`TransportEvent::Rejected`] for anything else.
    pub fn on_reply(&mut self, reply: Reply<'_>) -> TransportEvent {
        self.received = true;
        if self.counted {
            let (worker, task) = (self.worker, self.task);
            return rejected(format!("{worker}: another reply to {task} dropped (one counts)"));
        }
        let event = match reply {
            Reply::Answer(bytes) => self.answer(bytes),
            Reply::Error(bytes) => self.error(bytes),
        };
        match &event {
            TransportEvent::Rejected { reason } => self.last_dropped = Some(reason.clone()),
            _ => self.counted = true,
        }
        event
    }

    /// The event when the query closes: none once a reply counted; the
    /// attempt's failure when only invalid replies came; the worker gone
    /// when nothing came at all.
    pub fn on_close(&self) -> Option<TransportEvent> {
        let (worker, task) = (self.worker, self.task);
        match (self.counted, self.received) {
            (true, _) => None,
            (false, true) => {
                let last = self.last_dropped.as_deref().unwrap_or("");
                let reason = format!("{worker} sent no valid reply to {task} (last: {last})");
                Some(TransportEvent::Failed { worker, task, reason })
            }
            (false, false) => {
                let reason = "task query closed without a reply (worker gone)".into();
                Some(TransportEvent::Left { worker, reason })
            }
        }
    }

    fn answer(&self, bytes: &[u8]) -> TransportEvent {
        let (worker, task, lease) = (self.worker, self.task, self.seq);
        match self.mac.open::<FromWorker>(Direction::FromWorker, bytes) {
            Ok((seq, _)) if seq != lease => rejected(format!(
                "{worker}: a reply sealed for lease {seq} answered lease {lease} of {task} \
                 (replayed or misrouted); dropped"
            )),
            Ok((_, FromWorker::Result(result))) if result.id == task => {
                TransportEvent::Result { worker, result }
            }
            Ok((_, FromWorker::Result(result))) => {
                rejected(format!("{worker} answered {task} with a result for {}", result.id))
            }
            Ok((_, FromWorker::HandBack { id, .. })) if id == task => {
                TransportEvent::HandedBack { worker, task }
            }
            Ok(_) => rejected(format!("{worker} answered {task} with something else")),
            Err(e) => rejected(format!("reply from {worker} to {task} dropped: {e}")),
        }
    }

    fn error(&self, bytes: &[u8]) -> TransportEvent {
        let (worker, task) = (self.worker, self.task);
        let text = reason_text(bytes);
        rejected(format!("{worker}: an error reply to {task} carries no MAC, dropped: {text}"))
    }
}

fn rejected(reason: String) -> TransportEvent {
    TransportEvent::Rejected { reason }
}

/// An error reply's text, lossy UTF-8, at most [`MAX_REASON_BYTES`] of it.
fn reason_text(bytes: &[u8]) -> String {
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(MAX_REASON_BYTES)]);
    text.into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seal::{SweepKey, KEY_BYTES};
    use crate::{codec, Outcome, Outputs, TaskResult};

    const W: WorkerId = WorkerId(3);
    const T: TaskId = TaskId(7);
    const SEQ: u64 = 11;

    fn mac() -> Arc<SweepMac> {
        Arc::new(SweepMac::new(SweepKey::from_bytes([5; KEY_BYTES]), "sweep"))
    }

    fn gate() -> ReplyGate {
        ReplyGate::new(W, T, SEQ, mac())
    }

    fn result(id: TaskId, y: f64) -> FromWorker {
        let outputs = Outputs { scalars: vec![("y".into(), y)], histories: vec![] };
        FromWorker::Result(TaskResult {
            id,
            outcome: Outcome::Ok(outputs),
            wall_s: 0.1,
            host: "h".into(),
        })
    }

    fn sealed(seq: u64, msg: &FromWorker) -> Vec<u8> {
        mac().seal(Direction::FromWorker, seq, msg).unwrap()
    }

    fn is_rejected(ev: &TransportEvent) -> bool {
        matches!(ev, TransportEvent::Rejected { .. })
    }

    #[test]
    fn the_first_valid_reply_counts_and_later_ones_are_rejected() {
        let mut gate = gate();
        let first = gate.on_reply(Reply::Answer(&sealed(SEQ, &result(T, 1.0))));
        assert!(matches!(first, TransportEvent::Result { worker: W, .. }));
        assert!(is_rejected(&gate.on_reply(Reply::Answer(&sealed(SEQ, &result(T, 12345.0))))));
        let back = FromWorker::HandBack { id: T, reason: "x".into() };
        assert!(is_rejected(&gate.on_reply(Reply::Answer(&sealed(SEQ, &back)))));
        assert_eq!(gate.on_close(), None);
    }

    #[test]
    fn malformed_unsealed_or_foreign_answers_are_rejected_and_never_drop_the_worker() {
        let mut gate = gate();
        assert!(is_rejected(&gate.on_reply(Reply::Answer(b"\xff\xff\xff garbage"))));
        let plain = codec::encode(&result(T, 12345.0)).unwrap();
        assert!(is_rejected(&gate.on_reply(Reply::Answer(&plain))));
        assert!(is_rejected(&gate.on_reply(Reply::Answer(&sealed(SEQ, &result(TaskId(8), 1.0))))));
        let ok = gate.on_reply(Reply::Answer(&sealed(SEQ, &result(T, 2.0))));
        assert!(matches!(ok, TransportEvent::Result { .. }));
    }

    /// A reply sealed for another lease (an earlier attempt, another task)
    /// is a replay: refused.
    #[test]
    fn a_reply_sealed_for_another_lease_is_refused() {
        let mut gate = gate();
        let TransportEvent::Rejected { reason } =
            gate.on_reply(Reply::Answer(&sealed(SEQ - 1, &result(T, 1.0))))
        else {
            panic!("a replay counted");
        };
        assert!(reason.contains("replayed"), "{reason}");
    }

    #[test]
    fn an_error_reply_never_counts() {
        let mut gate = gate();
        let TransportEvent::Rejected { reason } = gate.on_reply(Reply::Error(b"model refused"))
        else {
            panic!("an error reply counted");
        };
        assert!(reason.contains("model refused") && reason.contains("no MAC"), "{reason}");
        assert!(is_rejected(&gate.on_reply(Reply::Error(b"hand-back: worker stopping"))));
    }

    #[test]
    fn a_sealed_hand_back_hands_the_task_back() {
        let mut gate = gate();
        let back = FromWorker::HandBack { id: T, reason: "worker stopping".into() };
        let ev = gate.on_reply(Reply::Answer(&sealed(SEQ, &back)));
        assert_eq!(ev, TransportEvent::HandedBack { worker: W, task: T });
    }

    #[test]
    fn closing_after_only_invalid_replies_fails_the_attempt() {
        let mut gate = gate();
        let _ = gate.on_reply(Reply::Answer(b"junk"));
        assert!(matches!(gate.on_close(), Some(TransportEvent::Failed { .. })));
        let silent = ReplyGate::new(W, T, SEQ, mac());
        assert!(matches!(silent.on_close(), Some(TransportEvent::Left { .. })));
    }

    #[test]
    fn a_huge_error_text_is_cut_to_the_bound() {
        let mut gate = gate();
        let big = vec![b'x'; 1 << 20];
        let TransportEvent::Rejected { reason } = gate.on_reply(Reply::Error(&big)) else {
            panic!("expected a rejection");
        };
        assert!(reason.len() < MAX_REASON_BYTES + 128);
    }
}
