//! `ceilfarm pipeline`: the seed's chapter 6 end to end. A sweep through the
//! farm into a store (resumable), GP emulators of the observed outputs
//! (70/20/10 split, kernel by validation RMSE), Sobol' screening,
//! Kennedy–O'Hagan calibration by BBVI against the measured values, and
//! model selection over parameter subsets. Every stage writes its files in
//! the output folder; a rerun resumes the sweep and redoes the analysis.

pub mod calibration;
pub mod config;
pub mod emulators;
pub mod report;
pub mod screening;
pub mod selection;

use crate::commands::sweep::FarmArgs;
use anyhow::{Context, Result};
use clap::Args as ClapArgs;
use config::PipelineConfig;
use coordinator::sweep::run_sweep;
use stats::calibration::GpEmulator;
use std::path::{Path, PathBuf};

/// `ceilfarm pipeline`.
#[derive(ClapArgs)]
pub struct Args {
    /// The pipeline file (a study plus [emulator], [sensitivity],
    /// [observations], [calibration], [selection]).
    pub config: PathBuf,
    /// Output folder (sweep.db and one file per stage); rerun to resume.
    #[arg(long)]
    pub out: PathBuf,
    /// Workers, transport, progress (as for `run`).
    #[command(flatten)]
    pub farm: FarmArgs,
}

/// Writes `text` to `dir/name`.
fn write(dir: &Path, name: &str, text: &str) -> Result<()> {
    let path = dir.join(name);
    std::fs::write(&path, text).with_context(|| format!("{}: cannot write", path.display()))
}

/// Runs the pipeline.
pub fn run(args: Args) -> Result<()> {
    let cfg = PipelineConfig::load(&args.config)?;
    let out = &args.out;
    std::fs::create_dir_all(out).with_context(|| format!("{}: cannot create", out.display()))?;
    let mut stages = report::Stages::new(args.farm.quiet);

    stages.start("sweep");
    let store = out.join("sweep.db");
    let opts = args.farm.options(store.clone(), true)?;
    let sweep = run_sweep(&cfg.study, &opts)?;
    stages.done(&format!("{} runs ({} failed now) in the store", sweep.tasks, sweep.failed));

    stages.start("emulators");
    let names: Vec<String> = cfg.study.parameters.iter().map(|p| p.name.clone()).collect();
    let bounds: Vec<(f64, f64)> = cfg.study.parameters.iter().map(|p| (p.low, p.high)).collect();
    let obs = &cfg.analysis.observations;
    let data = emulators::dataset(&store, &names, &bounds, &obs.outputs)?;
    let (gps, emus, split) = emulators::fit_all(&data, &cfg.analysis.emulator)?;
    let file = emulators::model_file(&data, &gps, &emus, &split, &store.display().to_string());
    write(out, "emulators.json", &serde_json::to_string_pretty(&file)?)?;
    stages.done(&report::emulator_line(&emus, &split));

    stages.start("sensitivity");
    let sens = screening::run(&names, &bounds, &obs.outputs, &gps, &cfg.analysis.sensitivity)?;
    write(out, "sobol.json", &serde_json::to_string_pretty(&sens)?)?;
    stages.done(&format!("keep {} parameters, drop {}", sens.keep.len(), sens.drop.join(", ")));

    stages.start("calibration");
    let emulator = GpEmulator::new(gps, false)?;
    let keep: Vec<usize> =
        sens.keep.iter().filter_map(|k| names.iter().position(|n| n == k)).collect();
    let cal = calibration::run(&emulator, &names, &bounds, &keep, obs, &cfg.analysis.calibration)?;
    calibration::write_posterior(out, &cfg.analysis.calibration.method, &cal)?;
    stages.done(&format!(
        "{} iterations, ELBO {:.2}",
        cal.result.diagnostics.iterations,
        cal.result.elbo.unwrap_or(f64::NAN)
    ));

    stages.start("selection");
    let sel = &cfg.analysis.selection;
    let cands = selection::candidates(sel, &names, &bounds, &sens.keep, obs.values.len());
    let table = selection::run(&emulator, &names, &bounds, obs, &cal.error_model, &cands, sel)?;
    write(out, "criteria.csv", &crate::commands::select::criteria_csv(&table))?;
    write(out, "criteria.json", &(serde_json::to_string_pretty(&table)? + "\n"))?;
    stages.done(&format!("selected {:?}", table.selected));

    let summary = report::Summary {
        config: args.config.display().to_string(),
        sweep,
        split,
        emulators: emus,
        screening: report::ScreeningSummary { keep: sens.keep, drop: sens.drop },
        posterior: cal.rows,
        predictive: cal.predictive,
        selected: table.selected.clone(),
        stages: stages.finish(),
    };
    write(out, "summary.json", &(serde_json::to_string_pretty(&summary)? + "\n"))?;
    print!("{}", report::text(&summary, &table));
    Ok(())
}
