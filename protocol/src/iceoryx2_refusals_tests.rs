//! iceoryx2: refusals of other protocol versions and other studies on both
//! sides, and garbage on the result channel, which leaves the coordinator
//! serving.

use super::*;

const HASH: &str = "00112233445566778899aabbccddeeff";

fn root(tag: &str) -> String {
    format!("cftest{}{tag}", std::process::id())
}

fn rejected_within(c: &mut IceoryxCoordinator, secs: u64) -> Option<String> {
    let deadline = Instant::now() + Duration::from_secs(secs);
    while Instant::now() < deadline {
        if let Some(TransportEvent::Rejected { reason }) =
            c.next_event(Duration::from_millis(20)).unwrap()
        {
            return Some(reason);
        }
    }
    None
}

/// A rogue worker's raw publisher on a sweep's result channel.
struct Rogue {
    publisher: Pub,
    _factory: Box<dyn std::any::Any>,
    _node: Node<Svc>,
}

impl Rogue {
    fn new(root: &str) -> Self {
        let n = node("cftest-rogue").unwrap();
        let name = format!("{root}/{}/result", sweep_of(HASH));
        let f = channel(&n, &name, RESULT_BUFFER, MAX_WORKERS, 0, false, 1).unwrap();
        Self { publisher: publisher(&f).unwrap(), _factory: Box::new(f), _node: n }
    }

    fn publish(&self, bytes: &[u8]) {
        send(&self.publisher, bytes).unwrap();
    }
}

/// Joins from another thread while `pump` runs here (the coordinator's side).
fn join_while(
    root: &str,
    req: JoinRequest,
    mut pump: impl FnMut(),
) -> Result<Option<Joined>, TransportError> {
    let root = root.to_string();
    let h = std::thread::spawn(move || {
        let mut w = IceoryxWorker::new(Some(&root)).unwrap();
        w.join(&req, Duration::from_secs(5))
    });
    while !h.is_finished() {
        pump();
        std::thread::sleep(Duration::from_millis(5));
    }
    h.join().unwrap()
}

#[test]
fn the_coordinator_rejects_other_versions_and_garbage_and_keeps_serving() {
    let root = root("a");
    let mut c = IceoryxCoordinator::new(Some(&root));
    c.start(HASH, &ModelSpec::noop()).unwrap();
    let hello = Envelope {
        from: "old".into(),
        node: 0,
        msg: FromWorker::Hello { proto: 9999, name: "old".into(), threads: 1, study: None },
    };
    let mut bytes = codec::encode(&hello).unwrap();
    bytes[..2].copy_from_slice(&9999u16.to_le_bytes());
    let rogue = Rogue::new(&root);
    rogue.publish(&bytes);
    let why = rejected_within(&mut c, 5).expect("rejected");
    assert!(why.contains("protocol version 9999 received"), "{why}");
    for garbage in [&[][..], &[1][..], &[1, 0, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff]] {
        rogue.publish(garbage);
        assert!(rejected_within(&mut c, 5).is_some(), "{garbage:?} not rejected");
    }
    // A real worker still joins and is seen.
    let r = root.clone();
    let h = std::thread::spawn(move || {
        let mut w = IceoryxWorker::new(Some(&r)).unwrap();
        let req = JoinRequest { name: "w1".into(), threads: 2, study: None };
        let joined = w.join(&req, Duration::from_secs(5)).unwrap().expect("joined");
        w.serve().unwrap();
        std::thread::sleep(Duration::from_secs(1));
        joined
    });
    let deadline = Instant::now() + Duration::from_secs(5);
    loop {
        assert!(Instant::now() < deadline, "worker never seen");
        if let Some(TransportEvent::Joined { slots, .. }) =
            c.next_event(Duration::from_millis(20)).unwrap()
        {
            assert_eq!(slots, 2);
            break;
        }
    }
    assert_eq!(h.join().unwrap().study_hash, HASH);
}

#[test]
fn a_worker_pinned_to_another_study_is_refused_on_both_sides() {
    let root = root("b");
    let mut c = IceoryxCoordinator::new(Some(&root));
    c.start(HASH, &ModelSpec::noop()).unwrap();
    let req = JoinRequest { name: "pinned".into(), threads: 1, study: Some("abcd".into()) };
    let mut seen = None;
    let err = join_while(&root, req, || {
        if let Ok(Some(TransportEvent::Rejected { reason })) = c.next_event(Duration::ZERO) {
            seen = Some(reason);
        }
    })
    .expect_err("refused");
    assert!(err.to_string().contains("serves only study abcd"), "{err}");
    let why = seen.or_else(|| rejected_within(&mut c, 5)).expect("coordinator logs it");
    assert!(why.contains("worker pinned refused"), "{why}");
}

#[test]
fn a_worker_refuses_a_coordinator_of_another_version_and_says_so() {
    let root = root("c");
    let sweep = sweep_of(HASH);
    let n = node(&coordinator_node_name(&sweep)).unwrap();
    let wf = channel(&n, &format!("{root}/welcome"), 1, 1, 1, true, MAX_WORKERS).unwrap();
    let welcome = publisher(&wf).unwrap();
    let mut msg = codec::encode(&ToWorker::Welcome {
        study_hash: HASH.into(),
        model: ModelSpec::noop(),
        key: crate::seal::SweepKey::random(),
    })
    .unwrap();
    msg[..2].copy_from_slice(&9999u16.to_le_bytes());
    send(&welcome, &frame_welcome(&sweep, n.id().value(), &msg)).unwrap();
    let rf =
        channel(&n, &format!("{root}/{sweep}/result"), RESULT_BUFFER, MAX_WORKERS, 0, false, 1)
            .unwrap();
    let results = subscriber(&rf, RESULT_BUFFER).unwrap();
    let req = JoinRequest { name: "new".into(), threads: 1, study: None };
    let mut announced = None;
    let err = join_while(&root, req, || {
        let _ = welcome.update_connections();
        if let Ok(Some(bytes)) = receive(&results) {
            announced = Some(bytes);
        }
    })
    .expect_err("refused");
    assert!(err.to_string().contains("another protocol"), "{err}");
    let bytes = announced.expect("the worker announced itself");
    let env: Envelope = codec::decode(&bytes).unwrap();
    assert!(matches!(env.msg, FromWorker::Hello { .. }), "{env:?}");
}

#[test]
fn welcome_frames_round_trip_and_reject_garbage() {
    let id = 0x0123_4567_89ab_cdef_fedc_ba98_7654_3210u128;
    let f = frame_welcome("abc123", id, &[1, 2, 3]);
    let want = Welcome { sweep: "abc123".into(), coordinator: id, message: &[1u8, 2, 3][..] };
    assert_eq!(split_welcome(&f), Some(want));
    assert_eq!(split_welcome(&[]), None);
    assert_eq!(split_welcome(&[10, b'a']), None);
    assert_eq!(split_welcome(&[2, b'/', b'x']), None);
    // The node id is missing or cut short.
    assert_eq!(split_welcome(&f[..7 + 15]), None);
}
