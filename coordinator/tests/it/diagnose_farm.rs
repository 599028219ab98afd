//! `ceilfarm diagnose` on the farm, end to end, on the tiny test campaign
//! (configs/synth/tiny-test.toml): two `ceilfarm worker` processes over
//! iceoryx2 or zenoh write the same diagnosis.json as the in-process farm, and a
//! diagnosis killed with SIGKILL then run again runs only the run
//! simulations its store lacks and writes the same diagnosis.json.

use crate::common::*;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The tiny campaign's bundle under `dir`.
fn bundle(dir: &Path) -> PathBuf {
    let out = dir.join("bundle");
    let spec = repo().join("configs/synth/tiny-test.toml");
    let answer = dir.join("answer.json");
    ceilfarm_ok(&["synth", s(&spec), "--out", s(&out), "--answer", s(&answer)]);
    out
}

/// Runs `diagnose` into `out` with extra arguments; returns (stderr, wall s).
fn diagnose(bundle: &Path, out: &Path, extra: &[&str]) -> (String, f64) {
    let t0 = Instant::now();
    let mut args = vec!["diagnose", s(bundle), "--out", s(out), "--quiet"];
    args.extend_from_slice(extra);
    let o = ceilfarm_ok(&args);
    (String::from_utf8_lossy(&o.stderr).into_owned(), t0.elapsed().as_secs_f64())
}

/// (evaluations run now, re-used, run simulations stored now) from the
/// `store:` line of `diagnose`.
fn spent(stderr: &str) -> (usize, usize, usize) {
    let line = stderr.lines().find(|l| l.starts_with("store: ")).expect("a store line");
    let num = |after: &str| -> usize {
        let tail = &line[line.find(after).expect(after) + after.len()..];
        tail.split_whitespace().next().unwrap().parse().unwrap()
    };
    (num("("), num("workers, "), num("re-used; "))
}

fn stored(db: &Path) -> usize {
    let flags = rusqlite::OpenFlags::SQLITE_OPEN_READ_ONLY;
    let Ok(conn) = rusqlite::Connection::open_with_flags(db, flags) else { return 0 };
    conn.query_row("SELECT count(*) FROM evaluations", [], |r| r.get::<_, i64>(0))
        .map_or(0, |n| n as usize)
}

#[test]
fn killed_diagnosis_runs_only_what_its_store_lacks() {
    let dir = tempfile::tempdir().unwrap();
    let b = bundle(dir.path());
    let whole = dir.path().join("whole");
    let (err, wall) = diagnose(&b, &whole, &[]);
    let (_, _, runs) = spent(&err);
    let out = dir.path().join("killed");
    let db = out.join("evaluations.db");
    let mut child = Command::new(bin())
        .args(["diagnose", s(&b), "--out", s(&out), "--quiet"])
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while stored(&db) < runs / 3 && t0.elapsed() < Duration::from_secs(300) {
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let before = stored(&db);
    assert!(before > 0 && before < runs, "kill landed outside: {before} of {runs}");
    assert!(!out.join("diagnosis.json").exists());
    let (err, _) = diagnose(&b, &out, &[]);
    let (_, _, ran) = spent(&err);
    eprintln!(
        "{runs} distinct run simulations in {wall:.1} s; killed at {before}, resume ran {ran}"
    );
    assert_eq!(ran, runs - before, "the resumed diagnosis ran only what was missing");
    assert_eq!(
        std::fs::read_to_string(out.join("diagnosis.json")).unwrap(),
        std::fs::read_to_string(whole.join("diagnosis.json")).unwrap()
    );
}

/// Worker processes, stopped with SIGTERM (then SIGKILL) when dropped.
struct Workers(Vec<Child>);

impl Workers {
    fn start(transport: &str, endpoint: &str, n: usize) -> Workers {
        let spawn = |i: usize| {
            Command::new(bin())
                .args(["worker", "--transport", transport, "--connect", endpoint])
                .args(["--name", &format!("dw{i}-{}", std::process::id())])
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .expect("spawn worker")
        };
        Workers((0..n).map(spawn).collect())
    }
}

impl Drop for Workers {
    fn drop(&mut self) {
        for c in &mut self.0 {
            if c.try_wait().ok().flatten().is_none() {
                let _ = Command::new("kill").args(["-TERM", &c.id().to_string()]).status();
            }
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

/// Diagnoses over `transport` with two worker processes at `endpoint` and
/// requires the in-process diagnosis.json byte for byte.
fn same_diagnosis_as_in_process(transport: &str, endpoint: &str) {
    let dir = tempfile::tempdir().unwrap();
    let b = bundle(dir.path());
    let local = dir.path().join("in-process");
    let (_, t_local) = diagnose(&b, &local, &["--workers", "2"]);
    let _workers = Workers::start(transport, endpoint, 2);
    let remote = dir.path().join(transport);
    let args = ["--transport", transport, "--endpoint", endpoint, "--workers", "2"];
    let (err, t_remote) = diagnose(&b, &remote, &args);
    assert!(err.contains(&format!("{transport} workers")), "{err}");
    eprintln!("in-process {t_local:.1} s, {transport} (2 worker processes) {t_remote:.1} s");
    assert_eq!(
        std::fs::read_to_string(remote.join("diagnosis.json")).unwrap(),
        std::fs::read_to_string(local.join("diagnosis.json")).unwrap()
    );
}

#[cfg(feature = "iceoryx2")]
#[test]
fn iceoryx2_workers_write_the_in_process_diagnosis() {
    same_diagnosis_as_in_process("iceoryx2", &format!("cfdiag{}", std::process::id()));
}

#[cfg(feature = "zenoh")]
#[test]
fn zenoh_workers_write_the_in_process_diagnosis() {
    let port = 41000 + (std::process::id() % 8000) as u16;
    same_diagnosis_as_in_process("zenoh", &format!("tcp/127.0.0.1:{port}"));
}

/// A worker process killed with SIGKILL mid-diagnosis: its tasks go to the
/// other worker, the diagnosis finishes with the in-process diagnosis.json
/// and every evaluation ran once.
#[cfg(feature = "iceoryx2")]
#[test]
fn a_worker_killed_mid_diagnosis_loses_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let b = bundle(dir.path());
    let local = dir.path().join("in-process");
    let (err, _) = diagnose(&b, &local, &[]);
    let (distinct, _, runs) = spent(&err);
    let prefix = format!("cfdiagkill{}", std::process::id());
    let mut workers = Workers::start("iceoryx2", &prefix, 2);
    let out = dir.path().join("iceoryx2");
    let child = Command::new(bin())
        .args(["diagnose", s(&b), "--out", s(&out), "--quiet", "--transport", "iceoryx2"])
        .args(["--endpoint", &prefix, "--workers", "2"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let db = out.join("evaluations.db");
    let t0 = Instant::now();
    while stored(&db) < runs / 3 && t0.elapsed() < Duration::from_secs(300) {
        std::thread::sleep(Duration::from_millis(5));
    }
    workers.0[0].kill().unwrap(); // SIGKILL
    workers.0[0].wait().unwrap();
    let killed_at = stored(&db);
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "diagnose failed after a worker was killed: {err}");
    assert!(killed_at < runs, "the kill landed after the diagnosis");
    assert_eq!(spent(&err).0, distinct, "every evaluation ran once");
    assert_eq!(spent(&err).2, runs, "every run simulation ran once");
    assert_eq!(
        std::fs::read_to_string(out.join("diagnosis.json")).unwrap(),
        std::fs::read_to_string(local.join("diagnosis.json")).unwrap()
    );
}
