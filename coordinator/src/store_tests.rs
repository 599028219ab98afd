//! Unit tests of the store: failures kept as data, `--retry-failed`
//! replacement, and the checks made on open.

use crate::store::{Keep, RunStatus, Store};
use crate::study::Study;
use protocol::{Outcome, Outputs, TaskId, TaskResult};
use std::path::Path;

/// A three-point ishigami study's store in `dir`.
pub(crate) fn small_store(dir: &Path) -> Store {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../configs/ishigami.toml"))
            .unwrap();
    let study = Study::parse(&text.replace("n = 1024", "n = 3"), Path::new("i.toml")).unwrap();
    let design = vec![vec![0.1, 0.2, 0.3], vec![0.4, 0.5, 0.6], vec![-1.0, 0.0, 1.0]];
    Store::create(&dir.join("s.db"), &study, &design, &["y".into()]).unwrap()
}

fn ok(id: u64, y: f64) -> TaskResult {
    TaskResult {
        id: TaskId(id),
        outcome: Outcome::Ok(Outputs { scalars: vec![("y".into(), y)], histories: vec![] }),
        wall_s: 0.0,
        host: "h".into(),
    }
}

fn failed(id: u64, reason: &str) -> TaskResult {
    TaskResult {
        id: TaskId(id),
        outcome: Outcome::Failed { reason: reason.into() },
        wall_s: 0.0,
        host: String::new(),
    }
}

fn status(store: &Store, id: usize) -> Option<RunStatus> {
    store.rows().unwrap()[id].status.clone()
}

#[test]
fn nan_and_infinite_outputs_are_recorded_as_failures() {
    let dir = tempfile::tempdir().unwrap();
    let mut store = small_store(dir.path());
    let keep = Keep::default();
    let fresh = store.record(&[ok(0, 1.5), ok(1, f64::NAN), ok(2, f64::INFINITY)], 1, &keep);
    assert_eq!(fresh.unwrap(), 3);
    assert_eq!(status(&store, 0), Some(RunStatus::Ok));
    let nan = RunStatus::Failed("non-finite output: y = NaN".into());
    assert_eq!(status(&store, 1), Some(nan));
    let inf = RunStatus::Failed("non-finite output: y = inf".into());
    assert_eq!(status(&store, 2), Some(inf));
    assert!(store.rows().unwrap()[1].scalars.is_empty());
    assert_eq!(store.counts().unwrap(), (1, 2, 0));
}

#[test]
fn retry_failed_runs_failures_again_and_a_new_result_replaces_them() {
    let dir = tempfile::tempdir().unwrap();
    let mut store = small_store(dir.path());
    let keep = Keep::default();
    store.record(&[ok(0, 1.5), failed(1, "lost with its worker 3 times")], 1, &keep).unwrap();
    assert_eq!(store.to_run(false).unwrap(), vec![TaskId(2)]);
    assert_eq!(store.to_run(true).unwrap(), vec![TaskId(1), TaskId(2)]);
    assert_eq!(store.record(&[ok(1, -2.0), failed(2, "timeout")], 2, &keep).unwrap(), 2);
    assert_eq!(status(&store, 1), Some(RunStatus::Ok));
    assert_eq!(store.rows().unwrap()[1].scalars.get("y"), Some(&-2.0));
    // A failure again replaces a failure; an ok result is never replaced.
    assert_eq!(store.record(&[failed(2, "timeout again"), failed(0, "x")], 3, &keep).unwrap(), 1);
    assert_eq!(status(&store, 2), Some(RunStatus::Failed("timeout again".into())));
    assert_eq!(status(&store, 0), Some(RunStatus::Ok));
    assert_eq!(store.to_run(true).unwrap(), vec![TaskId(2)]);
}

/// Copies a store open elsewhere with its WAL (as a crash leaves them);
/// returns the database size (pages) of the WAL's last commit.
fn snapshot_with_wal(from: &Path, to: &Path) -> u32 {
    let bytes = std::fs::read(crate::store_file::wal_path(from)).unwrap();
    std::fs::copy(from, to).unwrap();
    std::fs::write(crate::store_file::wal_path(to), &bytes).unwrap();
    let page = u32::from_be_bytes(bytes[8..12].try_into().unwrap()) as usize;
    let frames = bytes[32..].chunks_exact(24 + page);
    let sizes = frames.map(|f| u32::from_be_bytes(f[4..8].try_into().unwrap()));
    sizes.rev().find(|&n| n > 0).expect("a commit frame")
}

/// Regression (issue 56): after a checkpoint stopped by a full disk, the
/// main file's header already counts the pages still in the WAL; SQLite
/// reads them from the WAL and the store is whole, but the length check
/// called it truncated.
#[test]
fn a_whole_store_whose_pages_are_in_the_wal_opens() {
    let dir = tempfile::tempdir().unwrap();
    let mut store = small_store(dir.path());
    store.conn().execute_batch("PRAGMA wal_autocheckpoint = 0").unwrap();
    let big = |id| TaskResult {
        id: TaskId(id),
        outcome: Outcome::Ok(Outputs {
            scalars: (0..400).map(|i| (format!("y{i}"), i as f64)).collect(),
            histories: vec![],
        }),
        wall_s: 0.0,
        host: "h".into(),
    };
    store.record(&[big(0), big(1), failed(2, "boom")], 1, &Keep::default()).unwrap();
    let copy = dir.path().join("copy.db");
    let pages = snapshot_with_wal(&dir.path().join("s.db"), &copy);
    let len = std::fs::metadata(&copy).unwrap().len();
    assert!(pages as u64 * 4096 > len, "the WAL must hold pages beyond the main file");
    // The checkpoint wrote page 1 (with the new size) before the disk filled.
    let mut bytes = std::fs::read(&copy).unwrap();
    bytes[28..32].copy_from_slice(&pages.to_be_bytes());
    std::fs::write(&copy, bytes).unwrap();
    let reopened = Store::open(&copy).expect("a whole store with its WAL opens");
    let check = reopened.check_full().unwrap();
    assert_eq!((check.tasks, check.ok, check.failed), (3, 2, 1));
    assert_eq!(reopened.rows().unwrap()[1].scalars.len(), 400);
}

/// Without a WAL the main file must hold every page its header counts.
#[test]
fn a_truncated_store_without_wal_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.db");
    drop(small_store(dir.path()));
    let len = std::fs::metadata(&path).unwrap().len();
    std::fs::OpenOptions::new().write(true).open(&path).unwrap().set_len(len - 4096).unwrap();
    let err = Store::open_read_only(&path).err().unwrap().to_string();
    assert!(err.contains("truncated"), "{err}");
}

#[test]
fn a_read_only_store_reads_but_never_writes() {
    let dir = tempfile::tempdir().unwrap();
    let mut store = small_store(dir.path());
    store.record(&[ok(0, 1.5)], 1, &Keep::default()).unwrap();
    let path = dir.path().join("s.db");
    let owner = Store::open(&path).unwrap();
    let reader = Store::open_read_only(&path).expect("readers take no lock");
    assert_eq!(reader.counts().unwrap(), (1, 0, 2));
    let err = reader.begin_session("in-process", 1).err().unwrap().to_string();
    assert!(err.contains("readonly"), "{err}");
    drop(owner);
}

#[test]
fn a_second_writer_is_refused_while_the_first_owns_the_store() {
    let dir = tempfile::tempdir().unwrap();
    drop(small_store(dir.path()));
    let path = dir.path().join("s.db");
    let first = Store::open(&path).unwrap();
    let err = Store::open(&path).err().unwrap().to_string();
    assert!(err.contains(&format!("in use by pid {}", std::process::id())), "{err}");
    drop(first);
    Store::open(&path).expect("the lock is released with the store");
}
