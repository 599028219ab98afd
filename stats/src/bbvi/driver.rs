//! The BBVI driver: settings, state, one step, and a run loop with observers
//! (argmin/emcee shape). Seeded by a ChaCha8 RNG held in the state, so a run
//! is reproducible and can resume from any saved state.
//!
//! Convergence: lambda is averaged over windows of `window` iterations; the
//! run stops when the relative change ||avg_k − avg_{k−1}|| / max(1,
//! ||avg_{k−1}||) falls below `tol_rel_change`. The fit reported is the last
//! window average (Polyak–Ruppert averaging), which removes most of the
//! stochastic-gradient jitter.

use super::estimator::estimate;
use super::{Estimator, FamilyKind, GaussianQ, StepRule, StepState};
use crate::calibration::LogDensity;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Why BBVI could not run or continue.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BbviError {
    /// A setting is out of range.
    #[error("bbvi setting {key} = {value}: expected {expected}")]
    Setting {
        /// Setting name.
        key: &'static str,
        /// Its value.
        value: String,
        /// What is allowed.
        expected: &'static str,
    },
    /// Initial mean of the wrong length.
    #[error("initial mean has {found} values, the target has dimension {expected}")]
    Dimension {
        /// Length given.
        found: usize,
        /// Target dimension.
        expected: usize,
    },
    /// Every sample of an iteration had a non-finite log density.
    #[error("iteration {iter}: no sample had a finite log density (q mean {mean:?})")]
    NoFiniteSamples {
        /// Iteration number.
        iter: usize,
        /// Current mean of q.
        mean: Vec<f64>,
    },
}

/// BBVI settings.
#[derive(Debug, Clone, PartialEq)]
pub struct BbviSettings {
    /// Mean-field or full-rank.
    pub family: FamilyKind,
    /// Gradient estimator.
    pub estimator: Estimator,
    /// Monte Carlo samples per iteration.
    pub samples: usize,
    /// Step-size rule.
    pub step: StepRule,
    /// Iteration limit.
    pub max_iters: usize,
    /// Minimum iterations before convergence is checked.
    pub min_iters: usize,
    /// Averaging window (iterations).
    pub window: usize,
    /// Relative change of window averages that counts as converged.
    pub tol_rel_change: f64,
    /// Initial sd of every coordinate of q (unconstrained units).
    pub init_sd: f64,
    /// Samples for the final ELBO estimate.
    pub elbo_samples: usize,
    /// RNG seed.
    pub seed: u64,
}

impl BbviSettings {
    /// Reparameterisation gradient with Adam: the fast, accurate default.
    pub fn reparam(family: FamilyKind, seed: u64) -> Self {
        Self {
            family,
            estimator: Estimator::Reparam,
            samples: 32,
            step: StepRule::adam_default(),
            max_iters: 5000,
            min_iters: 400,
            window: 100,
            tol_rel_change: 5e-3,
            init_sd: 0.1,
            elbo_samples: 2000,
            seed,
        }
    }

    /// The seed's estimator: score function, control variates,
    /// Rao–Blackwellisation, AdaGrad steps (Ranganath et al. 2014).
    pub fn score(family: FamilyKind, seed: u64) -> Self {
        Self {
            estimator: Estimator::Score { control_variates: true, rao_blackwell: true },
            samples: 64,
            step: StepRule::AdaGrad { eta: 0.1 },
            max_iters: 20_000,
            min_iters: 1000,
            window: 500,
            tol_rel_change: 1e-3,
            ..Self::reparam(family, seed)
        }
    }

    /// Checks every setting.
    pub fn check(&self) -> Result<(), BbviError> {
        let bad = |key, value: String, expected| Err(BbviError::Setting { key, value, expected });
        if self.samples < 2 {
            return bad("samples", self.samples.to_string(), "at least 2");
        }
        if self.window == 0 {
            return bad("window", "0".into(), "at least 1");
        }
        if !(self.init_sd.is_finite() && self.init_sd > 0.0) {
            return bad("init_sd", self.init_sd.to_string(), "a finite value > 0");
        }
        if self.tol_rel_change.is_nan() || self.tol_rel_change < 0.0 {
            return bad("tol_rel_change", self.tol_rel_change.to_string(), "a value >= 0");
        }
        Ok(())
    }
}

/// Everything that changes between iterations.
#[derive(Debug, Clone)]
pub struct BbviState {
    /// Iterations done.
    pub iter: usize,
    /// Current variational distribution.
    pub q: GaussianQ,
    /// Latest ELBO estimate.
    pub elbo: f64,
    /// ELBO estimate of every iteration.
    pub elbo_trace: Vec<f64>,
    /// The RNG, so a saved state resumes the same stream.
    pub rng: ChaCha8Rng,
    /// Step-size rule memory.
    pub step: StepState,
    /// Sum of lambda over the current window.
    pub window_sum: Vec<f64>,
    /// Iterations in the current window.
    pub window_len: usize,
    /// Average of the last complete window.
    pub last_avg: Option<Vec<f64>>,
    /// Relative change between the last two window averages.
    pub rel_change: f64,
    /// True once the change fell below tolerance.
    pub converged: bool,
    /// Samples skipped for a non-finite log density.
    pub n_bad: usize,
}

/// The outcome of a run.
#[derive(Debug, Clone)]
pub struct BbviFit {
    /// The fitted q (last window average).
    pub q: GaussianQ,
    /// Iterations run.
    pub iterations: usize,
    /// Converged before `max_iters`.
    pub converged: bool,
    /// Final relative change.
    pub rel_change: f64,
    /// ELBO of the fitted q from `elbo_samples` draws.
    pub elbo: f64,
    /// Per-iteration ELBO estimates.
    pub elbo_trace: Vec<f64>,
    /// Samples skipped for a non-finite log density.
    pub n_bad: usize,
}

/// Watches a run; never changes the numbers.
pub trait Observer {
    /// Called after every iteration.
    fn observe(&mut self, state: &BbviState);
}

/// BBVI on a target log density.
pub struct Bbvi<'a, T: ?Sized> {
    target: &'a T,
    settings: BbviSettings,
}

impl<'a, T: LogDensity + ?Sized> Bbvi<'a, T> {
    /// Pairs a target with settings.
    pub fn new(target: &'a T, settings: BbviSettings) -> Self {
        Self { target, settings }
    }

    /// The settings.
    pub fn settings(&self) -> &BbviSettings {
        &self.settings
    }

    /// The starting state: q = N(init_mean, init_sd² I).
    pub fn init(&self, init_mean: &[f64]) -> Result<BbviState, BbviError> {
        self.settings.check()?;
        let d = self.target.dim();
        if init_mean.len() != d {
            return Err(BbviError::Dimension { found: init_mean.len(), expected: d });
        }
        let q = GaussianQ::new(self.settings.family, init_mean, &vec![self.settings.init_sd; d]);
        Ok(BbviState {
            iter: 0,
            window_sum: vec![0.0; q.lambda.len()],
            q,
            elbo: f64::NEG_INFINITY,
            elbo_trace: Vec::new(),
            rng: ChaCha8Rng::seed_from_u64(self.settings.seed),
            step: StepState::default(),
            window_len: 0,
            last_avg: None,
            rel_change: f64::INFINITY,
            converged: false,
            n_bad: 0,
        })
    }

    /// One stochastic-gradient iteration.
    pub fn step(&self, mut st: BbviState) -> Result<BbviState, BbviError> {
        let s = &self.settings;
        let g = estimate(s.estimator, &self.target, &st.q, s.samples, &mut st.rng);
        st.n_bad += g.n_bad;
        if !g.elbo.is_finite() {
            return Err(BbviError::NoFiniteSamples { iter: st.iter, mean: st.q.mean().to_vec() });
        }
        s.step.apply(&mut st.q.lambda, &g.grad, &mut st.step);
        st.iter += 1;
        st.elbo = g.elbo;
        st.elbo_trace.push(g.elbo);
        st.window_sum.iter_mut().zip(&st.q.lambda).for_each(|(a, l)| *a += l);
        st.window_len += 1;
        if st.window_len == s.window {
            let avg: Vec<f64> = st.window_sum.iter().map(|v| v / s.window as f64).collect();
            if let Some(prev) = &st.last_avg {
                st.rel_change = rel_change(prev, &avg);
                st.converged = st.iter >= s.min_iters && st.rel_change < s.tol_rel_change;
            }
            st.last_avg = Some(avg);
            st.window_sum.iter_mut().for_each(|v| *v = 0.0);
            st.window_len = 0;
        }
        Ok(st)
    }

    /// Runs from `init_mean` until converged or `max_iters`.
    pub fn run(
        &self,
        init_mean: &[f64],
        observers: &mut [&mut dyn Observer],
    ) -> Result<BbviFit, BbviError> {
        let mut st = self.init(init_mean)?;
        while !st.converged && st.iter < self.settings.max_iters {
            st = self.step(st)?;
            observers.iter_mut().for_each(|o| o.observe(&st));
        }
        Ok(self.finish(st))
    }

    /// The fit from a state: its last window average and a fresh ELBO estimate.
    pub fn finish(&self, mut st: BbviState) -> BbviFit {
        let mut q = st.q.clone();
        if let Some(avg) = &st.last_avg {
            q.lambda = avg.clone();
        }
        let elbo = elbo_estimate(&self.target, &q, self.settings.elbo_samples, &mut st.rng);
        BbviFit {
            q,
            iterations: st.iter,
            converged: st.converged,
            rel_change: st.rel_change,
            elbo,
            elbo_trace: st.elbo_trace,
            n_bad: st.n_bad,
        }
    }
}

/// ||b − a|| / max(1, ||a||).
fn rel_change(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
    let n: f64 = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    d / n.max(1.0)
}

/// ELBO = E_q[log p(z)] + H[q] from `n` draws.
pub fn elbo_estimate<T: LogDensity + ?Sized, R: rand::Rng>(
    target: &T,
    q: &GaussianQ,
    n: usize,
    rng: &mut R,
) -> f64 {
    let l = q.cholesky();
    let sum: f64 = (0..n).map(|_| target.log_density(&q.sample(&l, rng).1)).sum();
    sum / n as f64 + q.entropy()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A correlated 2-D Gaussian target: full-rank BBVI recovers its moments.
    struct Corr;
    impl LogDensity for Corr {
        fn dim(&self) -> usize {
            2
        }
        fn log_density(&self, z: &[f64]) -> f64 {
            // Covariance [[1, 0.9], [0.9, 1]], mean (1, −1).
            let (a, b) = (z[0] - 1.0, z[1] + 1.0);
            -0.5 * (a * a - 1.8 * a * b + b * b) / (1.0 - 0.81)
        }
    }

    #[test]
    fn full_rank_reparam_recovers_correlated_gaussian() {
        let fit = Bbvi::new(&Corr, BbviSettings::reparam(FamilyKind::FullRank, 11))
            .run(&[0.0, 0.0], &mut [])
            .unwrap();
        let c = fit.q.covariance();
        assert!(
            (fit.q.mean()[0] - 1.0).abs() < 0.1 && (fit.q.mean()[1] + 1.0).abs() < 0.1,
            "{:?}",
            fit.q.mean()
        );
        assert!((c[(0, 0)] - 1.0).abs() < 0.1 && (c[(0, 1)] - 0.9).abs() < 0.1, "{c}");
    }

    #[test]
    fn mean_field_is_narrower_on_correlated_gaussian() {
        // KL(q||p) optimum for mean-field: var = 1 / (Sigma^-1)_ii = 0.19.
        let fit = Bbvi::new(&Corr, BbviSettings::reparam(FamilyKind::MeanField, 5))
            .run(&[0.0, 0.0], &mut [])
            .unwrap();
        let sd = fit.q.sd();
        assert!((sd[0] - 0.19f64.sqrt()).abs() < 0.05, "{sd:?}");
    }

    #[test]
    fn score_function_recovers_conjugate_gaussian() {
        let fit = Bbvi::new(&Corr, BbviSettings::score(FamilyKind::FullRank, 2))
            .run(&[0.0, 0.0], &mut [])
            .unwrap();
        let c = fit.q.covariance();
        assert!((fit.q.mean()[0] - 1.0).abs() < 0.15, "{:?}", fit.q.mean());
        assert!((c[(0, 1)] - 0.9).abs() < 0.15, "{c}");
    }

    /// The seed's Algorithm 6.2: score function with a Robbins–Monro sequence.
    #[test]
    fn score_function_with_robbins_monro_steps() {
        let s = BbviSettings {
            step: crate::bbvi::StepRule::RobbinsMonro { eta: 0.5, tau: 100.0, kappa: 0.7 },
            ..BbviSettings::score(FamilyKind::FullRank, 6)
        };
        let fit = Bbvi::new(&Corr, s).run(&[0.0, 0.0], &mut []).unwrap();
        let c = fit.q.covariance();
        assert!(
            (fit.q.mean()[0] - 1.0).abs() < 0.15 && (fit.q.mean()[1] + 1.0).abs() < 0.15,
            "{:?}",
            fit.q.mean()
        );
        assert!((c[(0, 0)] - 1.0).abs() < 0.15 && (c[(0, 1)] - 0.9).abs() < 0.15, "{c}");
    }

    #[test]
    fn same_seed_same_answer() {
        let run = || {
            Bbvi::new(&Corr, BbviSettings::reparam(FamilyKind::FullRank, 9))
                .run(&[0.0, 0.0], &mut [])
                .unwrap()
                .q
        };
        assert_eq!(run(), run());
    }

    #[test]
    fn bad_setting_is_named() {
        let mut s = BbviSettings::reparam(FamilyKind::FullRank, 9);
        s.samples = 1;
        let e = Bbvi::new(&Corr, s).run(&[0.0, 0.0], &mut []).unwrap_err().to_string();
        assert!(e.contains("samples = 1"), "{e}");
    }
}
