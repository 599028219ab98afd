//! The evidence p(data | class) of one model class: the integral of its
//! likelihood over its whole prior (uniform on the class's unit cube, so
//! log-uniform where a [`Prior`](super::cause::Prior) is), computed with FE
//! runs spent where the posterior lives.
//!
//! The likelihood of a specimen's records is sharp: on the tiny test
//! campaign (two 2 s runs) its posterior fills about 1e-6 of the baseline's
//! cube, so no space-filling design lands in it and a stationary emulator
//! over the cube sees a flat floor with a needle. The evidence therefore
//! starts with a local search of the likelihood it integrates
//! ([`super::resume::peak_search`]: Levenberg–Marquardt on that
//! likelihood's own residuals, the band-passed ones under the band
//! likelihood), from the class calibration's best point under it: its best
//! point u* and the Gauss–Newton matrix H of −ln L there. One driver
//! then runs rounds over one ledger of FE evaluations (the calibration's
//! and the search's first):
//!
//! 1. **Emulator**: ln L̃ = q + r, never above the best FE value seen
//!    ([`Emulator`]). q(u) = ln L(u*) − ½ (u − u*)ᵀ H (u − u*) is the
//!    Laplace quadratic and r a GP (zero mean) of the residual
//!    max(ln L, f) − q, f = best − [`EvidencePolicy::floor`] the floor below
//!    which a value is negligible, in the whitened coordinates z =
//!    Lᵀ(u − u*) (H = L Lᵀ) where the posterior has unit width, through the
//!    calibration's points within the window (by ln L or by q) and every
//!    FE check of earlier rounds (so a check where the emulator was wrongly
//!    high teaches it so). The quadratic carries the decay the GP cannot,
//!    and leads the SMC from the prior to the mode (a negative-quadratic
//!    mean, as VBMC's: Acerbi 2018); the GP carries the skew and curvature
//!    the Laplace form misses. With too few points for a GP the emulator is
//!    q alone (the first round is then the Laplace approximation,
//!    corrected).
//! 2. **SMC**: a tempered SMC run on ln L̃ over the cube
//!    ([`stats::evidence::TemperedSmc`]).
//! 3. **FE check**: FE runs at [`EvidencePolicy::checks`] of its final
//!    particles; the evidence corrected by them
//!    ([`stats::evidence::correct_evidence`]: Z = Z̃ · mean of L/L̃ over
//!    draws of the emulated posterior). The checked points join the ledger,
//!    so each round's emulator is better where the last round's posterior
//!    was.
//! 4. **Stop** when the correction can be trusted
//!    ([`EvidencePolicy::settled`]: Pareto k̂ ≤
//!    [`EvidencePolicy::max_k_hat`], or ratios that hardly vary), the evidence's standard error is at
//!    most [`EvidencePolicy::target_sd_nats`] and it agrees with the last
//!    round's within twice their errors combined, or when the rounds run
//!    out (then [`ClassEvidence::converged`] is false and the estimate is
//!    the last round's, with its error).
//! 5. **Resume** ([`settled_evidence`]): when a round's checks rise above
//!    every FE value before them by more than [`rise_limit`] (d/2 nats),
//!    the start was not the posterior's mode and every form built at it is
//!    wrong; the rounds stop, the local search resumes from the highest
//!    check, and the evidence starts again at its new best point, at most
//!    [`EvidencePolicy::restarts`] times.
//!    An emulator cannot find a mode hundreds of nats above its start
//!    through a posterior it has to guess: on a friction-and-pounding
//!    campaign the rounds' emulated evidence rose by 660 nats over eight
//!    rounds while their corrections fell from +45 to −6600 nats of it
//!    (k̂ 4.6 to 52), never settling. The agreement is asked for because
//!    a correction's error cannot see mass its draws never reach: on the
//!    test campaign, from a Laplace form 5.5 times too narrow, the first
//!    round claimed 2105.7 ± 0.35 nat where quadrature gives 2108.6; the
//!    second, its emulator fitted through the first's checks, gave
//!    2108.59 ± 0.10.
//!
//! ln L is the likelihood the policy names ([`EvidencePolicy::likelihood`],
//! [`super::likelihood`]; the modal term included): the same for every
//! class judged on the same data, so evidences compare. The band
//! likelihood (the default) is not the one the calibration minimised: its
//! mode and curvature are its own search's. (Before, the start was the
//! calibration's best point under it with the time likelihood's curvature
//! scaled by the median ratio of the two likelihoods' rises; on the
//! combined classes of two project-model campaigns that form was so far
//! from the band posterior that FE checks and emulator differed by hundreds
//! to thousands of nats and no round settled.) The rounds' refit of the
//! quadratic to the ledger corrects a curvature the search got wrong (from
//! one 30 times off, the test campaign's evidence was within 0.06 nat of
//! quadrature).

use super::calibrate::{evaluate_points, Calibration};
use super::executor::{ExecutorError, FeExecutor};
use super::fit::Evaluation;
use super::likelihood::{ChannelWeights, Likelihood, LikelihoodKind};
use crate::bundle::Bundle;
use nalgebra::{DMatrix, DVector};
use stats::calibration::UniformBox;
use stats::evidence::{
    check_indices, correct_evidence, CorrectedEvidence, SmcError, SmcOptions, Start, TemperedSmc,
};
use stats::gp::{fit, Gp, GpError, GpSettings, InputScaling, MeanKind};

/// How a class's evidence is computed; every value with its reason.
#[derive(Debug, Clone, PartialEq)]
pub struct EvidencePolicy {
    /// Emulator rounds at most (each one SMC run and `checks` FE runs; at
    /// least two without annealing, as the stop rule compares consecutive
    /// rounds; one is then settled by the annealing alone).
    pub rounds: usize,
    /// FE runs per round at the emulated posterior's particles: 40 puts the
    /// correction's standard error near 0.15 nat when L/L̃ varies by a
    /// factor of e across the posterior.
    pub checks: usize,
    /// Largest Pareto k̂ of the log-ratios ln L − ln L̃ at which the
    /// correction is trusted: 0.7 (Vehtari et al. 2024, PSIS).
    pub max_k_hat: f64,
    /// Standard error of ln Z at which the rounds stop (nat): 0.3, a third of
    /// the 1 nat below which Jeffreys' scale calls odds "not worth more than
    /// a bare mention".
    pub target_sd_nats: f64,
    /// The emulator's window below the best FE value (nat), base and per
    /// parameter: 20 + 10 d. Raising values below it changes the evidence by
    /// less than e^−20 of itself when the posterior's width is above 1e-4
    /// of the cube on each axis (its volume is then above e^−8.3 d), and it
    /// keeps the emulator from spending its smoothness on regions of no mass.
    pub floor_nats: (f64, f64),
    /// The SMC runs on the emulator (their seed is advanced each round):
    /// 3000 particles, as the emulator costs no FE runs; at 1000 their own
    /// error was 0.35 to 0.6 nat on the demo's six-parameter classes,
    /// above [`target_sd_nats`](Self::target_sd_nats) on its own.
    pub smc: SmcOptions,
    /// The likelihood ln L (band by default: its nats do not grow with the
    /// sampling rate, see [`super::band_likelihood`]).
    pub likelihood: LikelihoodKind,
    /// The prior probability that each registered effect acts, independently
    /// of the others: a class of k of the n effects has prior
    /// p^k (1 − p)^(n − k). 0.5 by default: every class equally probable
    /// before the data, the evidence's Occam factor the only penalty on
    /// complexity ([`super::class_odds::ln_prior`]).
    pub effect_prior: f64,
    /// Times the calibration's local search may resume from higher ground
    /// a round's checks found ([`settled_evidence`]): 4, each a search of
    /// [`resume_steps`](Self::resume_steps) steps and at least one round of
    /// checks, so that the resumed searches cost at most about what the
    /// eight rounds do.
    pub restarts: usize,
    /// FE runs the annealing from the last round's emulated posterior to
    /// the FE posterior may spend when the rounds did not settle
    /// ([`Annealed`]; 0: none): 640, 8 stages of 40 particles moved twice,
    /// about the eight rounds' own 320 twice over.
    pub anneal_runs: usize,
    /// FE runs the annealing of a class the evidence does not yet order
    /// against the most probable one may grow to (the pipeline's decide
    /// step doubles [`anneal_runs`](Self::anneal_runs) up to it): 2560,
    /// two doublings. A choice, not measured: an annealing of 8 stages
    /// stopped at β 0.008 to 0.9 on the project's campaigns, and each
    /// doubling doubles its stages; the cost of deciding two classes is
    /// then at most 2 × 1920 FE runs, a campaign's own 5 300 being the
    /// scale.
    pub decide_runs: usize,
    /// Metropolis steps per particle and annealing stage: 2, so that a
    /// particle moves about a proposal's width from its resampled copies.
    pub anneal_steps: usize,
    /// Standard error (nat) at or below which an annealed evidence that
    /// reached the FE posterior counts as settled: 1, the Jeffreys scale's
    /// "not worth more than a bare mention" (40 particles cannot give the
    /// rounds' 0.3).
    pub anneal_sd_nats: f64,
    /// Tries of the curvature's scale check before the rounds
    /// ([`Rounds::check_scale`]; 0: none): 4, each one batch of 2d + 2 FE
    /// runs; a factor of 10⁴ off is then found in one or two tries.
    pub scale_tries: usize,
    /// Levenberg–Marquardt steps of each search of the evidence's likelihood
    /// (the first, and every restart), each (d + 2) FE runs (a Jacobian and
    /// a trial): 3, a bound on a start's cost (a choice, not measured: the
    /// next round's checks show whether it reached the mode, and another
    /// restart follows when it did not).
    pub resume_steps: usize,
}

impl Default for EvidencePolicy {
    fn default() -> Self {
        EvidencePolicy {
            rounds: 8,
            checks: 40,
            max_k_hat: 0.7,
            target_sd_nats: 0.3,
            floor_nats: (20.0, 10.0),
            smc: SmcOptions { particles: 3000, ..SmcOptions::default() },
            likelihood: LikelihoodKind::Band,
            effect_prior: 0.5,
            restarts: 4,
            resume_steps: 3,
            anneal_runs: 640,
            decide_runs: 2560,
            anneal_steps: 2,
            anneal_sd_nats: 1.0,
            scale_tries: 4,
        }
    }
}

impl EvidencePolicy {
    /// The emulator's window below the best value for `d` parameters (nat).
    pub fn floor(&self, d: usize) -> f64 {
        self.floor_nats.0 + self.floor_nats.1 * d as f64
    }

    /// FE runs of a search of the evidence's likelihood over `d` parameters.
    pub fn resume_runs(&self, d: usize) -> usize {
        self.resume_steps * (d + 2)
    }

    /// Whether round estimate `c` ends the rounds after `before` (the last
    /// corrected one): the correction trusted, its error within bounds, and
    /// the two agree within twice their errors combined. A correction is
    /// trusted when k̂ ≤ [`max_k_hat`](Self::max_k_hat), or when its
    /// log-ratios span at most [`target_sd_nats`](Self::target_sd_nats):
    /// then no tail among them can move it by more than the error asked
    /// for, while k̂, a tail-shape fit, reads rounding noise in ratios equal
    /// to 1e-5 (it gave 1.1 to 1.3 on the test campaign once the emulator
    /// was exact).
    fn settled(&self, c: &CorrectedEvidence, before: Option<&CorrectedEvidence>) -> bool {
        let agrees = before.is_some_and(|b| {
            let sd = (c.ln_evidence_sd.powi(2) + b.ln_evidence_sd.powi(2)).sqrt();
            (c.ln_evidence - b.ln_evidence).abs() <= 2.0 * sd
        });
        let trusted = c.k_hat <= self.max_k_hat || c.log_ratio_range <= self.target_sd_nats;
        trusted && c.ln_evidence_sd <= self.target_sd_nats && agrees
    }

    fn check(&self) -> Result<(), ClassEvidenceError> {
        let bad = |key: &'static str, value: String, expected: &'static str| {
            Err(ClassEvidenceError::Policy { key, value, expected })
        };
        if self.rounds < 2 && self.anneal_runs == 0 {
            return bad(
                "rounds",
                self.rounds.to_string(),
                "at least 2 without annealing (the stop rule compares two)",
            );
        }
        if self.checks < 2 {
            return bad("checks", self.checks.to_string(), "at least 2");
        }
        if self.anneal_steps < 1 {
            return bad("anneal_steps", self.anneal_steps.to_string(), "at least 1");
        }
        if !(self.anneal_sd_nats > 0.0 && self.anneal_sd_nats.is_finite()) {
            return bad("anneal_sd_nats", self.anneal_sd_nats.to_string(), "a positive number");
        }
        if self.scale_tries > 16 {
            return bad("scale_tries", self.scale_tries.to_string(), "at most 16");
        }
        if self.resume_steps < 1 {
            return bad("resume_steps", self.resume_steps.to_string(), "at least 1");
        }
        let (base, per_dim) = self.floor_nats;
        if !(base > 0.0 && per_dim >= 0.0 && base.is_finite() && per_dim.is_finite()) {
            let value = format!("{:?}", self.floor_nats);
            return bad("floor_nats", value, "a positive base and a per-parameter value ≥ 0");
        }
        Ok(())
    }
}

/// One round: the emulator's evidence and the corrected one.
#[derive(Debug, Clone, PartialEq)]
pub struct EvidenceRound {
    /// Ledger points the residual GP was fitted through (0: q alone).
    pub emulator_points: usize,
    /// ln Z of the emulator (SMC) and its standard error.
    pub emulated: (f64, f64),
    /// SMC stages (temperatures) the run took.
    pub smc_stages: usize,
    /// FE runs of its checks.
    pub fe_points: usize,
    /// The evidence corrected by this round's FE checks (None: every
    /// check failed to simulate).
    pub corrected: Option<CorrectedEvidence>,
    /// ln L of its highest check less the highest FE ln L before the round
    /// (nat; −∞ when every check failed).
    pub rise_nats: f64,
}

/// A check that rose above every FE value before its round by more than
/// [`rise_limit`]: the calibration's best point was not the mode.
#[derive(Debug, Clone, PartialEq)]
pub struct HigherGround {
    /// The check's unit-cube point.
    pub u: Vec<f64>,
    /// How far it rose (nat).
    pub rise_nats: f64,
}

/// The rise of a check above every FE value before it (nat) beyond which
/// the calibration's best point is taken for a point short of the mode: d/2
/// for `d` parameters. Draws of a posterior whose mode is that point lie
/// below it by χ²_d / 2, d/2 on average; a rise within that is a shape the
/// rounds' refitted quadratic and residual GP can carry, one beyond it a
/// mode the quadratic was not centred on.
pub fn rise_limit(d: usize) -> f64 {
    0.5 * d as f64
}

/// The evidence of one class, with its error and how it was reached.
#[derive(Debug, Clone, PartialEq)]
pub struct ClassEvidence {
    /// ln p(data | class) (nat; the likelihood's dropped constants are the
    /// same for every class on the same data).
    pub ln_evidence: f64,
    /// Its standard error (nat): the SMC run's and the correction's.
    pub ln_evidence_sd: f64,
    /// Pareto k̂ of the final correction.
    pub k_hat: f64,
    /// Whether the stop rule was met (else the rounds ran out).
    pub converged: bool,
    /// The Laplace approximation ln L(u*) + d/2 ln 2π − ½ ln det H, for
    /// comparison and as the class search's guide where the evidence does
    /// not settle (nat; H the search's times [`curvature_scale`](Self::curvature_scale)).
    pub laplace_ln_evidence: f64,
    /// The factor the scale check put on the search's curvature (1: none
    /// needed or none run; [`Rounds::check_scale`]).
    pub curvature_scale: f64,
    /// Every round, in order.
    pub rounds: Vec<EvidenceRound>,
    /// FE evaluations this computation ran (the calibration's and its
    /// local searches' not counted: they join the calibration).
    pub fe_points: usize,
    /// The likelihood it integrated.
    pub likelihood: LikelihoodKind,
    /// Times the calibration's search resumed from higher ground before
    /// this estimate ([`settled_evidence`]).
    pub restarts: usize,
    /// Where the rounds stopped for higher ground (None: they did not).
    pub higher_ground: Option<HigherGround>,
    /// The annealing from the last round's emulated posterior to the FE
    /// posterior, when the rounds did not settle (None: not run).
    pub annealed: Option<Annealed>,
}

/// The evidence annealed from the last round's emulated posterior to the
/// FE posterior: a tempered SMC ([`stats::evidence::TemperedSmc::run_from`])
/// from the round's checked particles (draws of p·L̃, normaliser Z̃) along
/// p·L̃·(L/L̃)^β, β from 0 to 1, each stage's particles moved by Metropolis
/// steps that run the FE model. One round's correction is this path in a
/// single step without moves; where the emulator is wrong over much of its
/// posterior that step's weights are too uneven to trust (k̂ ≫ 0.7), while
/// the stages reweight gradually and move the particles to where the FE
/// model puts its mass.
#[derive(Debug, Clone, PartialEq)]
pub struct Annealed {
    /// ln Z (nat: ln Z̃ plus the stages' increments) and its standard error
    /// (Z̃'s and the stages', genealogy estimator), when β reached 1 within
    /// [`EvidencePolicy::anneal_runs`] (None: the FE runs ran out first).
    pub estimate: Option<(f64, f64)>,
    /// Stages run.
    pub stages: usize,
    /// FE runs of its moves.
    pub fe_points: usize,
    /// The temperature reached (1: the FE posterior).
    pub beta: f64,
    /// When the FE runs ran out first: ln Z bounded below from the
    /// temperature reached and its standard error (nat; ln Z̃'s and the
    /// bound's combined; [`stats::evidence::Bounds`]); None otherwise.
    pub lower: Option<(f64, f64)>,
    /// When the FE runs ran out first: ln Z bounded above from the
    /// temperature reached by the highest ln L/L̃ its particles held, and
    /// its standard error (nat; [`stats::evidence::Bounds`]); None
    /// otherwise.
    pub upper: Option<(f64, f64)>,
}

/// A value in nats and its standard error.
pub type WithSd = (f64, f64);

impl Annealed {
    /// What bounds ln Z, each bound with its standard error: below and
    /// above by the annealed estimate when β reached 1 (an estimate whose
    /// error was too large to settle is still one: it bounds ln Z on both
    /// sides, within its error, the estimate of an annealing that reached
    /// +109.5 ± 1.01 nats over `none` would else not be weighed at all);
    /// else by the bounds from the temperature reached (the upper one None
    /// when unknown); None when neither is known.
    pub fn range(&self) -> Option<(WithSd, Option<WithSd>)> {
        match self.estimate {
            Some(z) => Some((z, Some(z))),
            None => self.lower.map(|l| (l, self.upper)),
        }
    }
}

/// Standard errors below a lower bound's estimate at which the bound is
/// counted ([`ClassEvidence::counted_ln_evidence`]): 2, so that, its error
/// being normal, the counted value lies below the bound with probability
/// 0.98 (the same two standard errors at which two rounds agree).
pub const BOUND_SDS: f64 = 2.0;

impl ClassEvidence {
    /// The ln Z at which the class is compared with others: the estimate
    /// when it settled; else its lower bound less [`BOUND_SDS`] standard
    /// errors, the bound being, when an annealing reached the FE posterior
    /// with an error above [`EvidencePolicy::anneal_sd_nats`], its
    /// estimate, and when one ran out of FE runs before it, the bound from
    /// the temperature reached (a class whose evidence is known to be at
    /// least this much is weighed at it: conservative for that class,
    /// never for its rivals); None otherwise (the rounds' unsettled
    /// estimate is never compared).
    pub fn counted_ln_evidence(&self) -> Option<f64> {
        if self.converged {
            return Some(self.ln_evidence);
        }
        let (bound, sd) = self.annealed.as_ref()?.range()?.0;
        Some(bound - BOUND_SDS * sd).filter(|v| v.is_finite())
    }

    /// The most ln Z may be, for ordering classes: the estimate when it
    /// settled; else its upper bound plus [`BOUND_SDS`] standard errors
    /// (the annealed estimate when it reached the FE posterior, else the
    /// bound from the temperature reached); None (no limit known)
    /// otherwise.
    pub fn ln_evidence_at_most(&self) -> Option<f64> {
        if self.converged {
            return Some(self.ln_evidence);
        }
        let (bound, sd) = self.annealed.as_ref()?.range()?.1?;
        Some(bound + BOUND_SDS * sd).filter(|v| v.is_finite())
    }
}

/// What the curvature's scale check found ([`Rounds::check_scale`]).
struct ScaleCheck {
    /// The factor put on the curvature in all.
    factor: f64,
    /// FE runs of its draws.
    fe_points: usize,
    /// A draw that rose above the best value by more than [`rise_limit`].
    higher_ground: Option<HigherGround>,
}

/// Why a class's evidence could not be computed.
#[derive(Debug, thiserror::Error)]
pub enum ClassEvidenceError {
    /// The executor could not deliver.
    #[error(transparent)]
    Executor(#[from] ExecutorError),
    /// A policy value out of range.
    #[error("evidence policy {key} = {value}: expected {expected}")]
    Policy {
        /// The field.
        key: &'static str,
        /// Its value.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// The calibration has no successful point or no curvature there.
    #[error("calibration of {cause}: {what}")]
    Start {
        /// The class.
        cause: &'static str,
        /// What it lacks.
        what: &'static str,
    },
    /// The SMC run on the emulator failed.
    #[error("SMC on the emulator, round {round}: {message}")]
    Smc {
        /// Round (from 1).
        round: usize,
        /// What failed.
        message: String,
    },
    /// No round's checks simulated.
    #[error("every FE check of {rounds} rounds failed to simulate")]
    NoCheck {
        /// Rounds run.
        rounds: usize,
    },
}

/// The evidence of `cal`'s class on `runs` of `bundle` under the policy's
/// likelihood (`w`: the diagnosis's channel weights), its rounds started
/// at `cal`'s best point under it with curvature `h` (the Gauss–Newton
/// matrix of that −ln L, unit cube), its FE runs through `exec`, by the
/// rounds of `policy` (see the module doc; the rounds never stop for higher
/// ground here).
pub fn class_evidence(
    cal: &Calibration,
    h: &DMatrix<f64>,
    data: (&Bundle, &[usize]),
    w: ChannelWeights<'_>,
    exec: &mut dyn FeExecutor,
    policy: &EvidencePolicy,
) -> Result<ClassEvidence, ClassEvidenceError> {
    evidence_rounds(cal, h, data, w, exec, policy, false)
}

/// The local search of the likelihood the evidence integrates from a point
/// (unit cube) over a calibration, its points joining it, its FE runs
/// through the executor given: the Gauss–Newton matrix of −ln L where it
/// ended (None: it could not linearise) ([`super::resume::peak_search`]).
pub type PeakSearch<'r> =
    dyn FnMut(&mut Calibration, Vec<f64>, &mut dyn FeExecutor) -> PeakResult + 'r;

/// What a [`PeakSearch`] gives: the Gauss–Newton matrix of −ln L where it
/// ended (None: it could not linearise).
pub type PeakResult = Result<Option<DMatrix<f64>>, ExecutorError>;

/// [`class_evidence`] from `search`'s end: from `cal`'s best point under
/// the policy's likelihood first, then, when a round's checks find higher
/// ground ([`rise_limit`]), from there, the evidence started again, at most
/// [`EvidencePolicy::restarts`] times (the last start's rounds run to
/// their end). The estimate counts every start's FE checks; the searches'
/// runs join `cal`.
pub fn settled_evidence(
    cal: &mut Calibration,
    data: (&Bundle, &[usize]),
    w: ChannelWeights<'_>,
    exec: &mut dyn FeExecutor,
    policy: &EvidencePolicy,
    search: &mut PeakSearch<'_>,
) -> Result<ClassEvidence, ClassEvidenceError> {
    let cause = cal.cause.as_str();
    let lik = policy.likelihood.with(w);
    let best =
        cal.best_by(&lik).ok_or(ClassEvidenceError::Start { cause, what: "no point simulated" })?;
    let mut from = cal.points[best].u.clone();
    let (mut spent, mut restarts) = (0, 0);
    loop {
        let h = search(cal, from, exec)?.ok_or(ClassEvidenceError::Start {
            cause,
            what: "no Gauss–Newton matrix (its local search could not linearise)",
        })?;
        let stop = restarts < policy.restarts;
        let mut got = evidence_rounds(cal, &h, data, w, exec, policy, stop)?;
        spent += got.fe_points;
        got.restarts = restarts;
        got.fe_points = spent;
        // Only rounds asked to stop for higher ground report it.
        let Some(high) = &got.higher_ground else { return Ok(got) };
        tracing::debug!(cause, restarts, rise = high.rise_nats, "higher ground");
        from = high.u.clone();
        restarts += 1;
    }
}

/// The rounds of [`class_evidence`]; with `stop_higher` they stop at the
/// first unsettled round whose checks found higher ground.
fn evidence_rounds(
    cal: &Calibration,
    h: &DMatrix<f64>,
    (bundle, runs): (&Bundle, &[usize]),
    w: ChannelWeights<'_>,
    exec: &mut dyn FeExecutor,
    policy: &EvidencePolicy,
    stop_higher: bool,
) -> Result<ClassEvidence, ClassEvidenceError> {
    policy.check()?;
    let lik = policy.likelihood.with(w);
    let d = cal.priors.len();
    let mut driver = Rounds {
        ev: cal.evaluation(bundle, runs),
        lik,
        policy,
        laplace: Laplace::of(cal, &lik, h)?,
        ledger: cal.points.iter().map(|p| (p.u.clone(), -p.neg_log_lik_by(&lik), false)).collect(),
        last: None,
    };
    let scale = driver.check_scale(exec, stop_higher)?;
    let (curvature_scale, mut fe_points) = (scale.factor, scale.fe_points);
    let laplace_ln_evidence = driver.laplace.ln_evidence();
    // Higher ground the check found (only with stop_higher): the search
    // resumes from it before any round (see settled_evidence).
    let mut higher_ground = scale.higher_ground;
    let rounds_left = if higher_ground.is_some() { 0 } else { policy.rounds };
    let mut rounds = Vec::new();
    let mut last: Option<CorrectedEvidence> = None;
    let mut converged = false;
    for round in 0..rounds_left {
        let (record, highest) = driver.round(round, exec)?;
        fe_points += record.fe_points;
        if let Some(c) = record.corrected.clone() {
            converged = policy.settled(&c, last.as_ref());
            last = Some(c);
        }
        let rise_nats = record.rise_nats;
        rounds.push(record);
        if converged {
            break;
        }
        if stop_higher && rise_nats > rise_limit(d) {
            higher_ground = highest.map(|u| HigherGround { u, rise_nats });
            break;
        }
    }
    let (ln_evidence, ln_evidence_sd, k_hat) = match (&last, &higher_ground) {
        (Some(c), _) => (c.ln_evidence, c.ln_evidence_sd, c.k_hat),
        (None, Some(_)) => (f64::NAN, f64::NAN, f64::NAN),
        (None, None) => return Err(ClassEvidenceError::NoCheck { rounds: rounds.len() }),
    };
    let annealed = match converged || higher_ground.is_some() || policy.anneal_runs == 0 {
        true => None,
        false => driver.anneal(exec)?,
    };
    let mut got = ClassEvidence {
        ln_evidence,
        ln_evidence_sd,
        k_hat,
        converged,
        laplace_ln_evidence,
        curvature_scale,
        rounds,
        fe_points,
        likelihood: policy.likelihood,
        restarts: 0,
        higher_ground,
        annealed: None,
    };
    if let Some(a) = annealed {
        got.fe_points += a.fe_points;
        if let Some((ln_evidence, sd)) = a.estimate {
            got.ln_evidence = ln_evidence;
            got.ln_evidence_sd = sd;
            got.converged = sd <= policy.anneal_sd_nats;
        }
        got.annealed = Some(a);
    }
    Ok(got)
}

/// The state the rounds share: the quadratic and the ledger.
struct Rounds<'a> {
    ev: Evaluation<'a>,
    lik: Likelihood<'a>,
    policy: &'a EvidencePolicy,
    laplace: Laplace,
    ledger: Vec<Entry>,
    /// The last round's emulator, SMC run and checks, which the annealing
    /// starts from ([`Rounds::anneal`]).
    last: Option<LastRound>,
}

/// What the annealing needs of the last round.
struct LastRound {
    em: Emulator,
    /// The emulator's ln Z̃ and its standard error.
    ln_z: (f64, f64),
    /// The checked particles, their emulated and their FE ln L.
    checks: Vec<(Vec<f64>, f64, f64)>,
    /// The round (from 0), for the annealing's seed.
    round: usize,
}

impl Rounds<'_> {
    /// One round (from 0): refit, emulate, SMC, check; its record and its
    /// highest check (None: every check failed). The checks join the ledger.
    fn round(
        &mut self,
        round: usize,
        exec: &mut dyn FeExecutor,
    ) -> Result<(EvidenceRound, Option<Vec<f64>>), ClassEvidenceError> {
        let d = self.laplace.mode.0.len();
        let floor = self.policy.floor(d);
        if let Some(refit) = self.laplace.refit(&self.ledger, floor) {
            self.laplace = refit;
        }
        let em = Emulator::fit(&self.laplace, &self.ledger, floor);
        let seed = self.policy.smc.seed.wrapping_add(round as u64);
        let smc = TemperedSmc::new(SmcOptions { seed, ..self.policy.smc.clone() });
        let cube =
            UniformBox { names: vec![String::new(); d], lower: vec![0.0; d], upper: vec![1.0; d] };
        let run = smc
            .run(&cube, &mut |xs: &[Vec<f64>]| em.ln_l(xs))
            .map_err(|e| ClassEvidenceError::Smc { round: round + 1, message: e.to_string() })?;
        let idx = check_indices(&run, self.policy.checks);
        let checks: Vec<Vec<f64>> = idx.iter().map(|&i| run.particles[i].clone()).collect();
        let exact = self.fe_ln_l(&checks, exec)?;
        let before = self.ledger.iter().map(|e| e.1).fold(f64::NEG_INFINITY, f64::max);
        let highest = highest(&exact);
        let rise_nats = highest.map_or(f64::NEG_INFINITY, |k| exact[k] - before);
        let highest = highest.map(|k| checks[k].clone());
        let record = EvidenceRound {
            emulator_points: em.points(),
            emulated: (run.ln_evidence, run.ln_evidence_sd),
            smc_stages: run.stages.len(),
            fe_points: checks.len(),
            corrected: correct_evidence(&run, &idx, &exact),
            rise_nats,
        };
        let emulated = idx.iter().map(|&i| run.ln_likelihood[i]);
        let checked = (checks.iter().cloned().zip(emulated).zip(exact.iter().copied()))
            .map(|((u, e), x)| (u, e, x))
            .collect();
        let ln_z = (run.ln_evidence, run.ln_evidence_sd);
        self.last = Some(LastRound { em, ln_z, checks: checked, round });
        self.ledger.extend(checks.into_iter().zip(exact).map(|(u, l)| (u, l, true)));
        Ok((record, highest))
    }

    /// The FE model's ln L at unit-cube points `us` (−∞ where a simulation
    /// failed).
    fn fe_ln_l(
        &self,
        us: &[Vec<f64>],
        exec: &mut dyn FeExecutor,
    ) -> Result<Vec<f64>, ExecutorError> {
        let points = evaluate_points(&self.ev, us, exec)?;
        Ok(points.iter().map(|p| -p.neg_log_lik_by(&self.lik)).collect())
    }

    /// Checks the Laplace form's scale by its own draws before the rounds:
    /// 2d + 2 points drawn from it (whitened z ~ N(0, I), inside the cube)
    /// run through the FE model, where an exact quadratic drops by ½|z|²
    /// below the best value; the median of their drops over ½|z|² is the
    /// factor its curvature is off by (a Gauss–Newton matrix from
    /// difference steps wider than a sharp likelihood's features is too
    /// small: its draws then fall hundreds of nats low and no round's
    /// correction can be trusted). While that factor lies outside [½, 2]
    /// the curvature is scaled by it, at most
    /// [`EvidencePolicy::scale_tries`] times. A draw that rises above the
    /// best value by more than [`rise_limit`] says the form's centre, not
    /// its scale, is wrong: with `stop_higher` the check stops there and
    /// reports it (else it goes on, the rounds' refit left to move the
    /// centre). The points join the ledger. Returns the factor applied in all, the FE
    /// runs spent and the higher ground found.
    fn check_scale(
        &mut self,
        exec: &mut dyn FeExecutor,
        stop_higher: bool,
    ) -> Result<ScaleCheck, ClassEvidenceError> {
        use rand::SeedableRng;
        let d = self.laplace.mode.0.len();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(self.policy.smc.seed ^ SCALE_SEED);
        let mut check = ScaleCheck { factor: 1.0, fe_points: 0, higher_ground: None };
        for _ in 0..self.policy.scale_tries {
            let draws = self.laplace.draws_in_cube(2 * d + 2, &mut rng);
            if draws.is_empty() {
                break;
            }
            let us: Vec<Vec<f64>> = draws.iter().map(|(u, _)| u.clone()).collect();
            let exact = self.fe_ln_l(&us, exec)?;
            check.fe_points += us.len();
            let top = self.laplace.mode.1;
            let rise = highest(&exact).map(|k| (us[k].clone(), exact[k] - top));
            let mut ratios: Vec<f64> = (draws.iter().zip(&exact))
                .filter(|((_, q), l)| l.is_finite() && *q > 1e-9)
                .map(|((_, q), l)| (top - l).max(0.0) / q)
                .collect();
            self.ledger.extend(us.into_iter().zip(exact).map(|(u, l)| (u, l, true)));
            if let Some((u, rise_nats)) = rise.filter(|r| stop_higher && r.1 > rise_limit(d)) {
                check.higher_ground = Some(HigherGround { u, rise_nats });
                break;
            }
            if ratios.is_empty() {
                break;
            }
            ratios.sort_by(f64::total_cmp);
            let factor = ratios[ratios.len() / 2].clamp(SCALE_LIMITS.0, SCALE_LIMITS.1);
            if (0.5..=2.0).contains(&factor) {
                break;
            }
            self.laplace = self.laplace.scaled(factor);
            check.factor *= factor;
        }
        Ok(check)
    }

    /// The annealing from the last round ([`Annealed`]); None without a
    /// last round or when its checks all failed.
    fn anneal(&self, exec: &mut dyn FeExecutor) -> Result<Option<Annealed>, ClassEvidenceError> {
        let Some(last) = &self.last else { return Ok(None) };
        let (em, policy) = (&last.em, self.policy);
        let n = last.checks.len();
        let start = Start {
            x: last.checks.iter().map(|c| c.0.clone()).collect(),
            ln_l: last.checks.iter().map(|c| c.2 - c.1).collect(),
            ln_z: last.ln_z.0,
        };
        if n < 2 || start.ln_l.iter().all(|v| *v == f64::NEG_INFINITY) {
            return Ok(None);
        }
        let max_stages = (policy.anneal_runs / (n * policy.anneal_steps)).max(1);
        let options = SmcOptions {
            mcmc_steps: policy.anneal_steps,
            max_stages,
            seed: policy.smc.seed.wrapping_add(1000 + last.round as u64),
            ..policy.smc.clone()
        };
        let in_cube = |u: &[f64]| u.iter().all(|v| (0.0..=1.0).contains(v));
        let ln_base = |u: &[f64]| match in_cube(u) {
            true => em.ln_l(&[u.to_vec()]).map_or(f64::NEG_INFINITY, |v| v[0]),
            false => f64::NEG_INFINITY,
        };
        let mut spent = 0;
        let mut ratio = |us: &[Vec<f64>]| -> Result<Vec<f64>, AnnealError> {
            let emulated = em.ln_l(us)?;
            let exact = self.fe_ln_l(us, exec)?;
            spent += us.len();
            Ok(exact.into_iter().zip(emulated).map(|(x, e)| x - e).collect())
        };
        let smc = TemperedSmc::new(options);
        let with_z = |sd: f64| (last.ln_z.1.powi(2) + sd.powi(2)).sqrt();
        let (estimate, stages, beta, bounds) = match smc.run_from(start, &ln_base, &mut ratio) {
            Ok(run) => {
                let sd = with_z(run.ln_evidence_sd);
                (Some((run.ln_evidence, sd)), run.stages.len(), 1.0, None)
            }
            Err(SmcError::Stages { beta, stages, bounds }) => {
                tracing::debug!(beta, stages, ?bounds, "annealing ran out of FE runs");
                (None, stages, beta, bounds)
            }
            Err(SmcError::Likelihood(AnnealError::Executor(e))) => return Err(e.into()),
            Err(e) => {
                let message = format!("annealing: {e}");
                return Err(ClassEvidenceError::Smc { round: last.round + 1, message });
            }
        };
        let lower = bounds.map(|b| (b.ln_evidence, with_z(b.sd)));
        let upper = bounds.map(|b| (b.ln_evidence_upper, with_z(b.upper_sd)));
        Ok(Some(Annealed { estimate, stages, fe_points: spent, beta, lower, upper }))
    }
}

/// Why an annealing step could not get its log-ratios.
#[derive(Debug, thiserror::Error)]
enum AnnealError {
    /// The FE executor could not deliver.
    #[error(transparent)]
    Executor(#[from] ExecutorError),
    /// The emulator could not predict.
    #[error("emulator: {0}")]
    Emulator(#[from] GpError),
}

/// The Laplace approximation at the calibration's best point.
#[derive(Debug, Clone)]
struct Laplace {
    /// The best point (unit cube) and its ln L.
    mode: (Vec<f64>, f64),
    /// Lᵀ of H = L Lᵀ, the whitening map z = Lᵀ (u − u*).
    lt: DMatrix<f64>,
}

impl Laplace {
    /// From `cal`'s best point under `lik` and the Gauss–Newton matrix `h`
    /// of −ln L. A direction without curvature (a parameter a local search
    /// held) takes the precision of the prior's own spread there (12: a
    /// uniform on [0, 1] has variance 1/12), added on the diagonal.
    fn of(
        cal: &Calibration,
        lik: &Likelihood,
        h: &DMatrix<f64>,
    ) -> Result<Laplace, ClassEvidenceError> {
        let cause = cal.cause.as_str();
        let best = cal
            .best_by(lik)
            .ok_or(ClassEvidenceError::Start { cause, what: "no point simulated" })?;
        let d = cal.priors.len();
        if h.shape() != (d, d) {
            return Err(ClassEvidenceError::Start {
                cause,
                what: "a curvature of another dimension",
            });
        }
        let h = (h + h.transpose()) * 0.5 + DMatrix::from_diagonal_element(d, d, PRIOR_PRECISION);
        let chol = h.cholesky().ok_or(ClassEvidenceError::Start {
            cause,
            what: "a Gauss–Newton matrix that is not positive definite",
        })?;
        let mode = (cal.points[best].u.clone(), -cal.points[best].neg_log_lik_by(lik));
        Ok(Laplace { mode, lt: chol.l().transpose() })
    }

    /// The quadratic refitted by least squares to the ledger's values
    /// within `floor` nats of its best (in this form's whitened
    /// coordinates): its vertex and curvature; None when there are fewer
    /// than twice as many such points as a quadratic's coefficients, the
    /// fit is not concave, or its vertex lies outside the box of the points
    /// (a peak no point has seen). The calibration's Gauss–Newton matrix is a
    /// local curvature at one point; the rounds' checks sample the whole
    /// posterior, and a quadratic through them is the Laplace form the
    /// emulator's residual should be small about (from a curvature 30
    /// times too large, the residual GP alone overshot by tens to hundreds
    /// of nats every round on the test campaign).
    fn refit(&self, ledger: &[Entry], floor: f64) -> Option<Laplace> {
        let d = self.mode.0.len();
        let best =
            ledger.iter().map(|p| p.1).filter(|v| v.is_finite()).fold(f64::NEG_INFINITY, f64::max);
        let near: Vec<(DVector<f64>, f64)> = (ledger.iter())
            .filter(|p| p.1.is_finite() && p.1 >= best - floor)
            .map(|p| (self.z(&p.0), p.1))
            .collect();
        let pairs: Vec<(usize, usize)> = (0..d).flat_map(|i| (i..d).map(move |j| (i, j))).collect();
        let k = 1 + d + pairs.len();
        if near.len() < 2 * k {
            return None;
        }
        let x = DMatrix::from_fn(near.len(), k, |r, c| {
            let z = &near[r].0;
            match c {
                0 => 1.0,
                c if c <= d => z[c - 1],
                c => {
                    let (i, j) = pairs[c - 1 - d];
                    if i == j {
                        0.5 * z[i] * z[i]
                    } else {
                        z[i] * z[j]
                    }
                }
            }
        });
        let y = DVector::from_iterator(near.len(), near.iter().map(|p| p.1));
        let beta = x.svd(true, true).solve(&y, 1e-12).ok()?;
        let g = DVector::from_iterator(d, (1..=d).map(|c| beta[c]));
        let mut a = DMatrix::zeros(d, d);
        for (c, &(i, j)) in pairs.iter().enumerate() {
            a[(i, j)] = beta[1 + d + c];
            a[(j, i)] = beta[1 + d + c];
        }
        let hz = -a;
        let chol_z = hz.clone().cholesky()?;
        let z_top = chol_z.solve(&g);
        let inside = (0..d).all(|i| {
            let (lo, hi) = near.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.0[i]), hi.max(p.0[i]))
            });
            z_top[i] >= lo && z_top[i] <= hi
        });
        if !inside {
            return None;
        }
        let top = beta[0] + 0.5 * g.dot(&z_top);
        // u = u* + L^-T z, so H_u = L H_z Lᵀ and the vertex is u* + L^-T z_top.
        let l = self.lt.transpose();
        let hu = &l * hz * self.lt.clone();
        let du = self.lt.clone().solve_upper_triangular(&z_top)?;
        let mode_u: Vec<f64> = self.mode.0.iter().zip(du.iter()).map(|(m, v)| m + v).collect();
        let chol = ((&hu + hu.transpose()) * 0.5).cholesky()?;
        Some(Laplace { mode: (mode_u, top), lt: chol.l().transpose() })
    }

    /// This form with its curvature times `factor` (its widths over √factor).
    fn scaled(&self, factor: f64) -> Laplace {
        Laplace { mode: self.mode.clone(), lt: &self.lt * factor.sqrt() }
    }

    /// Up to `n` draws from this form (whitened z ~ N(0, I)) that fall in
    /// the unit cube, each with its quadratic drop ½|z|² (at most 20 n
    /// tries: a form much wider than the cube gives fewer).
    fn draws_in_cube(&self, n: usize, rng: &mut impl rand::Rng) -> Vec<(Vec<f64>, f64)> {
        let d = self.mode.0.len();
        let mut out = Vec::with_capacity(n);
        for _ in 0..20 * n {
            if out.len() == n {
                break;
            }
            let z = DVector::from_iterator(
                d,
                (0..d).map(|_| rng.sample::<f64, _>(rand_distr::StandardNormal)),
            );
            let Some(du) = self.lt.clone().solve_upper_triangular(&z) else { break };
            let u: Vec<f64> = self.mode.0.iter().zip(du.iter()).map(|(m, v)| m + v).collect();
            if u.iter().all(|v| (0.0..=1.0).contains(v)) {
                out.push((u, 0.5 * z.norm_squared()));
            }
        }
        out
    }

    /// Whitened coordinates of `u`.
    fn z(&self, u: &[f64]) -> DVector<f64> {
        let du = DVector::from_iterator(u.len(), u.iter().zip(&self.mode.0).map(|(a, b)| a - b));
        &self.lt * du
    }

    /// The quadratic q at whitened `z`.
    fn q(&self, z: &DVector<f64>) -> f64 {
        self.mode.1 - 0.5 * z.norm_squared()
    }

    /// ln L(u*) + d/2 ln 2π − ½ ln det H.
    fn ln_evidence(&self) -> f64 {
        let d = self.mode.0.len() as f64;
        let ln_det: f64 = self.lt.diagonal().iter().map(|v| 2.0 * v.ln()).sum();
        self.mode.1 + 0.5 * d * (2.0 * std::f64::consts::PI).ln() - 0.5 * ln_det
    }
}

/// The index of the highest finite value of `ln_l` (None: none is finite).
fn highest(ln_l: &[f64]) -> Option<usize> {
    (0..ln_l.len()).filter(|k| ln_l[*k].is_finite()).max_by(|a, b| ln_l[*a].total_cmp(&ln_l[*b]))
}

/// Precision added to the Gauss–Newton matrix's diagonal: the uniform prior's
/// on [0, 1] (variance 1/12).
const PRIOR_PRECISION: f64 = 12.0;

/// The scale check's bounds on one try's factor: 10⁻⁴ to 10⁴, so that a
/// try whose draws all fail or all sit on rounding noise cannot move the
/// form by more than a search's own difference steps could be off.
const SCALE_LIMITS: (f64, f64) = (1e-4, 1e4);

/// Mixed into the SMC seed for the scale check's draws.
const SCALE_SEED: u64 = 0x5ca1e;

/// A ledger entry: unit-cube point, its FE ln L, whether it was a check.
type Entry = (Vec<f64>, f64, bool);

/// ln L̃ = min(q + r, the best FE ln L): the Laplace quadratic and a GP
/// of the residual, never above what the FE model has shown. Without the cap the GP's overshoot between points with large
/// residuals made peaks the FE checks then found 10 to 50 nats lower (the
/// demo's hysteresis class), and the next round's emulator made others;
/// capped, a region the emulator is unsure of is a plateau the SMC spreads
/// over and the checks sample, which is what an importance proposal should
/// do.
struct Emulator {
    laplace: Laplace,
    gp: Option<Gp>,
    /// The best FE ln L.
    cap: f64,
}

impl Emulator {
    /// The residual GP through the checks and the other points within
    /// `floor` nats of the best by ln L or by q (failed simulations at the
    /// floor); the quadratic alone when fewer than d + 2 such
    /// points exist or the GP cannot be fitted.
    fn fit(laplace: &Laplace, ledger: &[Entry], floor: f64) -> Self {
        let best =
            ledger.iter().map(|p| p.1).filter(|v| v.is_finite()).fold(laplace.mode.1, f64::max);
        let low = best - floor;
        let d = laplace.mode.0.len();
        let (mut x, mut y) = (Vec::new(), Vec::new());
        for (u, ln_l, check) in ledger {
            let z = laplace.z(u);
            let q = laplace.q(&z);
            if *check || ln_l.max(q) >= low {
                x.extend(z.iter());
                y.push(ln_l.max(low) - q);
            }
        }
        let gp = (y.len() >= d + 2).then(|| residual_gp(&x, d, &y)).flatten();
        Emulator { laplace: laplace.clone(), gp, cap: best }
    }

    /// Points the residual GP was fitted through (0: none).
    fn points(&self) -> usize {
        self.gp.as_ref().map_or(0, Gp::n_train)
    }

    /// ln L̃ at a batch of unit-cube points.
    fn ln_l(&self, us: &[Vec<f64>]) -> Result<Vec<f64>, GpError> {
        let zs: Vec<DVector<f64>> = us.iter().map(|u| self.laplace.z(u)).collect();
        let r = match &self.gp {
            Some(gp) => {
                gp.predict_mean(&zs.iter().flat_map(|z| z.iter().copied()).collect::<Vec<_>>())?
            }
            None => vec![0.0; us.len()],
        };
        let at = |z: &DVector<f64>, r: f64| (self.laplace.q(z) + r).min(self.cap);
        Ok(zs.iter().zip(r).map(|(z, r)| at(z, r)).collect())
    }
}

/// A GP through the residuals `y` at whitened points `x` ((n, d)
/// row-major), inputs scaled to the points' range; None when the fit fails.
fn residual_gp(x: &[f64], d: usize, y: &[f64]) -> Option<Gp> {
    let set = GpSettings { restarts: 2, threads: 1, mean: MeanKind::Zero, ..GpSettings::default() };
    let scaling = InputScaling::from_data(x, d);
    fit(x, d, y, Some(scaling), &set).ok()
}

#[cfg(test)]
#[path = "class_evidence_tests.rs"]
mod tests;
