//! `ceilfarm demo`: synthesise a small test campaign with a hidden effect
//! (configs/synth/demo.toml, built in), diagnose it through in-process
//! workers, and say where the report is.

use anyhow::{Context, Result};
use clap::Args as ClapArgs;
use coordinator::diagnose::calibrate::Budget;
use coordinator::diagnose::pipeline::DiagnoseOptions;
use std::path::PathBuf;

/// The built-in campaign.
const DEMO: &str = include_str!("../../../configs/synth/demo.toml");

/// Arguments of `demo`.
#[derive(ClapArgs)]
pub struct Args {
    /// Directory for the bundle, its answer and the diagnosis.
    #[arg(long, default_value = "demo")]
    pub out: PathBuf,
    /// Threads running FE simulations.
    #[arg(long, default_value_t = 2)]
    pub workers: usize,
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
    eprintln!("2/2 diagnosing {} without the answer", bundle.display());
    let opts = DiagnoseOptions {
        budget: Budget { threads: a.workers.max(1), ..Budget::default() },
        ..Default::default()
    };
    let report = super::diagnose::diagnose_dir(&bundle, &a.out.join("diagnosis"), &opts)?;
    let truth: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&answer)?)?;
    println!("hidden effect was: {}", truth["cause"].as_str().unwrap_or("?"));
    println!("report: {}", report.display());
    Ok(())
}
