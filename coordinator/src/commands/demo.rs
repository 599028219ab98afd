//! `ceilfarm demo`: synthesise a small test campaign with a hidden effect
//! (configs/synth/demo.toml, built in), diagnose it through the in-process
//! farm with a local evaluation store, and say where the store and the
//! report are. Running it again re-uses the stored evaluations.

use anyhow::{Context, Result};
use clap::Args as ClapArgs;
use coordinator::diagnose::calibrate::Budget;
use coordinator::diagnose::farm_executor::FarmPlan;
use coordinator::diagnose::pipeline::DiagnoseOptions;
use coordinator::farm::FarmSettings;
use coordinator::study::TransportKind;
use std::path::PathBuf;

/// The built-in campaign.
const DEMO: &str = include_str!("../../../configs/synth/demo.toml");

/// Arguments of `demo`.
#[derive(ClapArgs)]
pub struct Args {
    /// Directory for the bundle, its answer and the diagnosis.
    #[arg(long, default_value = "demo")]
    pub out: PathBuf,
    /// In-process workers running FE simulations.
    #[arg(long, default_value_t = 2)]
    pub workers: usize,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Runs `demo`.
pub fn run(a: Args) -> Result<()> {
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let spec = a.out.join("campaign.toml");
    std::fs::write(&spec, DEMO).with_context(|| format!("writing {}", spec.display()))?;
    let bundle = a.out.join("bundle");
    let answer = a.out.join("answer.json");
    eprintln!("1/2 simulating a test campaign (a hidden effect is in it) -> {}", bundle.display());
    coordinator::synth::synth_to_dir(&spec, &bundle, &answer, &mut |m| eprintln!("    {m}"))?;
    let out = a.out.join("diagnosis");
    let store = out.join("evaluations.db");
    eprintln!(
        "2/2 diagnosing {} without the answer (in-process farm, store {})",
        bundle.display(),
        store.display()
    );
    let workers = a.workers.max(1);
    let opts = DiagnoseOptions {
        budget: Budget { threads: workers, ..Budget::default() },
        ..Default::default()
    };
    let plan = FarmPlan {
        transport: TransportKind::InProcess,
        workers,
        endpoint: None,
        settings: FarmSettings::default(),
        store: Some(store.clone()),
        zenoh: Default::default(),
    };
    let rate = Some(coordinator::diagnose::resample::SIMULATION_RATE_HZ);
    let report = super::diagnose::diagnose_dir(&bundle, &out, &opts, rate, &plan, a.quiet)?;
    let truth: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&answer)?)?;
    println!("hidden effect was: {}", truth["cause"].as_str().unwrap_or("?"));
    println!("store: {}", store.display());
    println!("report: {}", report.display());
    Ok(())
}
