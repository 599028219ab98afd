//! Crash safety: a sweep killed with SIGKILL at random moments and resumed
//! each time with another worker count exports exactly the same bytes as an
//! uninterrupted sweep.

use crate::common::*;
use std::process::{Command, Stdio};
use std::time::Duration;

fn xorshift(state: &mut u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state
}

/// Results committed so far, read without disturbing the running sweep.
fn committed(store: &std::path::Path) -> usize {
    let flags = rusqlite::OpenFlags::SQLITE_OPEN_READ_ONLY;
    let Ok(conn) = rusqlite::Connection::open_with_flags(store, flags) else { return 0 };
    conn.query_row("SELECT count(*) FROM results", [], |r| r.get::<_, i64>(0))
        .map(|n| n as usize)
        .unwrap_or(0)
}

fn done_count(store: &std::path::Path) -> usize {
    let out = ceilfarm_ok(&["status", s(store), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    (v["ok"].as_u64().unwrap() + v["failed"].as_u64().unwrap()) as usize
}

#[test]
fn killed_and_resumed_sweep_exports_identical_bytes() {
    let dir = tempfile::tempdir().unwrap();
    // 200 runs of 10 ms: about 1 s on two workers.
    let study = borehole_study(dir.path(), "b.toml", |t| t.replace("cost_ms = 0", "cost_ms = 10"));
    let reference = dir.path().join("ref.db");
    ceilfarm_ok(&["run", s(&study), "--store", s(&reference), "--workers", "2", "--quiet"]);
    let ref_csv = dir.path().join("ref.csv");
    ceilfarm_ok(&["export", s(&reference), "--out", s(&ref_csv)]);

    let store = dir.path().join("killed.db");
    let seed =
        std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().as_nanos()
            as u64
            | 1;
    eprintln!("kill schedule seed {seed}");
    let mut rng = seed;
    let mut partial = 0;
    let worker_counts = [1, 2, 3, 4, 2, 1, 3, 2];
    for (round, workers) in worker_counts.iter().enumerate() {
        let before = committed(&store);
        // Kill once a random number of further runs are committed, plus a
        // random few milliseconds, so kills land between and during commits.
        let target = (before + 3 + (xorshift(&mut rng) % 40) as usize).min(199);
        let mut child = Command::new(bin())
            .args([
                "run",
                s(&study),
                "--store",
                s(&store),
                "--resume",
                "--quiet",
                "--workers",
                &workers.to_string(),
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        while committed(&store) < target && child.try_wait().unwrap().is_none() {
            std::thread::sleep(Duration::from_millis(2));
        }
        std::thread::sleep(Duration::from_millis(xorshift(&mut rng) % 15));
        child.kill().unwrap(); // SIGKILL on Unix
        child.wait().unwrap();
        let done = committed(&store);
        eprintln!("round {round}: killed with {workers} workers at {done}/200 (target {target})");
        if done > before && done < 200 {
            partial += 1;
        }
    }
    assert!(
        partial >= 5,
        "only {partial} kills landed mid-sweep; the test did not exercise resume"
    );
    ceilfarm_ok(&["run", s(&study), "--store", s(&store), "--resume", "--quiet", "--workers", "2"]);
    let csv_path = dir.path().join("killed.csv");
    ceilfarm_ok(&["export", s(&store), "--out", s(&csv_path)]);
    let (a, b) = (std::fs::read(&ref_csv).unwrap(), std::fs::read(&csv_path).unwrap());
    assert!(a == b, "exports differ after kill and resume");
    assert_eq!(done_count(&store), 200);
}

#[test]
fn resume_on_a_missing_store_starts_it() {
    let dir = tempfile::tempdir().unwrap();
    let store = dir.path().join("new.db");
    ceilfarm_ok(&[
        "run",
        s(&repo().join("configs/borehole.toml")),
        "--store",
        s(&store),
        "--resume",
        "--quiet",
    ]);
    assert_eq!(done_count(&store), 200);
}
