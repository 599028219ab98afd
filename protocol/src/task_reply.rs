//! What the replies to one task query mean, decided once per query: the
//! first valid reply counts; later, malformed or unexpected replies are
//! dropped as [`TransportEvent::Rejected`] and never touch the worker.
//! Used by the zenoh transport (one query may get several replies) and
//! testable without a network.

use crate::codec;
use crate::transport::{TransportEvent, WorkerId};
use crate::{FromWorker, TaskId};

/// Prefix of a reply error that gives a task back unrun.
pub const HAND_BACK: &str = "hand-back: ";

/// Longest part of an error reply's text kept as a reason, in bytes.
pub const MAX_REASON_BYTES: usize = 512;

/// One reply to a task query, as the transport received it.
#[derive(Debug, Clone, Copy)]
pub enum Reply<'a> {
    /// A reply sample: should be an encoded [`FromWorker::Result`] for the task.
    Answer(&'a [u8]),
    /// An error reply: a hand-back ([`HAND_BACK`]) or the worker's refusal.
    Error(&'a [u8]),
}

/// Decides what the replies to one task query (one lease) mean.
#[derive(Debug)]
pub struct ReplyGate {
    worker: WorkerId,
    task: TaskId,
    counted: bool,
    received: bool,
}

impl ReplyGate {
    /// A gate for the query that leased `task` to `worker`.
    pub fn new(worker: WorkerId, task: TaskId) -> Self {
        Self { worker, task, counted: false, received: false }
    }

    /// The task this query leased.
    pub fn task(&self) -> TaskId {
        self.task
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
        self.counted = !matches!(event, TransportEvent::Rejected { .. });
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
                let reason = format!("{worker} sent no valid reply to {task}");
                Some(TransportEvent::Failed { worker, task, reason })
            }
            (false, false) => {
                let reason = "task query closed without a reply (worker gone)".into();
                Some(TransportEvent::Left { worker, reason })
            }
        }
    }

    fn answer(&self, bytes: &[u8]) -> TransportEvent {
        let (worker, task) = (self.worker, self.task);
        match codec::decode::<FromWorker>(bytes) {
            Ok(FromWorker::Result(result)) if result.id == task => {
                TransportEvent::Result { worker, result }
            }
            Ok(FromWorker::Result(result)) => {
                rejected(format!("{worker} answered {task} with a result for {}", result.id))
            }
            Ok(_) => rejected(format!("{worker} answered {task} with something else")),
            Err(e) => rejected(format!("malformed reply from {worker} to {task}: {e}")),
        }
    }

    fn error(&self, bytes: &[u8]) -> TransportEvent {
        let (worker, task) = (self.worker, self.task);
        let text = reason_text(bytes);
        if text.starts_with(HAND_BACK) {
            return TransportEvent::HandedBack { worker, task };
        }
        TransportEvent::Failed { worker, task, reason: format!("{worker} refused {task}: {text}") }
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
    use crate::{Outcome, Outputs, TaskResult};

    const W: WorkerId = WorkerId(3);
    const T: TaskId = TaskId(7);

    fn result_bytes(id: TaskId, y: f64) -> Vec<u8> {
        let outputs = Outputs { scalars: vec![("y".into(), y)], histories: vec![] };
        let result =
            TaskResult { id, outcome: Outcome::Ok(outputs), wall_s: 0.1, host: "h".into() };
        codec::encode(&FromWorker::Result(result)).unwrap()
    }

    fn is_rejected(ev: &TransportEvent) -> bool {
        matches!(ev, TransportEvent::Rejected { .. })
    }

    #[test]
    fn the_first_valid_reply_counts_and_later_ones_are_rejected() {
        let mut gate = ReplyGate::new(W, T);
        let first = gate.on_reply(Reply::Answer(&result_bytes(T, 1.0)));
        assert!(matches!(first, TransportEvent::Result { worker: W, .. }));
        assert!(is_rejected(&gate.on_reply(Reply::Answer(&result_bytes(T, 12345.0)))));
        assert!(is_rejected(&gate.on_reply(Reply::Error(b"hand-back: x"))));
        assert_eq!(gate.on_close(), None);
    }

    #[test]
    fn malformed_or_foreign_answers_are_rejected_and_never_drop_the_worker() {
        let mut gate = ReplyGate::new(W, T);
        assert!(is_rejected(&gate.on_reply(Reply::Answer(b"\xff\xff\xff garbage"))));
        assert!(is_rejected(&gate.on_reply(Reply::Answer(&result_bytes(TaskId(8), 1.0)))));
        let ok = gate.on_reply(Reply::Answer(&result_bytes(T, 2.0)));
        assert!(matches!(ok, TransportEvent::Result { .. }));
    }

    #[test]
    fn an_error_reply_fails_the_attempt_not_the_worker() {
        let mut gate = ReplyGate::new(W, T);
        match gate.on_reply(Reply::Error(b"model refused")) {
            TransportEvent::Failed { worker, task, reason } => {
                assert_eq!((worker, task), (W, T));
                assert!(reason.contains("model refused"), "{reason}");
            }
            other => panic!("expected a failed attempt, got {other:?}"),
        }
    }

    #[test]
    fn hand_back_prefix_hands_the_task_back() {
        let mut gate = ReplyGate::new(W, T);
        let ev = gate.on_reply(Reply::Error(b"hand-back: worker stopping"));
        assert_eq!(ev, TransportEvent::HandedBack { worker: W, task: T });
    }

    #[test]
    fn closing_after_only_invalid_replies_fails_the_attempt() {
        let mut gate = ReplyGate::new(W, T);
        let _ = gate.on_reply(Reply::Answer(b"junk"));
        assert!(matches!(gate.on_close(), Some(TransportEvent::Failed { .. })));
        let silent = ReplyGate::new(W, T);
        assert!(matches!(silent.on_close(), Some(TransportEvent::Left { .. })));
    }

    #[test]
    fn a_huge_error_text_is_cut_to_the_bound() {
        let mut gate = ReplyGate::new(W, T);
        let big = vec![b'x'; 1 << 20];
        let TransportEvent::Failed { reason, .. } = gate.on_reply(Reply::Error(&big)) else {
            panic!("expected a failed attempt");
        };
        assert!(reason.len() < MAX_REASON_BYTES + 64);
    }
}
