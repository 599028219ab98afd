//! The tempered SMC driver: options, the run's record, and the loop.

use super::moves::{accept, proposal_factor, propose, weighted_covariance, Population};
use super::{multinomial, next_temperature, relative_variance, Prior};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Settings of a tempered SMC run, each with its reason.
#[derive(Debug, Clone, PartialEq)]
pub struct SmcOptions {
    /// Particles: 1000 gives an evidence to about 0.1 nat on smooth
    /// posteriors of a few parameters (the tests measure it).
    pub particles: usize,
    /// Coefficient of variation of the incremental weights at each step:
    /// 1 halves the effective sample size per stage (Ching & Chen 2007;
    /// Betz et al. 2016).
    pub target_cov: f64,
    /// Metropolis steps per particle and stage: enough to move each particle
    /// about a proposal's width away from its resampled copies.
    pub mcmc_steps: usize,
    /// Acceptance rate the proposal scale is steered to: 0.234 (Roberts,
    /// Gelman & Gilks 1997).
    pub target_acceptance: f64,
    /// Stages before the run gives up (a likelihood too sharp for the population).
    pub max_stages: usize,
    /// Seed of the run's random stream.
    pub seed: u64,
}

impl Default for SmcOptions {
    fn default() -> Self {
        Self {
            particles: 1000,
            target_cov: 1.0,
            mcmc_steps: 10,
            target_acceptance: 0.234,
            max_stages: 500,
            seed: 1,
        }
    }
}

/// One stage of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct SmcStage {
    /// Temperature reached.
    pub beta: f64,
    /// log mean of the incremental weights (this stage's share of ln Z).
    pub ln_increment: f64,
    /// Effective sample size of the incremental weights over N.
    pub ess_fraction: f64,
    /// Acceptance rate of the stage's Metropolis steps.
    pub acceptance: f64,
    /// Proposal scale at the stage's end (times the population's covariance factor).
    pub proposal_scale: f64,
    /// Likelihood evaluations of the stage.
    pub evaluations: usize,
    /// Batches they were asked for in (evaluations / batches = runs in flight).
    pub batches: usize,
}

/// What a run found.
#[derive(Debug, Clone, PartialEq)]
pub struct SmcRun {
    /// ln Ẑ, the log-evidence estimate.
    pub ln_evidence: f64,
    /// Its Monte-Carlo standard error, sqrt(ln(1 + relative variance)).
    pub ln_evidence_sd: f64,
    /// var(Ẑ) / Z² by the genealogy estimator (may exceed 1 when the
    /// genealogy collapsed: the run cannot tell its error).
    pub relative_variance: f64,
    /// Distinct first-population ancestors left at the last weighting.
    pub distinct_ancestors: usize,
    /// The stages, first to last.
    pub stages: Vec<SmcStage>,
    /// Posterior draws (equally weighted).
    pub particles: Vec<Vec<f64>>,
    /// Their log-likelihoods.
    pub ln_likelihood: Vec<f64>,
    /// Likelihood evaluations in all.
    pub evaluations: usize,
}

/// Why a run stopped.
#[derive(Debug, thiserror::Error)]
pub enum SmcError<E: std::error::Error + 'static> {
    /// An option out of its range.
    #[error("smc option {key} = {value}: expected {expected}")]
    Option { key: &'static str, value: String, expected: &'static str },
    /// The likelihood callback failed.
    #[error("likelihood evaluation failed: {0}")]
    Likelihood(#[source] E),
    /// The callback answered a batch with the wrong number of values.
    #[error("likelihood batch of {asked} points answered with {got} values")]
    BatchSize { asked: usize, got: usize },
    /// A log-likelihood that is NaN or +∞.
    #[error("log-likelihood {value} at {point:?}: expected a finite value or -inf")]
    NotFinite { point: Vec<f64>, value: f64 },
    /// Every prior draw has zero likelihood.
    #[error("all {particles} prior draws have zero likelihood: the evidence is below what the population resolves")]
    NoSupport { particles: usize },
    /// The temperature did not reach 1 within the stage limit; what the
    /// run reached still bounds the evidence ([`Bounds`]).
    #[error("temperature {beta:.3e} after {stages} stages: the likelihood is too sharp for the population")]
    Stages {
        /// Stages run.
        stages: usize,
        /// Temperature reached.
        beta: f64,
        /// The bounds on ln Z from there (None: a particle's
        /// log-likelihood was not finite).
        bounds: Option<Bounds>,
    },
}

/// Bounds on ln Z from a run that stopped at temperature β < 1.
///
/// Below: ln Z(β) = ln ∫ base · L^β is convex in β (it is the cumulant
/// generating function of ln L under the base), so it lies above its
/// tangent at β: ln Z(1) ≥ ln Z(β) + (1 − β) E_β[ln L], the slope being the
/// mean of ln L under the tempered posterior at β. Both estimates err on
/// the low side where they err: ln Ẑ(β) is biased low (Jensen), and a
/// population that lags behind β (too few moves) sits where the slope is
/// smaller (it grows with β, ln Z being convex).
///
/// Above: Z(1) = Z(β) E_β[L^(1−β)] ≤ Z(β) (sup L)^(1−β), so ln Z(1) ≤
/// ln Z(β) + (1 − β) sup ln L. The supremum is estimated by the highest
/// ln L any population of the run held: a bound if the likelihood is
/// nowhere higher than the particles found, an estimate otherwise (the
/// populations at higher β gather where L is highest).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// The lower bound: ln Ẑ(β) + (1 − β) × the population's mean ln L.
    pub ln_evidence: f64,
    /// Its standard error: ln Ẑ(β)'s (genealogy estimator) and the mean's
    /// (the sample's spread over the square root of its distinct ancestors,
    /// copies of one ancestor being correlated) combined.
    pub sd: f64,
    /// The upper bound: ln Ẑ(β) + (1 − β) × the highest ln L held.
    pub ln_evidence_upper: f64,
    /// Its standard error: ln Ẑ(β)'s.
    pub upper_sd: f64,
    /// ln Ẑ(β), the evidence of the tempered posterior reached.
    pub ln_evidence_at_beta: f64,
}

impl Bounds {
    /// The bounds from a population at `beta` with log-likelihoods `ln_l`
    /// and first-population ancestors `eve`, `ln_z` = ln Ẑ(β) with relative
    /// variance `rel_var`, `ln_l_max` the highest ln L any population held;
    /// None when a log-likelihood is not finite.
    fn at(
        beta: f64,
        (ln_z, rel_var): (f64, f64),
        ln_l: &[f64],
        eve: &[usize],
        ln_l_max: f64,
    ) -> Option<Self> {
        if ln_l.is_empty() || ln_l.iter().any(|v| !v.is_finite()) || !ln_l_max.is_finite() {
            return None;
        }
        let n = ln_l.len() as f64;
        let mean = ln_l.iter().sum::<f64>() / n;
        let var = ln_l.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        let distinct = count_distinct(eve.iter().copied()).max(1) as f64;
        let gap = 1.0 - beta;
        let upper_sd = ln_sd(rel_var);
        let sd = (upper_sd.powi(2) + gap * gap * var / distinct).sqrt();
        Some(Bounds {
            ln_evidence: ln_z + gap * mean,
            sd,
            ln_evidence_upper: ln_z + gap * ln_l_max,
            upper_sd,
            ln_evidence_at_beta: ln_z,
        })
    }
}

/// Tempered sequential Monte Carlo with the given options.
#[derive(Debug, Clone, Default)]
pub struct TemperedSmc {
    /// The run's settings.
    pub options: SmcOptions,
}

/// Where [`TemperedSmc::run_from`] starts: an equally weighted population
/// of the base density, its log-likelihoods, the base's ln normaliser.
#[derive(Debug, Clone, PartialEq)]
pub struct Start {
    /// The particles.
    pub x: Vec<Vec<f64>>,
    /// Their log-likelihoods (−∞ for zero likelihood).
    pub ln_l: Vec<f64>,
    /// ln of the base density's normaliser (0 for a normalised prior).
    pub ln_z: f64,
}

type Batch<'a, E> = dyn FnMut(&[Vec<f64>]) -> Result<Vec<f64>, E> + 'a;

impl TemperedSmc {
    /// A sampler with these options.
    pub fn new(options: SmcOptions) -> Self {
        Self { options }
    }

    /// Runs from `prior` to the posterior under `ln_likelihood`, which maps a
    /// batch of points to their log-likelihoods (−∞ for zero likelihood).
    pub fn run<P: Prior + ?Sized, E: std::error::Error + 'static>(
        &self,
        prior: &P,
        ln_likelihood: &mut Batch<'_, E>,
    ) -> Result<SmcRun, SmcError<E>> {
        let o = &self.options;
        check_options(o)?;
        let n = o.particles;
        let mut rng = ChaCha8Rng::seed_from_u64(o.seed);
        let x: Vec<Vec<f64>> = (0..n).map(|_| prior.sample(&mut rng)).collect();
        let ln_l = evaluate(ln_likelihood, &x)?;
        if ln_l.iter().all(|v| *v == f64::NEG_INFINITY) {
            return Err(SmcError::NoSupport { particles: n });
        }
        let start = Start { x, ln_l, ln_z: 0.0 };
        self.anneal(start, &|x: &[f64]| prior.ln_density(x), ln_likelihood, &mut rng)
    }

    /// Runs from an equally weighted population `start.x` of a base density
    /// `ln_base` (log, up to its normaliser e^`start.ln_z`; −∞ outside its
    /// support) to base × likelihood, `start.ln_l` the log-likelihoods at
    /// the population, `ln_likelihood` as in [`run`](Self::run). The
    /// evidence is the base's normaliser times the likelihood's mean under
    /// the base, estimated by tempering (`options.particles` is ignored: the
    /// population is `start.x`). [`run`](Self::run) is this from prior draws.
    pub fn run_from<E: std::error::Error + 'static>(
        &self,
        start: Start,
        ln_base: &dyn Fn(&[f64]) -> f64,
        ln_likelihood: &mut Batch<'_, E>,
    ) -> Result<SmcRun, SmcError<E>> {
        check_options(&SmcOptions { particles: start.x.len(), ..self.options.clone() })?;
        if start.x.len() != start.ln_l.len() {
            let (asked, got) = (start.x.len(), start.ln_l.len());
            return Err(SmcError::BatchSize { asked, got });
        }
        if start.ln_l.iter().all(|v| *v == f64::NEG_INFINITY) {
            return Err(SmcError::NoSupport { particles: start.x.len() });
        }
        let mut rng = ChaCha8Rng::seed_from_u64(self.options.seed);
        self.anneal(start, ln_base, ln_likelihood, &mut rng)
    }

    /// The tempering loop from `start` (see [`run_from`](Self::run_from)).
    fn anneal<E: std::error::Error + 'static>(
        &self,
        start: Start,
        ln_base: &dyn Fn(&[f64]) -> f64,
        ln_likelihood: &mut Batch<'_, E>,
        rng: &mut ChaCha8Rng,
    ) -> Result<SmcRun, SmcError<E>> {
        let o = &self.options;
        let Start { mut x, mut ln_l, ln_z: ln_z0 } = start;
        let n = x.len();
        let d = x.first().map_or(1, Vec::len);
        let mut ln_p: Vec<f64> = x.iter().map(|xi| ln_base(xi)).collect();
        let mut evaluations = n;
        let mut eve: Vec<usize> = (0..n).collect();
        // rel_var: ln Ẑ(β)'s relative variance at the last weighting.
        let (mut beta, mut ln_z, mut rel_var, mut distinct) = (0.0, ln_z0, f64::INFINITY, n);
        let mut scale = 2.38 / (d.max(1) as f64).sqrt();
        let mut stages = Vec::new();
        let mut ln_l_max = highest(&ln_l);
        while beta < 1.0 {
            if stages.len() >= o.max_stages {
                let bounds = Bounds::at(beta, (ln_z, rel_var), &ln_l, &eve, ln_l_max);
                return Err(SmcError::Stages { stages: stages.len(), beta, bounds });
            }
            let next = next_temperature(&ln_l, beta, o.target_cov);
            let lw: Vec<f64> = ln_l.iter().map(|l| (next - beta) * l).collect();
            let m = lw.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let w: Vec<f64> = lw.iter().map(|v| (v - m).exp()).collect();
            let sum_w: f64 = w.iter().sum();
            let ln_increment = m + (sum_w / n as f64).ln();
            ln_z += ln_increment;
            let ess_fraction = sum_w * sum_w / w.iter().map(|v| v * v).sum::<f64>() / n as f64;
            rel_var = relative_variance(&eve, &w, stages.len());
            if next >= 1.0 {
                distinct =
                    count_distinct(eve.iter().zip(&w).filter(|(_, w)| **w > 0.0).map(|e| *e.0));
            }
            let factor = proposal_factor(&weighted_covariance(&x, &w));
            let anc = multinomial(&w, rng);
            x = anc.iter().map(|&a| x[a].clone()).collect();
            ln_l = anc.iter().map(|&a| ln_l[a]).collect();
            ln_p = anc.iter().map(|&a| ln_p[a]).collect();
            eve = anc.iter().map(|&a| eve[a]).collect();
            beta = next;
            let mut pop = Population { x: &mut x, ln_l: &mut ln_l, ln_p: &mut ln_p };
            let moved = self.move_population(
                ln_base,
                ln_likelihood,
                &mut pop,
                &factor,
                &mut scale,
                beta,
                rng,
            )?;
            evaluations += moved.0;
            ln_l_max = ln_l_max.max(highest(&ln_l));
            stages.push(SmcStage {
                beta,
                ln_increment,
                ess_fraction,
                acceptance: moved.1,
                proposal_scale: scale,
                evaluations: moved.0,
                batches: moved.2,
            });
        }
        Ok(SmcRun {
            ln_evidence: ln_z,
            ln_evidence_sd: ln_sd(rel_var),
            relative_variance: rel_var,
            distinct_ancestors: distinct,
            stages,
            particles: x,
            ln_likelihood: ln_l,
            evaluations,
        })
    }

    /// The stage's Metropolis steps; returns (evaluations, acceptance rate,
    /// batches asked for: a step whose proposals all leave the support asks none)
    /// and steers `scale` toward the target acceptance after every step.
    #[allow(clippy::too_many_arguments)]
    fn move_population<E: std::error::Error + 'static>(
        &self,
        ln_base: &dyn Fn(&[f64]) -> f64,
        ln_likelihood: &mut Batch<'_, E>,
        pop: &mut Population<'_>,
        factor: &nalgebra::DMatrix<f64>,
        scale: &mut f64,
        beta: f64,
        rng: &mut ChaCha8Rng,
    ) -> Result<(usize, f64, usize), SmcError<E>> {
        let o = &self.options;
        let n = pop.x.len();
        let base = 2.38 / (factor.nrows().max(1) as f64).sqrt();
        let (mut evaluations, mut accepted, mut batches) = (0, 0, 0);
        for _ in 0..o.mcmc_steps {
            let y = propose(pop.x, factor, *scale, rng);
            let ln_p_y: Vec<f64> = y.iter().map(|yi| ln_base(yi)).collect();
            let inside: Vec<usize> = (0..n).filter(|&i| ln_p_y[i].is_finite()).collect();
            let asked: Vec<Vec<f64>> = inside.iter().map(|&i| y[i].clone()).collect();
            let got = if asked.is_empty() { Vec::new() } else { evaluate(ln_likelihood, &asked)? };
            evaluations += asked.len();
            batches += usize::from(!asked.is_empty());
            let mut ln_l_y = vec![f64::NEG_INFINITY; n];
            for (k, &i) in inside.iter().enumerate() {
                ln_l_y[i] = got[k];
            }
            let a = accept(pop, y, &ln_p_y, &ln_l_y, beta, rng);
            accepted += a;
            let rate = a as f64 / n as f64;
            *scale = (*scale * (rate - o.target_acceptance).exp()).clamp(1e-3 * base, 10.0 * base);
        }
        Ok((evaluations, accepted as f64 / (n * o.mcmc_steps).max(1) as f64, batches))
    }
}

/// Asks for one batch and checks its answers.
fn evaluate<E: std::error::Error + 'static>(
    f: &mut Batch<'_, E>,
    x: &[Vec<f64>],
) -> Result<Vec<f64>, SmcError<E>> {
    let v = f(x).map_err(SmcError::Likelihood)?;
    if v.len() != x.len() {
        return Err(SmcError::BatchSize { asked: x.len(), got: v.len() });
    }
    if let Some(i) = v.iter().position(|l| l.is_nan() || *l == f64::INFINITY) {
        return Err(SmcError::NotFinite { point: x[i].clone(), value: v[i] });
    }
    Ok(v)
}

/// Distinct ancestors among `eve`.
fn count_distinct(eve: impl Iterator<Item = usize>) -> usize {
    let mut e: Vec<usize> = eve.collect();
    e.sort_unstable();
    e.dedup();
    e.len()
}

/// The highest of `ln_l` (−∞ when empty).
fn highest(ln_l: &[f64]) -> f64 {
    ln_l.iter().copied().fold(f64::NEG_INFINITY, f64::max)
}

/// The standard error of ln Ẑ from Ẑ's relative variance,
/// sqrt(ln(1 + relative variance)).
fn ln_sd(rel_var: f64) -> f64 {
    (1.0 + rel_var.max(0.0)).ln().sqrt()
}

/// Refuses options no run can use.
fn check_options<E: std::error::Error + 'static>(o: &SmcOptions) -> Result<(), SmcError<E>> {
    let bad = |key, value: String, expected| Err(SmcError::Option { key, value, expected });
    if !(2..=10_000_000).contains(&o.particles) {
        return bad("particles", o.particles.to_string(), "2 to 10 000 000");
    }
    if !(o.target_cov.is_finite() && o.target_cov > 0.0) {
        return bad("target_cov", o.target_cov.to_string(), "a positive number");
    }
    if !(o.target_acceptance > 0.0 && o.target_acceptance < 1.0) {
        return bad("target_acceptance", o.target_acceptance.to_string(), "a number in (0, 1)");
    }
    if o.max_stages == 0 {
        return bad("max_stages", "0".into(), "at least 1");
    }
    Ok(())
}
