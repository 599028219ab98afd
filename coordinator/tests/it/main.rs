//! The integration tests of ceilfarm-coordinator in one test binary, so
//! that the crate and its dependencies (zenoh, iceoryx2, parquet, SQLite)
//! are linked once: one module per subject, and `common` for the helpers
//! of the end-to-end tests that run the `ceilfarm` binary. One module
//! alone: `cargo test -p ceilfarm-coordinator --test it MODULE::`.

mod common;
mod diagnose_farm;
mod diagnose_hidden;
mod docs_commands;
mod fe_run;
mod gp_cli;
mod opensees_variants;
mod pipeline_seed_ch6;
mod report_browser;
mod report_svg;
#[cfg(feature = "zenoh")]
mod secured_links;
#[cfg(feature = "zenoh")]
mod security_attacks;
#[cfg(feature = "zenoh")]
mod security_sigterm;
mod sobol_cli;
mod sweep_borehole;
mod sweep_ceiling;
mod sweep_faults;
mod sweep_refusals;
mod sweep_resume;
mod transports;
mod unused_dependencies;
