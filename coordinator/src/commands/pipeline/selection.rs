//! Stage 5: model selection among parameter subsets (seed 6.7, Tables
//! 6.3–6.4): each candidate frees some parameters, the others sit at their
//! prior centres; maximum-likelihood fit of the emulator means under the
//! calibrated error model (alpha, discrepancy and noise at their posterior
//! means: y − alpha eta ~ N(0, C), whitened by the Cholesky factor of C),
//! then AIC, BIC, DIC, ICOMP and MDL. A candidate with more free parameters
//! than observations has a singular Fisher information and no MDL
//! (reported as not identifiable).

use super::calibration::ErrorModel;
use super::config::{ObservationsSection, SelectionSection};
use anyhow::Result;
use stats::calibration::{GpEmulator, LinearMap, UniformBox};
use stats::mcmc::McmcSettings;
use stats::selection::{select, Candidate, SelectionProblem, SelectionSettings, SelectionTable};
use std::collections::BTreeMap;

/// The candidates: the configured ones, then (if asked) the `ranked`
/// parameters' nested subsets of sizes 1 to the number of observations.
pub fn candidates(
    cfg: &SelectionSection,
    names: &[String],
    bounds: &[(f64, f64)],
    ranked: &[String],
    n_obs: usize,
) -> Vec<Candidate> {
    let fixed = |free: &[String]| -> BTreeMap<String, f64> {
        names
            .iter()
            .zip(bounds)
            .filter(|(n, _)| !free.contains(n))
            .map(|(n, (l, h))| (n.clone(), 0.5 * (l + h)))
            .collect()
    };
    let mut out: Vec<Candidate> = cfg
        .candidates
        .iter()
        .map(|c| Candidate { name: c.name.clone(), free: c.free.clone(), fixed: fixed(&c.free) })
        .collect();
    if cfg.nested_by_sensitivity {
        for k in 1..=ranked.len().min(n_obs) {
            let free = ranked[..k].to_vec();
            out.push(Candidate { name: format!("top-{k}"), fixed: fixed(&free), free });
        }
    }
    out
}

/// Scores the candidates on the emulator means.
pub fn run(
    emulator: &GpEmulator,
    names: &[String],
    bounds: &[(f64, f64)],
    obs: &ObservationsSection,
    error: &ErrorModel,
    candidates: &[Candidate],
    cfg: &SelectionSection,
) -> Result<SelectionTable> {
    let cov = error.covariance();
    let log_det_l = cov.clone().cholesky().map_or(0.0, |c| c.l().diagonal().map(f64::ln).sum());
    let sim = LinearMap::whitening(emulator, cov, error.alpha)?;
    let y = sim.map_observations(&obs.values, error.alpha);
    let prior = UniformBox::new(
        names.to_vec(),
        bounds.iter().map(|b| b.0).collect(),
        bounds.iter().map(|b| b.1).collect(),
    )?;
    let problem = SelectionProblem { sim, prior, y, noise_sd: 1.0, truth: None };
    let settings = SelectionSettings {
        starts: cfg.starts,
        qmc_points: cfg.qmc_points,
        qmc_replicates: cfg.qmc_replicates,
        mcmc: McmcSettings { iters: 6000, warmup: 2000, ..McmcSettings::default() },
        seed: cfg.seed,
    };
    let mut table = select(&problem, candidates, &settings)?;
    unwhiten(&mut table, log_det_l);
    Ok(table)
}

/// Adds back the whitening's constant log det L, so that −log L and the
/// criteria are those of the data in their own units.
fn unwhiten(t: &mut SelectionTable, log_det_l: f64) {
    for c in &mut t.candidates {
        c.neg_log_likelihood += log_det_l;
        c.aic += 2.0 * log_det_l;
        c.bic += 2.0 * log_det_l;
        c.dic += 2.0 * log_det_l;
        c.icomp += 2.0 * log_det_l;
        c.mdl += log_det_l;
    }
}
