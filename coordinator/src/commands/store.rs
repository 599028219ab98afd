//! `ceilfarm store`: maintenance of a dataset store.

use anyhow::Result;
use clap::{Args, Subcommand};
use coordinator::store::Store;
use std::path::PathBuf;

/// Store maintenance.
#[derive(Subcommand)]
pub enum StoreCommand {
    /// Read every page of a store and check it (SQLite's integrity_check,
    /// foreign keys, the design's size); opening a store checks only its
    /// header and shape.
    Check(CheckArgs),
}

/// `ceilfarm store check`.
#[derive(Args)]
pub struct CheckArgs {
    /// The dataset store.
    pub store: PathBuf,
}

/// Runs a `store` subcommand.
pub fn run(cmd: StoreCommand) -> Result<()> {
    match cmd {
        StoreCommand::Check(args) => check(args),
    }
}

fn check(args: CheckArgs) -> Result<()> {
    let report = Store::open_read_only(&args.store)?.check_full()?;
    let missing = report.tasks - report.ok - report.failed;
    println!(
        "{}: ok ({} design points: {} ok, {} failed, {missing} missing)",
        args.store.display(),
        report.tasks,
        report.ok,
        report.failed
    );
    Ok(())
}
