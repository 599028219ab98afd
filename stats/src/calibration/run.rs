//! One calibration run end to end: pick a start (multi-start MAP), fit by
//! BBVI or sample by MCMC, draw posterior samples in physical units,
//! summarise them and collect diagnostics (ELBO, PSIS k-hat, R-hat, ESS).
//! This is the entry point the coordinator calls, whatever the simulator
//! (direct model or GP emulator).

use super::{CalibError, Likelihood, LogDensity, Posterior, PosteriorSummary};
use crate::bbvi::{Bbvi, BbviError, BbviSettings, FamilyKind, Observer};
use crate::mcmc::{psis, AdaptiveMetropolis, McmcError, McmcSettings};
use crate::selection::ml::fit_ml;
use rand::SeedableRng;

/// How the posterior is computed.
#[derive(Debug, Clone, PartialEq)]
pub enum Method {
    /// BBVI (any estimator and family).
    Bbvi(BbviSettings),
    /// Adaptive Metropolis.
    Mcmc(McmcSettings),
}

impl Method {
    /// `bbvi-meanfield`, `bbvi-fullrank`, `bbvi-score` (the seed's
    /// score-function estimator, mean-field, Rao–Blackwellised) or `mcmc`.
    pub fn from_name(name: &str, seed: u64) -> Option<Self> {
        Some(match name {
            "bbvi-meanfield" => Method::Bbvi(BbviSettings::reparam(FamilyKind::MeanField, seed)),
            "bbvi-fullrank" => Method::Bbvi(BbviSettings::reparam(FamilyKind::FullRank, seed)),
            "bbvi-score" => Method::Bbvi(BbviSettings::score(FamilyKind::MeanField, seed)),
            "mcmc" => Method::Mcmc(McmcSettings { seed, ..McmcSettings::default() }),
            _ => return None,
        })
    }

    /// Names accepted by [`Method::from_name`].
    pub const NAMES: [&'static str; 4] = ["bbvi-meanfield", "bbvi-fullrank", "bbvi-score", "mcmc"];
}

/// Settings of a run besides the method.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSettings {
    /// Fit or sampler.
    pub method: Method,
    /// Posterior draws to return (BBVI: from q; MCMC: thinned evenly).
    pub draws: usize,
    /// Starts of the MAP search that picks the initial point (0: prior centre).
    pub map_starts: usize,
    /// Seed for the MAP starts and the draws.
    pub seed: u64,
}

/// Diagnostics of a run (fields that do not apply are None).
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct Diagnostics {
    /// Iterations (BBVI) or iterations per chain (MCMC).
    pub iterations: usize,
    /// BBVI: converged by the relative-change rule.
    pub converged: Option<bool>,
    /// BBVI: final relative change of the window-averaged parameters.
    pub rel_change: Option<f64>,
    /// BBVI: Pareto k-hat of p/q (PSIS); < 0.5 reliable, > 0.7 unreliable.
    pub psis_k_hat: Option<f64>,
    /// BBVI: PSIS effective sample size of p/q.
    pub psis_ess: Option<f64>,
    /// MCMC: split R-hat per parameter.
    pub rhat: Option<Vec<f64>>,
    /// MCMC: effective sample size per parameter.
    pub ess: Option<Vec<f64>>,
    /// MCMC: acceptance rate per chain.
    pub acceptance: Option<Vec<f64>>,
    /// Samples with a non-finite log density.
    pub n_bad: usize,
    /// Physical parameters of the MAP start.
    pub map_start: Vec<f64>,
    /// Wall time of the fit (s).
    pub wall_s: f64,
}

/// The posterior of a run.
#[derive(Debug, Clone)]
pub struct CalibrationResult {
    /// Draws in physical units (draws, n_params), names as in the prior.
    pub draws: Vec<Vec<f64>>,
    /// Their summary.
    pub summary: PosteriorSummary,
    /// ELBO of the fitted q (BBVI only).
    pub elbo: Option<f64>,
    /// Per-iteration ELBO (BBVI only).
    pub elbo_trace: Vec<f64>,
    /// Diagnostics.
    pub diagnostics: Diagnostics,
}

/// Why a run failed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// Bad problem.
    #[error(transparent)]
    Calib(#[from] CalibError),
    /// BBVI failed.
    #[error(transparent)]
    Bbvi(#[from] BbviError),
    /// MCMC failed.
    #[error(transparent)]
    Mcmc(#[from] McmcError),
}

/// Runs the calibration of `post`; `observers` watch BBVI iterations.
pub fn calibrate<L: Likelihood>(
    post: &Posterior<L>,
    s: &RunSettings,
    observers: &mut [&mut dyn Observer],
) -> Result<CalibrationResult, RunError> {
    let prior = post.prior();
    let t0 = std::time::Instant::now();
    let start = if s.map_starts > 0 {
        let ml = fit_ml(post.likelihood(), prior, s.map_starts, s.seed as u32);
        prior.to_unconstrained(&ml.theta).unwrap_or_else(|| vec![0.0; prior.dim()])
    } else {
        vec![0.0; prior.dim()]
    };
    let mut diag = Diagnostics { map_start: prior.to_physical(&start), ..Diagnostics::default() };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(s.seed ^ 0x5eed);
    let (z_draws, elbo, trace): (Vec<Vec<f64>>, _, _) = match &s.method {
        Method::Bbvi(b) => {
            let fit = Bbvi::new(post, b.clone()).run(&start, observers)?;
            let l = fit.q.cholesky();
            let mut lw = Vec::with_capacity(s.draws);
            let zs: Vec<Vec<f64>> = (0..s.draws.max(100))
                .map(|_| {
                    let (_, z) = fit.q.sample(&l, &mut rng);
                    lw.push(post.log_density(&z) - fit.q.log_q(&z));
                    z
                })
                .collect();
            let p = psis(&lw);
            diag.iterations = fit.iterations;
            diag.converged = Some(fit.converged);
            diag.rel_change = Some(fit.rel_change);
            diag.psis_k_hat = Some(p.k_hat);
            diag.psis_ess = Some(p.ess);
            diag.n_bad = fit.n_bad;
            (zs.into_iter().take(s.draws).collect(), Some(fit.elbo), fit.elbo_trace)
        }
        Method::Mcmc(m) => {
            let run = AdaptiveMetropolis::new(m.clone()).run(post, &start)?;
            let all = run.draws();
            let step = (all.len() / s.draws.max(1)).max(1);
            diag.iterations = m.iters;
            diag.rhat = Some(run.rhat.clone());
            diag.ess = Some(run.ess.clone());
            diag.acceptance = Some(run.acceptance.clone());
            (all.into_iter().step_by(step).take(s.draws).collect(), None, vec![])
        }
    };
    diag.wall_s = t0.elapsed().as_secs_f64();
    let draws: Vec<Vec<f64>> = z_draws.iter().map(|z: &Vec<f64>| post.to_physical(z)).collect();
    let summary = PosteriorSummary::from_draws(&prior.names, &draws);
    Ok(CalibrationResult { draws, summary, elbo, elbo_trace: trace, diagnostics: diag })
}
