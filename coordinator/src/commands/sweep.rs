//! `run`, `design`, `export` and `status`: the sweep subcommands.

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use coordinator::store::Store;
use coordinator::study::{format_value, Study, TransportKind};
use coordinator::sweep::{run_sweep, SweepOptions};
use coordinator::transports::ZenohSecurity;
use std::path::PathBuf;

/// How a sweep is farmed out: the options `run` and `pipeline` share.
#[derive(Args)]
pub struct FarmArgs {
    /// Number of workers (default: the study's, else the machine's cores;
    /// 2 for `diagnose`).
    #[arg(long)]
    pub workers: Option<usize>,
    /// Transport (default: the study's [farm] transport, else in-process).
    #[arg(long, value_enum)]
    pub transport: Option<TransportKind>,
    /// Where the coordinator listens (zenoh, e.g. tls/0.0.0.0:7447; default
    /// the --zenoh-config file's, else tcp/127.0.0.1:7447) or the service
    /// prefix (iceoryx2).
    #[arg(long)]
    pub endpoint: Option<String>,
    /// zenoh's own JSON5 configuration: TLS with mutual authentication and
    /// access control (`ceilfarm farm certs` writes one).
    #[arg(long, value_name = "FILE")]
    pub zenoh_config: Option<PathBuf>,
    /// Let zenoh listen beyond loopback without TLS with mutual
    /// authentication: anyone who reaches the port may join (docs/farm.md).
    #[arg(long)]
    pub insecure: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

impl FarmArgs {
    /// Sweep options for `store`; refuses `--workers 0`.
    pub fn options(&self, store: PathBuf, resume: bool) -> Result<SweepOptions> {
        if self.workers == Some(0) {
            bail!("--workers 0: expected at least 1 worker");
        }
        Ok(SweepOptions {
            store,
            resume,
            retry_failed: false,
            workers: self.workers,
            quiet: self.quiet,
            transport: self.transport,
            endpoint: self.endpoint.clone(),
            zenoh: ZenohSecurity { config: self.zenoh_config.clone(), insecure: self.insecure },
        })
    }
}

/// `ceilfarm run`: run or resume a sweep.
#[derive(Args)]
pub struct RunArgs {
    /// The study file (TOML).
    pub study: PathBuf,
    /// The dataset store (SQLite) to create or, with --resume, to finish.
    #[arg(long)]
    pub store: PathBuf,
    /// Finish an interrupted sweep: run only what the store is missing
    /// (starts afresh if the store does not exist yet).
    #[arg(long)]
    pub resume: bool,
    /// With --resume, also run again the tasks recorded as failed (model
    /// errors, timeouts, tasks lost with their workers, non-finite outputs);
    /// a new result replaces the failure.
    #[arg(long, requires = "resume")]
    pub retry_failed: bool,
    /// Workers, transport, progress.
    #[command(flatten)]
    pub farm: FarmArgs,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `ceilfarm run`.
pub fn run(args: RunArgs) -> Result<()> {
    let study = Study::load(&args.study)?;
    let mut opts = args.farm.options(args.store, args.resume)?;
    opts.retry_failed = args.retry_failed;
    let report = run_sweep(&study, &opts)?;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else if !args.farm.quiet {
        eprintln!(
            "{}: {} runs in the store ({} before this run, {} ok and {} failed now) in {:.2} s with {} workers",
            report.store, report.tasks, report.already_done, report.ok, report.failed, report.wall_s, report.workers
        );
    }
    Ok(())
}

/// `ceilfarm design`: write a study's design in physical units.
#[derive(Args)]
pub struct DesignArgs {
    /// The study file (TOML).
    pub study: PathBuf,
    /// Output CSV (`task_id` then one column per parameter).
    #[arg(long)]
    pub out: PathBuf,
}

/// `ceilfarm design`.
pub fn design(args: DesignArgs) -> Result<()> {
    let study = Study::load(&args.study)?;
    let unit = coordinator::design::draw(
        study.design.method,
        study.design.n,
        study.parameters.len(),
        study.design.seed,
    );
    let mut w =
        csv::Writer::from_path(&args.out).with_context(|| args.out.display().to_string())?;
    let mut header = vec!["task_id".to_string()];
    header.extend(study.parameters.iter().map(|p| p.name.clone()));
    w.write_record(&header)?;
    for (i, row) in unit.to_physical(&study.parameters).iter().enumerate() {
        let mut rec = vec![i.to_string()];
        rec.extend(row.iter().map(|v| format_value(*v)));
        w.write_record(&rec)?;
    }
    w.flush()?;
    Ok(())
}

/// Export formats.
#[derive(Clone, Copy, ValueEnum)]
pub enum ExportFormat {
    /// Comma-separated text.
    Csv,
    /// Apache Parquet.
    Parquet,
}

/// `ceilfarm export`: a store as a table.
#[derive(Args)]
pub struct ExportArgs {
    /// The dataset store.
    pub store: PathBuf,
    /// Output format.
    #[arg(long, value_enum, default_value_t = ExportFormat::Csv)]
    pub format: ExportFormat,
    /// Output file.
    #[arg(long)]
    pub out: PathBuf,
    /// Also write each run's time histories into this directory.
    #[arg(long)]
    pub histories: Option<PathBuf>,
}

/// `ceilfarm export`.
pub fn export(args: ExportArgs) -> Result<()> {
    let store = Store::open_read_only(&args.store)?;
    match args.format {
        ExportFormat::Csv => coordinator::export::export_csv(&store, &args.out)?,
        ExportFormat::Parquet => coordinator::export_parquet::export_parquet(&store, &args.out)?,
    };
    if let Some(dir) = &args.histories {
        coordinator::export::export_histories(&store, dir)?;
    }
    Ok(())
}

/// `ceilfarm status`: what a store holds.
#[derive(Args)]
pub struct StatusArgs {
    /// The dataset store.
    pub store: PathBuf,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

/// `ceilfarm status`.
pub fn status(args: StatusArgs) -> Result<()> {
    let store = Store::open_read_only(&args.store)?;
    let (ok, failed, missing) = store.counts()?;
    let name = store.meta("study_name")?.unwrap_or_default();
    let hash = store.meta("study_hash")?.unwrap_or_default();
    if args.json {
        let v = serde_json::json!({"study": name, "hash": hash, "ok": ok, "failed": failed,
            "missing": missing});
        println!("{v}");
    } else {
        let short = &hash[..hash.len().min(16)];
        println!("{name} ({short}): {ok} ok, {failed} failed, {missing} missing");
    }
    Ok(())
}
