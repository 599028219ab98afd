//! The evidence of an expensive likelihood from a run on its emulator:
//! the run's draws from the emulated posterior, re-weighted by the exact
//! likelihood at a few of them.
//!
//! With p̃ ∝ p(θ) L̃(θ) the emulated posterior and Z̃ its evidence,
//! Z = Z̃ E_p̃[L / L̃]; the mean of r = exp(ln L − ln L̃) over M draws of p̃
//! estimates the ratio. Its relative variance is the sample variance of r
//! over M mean(r)², and the Pareto k̂ of the log-ratios (Vehtari et al.)
//! says whether that mean can be trusted at all (k̂ > 0.7: the emulator
//! misses where the exact posterior lives, refine it first).

use super::SmcRun;
use crate::mcmc::psis;

/// The corrected evidence.
#[derive(Debug, Clone, PartialEq)]
pub struct CorrectedEvidence {
    /// ln Z of the exact likelihood.
    pub ln_evidence: f64,
    /// Its standard error: the run's and the correction's, in quadrature.
    pub ln_evidence_sd: f64,
    /// ln of the correction factor mean(r).
    pub ln_correction: f64,
    /// Pareto k̂ of the log-ratios (> 0.7: unreliable).
    pub k_hat: f64,
    /// Effective sample size of the ratios over M.
    pub ess_fraction: f64,
    /// Exact evaluations used (M).
    pub checked: usize,
    /// max − min of the log-ratios ln L − ln L̃ (nat; +∞ when an exact
    /// likelihood is zero): no tail among them moves the correction by more.
    pub log_ratio_range: f64,
}

/// Corrects `run` (made on an emulated log-likelihood) by the exact
/// log-likelihoods `exact[k]` at `run.particles[idx[k]]`; None when no
/// index is given, an index is out of range or an exact value is NaN.
pub fn correct_evidence(run: &SmcRun, idx: &[usize], exact: &[f64]) -> Option<CorrectedEvidence> {
    if idx.is_empty() || idx.len() != exact.len() || idx.iter().any(|&i| i >= run.particles.len()) {
        return None;
    }
    if exact.iter().any(|v| v.is_nan()) {
        return None;
    }
    let log_r: Vec<f64> = idx.iter().zip(exact).map(|(&i, &l)| l - run.ln_likelihood[i]).collect();
    let m = log_r.len() as f64;
    let top = log_r.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !top.is_finite() {
        return None;
    }
    let r: Vec<f64> = log_r.iter().map(|v| (v - top).exp()).collect();
    let mean = r.iter().sum::<f64>() / m;
    let rel_var = if r.len() > 1 {
        r.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (m - 1.0) / m / (mean * mean)
    } else {
        f64::INFINITY
    };
    let ln_correction = top + mean.ln();
    let ps = psis(&log_r);
    let var = run.ln_evidence_sd.powi(2) + (1.0 + rel_var).ln();
    Some(CorrectedEvidence {
        ln_evidence: run.ln_evidence + ln_correction,
        ln_evidence_sd: var.sqrt(),
        ln_correction,
        k_hat: ps.k_hat,
        ess_fraction: ps.ess / m,
        checked: idx.len(),
        log_ratio_range: top - log_r.iter().copied().fold(f64::INFINITY, f64::min),
    })
}

/// `m` indices of distinct particles spread over the population (the
/// first of each run of duplicates, every k-th), for the exact checks.
pub fn check_indices(run: &SmcRun, m: usize) -> Vec<usize> {
    let mut seen: Vec<(Vec<u64>, usize)> = run
        .particles
        .iter()
        .enumerate()
        .map(|(i, p)| (p.iter().map(|v| v.to_bits()).collect(), i))
        .collect();
    seen.sort();
    seen.dedup_by(|a, b| a.0 == b.0);
    let mut distinct: Vec<usize> = seen.into_iter().map(|(_, i)| i).collect();
    distinct.sort_unstable();
    if distinct.len() <= m {
        return distinct;
    }
    let step = distinct.len() as f64 / m as f64;
    (0..m).map(|k| distinct[(k as f64 * step) as usize]).collect()
}
