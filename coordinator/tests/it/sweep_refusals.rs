//! Refusals: resuming with a changed study names the key; damaged stores are
//! detected and named; existing stores are not overwritten.

use crate::common::*;

fn run_and_fail(args: &[&str]) -> String {
    let out = ceilfarm(args);
    assert!(!out.status.success(), "ceilfarm {args:?} should fail");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn small_store(dir: &std::path::Path) -> std::path::PathBuf {
    let study = borehole_study(dir, "b.toml", |t| t.replace("n = 200", "n = 20"));
    let store = dir.join("s.db");
    ceilfarm_ok(&["run", s(&study), "--store", s(&store), "--quiet"]);
    store
}

#[test]
fn changed_seed_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let store = small_store(dir.path());
    let changed = borehole_study(dir.path(), "c.toml", |t| {
        t.replace("n = 200", "n = 20").replace("seed = 20240601", "seed = 5")
    });
    let err = run_and_fail(&["run", s(&changed), "--store", s(&store), "--resume"]);
    assert!(err.contains("design.seed: store has 20240601, study has 5"), "{err}");
}

#[test]
fn changed_bound_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let store = small_store(dir.path());
    let changed = borehole_study(dir.path(), "c.toml", |t| {
        t.replace("n = 200", "n = 20").replace("low = 0.05", "low = 0.06")
    });
    let err = run_and_fail(&["run", s(&changed), "--store", s(&store), "--resume"]);
    assert!(err.contains("parameters.rw.low: store has 0.05, study has 0.06"), "{err}");
}

#[test]
fn changed_cost_or_workers_is_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let store = small_store(dir.path());
    let changed = borehole_study(dir.path(), "c.toml", |t| {
        t.replace("n = 200", "n = 20").replace("cost_ms = 0", "cost_ms = 1")
    });
    ceilfarm_ok(&[
        "run",
        s(&changed),
        "--store",
        s(&store),
        "--resume",
        "--workers",
        "1",
        "--quiet",
    ]);
}

#[test]
fn truncated_store_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let store = small_store(dir.path());
    let len = std::fs::metadata(&store).unwrap().len();
    let f = std::fs::OpenOptions::new().write(true).open(&store).unwrap();
    f.set_len(len / 2 + 100).unwrap();
    let err = run_and_fail(&["export", s(&store), "--out", s(&dir.path().join("x.csv"))]);
    assert!(err.contains("s.db") && err.contains("truncated"), "{err}");
    let err =
        run_and_fail(&["run", s(&dir.path().join("b.toml")), "--store", s(&store), "--resume"]);
    assert!(err.contains("truncated"), "{err}");
}

#[test]
fn overwritten_pages_are_detected() {
    let dir = tempfile::tempdir().unwrap();
    let store = small_store(dir.path());
    let mut bytes = std::fs::read(&store).unwrap();
    let n = bytes.len();
    for b in &mut bytes[4096..n.min(4096 * 3)] {
        *b = 0xA5;
    }
    std::fs::write(&store, bytes).unwrap();
    let err = run_and_fail(&["status", s(&store)]);
    assert!(
        err.contains("s.db") && (err.contains("malformed") || err.contains("integrity")),
        "{err}"
    );
}

#[test]
fn not_a_store_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let bogus = dir.path().join("bogus.db");
    std::fs::write(&bogus, vec![b'x'; 8192]).unwrap();
    let err = run_and_fail(&["status", s(&bogus)]);
    assert!(err.contains("not a SQLite database"), "{err}");
}

#[test]
fn existing_store_needs_resume() {
    let dir = tempfile::tempdir().unwrap();
    let store = small_store(dir.path());
    let err = run_and_fail(&["run", s(&dir.path().join("b.toml")), "--store", s(&store)]);
    assert!(err.contains("store exists; pass --resume"), "{err}");
}

#[test]
fn bad_study_names_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let study = borehole_study(dir.path(), "bad.toml", |t| {
        t.replace("max_retries = 1", "max_retries = 1\nretries = 3")
    });
    let err = run_and_fail(&["run", s(&study), "--store", s(&dir.path().join("x.db"))]);
    assert!(err.contains("bad.toml") && err.contains("unknown field `retries`"), "{err}");
}

/// Regression (issue 56): two `ceilfarm run` on one store path both ran.
/// While one run owns the store, a second (with or without --resume) is
/// refused with the owner's pid and host; readers still read; after the
/// owner is killed, --resume finishes the store.
#[test]
fn a_second_run_on_one_store_is_refused_with_the_owners_pid_and_host() {
    let dir = tempfile::tempdir().unwrap();
    let study = borehole_study(dir.path(), "b.toml", |t| {
        t.replace("n = 200", "n = 20").replace("cost_ms = 0", "cost_ms = 200")
    });
    let store = dir.path().join("s.db");
    let mut owner = std::process::Command::new(bin())
        .args(["run", s(&study), "--store", s(&store), "--workers", "1", "--quiet"])
        .spawn()
        .unwrap();
    let holder = format!("pid {} on host", owner.id());
    let lock = dir.path().join("s.db.lock");
    let start = std::time::Instant::now();
    while !std::fs::read_to_string(&lock).unwrap_or_default().contains(&holder) {
        assert!(start.elapsed().as_secs() < 20, "the first run never took the lock");
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    while !store.exists() {
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    for resume in [true, false] {
        let mut args = vec!["run", s(&study), "--store", s(&store), "--quiet"];
        if resume {
            args.push("--resume");
        }
        let err = run_and_fail(&args);
        assert!(err.contains("s.db: in use by") && err.contains(&holder), "{err}");
    }
    ceilfarm_ok(&["status", s(&store)]);
    owner.kill().unwrap();
    owner.wait().unwrap();
    let fast = borehole_study(dir.path(), "f.toml", |t| t.replace("n = 200", "n = 20"));
    ceilfarm_ok(&["run", s(&fast), "--store", s(&store), "--resume", "--quiet"]);
    let out = ceilfarm_ok(&["status", s(&store), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["ok"].as_u64(), Some(20), "{v}");
}

#[test]
fn store_check_reads_every_page() {
    let dir = tempfile::tempdir().unwrap();
    let store = small_store(dir.path());
    let out = ceilfarm_ok(&["store", "check", s(&store)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("ok (20 design points: 20 ok, 0 failed, 0 missing)"), "{text}");
    // Damage a page the constant-time checks on open do not read: the last.
    let mut bytes = std::fs::read(&store).unwrap();
    let n = bytes.len();
    for b in &mut bytes[n - 4096 + 8..n] {
        *b = 0xA5;
    }
    std::fs::write(&store, bytes).unwrap();
    let err = run_and_fail(&["store", "check", s(&store)]);
    assert!(
        err.contains("s.db") && (err.contains("integrity") || err.contains("malformed")),
        "{err}"
    );
}
