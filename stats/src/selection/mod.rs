//! Model selection among parameter subsets (seed §3.7.2, §6.7; Table 6.3).
//!
//! Roles: [`nelder_mead`] and [`fit_ml`] find the maximum-likelihood
//! parameters inside the prior box (multi-start); [`fisher`] computes the
//! per-observation Fisher information I1 = J^T J / sigma² / n and
//! log ∫ sqrt(det I1) over the box by scrambled-Sobol' quasi Monte Carlo
//! with a replicate error estimate; [`criteria`] holds AIC, BIC, DIC, ICOMP
//! and MDL (Fisher-information approximation, seed eq. 3.63);
//! [`generalisability`] is Gr % of seed eq. 6.12; [`select()`](select::select)
//! scores every candidate and names the winner under each criterion.
//!
//! ```
//! use stats::selection::criteria::{aic, bic};
//! assert_eq!(aic(10.0, 2), 24.0);
//! assert!((bic(10.0, 2, 20) - (20.0 + 2.0 * 20f64.ln())).abs() < 1e-12);
//! ```

pub mod criteria;
pub mod fisher;
pub mod generalisability;
pub mod ml;
pub mod nelder_mead;
pub mod select;

pub use criteria::CandidateScore;
pub use select::{
    select, Candidate, SelectionError, SelectionProblem, SelectionSettings, SelectionTable,
};
