//! `ceilfarm bundle check DIR`: validate a measured-data bundle.

use anyhow::Result;
use clap::{Args, Subcommand};
use std::path::PathBuf;

/// Measured-data bundles (`ceiling-measured/1`).
#[derive(Subcommand)]
pub enum BundleCommand {
    /// Check a bundle and print what it holds: specimen, sensors, runs, durations.
    Check(CheckArgs),
}

/// Arguments of `bundle check`.
#[derive(Args)]
pub struct CheckArgs {
    /// The bundle directory (holding bundle.toml).
    pub dir: PathBuf,
}

/// Runs a `bundle` subcommand.
pub fn run(cmd: BundleCommand) -> Result<()> {
    match cmd {
        BundleCommand::Check(a) => {
            let bundle = coordinator::bundle::read_bundle(&a.dir)?;
            println!("{}", bundle.summary());
            Ok(())
        }
    }
}
