//! iceoryx2: joining is bound to the coordinator that published the welcome,
//! and a wait shorter than a microsecond returns.

use super::*;

const HASH: &str = "ffeeddccbbaa99887766554433221100";

fn root(tag: &str) -> String {
    format!("cftest{}j{tag}", std::process::id())
}

fn request(name: &str) -> JoinRequest {
    JoinRequest { name: name.into(), threads: 1, study: None }
}

/// Runs `f` on another thread; `None` if it has not returned within `limit`.
fn within<T: Send + 'static>(limit: Duration, f: impl FnOnce() -> T + Send + 'static) -> Option<T> {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(limit).ok()
}

#[test]
fn a_nap_shorter_than_a_microsecond_returns() {
    let name = format!("{}/ready", root("nap"));
    let done = within(Duration::from_secs(10), move || {
        let n = node("cftest-nap").unwrap();
        let (l, _keep) = listener(&n, &name, 1).unwrap();
        for ns in [0, 1, 500, 999] {
            nap(&l, Duration::from_nanos(ns));
        }
    });
    assert!(done.is_some(), "a sub-microsecond nap waited for a notification that never came");
}

#[test]
fn a_welcome_of_a_coordinator_that_is_gone_is_not_joined() {
    let root = root("stale");
    let sweep = sweep_of(HASH);
    // A welcome that names a node id no live process holds, as a killed
    // coordinator's last welcome does, while a live node has its name.
    let n = node(&coordinator_node_name(&sweep)).unwrap();
    let wf = channel(&n, &format!("{root}/welcome"), 1, 1, 1, true, MAX_WORKERS).unwrap();
    let welcome = publisher(&wf).unwrap();
    let msg = codec::encode(&ToWorker::Welcome {
        study_hash: HASH.into(),
        model: ModelSpec::noop(),
        key: crate::seal::SweepKey::random(),
    })
    .unwrap();
    let dead = n.id().value() ^ 1;
    send(&welcome, &frame_welcome(&sweep, dead, &msg)).unwrap();
    let mut w = IceoryxWorker::new(Some(&root)).unwrap();
    assert!(w.join(&request("w"), Duration::from_secs(2)).unwrap().is_none());
    // The same welcome from the live node is joined.
    send(&welcome, &frame_welcome(&sweep, n.id().value(), &msg)).unwrap();
    let joined = w.join(&request("w"), Duration::from_secs(2)).unwrap().expect("joined");
    assert_eq!(joined.study_hash, HASH);
}
