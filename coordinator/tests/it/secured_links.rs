//! A secured sweep's TLS links stay up while results and tasks cross them
//! both ways at once: two worker processes with `farm certs`' TLS, mutual
//! authentication and access control on loopback answer 800 tasks with a
//! 1 MiB history each, two tasks in flight per worker, so the coordinator
//! reads one reply while it writes the next query on the same link.
//!
//! zenoh 1.10.2's TLS link let the reading and the writing task use the
//! one rustls connection at once (eclipse-zenoh/zenoh#2557): a write failed
//! with "handshake not complete", the link closed, its queries closed
//! unanswered and the farm re-issued their tasks (lost three times: failed),
//! and at times a worker hung or a process crashed. Against that crate
//! this test failed: of 12 runs, 9 at this assertion (workers left) and 3
//! ended without a test summary. Against the copy in `vendor/zenoh-link-tls`
//! no link drops, so no worker leaves and no task is re-issued.

use coordinator::farm::{run_farm, FarmObserver, FarmSettings, FarmSummary, ResultSink};
use coordinator::farm_certs::{write_lab, LabSettings};
use coordinator::study::TransportKind;
use coordinator::transports::{coordinator_transport_secured, ZenohSecurity};
use protocol::{ModelSpec, Task, TaskId, TaskResult, WorkerId};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

const TASKS: usize = 800;
/// f64 samples of each result's history: 1 MiB.
const SAMPLES: usize = 131_072;

struct Null;
impl ResultSink for Null {
    fn accept(&mut self, _: &[TaskResult]) -> Result<(), String> {
        Ok(())
    }
}

/// Every worker that left, with the farm's reason.
#[derive(Default)]
struct Leaves(Vec<String>);
impl FarmObserver for Leaves {
    fn membership(&mut self, joined: bool, worker: WorkerId, detail: &str) {
        if !joined {
            self.0.push(format!("{worker}: {detail}"));
        }
    }
}

struct Kill(Child);
impl Drop for Kill {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn worker(certs: &Path, k: usize, endpoint: &str, log: &Path) -> Kill {
    let config = certs.join(format!("worker-{k}.json5"));
    Kill(
        Command::new(env!("CARGO_BIN_EXE_ceilfarm"))
            .args(["worker", "--transport", "zenoh", "--connect", endpoint])
            .arg("--zenoh-config")
            .arg(config)
            .arg("-v")
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(log).unwrap())
            .spawn()
            .unwrap(),
    )
}

fn tail(path: &PathBuf) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(10)..].join("\n")
}

#[test]
fn tls_links_stay_up_under_large_results_both_ways() {
    let dir = tempfile::tempdir().unwrap();
    let certs = dir.path().join("certs");
    let lab = LabSettings {
        workers: 2,
        hosts: vec!["127.0.0.1".into(), "localhost".into()],
        port: 7447,
        validity_days: 1,
    };
    write_lab(&certs, &lab).unwrap();
    let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    let endpoint = format!("tls/127.0.0.1:{port}");
    let security = ZenohSecurity { config: Some(certs.join("coordinator.json5")), insecure: false };
    let mut transport =
        coordinator_transport_secured(TransportKind::Zenoh, 2, Some(&endpoint), &security).unwrap();
    let logs: Vec<PathBuf> = (1..=2).map(|k| dir.path().join(format!("worker-{k}.log"))).collect();
    let _workers: Vec<Kill> = (1..=2).map(|k| worker(&certs, k, &endpoint, &logs[k - 1])).collect();

    let model = ModelSpec {
        kind: "noop".into(),
        options_json: format!("{{\"history_samples\": {SAMPLES}}}"),
        param_names: vec!["a".into()],
        outputs: vec![],
    };
    let tasks: Vec<Task> =
        (0..TASKS).map(|i| Task { id: TaskId(i as u64), params: vec![i as f64] }).collect();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let settings = FarmSettings { window_per_slot: 2, ..FarmSettings::default() };
        let mut leaves = Leaves::default();
        let hash = format!("{:032x}", u128::from(port) << 64 | 0x5ec);
        let s =
            run_farm(transport.as_mut(), &hash, &model, tasks, &settings, &mut Null, &mut leaves);
        let _ = tx.send((s.map_err(|e| e.to_string()), leaves.0));
    });
    // A link that drops can leave a worker hung: fail then, do not wait for ever.
    let Ok((summary, leaves)) = rx.recv_timeout(Duration::from_secs(300)) else {
        panic!(
            "the sweep did not finish\nworker 1:\n{}\nworker 2:\n{}",
            tail(&logs[0]),
            tail(&logs[1])
        );
    };
    let summary = summary.unwrap();
    let want = FarmSummary { ok: TASKS, failed: 0, reissued: 0, duplicates: 0 };
    assert!(leaves.is_empty(), "workers left (links dropped): {leaves:?}; {summary:?}");
    assert_eq!(summary, want);
}
