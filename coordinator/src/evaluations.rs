//! The evaluation store: one SQLite file (WAL) keeping every FE evaluation
//! an adaptive computation (a diagnosis) asks the farm for, keyed by study
//! hash and the exact parameter values (little-endian f64 bytes), with its
//! outcome: scalars and time histories bit for bit (f64 bytes, histories
//! zstd-compressed), or the failure's reason. Each batch of results is one
//! transaction, so a `kill -9` loses at most the evaluations in flight; a
//! computation that asks again for a stored point gets the stored outcome.
//!
//! Histories are kept whole (a resumed computation needs them bit for
//! bit): about 90 kB per evaluation per thousand samples of five sensors
//! over three runs (the demo's store: 233 evaluations, 22 MB).
//!
//! Format `ceilfarm-evaluations/1`. A sweep's store (`store.rs`,
//! `ceilfarm-store/1`) holds one study with a design fixed up front; here
//! the points are chosen as results arrive and many studies share a file.

use crate::store::{bytes_to_f64s, check_file, f64s_to_bytes};
use protocol::{History, ModelSpec, Outcome, Outputs, TaskResult};
use rusqlite::{params, Connection, OpenFlags, OptionalExtension};
use std::path::{Path, PathBuf};

/// Version of the layout.
pub const EVALUATIONS_FORMAT: &str = "ceilfarm-evaluations/1";

/// Why the evaluation store cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum EvaluationStoreError {
    /// SQLite failed.
    #[error("{path}: {source}")]
    Sql {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: rusqlite::Error,
    },
    /// Not an evaluation store, or damaged.
    #[error("{path}: {reason}; refusing to use it (move it aside and start again)")]
    Corrupt {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// Compressing or reading a history failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

const SCHEMA: &str = "
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE studies (hash TEXT PRIMARY KEY, kind TEXT NOT NULL, param_names TEXT NOT NULL,
    options BLOB NOT NULL, created_at TEXT NOT NULL);
CREATE TABLE evaluations (id INTEGER PRIMARY KEY, study TEXT NOT NULL REFERENCES studies(hash),
    params BLOB NOT NULL, status TEXT NOT NULL, reason TEXT, scalar_names TEXT NOT NULL,
    scalar_values BLOB NOT NULL, host TEXT NOT NULL, wall_s REAL NOT NULL,
    finished_at TEXT NOT NULL, UNIQUE (study, params));
CREATE TABLE histories (evaluation INTEGER NOT NULL REFERENCES evaluations(id),
    idx INTEGER NOT NULL, name TEXT NOT NULL, dt_s BLOB NOT NULL, channels TEXT NOT NULL,
    data BLOB NOT NULL, PRIMARY KEY (evaluation, idx)) WITHOUT ROWID;
";

/// An open evaluation store.
pub struct EvaluationStore {
    conn: Connection,
    path: PathBuf,
}

fn now() -> String {
    let t = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default();
    format!("{:.3}", t.as_secs_f64())
}

impl EvaluationStore {
    fn sql(&self) -> impl Fn(rusqlite::Error) -> EvaluationStoreError + '_ {
        |source| EvaluationStoreError::Sql { path: self.path.clone(), source }
    }

    /// Opens the store at `path`, creating it (and its directory) if absent.
    pub fn open_or_create(path: &Path) -> Result<Self, EvaluationStoreError> {
        if path.exists() {
            return Self::open(path);
        }
        let io = |source| EvaluationStoreError::Io { path: path.to_path_buf(), source };
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(io)?;
        }
        // Made under a temporary name so a crash never leaves a half-made store.
        let tmp = path.with_extension(format!("tmp-{}", std::process::id()));
        let _ = std::fs::remove_file(&tmp);
        {
            let sql = |source| EvaluationStoreError::Sql { path: tmp.clone(), source };
            let conn = Connection::open(&tmp).map_err(sql)?;
            conn.execute_batch(SCHEMA).map_err(sql)?;
            conn.execute("INSERT INTO meta VALUES ('format', ?1)", [EVALUATIONS_FORMAT])
                .map_err(sql)?;
            conn.execute("INSERT INTO meta VALUES ('created_at', ?1)", [now()]).map_err(sql)?;
        }
        std::fs::rename(&tmp, path).map_err(io)?;
        Self::open(path)
    }

    /// Opens an existing store after checking that it is whole and of this format.
    pub fn open(path: &Path) -> Result<Self, EvaluationStoreError> {
        let corrupt =
            |reason: String| EvaluationStoreError::Corrupt { path: path.to_path_buf(), reason };
        check_file(path).map_err(|e| corrupt(e.to_string()))?;
        let sql = |source| EvaluationStoreError::Sql { path: path.to_path_buf(), source };
        let conn =
            Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_WRITE).map_err(sql)?;
        conn.execute_batch(
            "PRAGMA journal_mode = WAL; PRAGMA synchronous = NORMAL; PRAGMA foreign_keys = ON;",
        )
        .map_err(|e| corrupt(e.to_string()))?;
        let verdict: String = conn
            .query_row("PRAGMA quick_check", [], |r| r.get(0))
            .map_err(|e| corrupt(e.to_string()))?;
        if verdict != "ok" {
            return Err(corrupt(format!("integrity check failed: {verdict}")));
        }
        let format: Option<String> = conn
            .query_row("SELECT value FROM meta WHERE key = 'format'", [], |r| r.get(0))
            .optional()
            .map_err(|_| corrupt("not a ceilfarm evaluation store (no meta table)".into()))?;
        if format.as_deref() != Some(EVALUATIONS_FORMAT) {
            return Err(corrupt(format!("format {format:?}, expected {EVALUATIONS_FORMAT:?}")));
        }
        Ok(Self { conn, path: path.to_path_buf() })
    }

    /// The store file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Records a study (once; provenance of its evaluations).
    pub fn add_study(&self, hash: &str, spec: &ModelSpec) -> Result<(), EvaluationStoreError> {
        let options = zstd::encode_all(spec.options_json.as_bytes(), 3)
            .map_err(|source| EvaluationStoreError::Io { path: self.path.clone(), source })?;
        let names = serde_json::to_string(&spec.param_names).unwrap_or_default();
        self.conn
            .execute(
                "INSERT OR IGNORE INTO studies VALUES (?1, ?2, ?3, ?4, ?5)",
                params![hash, spec.kind, names, options, now()],
            )
            .map_err(self.sql())?;
        Ok(())
    }

    /// The stored outcome of `params` in study `hash`, if any.
    pub fn get(&self, hash: &str, params: &[f64]) -> Result<Option<Outcome>, EvaluationStoreError> {
        let row = self
            .conn
            .query_row(
                "SELECT id, status, reason, scalar_names, scalar_values FROM evaluations WHERE study = ?1 AND params = ?2",
                params![hash, f64s_to_bytes(params)],
                |r| {
                    Ok((
                        r.get::<_, i64>(0)?,
                        r.get::<_, String>(1)?,
                        r.get::<_, Option<String>>(2)?,
                        r.get::<_, String>(3)?,
                        r.get::<_, Vec<u8>>(4)?,
                    ))
                },
            )
            .optional()
            .map_err(self.sql())?;
        let Some((id, status, reason, names, values)) = row else { return Ok(None) };
        if status != "ok" {
            return Ok(Some(Outcome::Failed { reason: reason.unwrap_or_default() }));
        }
        let names: Vec<String> = serde_json::from_str(&names).map_err(|e| self.corrupt(id, e))?;
        let scalars = names.into_iter().zip(bytes_to_f64s(&values)).collect();
        Ok(Some(Outcome::Ok(Outputs { scalars, histories: self.histories(id)? })))
    }

    fn corrupt(&self, id: i64, e: impl std::fmt::Display) -> EvaluationStoreError {
        EvaluationStoreError::Corrupt {
            path: self.path.clone(),
            reason: format!("evaluation {id}: {e}"),
        }
    }

    fn histories(&self, id: i64) -> Result<Vec<History>, EvaluationStoreError> {
        let mut stmt = self
            .conn
            .prepare("SELECT name, dt_s, channels, data FROM histories WHERE evaluation = ?1 ORDER BY idx")
            .map_err(self.sql())?;
        let rows = stmt
            .query_map([id], |r| {
                Ok((
                    r.get::<_, String>(0)?,
                    r.get::<_, Vec<u8>>(1)?,
                    r.get::<_, String>(2)?,
                    r.get::<_, Vec<u8>>(3)?,
                ))
            })
            .map_err(self.sql())?;
        let mut out = Vec::new();
        for row in rows {
            let (name, dt, channels, blob) = row.map_err(self.sql())?;
            let raw = zstd::decode_all(blob.as_slice()).map_err(|e| self.corrupt(id, e))?;
            let channels = serde_json::from_str(&channels).map_err(|e| self.corrupt(id, e))?;
            let dt_s =
                bytes_to_f64s(&dt).first().copied().ok_or_else(|| self.corrupt(id, "dt_s"))?;
            out.push(History { name, dt_s, channels, data: bytes_to_f64s(&raw) });
        }
        Ok(out)
    }

    /// Records results of study `hash`, each with its parameters, in one
    /// transaction; a point already stored is kept as it was. Returns how
    /// many were new.
    pub fn record(
        &mut self,
        hash: &str,
        results: &[(&[f64], &TaskResult)],
    ) -> Result<usize, EvaluationStoreError> {
        let path = self.path.clone();
        let sql = |source| EvaluationStoreError::Sql { path: path.clone(), source };
        let tx = self.conn.transaction().map_err(sql)?;
        let mut fresh = 0;
        for (params, r) in results {
            let (status, reason, scalars) = match &r.outcome {
                Outcome::Ok(out) => ("ok", None, out.scalars.as_slice()),
                Outcome::Failed { reason } => ("failed", Some(reason.as_str()), &[][..]),
            };
            let names: Vec<&str> = scalars.iter().map(|(n, _)| n.as_str()).collect();
            let values: Vec<f64> = scalars.iter().map(|(_, v)| *v).collect();
            let added = tx
                .execute(
                    "INSERT OR IGNORE INTO evaluations (study, params, status, reason, scalar_names, scalar_values, host, wall_s, finished_at) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)",
                    params![
                        hash,
                        f64s_to_bytes(params),
                        status,
                        reason,
                        serde_json::to_string(&names).unwrap_or_default(),
                        f64s_to_bytes(&values),
                        r.host,
                        r.wall_s,
                        now()
                    ],
                )
                .map_err(sql)?;
            if added == 0 {
                continue;
            }
            fresh += 1;
            let id = tx.last_insert_rowid();
            if let Outcome::Ok(out) = &r.outcome {
                for (k, h) in out.histories.iter().enumerate() {
                    let blob = zstd::encode_all(f64s_to_bytes(&h.data).as_slice(), 3).map_err(
                        |source| EvaluationStoreError::Io { path: path.clone(), source },
                    )?;
                    let channels = serde_json::to_string(&h.channels).unwrap_or_default();
                    tx.execute(
                        "INSERT INTO histories VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
                        params![id, k as i64, h.name, f64s_to_bytes(&[h.dt_s]), channels, blob],
                    )
                    .map_err(sql)?;
                }
            }
        }
        tx.commit().map_err(sql)?;
        Ok(fresh)
    }

    /// Evaluations stored (ok and failed).
    pub fn len(&self) -> Result<usize, EvaluationStoreError> {
        self.conn
            .query_row("SELECT count(*) FROM evaluations", [], |r| r.get::<_, i64>(0))
            .map(|n| n as usize)
            .map_err(self.sql())
    }

    /// Whether no evaluation is stored.
    pub fn is_empty(&self) -> Result<bool, EvaluationStoreError> {
        self.len().map(|n| n == 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use protocol::TaskId;

    fn result(outcome: Outcome) -> TaskResult {
        TaskResult { id: TaskId(0), outcome, wall_s: 0.5, host: "h".into() }
    }

    #[test]
    fn outcomes_come_back_bit_for_bit_and_points_are_stored_once() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub").join("e.db");
        let mut store = EvaluationStore::open_or_create(&path).unwrap();
        let spec = ModelSpec {
            kind: "k".into(),
            options_json: "{}".into(),
            param_names: vec!["a".into()],
            outputs: vec![],
        };
        store.add_study("h1", &spec).unwrap();
        let tiny = f64::from_bits(1);
        let out = Outputs {
            scalars: vec![("s".into(), 0.1 + 0.2), ("n".into(), f64::NAN)],
            histories: vec![History {
                name: "r/A".into(),
                dt_s: 0.1 / 3.0,
                channels: vec!["A_accel_m_s2".into()],
                data: vec![tiny, -0.0, 1e300, 1.0 / 3.0],
            }],
        };
        let ok = result(Outcome::Ok(out.clone()));
        let bad = result(Outcome::Failed { reason: "run r: diverged".into() });
        let (p1, p2) = ([0.1 + 0.2], [0.3]);
        assert_eq!(store.record("h1", &[(&p1, &ok), (&p2, &bad)]).unwrap(), 2);
        assert_eq!(store.record("h1", &[(&p1, &bad)]).unwrap(), 0);
        drop(store);
        let store = EvaluationStore::open(&path).unwrap();
        assert_eq!(store.len().unwrap(), 2);
        let Some(Outcome::Ok(back)) = store.get("h1", &p1).unwrap() else { panic!("stored ok") };
        let bits = |o: &Outputs| -> Vec<u64> {
            let s = o.scalars.iter().map(|(_, v)| v.to_bits());
            let h = o.histories.iter().flat_map(|h| h.data.iter().map(|v| v.to_bits()));
            s.chain(h).chain(o.histories.iter().map(|h| h.dt_s.to_bits())).collect()
        };
        assert_eq!(bits(&back), bits(&out));
        assert_eq!(back.histories[0].name, "r/A");
        assert_eq!(store.get("h1", &p2).unwrap(), Some(bad.outcome));
        assert_eq!(store.get("h2", &p1).unwrap(), None);
    }

    #[test]
    fn other_files_are_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.db");
        std::fs::write(&path, b"not a database at all, just text".repeat(10)).unwrap();
        let e = EvaluationStore::open_or_create(&path).err().unwrap().to_string();
        assert!(e.contains("not a SQLite database"), "{e}");
    }
}
