//! The integration tests of ceilfarm-stats in one test binary, so that the crate
//! and its dependencies are linked once: one module per subject, and
//! `calib_common` for the calibration benchmark's shared pieces. One module
//! alone: `cargo test -p ceilfarm-stats --test it MODULE::`.

mod calib_bbvi;
mod calib_bench;
mod calib_common;
mod calib_exact;
mod calib_inferred;
mod calib_mcmc;
mod calib_selection;
mod gp_benchmarks;
mod gp_gradient;
mod gp_loo;
mod gp_pca;
mod sobol_exact;
