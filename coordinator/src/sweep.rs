//! A sweep end to end: study → design → store → farm → store, resumable.

use crate::design;
use crate::farm::{run_farm, FarmSettings, FarmSummary, ResultSink};
use crate::progress::{bar, SweepProgress};
use crate::store::{Keep, Store, StoreError};
use crate::store_lock::StoreLock;
use crate::study::Study;
use protocol::{Task, TaskId, TaskResult, Transport};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Why a sweep could not run.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The store already exists and `--resume` was not given.
    #[error("{0}: store exists; pass --resume to finish it, or choose another --store")]
    Exists(PathBuf),
    /// The store refused.
    #[error(transparent)]
    Store(#[from] StoreError),
    /// The model cannot be built.
    #[error("model: {0}")]
    Model(String),
    /// The farm stopped.
    #[error(transparent)]
    Farm(#[from] crate::farm::FarmError),
    /// The transport is not available.
    #[error(transparent)]
    Transport(#[from] crate::transports::TransportChoiceError),
}

/// How to run a sweep.
#[derive(Debug, Clone)]
pub struct SweepOptions {
    /// The store file.
    pub store: PathBuf,
    /// Continue an existing store.
    pub resume: bool,
    /// With `resume`, also run again the tasks recorded as failed.
    pub retry_failed: bool,
    /// Worker count (overrides the study).
    pub workers: Option<usize>,
    /// No progress bar.
    pub quiet: bool,
    /// Transport (overrides the study).
    pub transport: Option<crate::study::TransportKind>,
    /// Transport endpoint (overrides the study).
    pub endpoint: Option<String>,
    /// zenoh's security: configuration file and `--insecure`.
    pub zenoh: crate::transports::ZenohSecurity,
}

/// What a sweep did.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SweepReport {
    /// Study name.
    pub study: String,
    /// Store file.
    pub store: String,
    /// Design size.
    pub tasks: usize,
    /// Results already in the store before this run.
    pub already_done: usize,
    /// Tasks finished with outputs in this run.
    pub ok: usize,
    /// Tasks recorded as failed in this run.
    pub failed: usize,
    /// Extra tries (retries, re-issues).
    pub reissued: usize,
    /// Workers used.
    pub workers: usize,
    /// Wall time of this run in seconds.
    pub wall_s: f64,
}

struct StoreSink<'a> {
    store: &'a mut Store,
    session: i64,
    keep: Keep,
}

impl ResultSink for StoreSink<'_> {
    fn accept(&mut self, results: &[TaskResult]) -> Result<(), String> {
        self.store.record(results, self.session, &self.keep).map(|_| ()).map_err(|e| e.to_string())
    }
}

/// Opens the study's store (resuming) or creates it with a fresh design,
/// owning it (its lock) until the store is dropped: a second coordinator on
/// the same path is refused before it looks at the file.
pub fn open_or_create(study: &Study, path: &Path, resume: bool) -> Result<Store, SweepError> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|source| StoreError::Io { path: dir.to_path_buf(), source })?;
    }
    let owner = StoreLock::acquire(path).map_err(StoreError::from)?;
    if path.exists() {
        if !resume {
            return Err(SweepError::Exists(path.to_path_buf()));
        }
        let store = Store::open_owned(path, owner)?;
        store.check_study(study)?;
        return Ok(store);
    }
    let unit = design::draw(
        study.design.method,
        study.design.n,
        study.parameters.len(),
        study.design.seed,
    );
    let physical = unit.to_physical(&study.parameters);
    let model = worker::registry::build(&study.model_spec())
        .map_err(|e| SweepError::Model(e.to_string()))?;
    let keep = Keep { scalars: study.outputs.clone(), histories: study.keep_histories };
    let outputs: Vec<String> =
        model.output_names().into_iter().filter(|n| keep.scalar(n)).collect();
    // Build under a temporary name so a crash never leaves a half-made store.
    let tmp = path.with_extension(format!("tmp-{}", std::process::id()));
    let _ = std::fs::remove_file(&tmp);
    drop(Store::create(&tmp, study, &physical, &outputs)?);
    std::fs::rename(&tmp, path)
        .map_err(|source| StoreError::Io { path: path.to_path_buf(), source })?;
    Ok(Store::open_owned(path, owner)?)
}

/// Runs (or resumes) a sweep on the study's (or the options') transport.
pub fn run_sweep(study: &Study, opts: &SweepOptions) -> Result<SweepReport, SweepError> {
    let workers = opts.workers.unwrap_or(study.farm.workers).max(1);
    let kind = opts.transport.unwrap_or(study.farm.transport);
    let endpoint = opts.endpoint.as_deref().or(study.farm.endpoint.as_deref());
    let transport =
        crate::transports::coordinator_transport_secured(kind, workers, endpoint, &opts.zenoh)?;
    run_sweep_on(study, opts, transport, workers)
}

/// Runs (or resumes) a sweep on a given transport.
pub fn run_sweep_on(
    study: &Study,
    opts: &SweepOptions,
    mut transport: Box<dyn Transport>,
    workers: usize,
) -> Result<SweepReport, SweepError> {
    let start = Instant::now();
    let mut store = open_or_create(study, &opts.store, opts.resume)?;
    let design = store.design()?;
    let missing = store.to_run(opts.resume && opts.retry_failed)?;
    let tasks: Vec<Task> = missing
        .iter()
        .map(|&TaskId(i)| Task { id: TaskId(i), params: design[i as usize].clone() })
        .collect();
    let already_done = design.len() - tasks.len();
    let session = store.begin_session(transport.name(), workers)?;
    let settings = FarmSettings {
        task_timeout: Duration::from_secs_f64(study.farm.task_timeout_s),
        max_retries: study.farm.max_retries,
        ..FarmSettings::default()
    };
    let mut progress = SweepProgress {
        bar: bar(design.len() as u64, already_done as u64, opts.quiet, &study.name),
        failed: 0,
    };
    let keep = Keep { scalars: study.outputs.clone(), histories: study.keep_histories };
    let mut sink = StoreSink { store: &mut store, session, keep };
    let summary: FarmSummary = run_farm(
        transport.as_mut(),
        &study.hash(),
        &study.model_spec(),
        tasks,
        &settings,
        &mut sink,
        &mut progress,
    )?;
    progress.bar.finish_and_clear();
    Ok(SweepReport {
        study: study.name.clone(),
        store: opts.store.display().to_string(),
        tasks: design.len(),
        already_done,
        ok: summary.ok,
        failed: summary.failed,
        reissued: summary.reissued,
        workers,
        wall_s: start.elapsed().as_secs_f64(),
    })
}
