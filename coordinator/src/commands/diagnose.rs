//! `ceilfarm diagnose BUNDLE --out DIR`: check the bundle, calibrate the
//! baseline and its extensions, name the cause, write `diagnosis.json` and
//! `report.html`.

use anyhow::{bail, Context, Result};
use clap::Args as ClapArgs;
use coordinator::diagnose::calibrate::Budget;
use coordinator::diagnose::pipeline::{diagnose, DiagnoseOptions};
use coordinator::diagnose::verdict::verdict;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};

/// Arguments of `diagnose`.
#[derive(ClapArgs)]
pub struct Args {
    /// The bundle directory.
    pub bundle: PathBuf,
    /// Output directory (diagnosis.json, report.html).
    #[arg(long)]
    pub out: PathBuf,
    /// Threads running FE simulations.
    #[arg(long, default_value_t = 2)]
    pub workers: usize,
    /// Transport to the workers (this command runs them in-process).
    #[arg(long, default_value = "in-process")]
    pub transport: String,
    /// Design points per calibrated parameter.
    #[arg(long, default_value_t = 5)]
    pub points_per_parameter: usize,
    /// Seed of the calibration designs.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// Runs `diagnose`.
pub fn run(a: Args) -> Result<()> {
    if a.transport != "in-process" {
        bail!(
            "--transport {}: diagnose runs its FE simulations in-process only (use --workers N)",
            a.transport
        );
    }
    if a.workers == 0 {
        bail!("--workers 0: expected at least 1");
    }
    let budget = Budget {
        threads: a.workers,
        per_dim: a.points_per_parameter,
        seed: a.seed,
        ..Budget::default()
    };
    let path = diagnose_dir(&a.bundle, &a.out, &DiagnoseOptions { budget, ..Default::default() })?;
    println!("report: {}", path.display());
    Ok(())
}

/// Diagnoses the bundle in `dir`, writes the verdict and report to `out`;
/// returns the report's path.
pub fn diagnose_dir(dir: &Path, out: &Path, opts: &DiagnoseOptions) -> Result<PathBuf> {
    let bundle = coordinator::bundle::read_bundle(dir)?;
    eprintln!("{}", bundle.summary());
    let bar = ProgressBar::new(1);
    bar.set_style(
        ProgressStyle::with_template("{msg:28} [{bar:30}] {pos}/{len} FE points {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let d = diagnose(&bundle, opts, &mut |stage, done, planned| {
        bar.set_message(stage.to_string());
        bar.set_length(planned as u64);
        bar.set_position(done as u64);
    })
    .map_err(anyhow::Error::msg)?;
    bar.finish_and_clear();
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let ids: Vec<String> = bundle.manifest.runs.iter().map(|r| r.id.clone()).collect();
    let v = verdict(&d, &ids);
    let json = out.join("diagnosis.json");
    std::fs::write(&json, serde_json::to_string_pretty(&v)?)
        .with_context(|| format!("writing {}", json.display()))?;
    let report = out.join("report.html");
    let html = coordinator::diagnose::report::render(&bundle, &d);
    std::fs::write(&report, html).with_context(|| format!("writing {}", report.display()))?;
    eprintln!(
        "cause: {} (gain {:.3}: validation error {:.3} -> {:.3}; {} FE points)",
        v.cause, v.gain, v.baseline_validation_error, v.extended_validation_error, v.fe_points
    );
    Ok(report)
}
