//! `ceilfarm synth SPEC.toml --out DIR`: simulate a test campaign and write
//! it as a measured-data bundle, the truth beside it.

use anyhow::Result;
use clap::Args as ClapArgs;
use std::path::PathBuf;

/// Arguments of `synth`.
#[derive(ClapArgs)]
pub struct Args {
    /// The campaign file (specimen, sensors, runs, truth, hidden effect, noise).
    pub spec: PathBuf,
    /// The bundle directory to write.
    #[arg(long)]
    pub out: PathBuf,
    /// Where the answer goes (default: DIR.answer.json beside the bundle).
    #[arg(long)]
    pub answer: Option<PathBuf>,
    /// Also write every run's true FE model, base records and sensor recipe
    /// here (for another simulator: scripts/opensees/run_campaign.py).
    #[arg(long, value_name = "MDIR", conflicts_with = "histories")]
    pub export_models: Option<PathBuf>,
    /// Assemble the bundle from another simulator's histories of the models
    /// exported to MDIR (`<run>.history.csv`, `modal.json`, `simulator.json`)
    /// instead of simulating.
    #[arg(long, value_name = "MDIR")]
    pub histories: Option<PathBuf>,
}

/// Runs `synth`.
pub fn run(a: Args) -> Result<()> {
    let answer = a.answer.unwrap_or_else(|| {
        let mut name = a.out.file_name().unwrap_or_default().to_os_string();
        name.push(".answer.json");
        a.out.with_file_name(name)
    });
    use coordinator::synth::Simulator;
    let simulator = match (&a.export_models, &a.histories) {
        (_, Some(dir)) => Simulator::Histories(dir),
        (export, None) => Simulator::Ceilfarm { export: export.as_deref() },
    };
    let ans =
        coordinator::synth::synth_to_dir_with(&a.spec, &a.out, &answer, simulator, &mut |m| {
            eprintln!("synth: {m}")
        })?;
    println!(
        "wrote bundle {} to {} ({} hidden, simulated by {}); answer in {}",
        ans.bundle,
        a.out.display(),
        ans.cause,
        ans.simulator,
        answer.display()
    );
    if let Some(dir) = &a.export_models {
        println!("exported the run models to {}", dir.display());
    }
    Ok(())
}
