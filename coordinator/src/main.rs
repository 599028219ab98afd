//! `ceilfarm`: parameter sweeps of suspended-ceiling models on a farm of
//! workers, with surrogates, sensitivity, calibration and diagnosis.

use clap::{Parser, Subcommand};

mod commands;

/// Sweeps, surrogates, calibration and diagnosis for suspended-ceiling models.
#[derive(Parser)]
#[command(name = "ceilfarm", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Bayesian calibration of a model against data (posterior.json, samples.csv).
    Calibrate(commands::calibrate::Args),
    /// Model selection among parameter subsets (criteria.csv, criteria.json).
    Select(commands::select::Args),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result: anyhow::Result<()> = match cli.command {
        Command::Calibrate(args) => commands::calibrate::run(args),
        Command::Select(args) => commands::select::run(args),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
