//! The coordinator: reads a study, draws its design, runs it on a farm of
//! workers through a transport, keeps every result in a crash-safe store,
//! and runs the analyses centrally.
//!
//! Data flows one way: [`study::Study`] → [`design`] → [`store::Store`] →
//! [`farm::run_farm`] (through a [`protocol::Transport`]) → store →
//! [`export`] and the analyses.

pub mod bundle;
pub mod design;
pub mod diagnose;
pub mod evaluations;
pub mod export;
pub mod export_parquet;
pub mod farm;
pub mod farm_acl;
pub mod farm_certs;
pub mod farm_hand_backs;
pub mod farm_zenoh_config;
pub mod progress;
pub mod report;
pub mod specimen;
pub mod store;
pub mod store_file;
pub mod store_lock;
#[cfg(test)]
mod store_tests;
pub mod study;
pub mod study_files;
pub mod sweep;
pub mod synth;
pub mod transports;
