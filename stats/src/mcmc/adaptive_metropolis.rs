//! Adaptive Metropolis (Haario et al. 2001): Gaussian random-walk proposals
//! with covariance s_d (C_t + eps I), s_d = 2.38² / d, C_t the running
//! covariance of the chain. Adaptation runs during warm-up only, so the
//! kept draws come from a fixed-kernel Metropolis chain.

use super::diagnostics::{ess, split_rhat};
use crate::calibration::LogDensity;
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// Sampler settings.
#[derive(Debug, Clone, PartialEq)]
pub struct McmcSettings {
    /// Independent chains.
    pub chains: usize,
    /// Iterations per chain, warm-up included.
    pub iters: usize,
    /// Warm-up iterations (adapting, discarded).
    pub warmup: usize,
    /// Iteration from which the proposal adapts (before: init_sd² s_d I).
    pub adapt_start: usize,
    /// sd of the over-dispersed starting points around the initial point.
    pub init_sd: f64,
    /// Keep every `thin`-th draw.
    pub thin: usize,
    /// RNG seed (chain i uses stream i).
    pub seed: u64,
}

impl Default for McmcSettings {
    fn default() -> Self {
        Self {
            chains: 4,
            iters: 20_000,
            warmup: 5_000,
            adapt_start: 500,
            init_sd: 0.1,
            thin: 1,
            seed: 1,
        }
    }
}

/// Why sampling could not start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum McmcError {
    /// A setting is out of range.
    #[error("mcmc setting {key} = {value}: expected {expected}")]
    Setting {
        /// Setting name.
        key: &'static str,
        /// Its value.
        value: String,
        /// What is allowed.
        expected: &'static str,
    },
    /// No finite log density near the initial point.
    #[error("chain {chain}: no finite log density near the initial point {init:?}")]
    BadStart {
        /// Chain index.
        chain: usize,
        /// The initial point.
        init: Vec<f64>,
    },
}

/// Kept draws and diagnostics.
#[derive(Debug, Clone)]
pub struct McmcRun {
    /// Draws per chain: chains[c][i] is a point (d).
    pub chains: Vec<Vec<Vec<f64>>>,
    /// Acceptance rate after warm-up, per chain.
    pub acceptance: Vec<f64>,
    /// Split R-hat per coordinate.
    pub rhat: Vec<f64>,
    /// Effective sample size per coordinate.
    pub ess: Vec<f64>,
}

impl McmcRun {
    /// All kept draws, chains concatenated.
    pub fn draws(&self) -> Vec<Vec<f64>> {
        self.chains.iter().flatten().cloned().collect()
    }
}

/// The adaptive Metropolis sampler.
pub struct AdaptiveMetropolis {
    settings: McmcSettings,
}

/// Running mean and covariance (Welford).
struct Moments {
    n: f64,
    mean: DVector<f64>,
    m2: DMatrix<f64>,
}

impl Moments {
    fn push(&mut self, x: &[f64]) {
        self.n += 1.0;
        let x = DVector::from_column_slice(x);
        let d1 = &x - &self.mean;
        self.mean += &d1 / self.n;
        let d2 = &x - &self.mean;
        self.m2 += &d1 * d2.transpose();
    }
}

impl AdaptiveMetropolis {
    /// A sampler with `settings`.
    pub fn new(settings: McmcSettings) -> Self {
        Self { settings }
    }

    fn check(&self) -> Result<(), McmcError> {
        let s = &self.settings;
        let bad = |key, value: usize, expected| {
            Err(McmcError::Setting { key, value: value.to_string(), expected })
        };
        if s.chains < 2 {
            return bad("chains", s.chains, "at least 2 (for R-hat)");
        }
        if s.iters < s.warmup + 8 {
            return bad("iters", s.iters, "at least warmup + 8");
        }
        if s.thin == 0 {
            return bad("thin", 0, "at least 1");
        }
        Ok(())
    }

    /// Runs every chain from over-dispersed points around `init` (d).
    pub fn run<T: LogDensity + ?Sized>(
        &self,
        target: &T,
        init: &[f64],
    ) -> Result<McmcRun, McmcError> {
        self.check()?;
        let mut chains = Vec::new();
        let mut acceptance = Vec::new();
        for c in 0..self.settings.chains {
            let (draws, acc) = self.chain(target, init, c)?;
            chains.push(draws);
            acceptance.push(acc);
        }
        let d = init.len();
        let coord = |j: usize| -> Vec<Vec<f64>> {
            chains.iter().map(|ch| ch.iter().map(|x| x[j]).collect()).collect()
        };
        let rhat = (0..d).map(|j| split_rhat(&coord(j))).collect();
        let ess = (0..d).map(|j| ess(&coord(j))).collect();
        Ok(McmcRun { chains, acceptance, rhat, ess })
    }

    // `%` rather than `is_multiple_of`: the workspace MSRV is 1.85.
    #[allow(clippy::manual_is_multiple_of)]
    fn chain<T: LogDensity + ?Sized>(
        &self,
        target: &T,
        init: &[f64],
        c: usize,
    ) -> Result<(Vec<Vec<f64>>, f64), McmcError> {
        let s = &self.settings;
        let d = init.len();
        let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
        rng.set_stream(c as u64);
        let (mut x, mut lp) = start(target, init, s.init_sd, &mut rng)
            .ok_or(McmcError::BadStart { chain: c, init: init.to_vec() })?;
        let sd_scale = 2.38 * 2.38 / d as f64;
        let mut chol = DMatrix::identity(d, d) * (s.init_sd * sd_scale.sqrt());
        let mut mom = Moments { n: 0.0, mean: DVector::zeros(d), m2: DMatrix::zeros(d, d) };
        let (mut kept, mut accepted) = (Vec::new(), 0usize);
        for it in 0..s.iters {
            let eps =
                DVector::from_iterator(d, (0..d).map(|_| rng.sample::<f64, _>(StandardNormal)));
            let step = &chol * eps;
            let y: Vec<f64> = (0..d).map(|i| x[i] + step[i]).collect();
            let lq = target.log_density(&y);
            if lq.is_finite() && rng.random::<f64>().ln() < lq - lp {
                x = y;
                lp = lq;
                accepted += usize::from(it >= s.warmup);
            }
            if it < s.warmup {
                mom.push(&x);
                if it >= s.adapt_start && it % 50 == 0 {
                    let cov = &mom.m2 / (mom.n - 1.0) + DMatrix::identity(d, d) * 1e-10;
                    if let Some(ch) = (cov * sd_scale).cholesky() {
                        chol = ch.l();
                    }
                }
            } else if (it - s.warmup) % s.thin == 0 {
                kept.push(x.clone());
            }
        }
        Ok((kept, accepted as f64 / (s.iters - s.warmup) as f64))
    }
}

/// A finite starting point near `init`, over-dispersed by `sd`.
fn start<T: LogDensity + ?Sized, R: Rng>(
    target: &T,
    init: &[f64],
    sd: f64,
    rng: &mut R,
) -> Option<(Vec<f64>, f64)> {
    for _ in 0..100 {
        let x: Vec<f64> =
            init.iter().map(|v| v + sd * rng.sample::<f64, _>(StandardNormal)).collect();
        let lp = target.log_density(&x);
        if lp.is_finite() {
            return Some((x, lp));
        }
    }
    let lp = target.log_density(init);
    lp.is_finite().then(|| (init.to_vec(), lp))
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Corr;
    impl LogDensity for Corr {
        fn dim(&self) -> usize {
            2
        }
        fn log_density(&self, z: &[f64]) -> f64 {
            let (a, b) = (z[0] - 1.0, z[1] + 1.0);
            -0.5 * (a * a - 1.8 * a * b + b * b) / (1.0 - 0.81)
        }
    }

    #[test]
    fn samples_correlated_gaussian() {
        let run = AdaptiveMetropolis::new(McmcSettings::default()).run(&Corr, &[0.0, 0.0]).unwrap();
        let draws = run.draws();
        let n = draws.len() as f64;
        let m0 = draws.iter().map(|x| x[0]).sum::<f64>() / n;
        let c01 = draws.iter().map(|x| (x[0] - 1.0) * (x[1] + 1.0)).sum::<f64>() / n;
        assert!((m0 - 1.0).abs() < 0.05 && (c01 - 0.9).abs() < 0.05, "{m0} {c01}");
        assert!(run.rhat.iter().all(|r| *r < 1.01), "{:?}", run.rhat);
        assert!(run.ess.iter().all(|e| *e > 1000.0), "{:?}", run.ess);
    }

    #[test]
    fn one_chain_is_refused() {
        let s = McmcSettings { chains: 1, ..McmcSettings::default() };
        let e = AdaptiveMetropolis::new(s).run(&Corr, &[0.0, 0.0]).unwrap_err().to_string();
        assert!(e.contains("chains = 1"), "{e}");
    }
}
