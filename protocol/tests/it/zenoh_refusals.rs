//! zenoh: a worker of another protocol version or pinned to another study is
//! refused with a reason on both sides; garbage on the welcome and result
//! paths is rejected and the coordinator keeps serving (garbage in answer
//! to a task fails that attempt, never the worker).
#![cfg(feature = "zenoh")]

use protocol::codec;
use protocol::link::{JoinRequest, LinkEvent, WorkerLink};
use protocol::zenoh_transport::{open_session, Role, ZenohCoordinator, ZenohSecurity, ZenohWorker};
use protocol::{FromWorker, ModelSpec, Task, TaskId, Transport, TransportEvent};
use std::time::{Duration, Instant};
use zenoh::Wait;

const HASH: &str = "0123456789abcdef0123456789abcdef";

fn endpoint() -> String {
    let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    format!("tcp/127.0.0.1:{port}")
}

fn model() -> ModelSpec {
    ModelSpec {
        kind: "noop".into(),
        options_json: "{}".into(),
        param_names: vec!["x".into()],
        outputs: vec![],
    }
}

fn coordinator(ep: &str) -> ZenohCoordinator {
    let mut c = ZenohCoordinator::new(Some(ep), &ZenohSecurity::default()).unwrap();
    c.start(HASH, &model()).expect("coordinator starts");
    c
}

/// Events until one matches, for at most 10 s.
fn wait_for(c: &mut ZenohCoordinator, pred: impl Fn(&TransportEvent) -> bool) -> TransportEvent {
    let deadline = Instant::now() + Duration::from_secs(10);
    while Instant::now() < deadline {
        if let Some(ev) = c.next_event(Duration::from_millis(50)).expect("event") {
            if pred(&ev) {
                return ev;
            }
        }
    }
    panic!("no matching event within 10 s");
}

fn rejected(ev: &TransportEvent) -> Option<&str> {
    match ev {
        TransportEvent::Rejected { reason } => Some(reason),
        _ => None,
    }
}

fn hello(study: Option<&str>) -> Vec<u8> {
    hello_as("w", study)
}

fn hello_as(name: &str, study: Option<&str>) -> Vec<u8> {
    let msg = FromWorker::Hello {
        proto: protocol::PROTOCOL_VERSION,
        name: name.into(),
        threads: 1,
        study: study.map(Into::into),
    };
    codec::encode(&msg).unwrap()
}

/// Sends raw bytes as a Hello; returns the error replies' texts.
fn raw_hello(ep: &str, payload: Vec<u8>) -> Vec<String> {
    let s = open_session(Role::Connect, Some(ep), &ZenohSecurity::default()).unwrap();
    let replies = s
        .get("ceilfarm/*/welcome")
        .payload(payload)
        .timeout(Duration::from_secs(5))
        .wait()
        .unwrap();
    let mut errors = Vec::new();
    while let Ok(r) = replies.recv() {
        if let Err(e) = r.result() {
            errors.push(String::from_utf8_lossy(&e.payload().to_bytes()).into_owned());
        }
    }
    errors
}

#[test]
fn another_protocol_version_is_refused_on_both_sides() {
    let ep = endpoint();
    let mut c = coordinator(&ep);
    let mut bytes = hello(None);
    bytes[..2].copy_from_slice(&9999u16.to_le_bytes());
    let errors = raw_hello(&ep, bytes);
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(errors[0].contains("protocol version 9999 received"), "{}", errors[0]);
    let ev = wait_for(&mut c, |e| rejected(e).is_some());
    assert!(rejected(&ev).unwrap().contains("protocol version 9999"), "{ev:?}");
}

#[test]
fn a_worker_pinned_to_another_study_is_refused_on_both_sides() {
    let ep = endpoint();
    let mut c = coordinator(&ep);
    let mut w = ZenohWorker::connect(Some(&ep), &ZenohSecurity::default()).unwrap();
    let req = JoinRequest { name: "w1".into(), threads: 1, study: Some("fedcba".into()) };
    let err = join_until(&mut w, &req).expect_err("refused");
    assert!(err.to_string().contains("serves only study fedcba"), "{err}");
    let ev = wait_for(&mut c, |e| rejected(e).is_some());
    assert!(rejected(&ev).unwrap().contains("worker w1 refused"), "{ev:?}");
    // The right pin is welcome.
    let req = JoinRequest { study: Some("0123".into()), ..req };
    let joined = join_until(&mut w, &req).unwrap();
    assert_eq!(joined.study_hash, HASH);
}

fn join_until(
    w: &mut ZenohWorker,
    req: &JoinRequest,
) -> Result<protocol::link::Joined, protocol::TransportError> {
    for _ in 0..20 {
        if let Some(j) = w.join(req, Duration::from_millis(500))? {
            return Ok(j);
        }
    }
    panic!("no answer to join");
}

#[test]
fn garbage_is_rejected_and_the_coordinator_keeps_serving() {
    let ep = endpoint();
    let mut c = coordinator(&ep);
    for garbage in [vec![], vec![1u8], vec![1, 0, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff]] {
        let errors = raw_hello(&ep, garbage);
        assert_eq!(errors.len(), 1, "{errors:?}");
        wait_for(&mut c, |e| rejected(e).is_some());
    }
    // A hand-made worker (Hello, queryable, token) that answers its task
    // with garbage: the reply is rejected and that attempt fails; the
    // worker is not dropped.
    assert_eq!(raw_hello(&ep, hello_as("fake", None)), Vec::<String>::new());
    let s = open_session(Role::Connect, Some(&ep), &ZenohSecurity::default()).unwrap();
    let q = s.declare_queryable("ceilfarm/0123456789abcdef/task/fake").wait().unwrap();
    let _tok = s.liveliness().declare_token("ceilfarm/0123456789abcdef/alive/fake/1").wait();
    let joined = wait_for(&mut c, |e| matches!(e, TransportEvent::Joined { .. }));
    let TransportEvent::Joined { worker, .. } = joined else { unreachable!() };
    c.send(worker, Task { id: TaskId(7), params: vec![0.5] }).unwrap();
    let query = q.recv_timeout(Duration::from_secs(10)).unwrap().expect("task query");
    query.reply(query.key_expr().clone(), vec![1u8, 0, 42, 42]).wait().unwrap();
    drop(query);
    let ev = wait_for(&mut c, |e| rejected(e).is_some_and(|r| r.contains("dropped")));
    assert!(format!("{ev:?}").contains("task 7"), "{ev:?}");
    let ev = wait_for(&mut c, |e| {
        assert!(!matches!(e, TransportEvent::Left { .. }), "worker dropped: {e:?}");
        matches!(e, TransportEvent::Failed { .. })
    });
    assert!(matches!(ev, TransportEvent::Failed { worker: w, task: TaskId(7), .. } if w == worker));
    // A real worker still joins and serves.
    let mut w = ZenohWorker::connect(Some(&ep), &ZenohSecurity::default()).unwrap();
    let req = JoinRequest { name: "w2".into(), threads: 1, study: None };
    join_until(&mut w, &req).unwrap();
    w.serve().unwrap();
    let ev = wait_for(&mut c, |e| matches!(e, TransportEvent::Joined { .. }));
    let TransportEvent::Joined { worker, name, .. } = ev else { unreachable!() };
    assert!(name.starts_with("w2"), "{name}");
    c.send(worker, Task { id: TaskId(8), params: vec![0.5] }).unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        assert!(Instant::now() < deadline, "task not delivered");
        if let LinkEvent::Task(t) = w.next(Duration::from_millis(100)).unwrap() {
            assert_eq!(t.task.id, TaskId(8));
            break;
        }
    }
}
