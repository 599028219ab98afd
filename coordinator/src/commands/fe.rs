//! `ceilfarm fe ...`: the ceiling FE model on its own (materials, models, modes).

use anyhow::Result;
use clap::{Args, Subcommand};
use std::path::PathBuf;

/// Finite-element tools.
#[derive(Subcommand)]
pub enum FeCommand {
    /// Drive one uniaxial material through an imposed deformation protocol.
    ///
    /// MATERIAL.json is one object as in the model format's materials list;
    /// PROTOCOL.csv has the header `step,deformation_mm`. Writes
    /// `deformation_mm,force_N,tangent_N_per_mm`, one committed step per row.
    Material(MaterialArgs),
}

/// Arguments of `fe material`.
#[derive(Args)]
pub struct MaterialArgs {
    /// The material JSON file.
    pub material: PathBuf,
    /// The deformation protocol CSV (`step,deformation_mm`).
    pub protocol: PathBuf,
    /// Output CSV.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs an `fe` subcommand.
pub fn run(cmd: FeCommand) -> Result<()> {
    match cmd {
        FeCommand::Material(a) => {
            let rows = fe::materials::driver::run_files(&a.material, &a.protocol, &a.out)?;
            eprintln!("{rows} steps written to {}", a.out.display());
            Ok(())
        }
    }
}
