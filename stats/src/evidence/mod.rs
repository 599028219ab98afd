//! Model evidence p(data | class) by tempered sequential Monte Carlo.
//!
//! [`TemperedSmc`] moves a population of particles from the prior (β = 0) to
//! the posterior (β = 1) through the tempered targets p(θ) L(θ)^β, the
//! transitional MCMC of Ching & Chen (2007) as quoFEM and structural
//! identification use it, with the refinements of Betz, Papaioannou &
//! Straub (2016): each next β is the one at which the coefficient of
//! variation of the incremental weights L^(β' − β) equals a target (so the
//! effective sample size halves at most, [`next_temperature`]); particles are
//! resampled multinomially and moved by random-walk Metropolis steps whose
//! Gaussian proposal is the population's weighted covariance times a scale
//! adapted to the acceptance rate. The log-evidence is the sum over stages
//! of log mean(L^(β' − β)), an unbiased estimate of Z (not of ln Z) whatever
//! the moves' mixing; its Monte-Carlo error comes from the same run by the
//! genealogy estimator of Lee & Whiteley (2018) ([`relative_variance`]).
//!
//! A likelihood too dear for thousands of evaluations (an FE model) is
//! run on an emulator of its log-likelihood and the evidence corrected by
//! the exact likelihood at a few posterior draws ([`correct_evidence`]).
//!
//! Every stage hands its likelihood evaluations over as one batch (all
//! particles at once), so a farm evaluating them runs as many models in
//! flight as there are particles.

mod correction;
mod moves;
mod prior;
mod resample;
mod smc;
mod tempering;
mod variance;

#[cfg(test)]
mod tests;

pub use correction::{check_indices, correct_evidence, CorrectedEvidence};
pub use prior::{GaussianPrior, Prior};
pub use resample::multinomial;
pub use smc::{Bounds, SmcError, SmcOptions, SmcRun, SmcStage, Start, TemperedSmc};
pub use tempering::{incremental_weight_cov, next_temperature};
pub use variance::relative_variance;
