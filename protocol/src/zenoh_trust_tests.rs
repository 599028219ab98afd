//! zenoh: a liveliness token alone makes no worker; an error reply never
//! counts (it carries no MAC), and the attempt it spoilt fails without
//! dropping the worker (issue 56).

use super::*;
use crate::{Outcome, Outputs, TaskId};
use std::time::Instant;

const HASH: &str = "00112233445566778899aabbccddeeff";

fn endpoint(k: u16) -> String {
    format!("tcp/127.0.0.1:{}", 40000 + (std::process::id() % 10000) as u16 + k)
}

/// The first event within 10 s that `want` accepts; panics on a Joined or
/// Left it does not accept (nobody else should join or leave here).
fn expect(c: &mut ZenohCoordinator, want: impl Fn(&TransportEvent) -> bool) -> TransportEvent {
    let until = Instant::now() + Duration::from_secs(10);
    while Instant::now() < until {
        match c.next_event(Duration::from_millis(100)).unwrap() {
            Some(ev) if want(&ev) => return ev,
            Some(ev @ (TransportEvent::Joined { .. } | TransportEvent::Left { .. })) => {
                panic!("unexpected {ev:?}")
            }
            _ => {}
        }
    }
    panic!("no expected event within 10 s")
}

/// A worker joined and serving; retries until the coordinator answers.
fn joined_worker(ep: &str, name: &str) -> ZenohWorker {
    let mut w = ZenohWorker::connect(Some(ep), &ZenohSecurity::default()).unwrap();
    let request = JoinRequest { name: name.into(), threads: 1, study: None };
    let until = Instant::now() + Duration::from_secs(10);
    while w.join(&request, Duration::from_millis(500)).unwrap().is_none() {
        assert!(Instant::now() < until, "never welcomed");
    }
    w.serve().unwrap();
    w
}

/// A coordinator started at `ep` with one worker, `w`, joined: both, and
/// the worker's id.
fn started_with_worker(ep: &str) -> (ZenohCoordinator, ZenohWorker, WorkerId) {
    let mut c = ZenohCoordinator::new(Some(ep), &ZenohSecurity::default()).unwrap();
    c.start(HASH, &ModelSpec::noop()).unwrap();
    let w = joined_worker(ep, "w");
    match expect(&mut c, |ev| matches!(ev, TransportEvent::Joined { .. })) {
        TransportEvent::Joined { worker, .. } => (c, w, worker),
        _ => unreachable!(),
    }
}

fn next_ticket(w: &mut ZenohWorker) -> Ticket {
    for _ in 0..100 {
        if let LinkEvent::Task(t) = w.next(Duration::from_millis(100)).unwrap() {
            return t;
        }
    }
    panic!("no task within 10 s")
}

#[test]
fn a_liveliness_token_without_a_hello_makes_no_worker() {
    let ep = endpoint(1);
    let mut c = ZenohCoordinator::new(Some(&ep), &ZenohSecurity::default()).unwrap();
    c.start(HASH, &ModelSpec::noop()).unwrap();
    let intruder = open_session(Role::Connect, Some(&ep), &ZenohSecurity::default()).unwrap();
    let key = format!("{}/alive/intruder/1", sweep_prefix(HASH));
    let _token = intruder.liveliness().declare_token(key).wait().unwrap();
    let rejected = |ev: &TransportEvent| matches!(ev, TransportEvent::Rejected { reason } if reason.contains("without a Hello"));
    expect(&mut c, rejected);
    // A worker that says Hello first joins as before.
    let _w = joined_worker(&ep, "honest");
    expect(&mut c, |ev| matches!(ev, TransportEvent::Joined { name, .. } if name == "honest"));
    c.shutdown();
}

#[test]
fn an_error_reply_fails_the_attempt_and_the_worker_stays() {
    let ep = endpoint(2);
    let (mut c, mut w, worker) = started_with_worker(&ep);
    c.send(worker, Task { id: TaskId(1), params: vec![1.0] }).unwrap();
    let lease = next_ticket(&mut w).route.downcast::<Lease>().unwrap();
    lease.query.reply_err("model refused").wait().unwrap();
    drop(lease);
    let dropped = |ev: &TransportEvent| matches!(ev, TransportEvent::Rejected { reason } if reason.contains("model refused") && reason.contains("no MAC"));
    expect(&mut c, dropped);
    let failed = expect(&mut c, |ev| matches!(ev, TransportEvent::Failed { .. }));
    assert!(matches!(failed, TransportEvent::Failed { task: TaskId(1), .. }));
    // The same worker still gets and answers tasks.
    c.send(worker, Task { id: TaskId(2), params: vec![2.0] }).unwrap();
    let ticket = next_ticket(&mut w);
    let outcome = Outcome::Ok(Outputs::default());
    let result = TaskResult { id: TaskId(2), outcome, wall_s: 0.0, host: "h".into() };
    w.reply(ticket.route, result).unwrap();
    expect(&mut c, |ev| matches!(ev, TransportEvent::Result { worker: by, .. } if *by == worker));
    c.shutdown();
}

#[test]
fn one_reply_per_task_query_counts_and_a_hand_back_is_reported() {
    let ep = endpoint(3);
    let (mut c, mut w, worker) = started_with_worker(&ep);
    c.send(worker, Task { id: TaskId(3), params: vec![3.0] }).unwrap();
    let lease = next_ticket(&mut w).route.downcast::<Lease>().unwrap();
    let mac = w.mac.clone().unwrap();
    for wall_s in [1.0, 12345.0] {
        let outcome = Outcome::Ok(Outputs::default());
        let result = TaskResult { id: TaskId(3), outcome, wall_s, host: "h".into() };
        let bytes = mac.seal(Direction::FromWorker, lease.seq, &FromWorker::Result(result));
        lease.query.reply(lease.query.key_expr().clone(), bytes.unwrap()).wait().unwrap();
    }
    drop(lease);
    let first = expect(&mut c, |ev| matches!(ev, TransportEvent::Result { .. }));
    assert!(matches!(first, TransportEvent::Result { result, .. } if result.wall_s == 1.0));
    expect(
        &mut c,
        |ev| matches!(ev, TransportEvent::Rejected { reason } if reason.contains("another reply")),
    );
    c.send(worker, Task { id: TaskId(4), params: vec![4.0] }).unwrap();
    let route = next_ticket(&mut w).route;
    w.hand_back(route, "worker stopping");
    let back = expect(&mut c, |ev| matches!(ev, TransportEvent::HandedBack { .. }));
    assert_eq!(back, TransportEvent::HandedBack { worker, task: TaskId(4) });
    c.shutdown();
}
