//! The dataset store: one SQLite file (WAL) holding the study, its design,
//! every result (scalars in rows, time histories as zstd-compressed f64
//! blobs), failures and provenance. Each batch of results is one
//! transaction, so a `kill -9` at any moment loses at most the runs in
//! flight; with `synchronous = FULL` a committed batch also survives a
//! power cut. One coordinator owns a store at a time ([`StoreLock`]);
//! readers open it read-only and take no lock. Opening checks the file in
//! constant time ([`check_file`], the meta table, the design's extent);
//! [`Store::check_full`] reads every page (`ceilfarm store check`).

pub use crate::store_file::check_file;
use crate::store_lock::{LockError, StoreLock};
use crate::study::{format_value, Study};
use protocol::{History, Outcome, TaskId, TaskResult};
use rusqlite::{params, Connection, OpenFlags, OptionalExtension};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Version of the store layout.
pub const STORE_FORMAT: &str = "ceilfarm-store/1";

/// Why the store cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    /// SQLite failed.
    #[error("{path}: {source}")]
    Sql {
        /// The store file.
        path: PathBuf,
        /// The cause.
        source: rusqlite::Error,
    },
    /// The file is damaged, truncated or not a ceilfarm store.
    #[error("{path}: {reason}; refusing to use it (move it aside and start again)")]
    Corrupt {
        /// The store file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The study differs from the one the store was made for.
    #[error("{path}: the study changed since this store was made: {}", diffs.join("; "))]
    StudyChanged {
        /// The store file.
        path: PathBuf,
        /// One entry per changed key: `key: store has X, study has Y`.
        diffs: Vec<String>,
    },
    /// Another coordinator owns the store, or its lock file failed.
    #[error(transparent)]
    Lock(#[from] LockError),
    /// Reading or writing the file failed.
    #[error("{path}: {source}")]
    Io {
        /// The store file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

/// A run's status in the store.
#[derive(Debug, Clone, PartialEq)]
pub enum RunStatus {
    /// Finished with outputs.
    Ok,
    /// Failed, with the reason.
    Failed(String),
}

/// One exported row: a design point and what came of it.
#[derive(Debug, Clone, PartialEq)]
pub struct RunRow {
    /// Design row.
    pub task: TaskId,
    /// Parameter values (physical units).
    pub params: Vec<f64>,
    /// Status, or `None` when not run yet.
    pub status: Option<RunStatus>,
    /// Scalar outputs by name.
    pub scalars: BTreeMap<String, f64>,
}

/// An open store.
pub struct Store {
    conn: Connection,
    path: PathBuf,
    /// Held for as long as this store may write (absent when read-only).
    _owner: Option<StoreLock>,
}

/// What [`Store::check_full`] found in a whole store.
#[derive(Debug, Clone, PartialEq)]
pub struct StoreCheck {
    /// Design points.
    pub tasks: usize,
    /// Runs finished with outputs.
    pub ok: usize,
    /// Runs recorded as failed.
    pub failed: usize,
}

const SCHEMA: &str = "
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE study_keys (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE parameters (idx INTEGER PRIMARY KEY, name TEXT NOT NULL, low REAL NOT NULL,
    high REAL NOT NULL, units TEXT NOT NULL, distribution TEXT NOT NULL);
CREATE TABLE design (task_id INTEGER PRIMARY KEY, params BLOB NOT NULL);
CREATE TABLE results (task_id INTEGER PRIMARY KEY REFERENCES design(task_id),
    status TEXT NOT NULL, reason TEXT, host TEXT NOT NULL, wall_s REAL NOT NULL,
    finished_at TEXT NOT NULL, session INTEGER NOT NULL);
CREATE TABLE scalars (task_id INTEGER NOT NULL REFERENCES results(task_id), name TEXT NOT NULL,
    value REAL NOT NULL, PRIMARY KEY (task_id, name)) WITHOUT ROWID;
CREATE TABLE histories (task_id INTEGER NOT NULL REFERENCES results(task_id), name TEXT NOT NULL,
    dt_s REAL NOT NULL, channels TEXT NOT NULL, n_samples INTEGER NOT NULL, data BLOB NOT NULL,
    PRIMARY KEY (task_id, name));
CREATE TABLE sessions (id INTEGER PRIMARY KEY, started_at TEXT NOT NULL, host TEXT NOT NULL,
    transport TEXT NOT NULL, workers INTEGER NOT NULL, ceilfarm_version TEXT NOT NULL);
";

/// Inserts a result, or replaces a recorded failure; an `ok` row is never
/// touched (a failed row holds no scalars or histories to clean up).
const UPSERT_RESULT: &str = "INSERT INTO results VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)
    ON CONFLICT(task_id) DO UPDATE SET status = excluded.status, reason = excluded.reason,
        host = excluded.host, wall_s = excluded.wall_s, finished_at = excluded.finished_at,
        session = excluded.session
    WHERE results.status = 'failed'";

fn now() -> String {
    let t = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default();
    format!("{:.3}", t.as_secs_f64())
}

impl Store {
    fn sql(&self) -> impl Fn(rusqlite::Error) -> StoreError + '_ {
        |source| StoreError::Sql { path: self.path.clone(), source }
    }

    /// Creates a new store for `study` with its design (physical units).
    pub fn create(
        path: &Path,
        study: &Study,
        design: &[Vec<f64>],
        outputs: &[String],
    ) -> Result<Store, StoreError> {
        let sql = |source| StoreError::Sql { path: path.to_path_buf(), source };
        let conn = Connection::open(path).map_err(sql)?;
        let mut store = Store { conn, path: path.to_path_buf(), _owner: None };
        store.pragmas()?;
        let tx = store.conn.transaction().map_err(sql)?;
        tx.execute_batch(SCHEMA).map_err(sql)?;
        let meta = [
            ("format", STORE_FORMAT.to_string()),
            ("study_name", study.name.clone()),
            ("study_hash", study.hash()),
            ("study_path", study.path.display().to_string()),
            ("model_spec", serde_json::to_string(&spec_json(study)).unwrap_or_default()),
            ("n_tasks", design.len().to_string()),
            ("output_names", serde_json::to_string(outputs).unwrap_or_default()),
            ("created_at", now()),
            ("ceilfarm_version", env!("CARGO_PKG_VERSION").to_string()),
        ];
        for (k, v) in meta {
            tx.execute("INSERT INTO meta VALUES (?1, ?2)", params![k, v]).map_err(sql)?;
        }
        for (k, v) in study.result_keys() {
            tx.execute("INSERT INTO study_keys VALUES (?1, ?2)", params![k, v]).map_err(sql)?;
        }
        for (i, p) in study.parameters.iter().enumerate() {
            tx.execute(
                "INSERT INTO parameters VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
                params![i as i64, p.name, p.low, p.high, p.units, format!("{:?}", p.distribution)],
            )
            .map_err(sql)?;
        }
        {
            let mut ins = tx.prepare("INSERT INTO design VALUES (?1, ?2)").map_err(sql)?;
            for (i, row) in design.iter().enumerate() {
                ins.execute(params![i as i64, f64s_to_bytes(row)]).map_err(sql)?;
            }
        }
        tx.commit().map_err(sql)?;
        Ok(store)
    }

    /// Opens an existing store to write to it: takes its lock (refused while
    /// another process owns it), then checks it in constant time.
    pub fn open(path: &Path) -> Result<Store, StoreError> {
        let owner = StoreLock::acquire(path)?;
        Store::open_owned(path, owner)
    }

    /// Opens an existing store to write to it under a lock already held.
    pub fn open_owned(path: &Path, owner: StoreLock) -> Result<Store, StoreError> {
        check_file(path)?;
        let sql = |source| StoreError::Sql { path: path.to_path_buf(), source };
        let conn =
            Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_WRITE).map_err(sql)?;
        let store = Store { conn, path: path.to_path_buf(), _owner: Some(owner) };
        store.pragmas()?;
        store.check_shape()?;
        Ok(store)
    }

    /// Opens an existing store to read it (`status`, `export`, analyses): no
    /// lock, no write, works on a read-only file and beside a running sweep.
    pub fn open_read_only(path: &Path) -> Result<Store, StoreError> {
        check_file(path)?;
        let sql = |source| StoreError::Sql { path: path.to_path_buf(), source };
        let flags = OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX;
        let conn = Connection::open_with_flags(path, flags).map_err(sql)?;
        let store = Store { conn, path: path.to_path_buf(), _owner: None };
        store.check_shape()?;
        Ok(store)
    }

    /// The SQLite connection (tests drive checkpoints through it).
    #[cfg(test)]
    pub(crate) fn conn(&self) -> &Connection {
        &self.conn
    }

    fn pragmas(&self) -> Result<(), StoreError> {
        self.conn
            .execute_batch(
                "PRAGMA journal_mode = WAL; PRAGMA synchronous = FULL; PRAGMA foreign_keys = ON;",
            )
            .map_err(|e| self.corrupt_or_sql(e))
    }

    fn corrupt_or_sql(&self, e: rusqlite::Error) -> StoreError {
        match e.sqlite_error_code() {
            Some(rusqlite::ErrorCode::DatabaseCorrupt)
            | Some(rusqlite::ErrorCode::NotADatabase) => {
                StoreError::Corrupt { path: self.path.clone(), reason: e.to_string() }
            }
            _ => StoreError::Sql { path: self.path.clone(), source: e },
        }
    }

    fn corrupt(&self, reason: String) -> StoreError {
        StoreError::Corrupt { path: self.path.clone(), reason }
    }

    /// The constant-time checks: a ceilfarm store of this format whose
    /// design reaches the last task the meta table promises (task ids are
    /// written 0..n in one transaction, so the largest id stands for all).
    fn check_shape(&self) -> Result<(), StoreError> {
        let format = self.meta("format").map_err(|e| match e {
            StoreError::Sql { .. } => self.corrupt("not a ceilfarm store (no meta table)".into()),
            other => other,
        })?;
        if format.as_deref() != Some(STORE_FORMAT) {
            return Err(self.corrupt(format!("format {format:?}, expected {STORE_FORMAT:?}")));
        }
        let n = self.n_tasks()?;
        let last: Option<i64> = self
            .conn
            .query_row("SELECT max(task_id) FROM design", [], |r| r.get(0))
            .map_err(|e| self.corrupt_or_sql(e))?;
        let rows = last.map_or(0, |l| l as usize + 1);
        if rows != n {
            return Err(self.corrupt(format!("design ends at {rows} rows, meta says {n}")));
        }
        Ok(())
    }

    fn n_tasks(&self) -> Result<usize, StoreError> {
        self.meta("n_tasks")?
            .and_then(|v| v.parse().ok())
            .ok_or_else(|| self.corrupt("meta n_tasks missing".into()))
    }

    /// Reads every page: SQLite's `integrity_check`, foreign keys, and the
    /// design's row count against the meta table (`ceilfarm store check`).
    pub fn check_full(&self) -> Result<StoreCheck, StoreError> {
        let mut stmt =
            self.conn.prepare("PRAGMA integrity_check").map_err(|e| self.corrupt_or_sql(e))?;
        let verdicts: Vec<String> = stmt
            .query_map([], |r| r.get(0))
            .and_then(|rows| rows.collect())
            .map_err(|e| self.corrupt_or_sql(e))?;
        if verdicts != ["ok"] {
            return Err(self.corrupt(format!("integrity check failed: {}", verdicts.join("; "))));
        }
        let orphans: i64 = self
            .conn
            .query_row("SELECT count(*) FROM pragma_foreign_key_check", [], |r| r.get(0))
            .map_err(|e| self.corrupt_or_sql(e))?;
        if orphans != 0 {
            return Err(
                self.corrupt(format!("{orphans} rows refer to a missing design point or result"))
            );
        }
        let rows: i64 = self
            .conn
            .query_row("SELECT count(*) FROM design", [], |r| r.get(0))
            .map_err(|e| self.corrupt_or_sql(e))?;
        let n = self.n_tasks()?;
        if rows as usize != n {
            return Err(self.corrupt(format!("design has {rows} rows, meta says {n}")));
        }
        let (ok, failed, _) = self.counts()?;
        Ok(StoreCheck { tasks: n, ok, failed })
    }

    /// A value of the meta table.
    pub fn meta(&self, key: &str) -> Result<Option<String>, StoreError> {
        self.conn
            .query_row("SELECT value FROM meta WHERE key = ?1", [key], |r| r.get(0))
            .optional()
            .map_err(|e| self.corrupt_or_sql(e))
    }

    /// Refuses a study whose result-affecting keys differ, naming each key.
    pub fn check_study(&self, study: &Study) -> Result<(), StoreError> {
        let mut stmt =
            self.conn.prepare("SELECT key, value FROM study_keys").map_err(self.sql())?;
        let stored: BTreeMap<String, String> = stmt
            .query_map([], |r| Ok((r.get(0)?, r.get(1)?)))
            .map_err(self.sql())?
            .collect::<Result<_, _>>()
            .map_err(self.sql())?;
        let given = study.result_keys();
        let mut diffs = Vec::new();
        for key in stored.keys().chain(given.keys().filter(|k| !stored.contains_key(*k))) {
            let (a, b) = (stored.get(key), given.get(key));
            if a != b {
                let show = |v: Option<&String>| {
                    v.map(|s| s.to_string()).unwrap_or_else(|| "(absent)".into())
                };
                diffs.push(format!("{key}: store has {}, study has {}", show(a), show(b)));
            }
        }
        if diffs.is_empty() {
            Ok(())
        } else {
            Err(StoreError::StudyChanged { path: self.path.clone(), diffs })
        }
    }

    /// Records the start of a run session (provenance); returns its id.
    pub fn begin_session(&self, transport: &str, workers: usize) -> Result<i64, StoreError> {
        self.conn
            .execute(
                "INSERT INTO sessions (started_at, host, transport, workers, ceilfarm_version) VALUES (?1, ?2, ?3, ?4, ?5)",
                params![now(), worker::run::host_name(), transport, workers as i64, env!("CARGO_PKG_VERSION")],
            )
            .map_err(self.sql())?;
        Ok(self.conn.last_insert_rowid())
    }

    /// The design (physical units), in task order.
    pub fn design(&self) -> Result<Vec<Vec<f64>>, StoreError> {
        let mut stmt =
            self.conn.prepare("SELECT params FROM design ORDER BY task_id").map_err(self.sql())?;
        let rows = stmt.query_map([], |r| r.get::<_, Vec<u8>>(0)).map_err(self.sql())?;
        rows.map(|b| b.map(|b| bytes_to_f64s(&b)).map_err(self.sql())).collect()
    }

    /// Parameter names, in design-column order.
    pub fn parameter_names(&self) -> Result<Vec<String>, StoreError> {
        let mut stmt =
            self.conn.prepare("SELECT name FROM parameters ORDER BY idx").map_err(self.sql())?;
        let rows = stmt.query_map([], |r| r.get(0)).map_err(self.sql())?;
        rows.collect::<Result<_, _>>().map_err(self.sql())
    }

    /// Tasks without a recorded result, in order.
    pub fn missing(&self) -> Result<Vec<TaskId>, StoreError> {
        self.to_run(false)
    }

    /// Tasks a run should do, in order: those without a result and, with
    /// `retry_failed`, those recorded as failed (model errors, timeouts,
    /// tasks lost with their workers, non-finite outputs).
    pub fn to_run(&self, retry_failed: bool) -> Result<Vec<TaskId>, StoreError> {
        let query = if retry_failed {
            "SELECT task_id FROM design WHERE task_id NOT IN
                (SELECT task_id FROM results WHERE status = 'ok') ORDER BY task_id"
        } else {
            "SELECT task_id FROM design WHERE task_id NOT IN (SELECT task_id FROM results)
                ORDER BY task_id"
        };
        let mut stmt = self.conn.prepare(query).map_err(self.sql())?;
        let rows = stmt.query_map([], |r| r.get::<_, i64>(0)).map_err(self.sql())?;
        rows.map(|r| r.map(|v| TaskId(v as u64)).map_err(self.sql())).collect()
    }

    /// Records results in one transaction. A result already present is
    /// skipped (idempotent) unless it is a failure, which a new result
    /// replaces (`--retry-failed`). Outputs with a NaN or an infinity are
    /// recorded as a failure naming the value. Returns how many were new.
    pub fn record(
        &mut self,
        results: &[TaskResult],
        session: i64,
        keep: &Keep,
    ) -> Result<usize, StoreError> {
        let path = self.path.clone();
        let sql = |source| StoreError::Sql { path: path.clone(), source };
        let tx = self.conn.transaction().map_err(sql)?;
        let mut fresh = 0;
        for r in results {
            let non_finite = match &r.outcome {
                Outcome::Ok(out) => out.non_finite(),
                Outcome::Failed { .. } => None,
            };
            let (status, reason) = match (&r.outcome, &non_finite) {
                (_, Some(why)) => ("failed", Some(why.as_str())),
                (Outcome::Ok(_), None) => ("ok", None),
                (Outcome::Failed { reason }, None) => ("failed", Some(reason.as_str())),
            };
            let added = tx
                .execute(
                    UPSERT_RESULT,
                    params![r.id.0 as i64, status, reason, r.host, r.wall_s, now(), session],
                )
                .map_err(sql)?;
            if added == 0 {
                continue;
            }
            fresh += 1;
            if let (Outcome::Ok(out), None) = (&r.outcome, &non_finite) {
                for (name, value) in out.scalars.iter().filter(|(n, _)| keep.scalar(n)) {
                    tx.execute(
                        "INSERT INTO scalars VALUES (?1, ?2, ?3)",
                        params![r.id.0 as i64, name, value],
                    )
                    .map_err(sql)?;
                }
                if keep.histories {
                    for h in &out.histories {
                        insert_history(&tx, r.id, h).map_err(|e| match e {
                            HistoryError::Sql(s) => sql(s),
                            HistoryError::Io(source) => {
                                StoreError::Io { path: path.clone(), source }
                            }
                        })?;
                    }
                }
            }
        }
        tx.commit().map_err(sql)?;
        Ok(fresh)
    }

    /// Every design point with its result, in task order.
    pub fn rows(&self) -> Result<Vec<RunRow>, StoreError> {
        let design = self.design()?;
        let mut rows: Vec<RunRow> = design
            .into_iter()
            .enumerate()
            .map(|(i, params)| RunRow {
                task: TaskId(i as u64),
                params,
                status: None,
                scalars: BTreeMap::new(),
            })
            .collect();
        let mut stmt =
            self.conn.prepare("SELECT task_id, status, reason FROM results").map_err(self.sql())?;
        let res = stmt
            .query_map([], |r| {
                Ok((r.get::<_, i64>(0)?, r.get::<_, String>(1)?, r.get::<_, Option<String>>(2)?))
            })
            .map_err(self.sql())?;
        for r in res {
            let (id, status, reason) = r.map_err(self.sql())?;
            let row = self.row_mut(&mut rows, id)?;
            row.status = Some(if status == "ok" {
                RunStatus::Ok
            } else {
                RunStatus::Failed(reason.unwrap_or_default())
            });
        }
        let mut stmt =
            self.conn.prepare("SELECT task_id, name, value FROM scalars").map_err(self.sql())?;
        let sc = stmt
            .query_map([], |r| {
                Ok((r.get::<_, i64>(0)?, r.get::<_, String>(1)?, r.get::<_, f64>(2)?))
            })
            .map_err(self.sql())?;
        for s in sc {
            let (id, name, value) = s.map_err(self.sql())?;
            self.row_mut(&mut rows, id)?.scalars.insert(name, value);
        }
        Ok(rows)
    }

    fn row_mut<'a>(&self, rows: &'a mut [RunRow], id: i64) -> Result<&'a mut RunRow, StoreError> {
        let n = rows.len();
        rows.get_mut(id as usize).ok_or_else(|| StoreError::Corrupt {
            path: self.path.clone(),
            reason: format!("result for task {id} outside the design of {n} points"),
        })
    }

    /// Scalar output names, in the model's order.
    pub fn scalar_names(&self) -> Result<Vec<String>, StoreError> {
        let text = self.meta("output_names")?.unwrap_or_else(|| "[]".into());
        serde_json::from_str(&text).map_err(|e| StoreError::Corrupt {
            path: self.path.clone(),
            reason: format!("meta output_names: {e}"),
        })
    }

    /// Time histories of one task.
    pub fn histories(&self, task: TaskId) -> Result<Vec<History>, StoreError> {
        let mut stmt = self
            .conn
            .prepare(
                "SELECT name, dt_s, channels, data FROM histories WHERE task_id = ?1 ORDER BY name",
            )
            .map_err(self.sql())?;
        let rows = stmt
            .query_map([task.0 as i64], |r| {
                Ok((
                    r.get::<_, String>(0)?,
                    r.get::<_, f64>(1)?,
                    r.get::<_, String>(2)?,
                    r.get::<_, Vec<u8>>(3)?,
                ))
            })
            .map_err(self.sql())?;
        let mut out = Vec::new();
        for r in rows {
            let (name, dt_s, channels, blob) = r.map_err(self.sql())?;
            let raw = zstd::decode_all(blob.as_slice()).map_err(|e| StoreError::Corrupt {
                path: self.path.clone(),
                reason: format!("history {name} of task {}: {e}", task.0),
            })?;
            let channels = serde_json::from_str(&channels).unwrap_or_default();
            out.push(History { name, dt_s, channels, data: bytes_to_f64s(&raw) });
        }
        Ok(out)
    }

    /// Counts of (done ok, failed, missing).
    pub fn counts(&self) -> Result<(usize, usize, usize), StoreError> {
        let q = |s: &str| -> Result<usize, StoreError> {
            self.conn
                .query_row(s, [], |r| r.get::<_, i64>(0))
                .map(|v| v as usize)
                .map_err(self.sql())
        };
        let ok = q("SELECT count(*) FROM results WHERE status = 'ok'")?;
        let failed = q("SELECT count(*) FROM results WHERE status = 'failed'")?;
        let total = q("SELECT count(*) FROM design")?;
        Ok((ok, failed, total.saturating_sub(ok + failed)))
    }
}

/// Which outputs a study keeps.
#[derive(Debug, Clone, Default)]
pub struct Keep {
    /// Scalars to keep; empty keeps all.
    pub scalars: Vec<String>,
    /// Whether to store time histories.
    pub histories: bool,
}

impl Keep {
    /// Whether the named scalar is kept.
    pub fn scalar(&self, name: &str) -> bool {
        self.scalars.is_empty() || self.scalars.iter().any(|s| s == name)
    }
}

enum HistoryError {
    Sql(rusqlite::Error),
    Io(std::io::Error),
}

fn insert_history(
    tx: &rusqlite::Transaction<'_>,
    id: TaskId,
    h: &History,
) -> Result<(), HistoryError> {
    let blob = zstd::encode_all(f64s_to_bytes(&h.data).as_slice(), 3).map_err(HistoryError::Io)?;
    let channels = serde_json::to_string(&h.channels).unwrap_or_default();
    tx.execute(
        "INSERT INTO histories VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
        params![id.0 as i64, h.name, h.dt_s, channels, h.n_samples() as i64, blob],
    )
    .map_err(HistoryError::Sql)?;
    Ok(())
}

fn spec_json(study: &Study) -> serde_json::Value {
    serde_json::json!({
        "kind": study.model_kind,
        "options": study.model_options,
        "parameters": study.parameters.iter().map(|p| serde_json::json!({
            "name": p.name, "low": format_value(p.low), "high": format_value(p.high), "units": p.units,
        })).collect::<Vec<_>>(),
    })
}

/// Little-endian bytes of a float slice.
pub fn f64s_to_bytes(v: &[f64]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// Floats from little-endian bytes (a partial trailing value is dropped).
pub fn bytes_to_f64s(b: &[u8]) -> Vec<f64> {
    b.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8]))).collect()
}
