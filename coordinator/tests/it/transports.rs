//! The same sweep over separate worker processes, on iceoryx2 shared memory
//! and on zenoh (peer coordinator on loopback, multicast scouting off),
//! exports exactly what the in-process farm exports; and it survives a
//! worker killed with SIGKILL and a coordinator killed and resumed.
#![cfg(any(feature = "zenoh", feature = "iceoryx2"))]

use crate::common::*;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicU16, Ordering};
use std::time::{Duration, Instant};

/// Unique per test: zenoh port or iceoryx2 service root.
fn endpoint(transport: &str) -> String {
    static NEXT: AtomicU16 = AtomicU16::new(0);
    let k = NEXT.fetch_add(1, Ordering::Relaxed);
    let pid = std::process::id();
    match transport {
        "zenoh" => format!("tcp/127.0.0.1:{}", 20000 + (pid % 20000) as u16 + 10 * k),
        _ => format!("cftest{pid}x{k}"),
    }
}

struct Workers(Vec<Child>);

impl Workers {
    fn start(transport: &str, endpoint: &str, n: usize) -> Workers {
        Workers(
            (0..n)
                .map(|i| {
                    Command::new(bin())
                        .args([
                            "worker",
                            "--transport",
                            transport,
                            "--connect",
                            endpoint,
                            "--name",
                            &format!("w{i}-{}", std::process::id()),
                        ])
                        .stdout(Stdio::null())
                        .stderr(Stdio::null())
                        .spawn()
                        .expect("spawn worker")
                })
                .collect(),
        )
    }
}

impl Drop for Workers {
    fn drop(&mut self) {
        for c in &mut self.0 {
            let _ = Command::new("kill").args(["-TERM", &c.id().to_string()]).status();
        }
        for c in &mut self.0 {
            let deadline = Instant::now() + Duration::from_secs(5);
            while c.try_wait().ok().flatten().is_none() && Instant::now() < deadline {
                std::thread::sleep(Duration::from_millis(20));
            }
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

fn run_args<'a>(study: &'a str, store: &'a str, transport: &'a str, ep: &'a str) -> Vec<&'a str> {
    vec!["run", study, "--store", store, "--transport", transport, "--endpoint", ep, "--quiet"]
}

fn export(store: &Path) -> Vec<u8> {
    let out = store.with_extension("csv");
    ceilfarm_ok(&["export", s(store), "--out", s(&out)]);
    std::fs::read(out).unwrap()
}

fn reference(dir: &Path, study: &Path) -> Vec<u8> {
    let store = dir.join("ref.db");
    ceilfarm_ok(&["run", s(study), "--store", s(&store), "--workers", "2", "--quiet"]);
    export(&store)
}

fn small_study(dir: &Path, cost_ms: u32) -> PathBuf {
    borehole_study(dir, "b.toml", |t| {
        t.replace("n = 200", "n = 60").replace("cost_ms = 0", &format!("cost_ms = {cost_ms}"))
    })
}

fn same_export_as_in_process(transport: &str) {
    let dir = tempfile::tempdir().unwrap();
    let study = small_study(dir.path(), 0);
    let ep = endpoint(transport);
    let _workers = Workers::start(transport, &ep, 2);
    let store = dir.path().join("t.db");
    ceilfarm_ok(&run_args(s(&study), s(&store), transport, &ep));
    assert!(
        export(&store) == reference(dir.path(), &study),
        "{transport} export differs from in-process"
    );
}

/// A 6-point ceiling-modal study, its specimen copied beside it (a study
/// reads files inside its own folder only).
fn ceiling_study(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(repo().join("configs/ceiling-modal.toml")).unwrap();
    std::fs::copy(repo().join("configs/specimens/type-c.toml"), dir.join("type-c.toml")).unwrap();
    let text = text
        .replace("spec = \"specimens/type-c.toml\"", "spec = \"type-c.toml\"")
        .replace("n = 200", "n = 6");
    let path = dir.join("c.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn ceiling_same_export_as_in_process(transport: &str) {
    let dir = tempfile::tempdir().unwrap();
    let study = ceiling_study(dir.path());
    let ep = endpoint(transport);
    // Workers start elsewhere: they need no specimen file, the study carries it.
    let _workers = Workers::start(transport, &ep, 2);
    let store = dir.path().join("t.db");
    ceilfarm_ok(&run_args(s(&study), s(&store), transport, &ep));
    let got = export(&store);
    assert_eq!(got.iter().filter(|b| **b == b'\n').count(), 7, "header and 6 runs");
    assert!(
        got == reference(dir.path(), &study),
        "{transport}: ceiling-modal export differs from in-process"
    );
}

fn committed(store: &Path) -> usize {
    let Ok(conn) =
        rusqlite::Connection::open_with_flags(store, rusqlite::OpenFlags::SQLITE_OPEN_READ_ONLY)
    else {
        return 0;
    };
    conn.query_row("SELECT count(*) FROM results", [], |r| r.get::<_, i64>(0))
        .map(|n| n as usize)
        .unwrap_or(0)
}

fn wait_for(store: &Path, n: usize, limit: Duration) {
    let t0 = Instant::now();
    while committed(store) < n && t0.elapsed() < limit {
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn survives_worker_kill(transport: &str) {
    let dir = tempfile::tempdir().unwrap();
    let study = small_study(dir.path(), 20);
    let ep = endpoint(transport);
    let mut workers = Workers::start(transport, &ep, 2);
    let store = dir.path().join("t.db");
    let coord = Command::new(bin())
        .args(run_args(s(&study), s(&store), transport, &ep))
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for(&store, 15, Duration::from_secs(60));
    let victim = &mut workers.0[0];
    victim.kill().unwrap(); // SIGKILL
    victim.wait().unwrap();
    let out = coord.wait_with_output_timeout(Duration::from_secs(120));
    assert!(out.0, "coordinator failed after a worker was killed: {}", out.1);
    assert_eq!(committed(&store), 60);
    assert!(
        export(&store) == reference(dir.path(), &study),
        "{transport}: export differs after a worker kill"
    );
}

fn survives_coordinator_kill(transport: &str) {
    let dir = tempfile::tempdir().unwrap();
    let study = small_study(dir.path(), 20);
    let ep = endpoint(transport);
    let _workers = Workers::start(transport, &ep, 2);
    let store = dir.path().join("t.db");
    let log_path = dir.path().join("coordinator.log");
    let log = std::fs::File::create(&log_path).unwrap();
    let mut coord = Command::new(bin())
        .args(run_args(s(&study), s(&store), transport, &ep))
        .arg("-v")
        .stderr(Stdio::from(log))
        .spawn()
        .unwrap();
    wait_for(&store, 15, Duration::from_secs(60));
    coord.kill().unwrap();
    coord.wait().unwrap();
    let done = committed(&store);
    assert!(
        done > 0 && done < 60,
        "kill landed outside the sweep ({done} done); coordinator log:\n{}",
        std::fs::read_to_string(&log_path).unwrap_or_default()
    );
    let mut args = run_args(s(&study), s(&store), transport, &ep);
    args.push("--resume");
    ceilfarm_ok(&args);
    assert!(
        export(&store) == reference(dir.path(), &study),
        "{transport}: export differs after a coordinator kill"
    );
}

trait WaitTimeout {
    fn wait_with_output_timeout(self, limit: Duration) -> (bool, String);
}

impl WaitTimeout for Child {
    fn wait_with_output_timeout(mut self, limit: Duration) -> (bool, String) {
        let t0 = Instant::now();
        loop {
            if let Some(status) = self.try_wait().unwrap() {
                let mut err = String::new();
                if let Some(mut e) = self.stderr.take() {
                    use std::io::Read;
                    let _ = e.read_to_string(&mut err);
                }
                return (status.success(), err);
            }
            if t0.elapsed() > limit {
                let _ = self.kill();
                return (false, "timed out".into());
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

#[cfg(feature = "zenoh")]
mod zenoh {
    #[test]
    fn same_export_as_in_process() {
        super::same_export_as_in_process("zenoh");
    }
    #[test]
    fn ceiling_modal_same_export_as_in_process() {
        super::ceiling_same_export_as_in_process("zenoh");
    }
    #[test]
    fn survives_worker_kill() {
        super::survives_worker_kill("zenoh");
    }
    #[test]
    fn survives_coordinator_kill() {
        super::survives_coordinator_kill("zenoh");
    }
}

#[cfg(feature = "iceoryx2")]
mod iceoryx2 {
    #[test]
    fn same_export_as_in_process() {
        super::same_export_as_in_process("iceoryx2");
    }
    #[test]
    fn ceiling_modal_same_export_as_in_process() {
        super::ceiling_same_export_as_in_process("iceoryx2");
    }
    #[test]
    fn survives_worker_kill() {
        super::survives_worker_kill("iceoryx2");
    }
    #[test]
    fn survives_coordinator_kill() {
        super::survives_coordinator_kill("iceoryx2");
    }
}
