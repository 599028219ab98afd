//! `ceilfarm`: parameter sweeps of suspended-ceiling models on a farm of
//! workers, with surrogates, sensitivity, calibration and diagnosis.

use clap::{Parser, Subcommand};

mod commands;

/// Sweeps, surrogates, calibration and diagnosis for suspended-ceiling models.
///
/// Start with `ceilfarm run configs/borehole.toml --store runs/borehole.db`,
/// then `ceilfarm export runs/borehole.db --out borehole.csv`.
#[derive(Parser)]
#[command(name = "ceilfarm", version, about, long_about = None)]
struct Cli {
    /// More log output (repeat for more); RUST_LOG overrides.
    #[arg(short, long, global = true, action = clap::ArgAction::Count)]
    verbose: u8,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a study's sweep into a store, or finish it with --resume.
    Run(commands::sweep::RunArgs),
    /// Write a study's design (physical units) as CSV without running it.
    Design(commands::sweep::DesignArgs),
    /// Export a store: one row per run, inputs and scalar outputs.
    Export(commands::sweep::ExportArgs),
    /// Count what a store holds: done, failed, missing.
    Status(commands::sweep::StatusArgs),
    /// Dataset stores: check one page by page.
    #[command(subcommand)]
    Store(commands::store::StoreCommand),
    /// Serve sweeps as a worker process (iceoryx2 or zenoh transport).
    Worker(commands::worker::WorkerArgs),
    /// Farm set-up across machines: the lab's certificates and zenoh configurations.
    #[command(subcommand)]
    Farm(commands::farm::FarmCommand),
    /// Measured-data bundles: check one.
    #[command(subcommand)]
    Bundle(commands::bundle::BundleCommand),
    /// The ceiling FE model on its own: materials, models, modes.
    #[command(subcommand)]
    Fe(commands::fe::FeCommand),
    /// Bayesian calibration of a model against data (posterior.json, samples.csv).
    Calibrate(commands::calibrate::Args),
    /// Model selection among parameter subsets (criteria.csv, criteria.json).
    Select(commands::select::Args),
    /// Gaussian-process emulators: fit to a dataset, predict at points.
    #[command(subcommand)]
    Gp(commands::gp::GpCommand),
    /// The seed's chapter 6 end to end: sweep, emulators, Sobol' screening, KOH + BBVI, MDL.
    Pipeline(commands::pipeline::Args),
    /// Sobol' sensitivity indices of a function or a GP emulator of a dataset.
    Sobol(commands::sobol::Args),
    /// Synthesise a small campaign with a hidden effect and diagnose it (about a minute).
    Demo(commands::demo::Args),
    /// Diagnose a measured-data bundle: name what the model misses, extend it, measure the gain.
    Diagnose(commands::diagnose::Args),
    /// Simulate a shaking-table campaign and write it as a measured-data bundle.
    Synth(commands::synth::Args),
}

fn init_logging(verbose: u8) {
    let default = match verbose {
        0 => "warn",
        1 => "info",
        _ => "debug",
    };
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(default));
    let _ =
        tracing_subscriber::fmt().with_env_filter(filter).with_writer(std::io::stderr).try_init();
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    init_logging(cli.verbose);
    let result = match cli.command {
        Command::Run(a) => commands::sweep::run(a),
        Command::Design(a) => commands::sweep::design(a),
        Command::Export(a) => commands::sweep::export(a),
        Command::Status(a) => commands::sweep::status(a),
        Command::Store(c) => commands::store::run(c),
        Command::Bundle(c) => commands::bundle::run(c),
        Command::Fe(c) => commands::fe::run(c),
        Command::Worker(a) => commands::worker::run(a),
        Command::Farm(c) => commands::farm::run(c),
        Command::Calibrate(a) => commands::calibrate::run(a),
        Command::Pipeline(a) => commands::pipeline::run(a),
        Command::Select(a) => commands::select::run(a),
        Command::Gp(c) => commands::gp::run(c),
        Command::Sobol(a) => commands::sobol::run(a),
        Command::Synth(a) => commands::synth::run(a),
        Command::Diagnose(a) => commands::diagnose::run(a),
        Command::Demo(a) => commands::demo::run(a),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
