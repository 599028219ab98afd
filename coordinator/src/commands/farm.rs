//! `ceilfarm farm`: setting up a farm across machines.

use anyhow::Result;
use clap::{Args, Subcommand};
use coordinator::farm_certs::{write_lab, LabSettings, DEFAULT_VALIDITY_DAYS};
use std::path::PathBuf;

/// Setting up a farm across machines.
#[derive(Subcommand)]
pub enum FarmCommand {
    /// Make a lab's CA, a coordinator and N worker certificates, and zenoh
    /// configurations for TLS with mutual authentication and access control.
    Certs(CertsArgs),
}

/// `ceilfarm farm certs`.
#[derive(Args)]
pub struct CertsArgs {
    /// Folder to write into (created; existing files are never overwritten).
    #[arg(long)]
    pub out: PathBuf,
    /// Worker certificates to make (ceilfarm-worker-1 ...).
    #[arg(long, default_value_t = 1)]
    pub workers: usize,
    /// The coordinator's host name or IP address as workers reach it
    /// (repeat for several; workers connect to the first).
    #[arg(long = "host", default_values_t = ["127.0.0.1".to_string(), "localhost".to_string()])]
    pub hosts: Vec<String>,
    /// The coordinator's TCP port.
    #[arg(long, default_value_t = 7447)]
    pub port: u16,
    /// Days the certificates (the CA's too) stay valid, 1 to 3650.
    #[arg(long, default_value_t = DEFAULT_VALIDITY_DAYS)]
    pub days: u32,
}

/// Runs a `farm` subcommand.
pub fn run(cmd: FarmCommand) -> Result<()> {
    match cmd {
        FarmCommand::Certs(a) => {
            let settings = LabSettings {
                workers: a.workers,
                hosts: a.hosts,
                port: a.port,
                validity_days: a.days,
            };
            for path in write_lab(&a.out, &settings)? {
                println!("{}", path.display());
            }
            Ok(())
        }
    }
}
