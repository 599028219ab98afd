//! A task that panics, errors or hangs past its timeout is recorded as a
//! failure with its reason, and the sweep completes.

mod common;
use common::*;

const STUDY: &str = r#"
[study]
name = "faults"
[model]
kind = "test-faults"
panic_on = [3]
error_on = [5]
hang_on = [7]
[[parameters]]
name = "a"
low = 0.0
high = 1.0
[design]
method = "lhs"
n = 12
seed = 1
[farm]
task_timeout_s = 0.3
max_retries = 1
"#;

#[test]
fn failures_are_recorded_and_the_sweep_completes() {
    let dir = tempfile::tempdir().unwrap();
    let study = dir.path().join("f.toml");
    std::fs::write(&study, STUDY).unwrap();
    let store = dir.path().join("f.db");
    let out = ceilfarm_ok(&[
        "run",
        s(&study),
        "--store",
        s(&store),
        "--workers",
        "2",
        "--quiet",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!((v["ok"].as_u64(), v["failed"].as_u64()), (Some(9), Some(3)), "{v}");
    // Each failing task was tried twice (max_retries = 1); tasks queued behind
    // a hung run are handed out again too.
    assert!(v["reissued"].as_u64().unwrap() >= 3, "{v}");
    let csv_path = dir.path().join("f.csv");
    ceilfarm_ok(&["export", s(&store), "--out", s(&csv_path)]);
    let mut rdr = csv::Reader::from_path(&csv_path).unwrap();
    let rows: Vec<csv::StringRecord> = rdr.records().map(Result::unwrap).collect();
    let status = |i: usize| (rows[i][3].to_string(), rows[i][4].to_string());
    assert_eq!(status(3), ("failed".into(), "panic: injected panic in task 3".into()));
    assert_eq!(status(5), ("failed".into(), "injected error in task 5".into()));
    assert_eq!(status(7).0, "failed");
    assert!(status(7).1.starts_with("timeout: no result after 0.3 s"), "{:?}", status(7));
    assert_eq!(status(0).0, "ok");
    // Nothing is missing: a later resume has nothing to do.
    let out = ceilfarm_ok(&["run", s(&study), "--store", s(&store), "--resume", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["already_done"].as_u64(), Some(12));
}
