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
enum Command {}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result: anyhow::Result<()> = match cli.command {};
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
