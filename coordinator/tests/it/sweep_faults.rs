//! A task that panics, errors or hangs past its timeout is recorded as a
//! failure with its reason, and the sweep completes.

use crate::common::*;

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
task_timeout_s = 2.0
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
    assert!(status(7).1.starts_with("timeout: no result after 2 s"), "{:?}", status(7));
    assert_eq!(status(0).0, "ok");
    // Nothing is missing: a later resume has nothing to do.
    let out = ceilfarm_ok(&["run", s(&study), "--store", s(&store), "--resume", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["already_done"].as_u64(), Some(12));
}

/// Regression (issue 56): one NaN output failed the store's NOT NULL
/// constraint, so no result of the batch was recorded and every `--resume`
/// failed the same way.
#[test]
fn non_finite_outputs_are_failed_runs_with_their_reason() {
    let dir = tempfile::tempdir().unwrap();
    let study = dir.path().join("nan.toml");
    let text = STUDY
        .replace("panic_on = [3]\nerror_on = [5]\nhang_on = [7]", "nan_on = [2]\ninf_on = [4]")
        .replace("max_retries = 1", "max_retries = 0");
    std::fs::write(&study, text).unwrap();
    let store = dir.path().join("nan.db");
    let args = ["run", s(&study), "--store", s(&store), "--workers", "2", "--quiet", "--json"];
    let v: serde_json::Value = serde_json::from_slice(&ceilfarm_ok(&args).stdout).unwrap();
    assert_eq!((v["ok"].as_u64(), v["failed"].as_u64()), (Some(10), Some(2)), "{v}");
    let csv_path = dir.path().join("nan.csv");
    ceilfarm_ok(&["export", s(&store), "--out", s(&csv_path)]);
    let mut rdr = csv::Reader::from_path(&csv_path).unwrap();
    let rows: Vec<csv::StringRecord> = rdr.records().map(Result::unwrap).collect();
    let status = |i: usize| (rows[i][3].to_string(), rows[i][4].to_string());
    assert_eq!(status(2), ("failed".into(), "non-finite output: y = NaN".into()));
    assert_eq!(status(4), ("failed".into(), "non-finite output: y = inf".into()));
    let out = ceilfarm_ok(&["status", s(&store), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        (v["ok"].as_u64(), v["failed"].as_u64(), v["missing"].as_u64()),
        (Some(10), Some(2), Some(0))
    );
}

/// `--resume` keeps recorded failures; `--resume --retry-failed` runs them
/// again and a success replaces the failure (here: runs of 300 ms that
/// timed out at 0.1 s, retried with a 10 s timeout).
#[test]
fn retry_failed_runs_failed_tasks_again() {
    let dir = tempfile::tempdir().unwrap();
    let study = |timeout: &str| {
        let path = dir.path().join(format!("t{timeout}.toml"));
        let text = STUDY
            .replace("panic_on = [3]\nerror_on = [5]\nhang_on = [7]", "cost_ms = 300")
            .replace("n = 12", "n = 4")
            .replace("task_timeout_s = 2.0", &format!("task_timeout_s = {timeout}"))
            .replace("max_retries = 1", "max_retries = 0");
        assert!(text.contains(&format!("task_timeout_s = {timeout}\n")), "{text}");
        std::fs::write(&path, text).unwrap();
        path
    };
    let (short, long) = (study("0.1"), study("10"));
    let store = dir.path().join("t.db");
    let run = |study: &std::path::Path, extra: &[&str]| {
        let mut args = vec!["run", s(study), "--store", s(&store), "--workers", "2", "--quiet"];
        args.extend_from_slice(extra);
        args.push("--json");
        let out = ceilfarm_ok(&args);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (
            v["already_done"].as_u64().unwrap(),
            v["ok"].as_u64().unwrap(),
            v["failed"].as_u64().unwrap(),
        )
    };
    assert_eq!(run(&short, &[]), (0, 0, 4));
    assert_eq!(run(&long, &["--resume"]), (4, 0, 0), "plain --resume keeps the failures");
    assert_eq!(run(&long, &["--resume", "--retry-failed"]), (0, 4, 0));
    let out = ceilfarm_ok(&["status", s(&store), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!((v["ok"].as_u64(), v["failed"].as_u64()), (Some(4), Some(0)));
    let err = ceilfarm(&["run", s(&long), "--store", s(&store), "--retry-failed"]);
    assert!(!err.status.success(), "--retry-failed without --resume must be refused");
}
