//! The linear stage: before any effect is judged, the specimen's linear
//! form is fitted to the runs that respond linearly and to `modal.csv`,
//! with every parameter that moves the linear response ([`priors`]), and
//! held by every later evaluation ([`crate::bundle::Bundle::linear_form`]).
//! A linear model's run costs milliseconds by modal superposition
//! ([`model`]), so the stage searches its dimensions (twelve, and one
//! along factor per grid line that ends on a sliding wall) directly on the
//! model: a maximin design, Levenberg–Marquardt from its best points
//! ([`search`]) on −log L plus the line factors' log-normal prior, the
//! Laplace spread at the estimate.
//!
//! Which runs are linear: for each direction the calibration runs shake,
//! the one with the smallest peak input (a lab's weakest run exists to be
//! linear); the stage then predicts every calibration run with the fitted
//! linear model, and the report shows how far each departs.

pub mod model;
pub mod priors;
pub mod report;
pub mod search;

use crate::bundle::{Bundle, Direction};
use crate::design::draw;
use crate::diagnose::cause::Prior;
use crate::diagnose::evidence::pga_g;
use crate::diagnose::fit::{effective_sizes, mean_nrmse, ChannelFit, Simulated};
use crate::study::DesignMethod;
use model::{Judged, LinearModel};
use search::{Located, Searcher};

pub use priors::{linear_priors, nominal, LINEAR_PRIORS, LINE_BOUNDS, LINE_LOG_SD, NOMINAL};

/// Design points per parameter (the design is cheap: a point is one eigen
/// solution and a few modal superpositions).
const DESIGN_PER_DIM: usize = 12;
/// Design points the local searches start from.
const STARTS: usize = 3;
/// Linearisations per local search.
const ITERATIONS: usize = 40;

/// The stage's outcome.
#[derive(Debug, Clone)]
pub struct LinearStage {
    /// Its parameters and priors.
    pub priors: Vec<Prior>,
    /// The runs taken as linear (bundle indices).
    pub runs: Vec<usize>,
    /// The estimate (unit cube).
    pub u: Vec<f64>,
    /// The estimate (physical values, prior order).
    pub theta: Vec<f64>,
    /// Laplace standard deviations (unit cube; NaN where the Gauss–Newton
    /// matrix is singular).
    pub sd_unit: Vec<f64>,
    /// −log L at the estimate.
    pub neg_log_lik: f64,
    /// The channel weights it was fitted under.
    pub n_eff: Vec<f64>,
    /// What the estimate gives on the linear runs.
    pub judged: Judged,
    /// The linear runs simulated at the estimate.
    pub sims: Vec<Simulated>,
    /// Linear evaluations spent.
    pub evaluations: usize,
}

impl LinearStage {
    /// The values every later evaluation holds: each parameter's estimate.
    pub fn held(&self) -> Vec<(&'static str, f64)> {
        self.priors.iter().map(|p| p.name).zip(self.theta.iter().copied()).collect()
    }

    /// Mean normalised error of the linear runs at the estimate.
    pub fn nrmse(&self) -> f64 {
        mean_nrmse(&self.judged.channels)
    }

    /// The fits of the linear runs at the estimate.
    pub fn channels(&self) -> &[ChannelFit] {
        &self.judged.channels
    }
}

/// The calibration runs taken as linear: for each direction a calibration
/// run shakes, the one with the smallest peak input in that direction.
pub fn linear_runs(b: &Bundle, cal_runs: &[usize]) -> Vec<usize> {
    let mut out: Vec<usize> = Vec::new();
    for d in [Direction::X, Direction::Y] {
        let weakest = cal_runs
            .iter()
            .copied()
            .filter(|k| pga_g(&b.runs[*k], d) > 0.0)
            .min_by(|a, c| pga_g(&b.runs[*a], d).total_cmp(&pga_g(&b.runs[*c], d)));
        if let Some(k) = weakest.filter(|k| !out.contains(k)) {
            out.push(k);
        }
    }
    out.sort_unstable();
    out
}

/// Whether the stage applies to `b`: a single-layer ceiling (the carrying
/// channels of a double layer are not yet among its parameters).
pub fn applies(b: &Bundle) -> bool {
    b.manifest.structure.layers == 1
}

/// Fits the linear form on the linear runs of `cal_runs` and `modal.csv`,
/// `threads` evaluations at once, the designs drawn with `seed`; `progress`
/// hears (done, planned) evaluations. Err when every design point fails.
///
/// Two phases: the frequencies alone first (an eigen solution a point, a
/// design of [`MODAL_PER_DIM`] points per dimension and local searches from
/// its best [`STARTS`]: the most robust linear feature, searched widely),
/// then the whole likelihood from the best of its own design and of the
/// frequency fits.
pub fn linear_stage(
    b: &Bundle,
    cal_runs: &[usize],
    threads: usize,
    seed: u64,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<LinearStage, String> {
    let priors = linear_priors(b);
    let d = priors.len();
    let model = LinearModel { bundle: b, runs: linear_runs(b, cal_runs), priors };
    let planned = DESIGN_PER_DIM * d + (2 * STARTS + 1) * ITERATIONS * (d + 2);
    let mut s = Searcher { model: &model, n_eff: vec![], threads, spent: 0, modal_only: false };
    let nominal: Vec<f64> = (model.priors.iter().zip(nominal(&model.priors)))
        .map(|(p, v)| p.unit(v).clamp(0.0, 1.0))
        .collect();
    let mut starts = vec![nominal];
    starts.extend(frequency_fits(&mut s, seed));
    s.modal_only = false;
    let us = design(DESIGN_PER_DIM * d, d, seed);
    let judged = s.judge_all(&us);
    progress(s.spent, planned);
    let unweighted: Vec<f64> = judged
        .iter()
        .map(|j| j.as_ref().map_or(f64::INFINITY, |j| j.neg_log_lik(&ones(j))))
        .collect();
    let order = ranked(&unweighted);
    let Some(&best) = order.first().filter(|k| unweighted[**k].is_finite()) else {
        let why = judged.iter().find_map(|j| j.as_ref().err()).cloned();
        return Err(format!(
            "the linear model failed at every design point: {}",
            why.unwrap_or_default()
        ));
    };
    // Every channel counts alike while the searches run: weights read off
    // the residuals of a poor fit (large lag-one correlation, few
    // effective samples) would leave the channels it misses most with the
    // least say. The fit's own weights come back for the last search.
    s.n_eff = judged[best].as_ref().map(ones).unwrap_or_default();
    starts.extend(
        order.iter().take(STARTS).filter(|k| unweighted[**k].is_finite()).map(|k| us[*k].clone()),
    );
    let mut found: Option<Located> = None;
    for start in &starts {
        if let Some(at) = s.levenberg_marquardt(start, ITERATIONS) {
            progress(s.spent, planned);
            tracing::debug!(f = at.f, spent = s.spent, u = ?at.u, "linear stage: a local search ended");
            if found.as_ref().is_none_or(|f| at.f < f.f) {
                found = Some(at);
            }
        }
    }
    let first = found.ok_or("no local search of the linear model could start")?;
    s.n_eff = effective_sizes(&first.judged.channels);
    let at = s.levenberg_marquardt(&first.u, ITERATIONS).unwrap_or(first);
    progress(s.spent, s.spent);
    conclude(&model, at, s.n_eff.clone(), s.spent)
}

/// Local searches of the frequencies-only phase.
const MODAL_STARTS: usize = 6;

/// Design points per parameter of the frequencies-only phase (a point is
/// one eigen solution of a few dozen modes: milliseconds).
const MODAL_PER_DIM: usize = 60;

/// The end points of local searches on the frequencies alone from the
/// best [`STARTS`] points of a wide design (none without `modal.csv`).
fn frequency_fits(s: &mut Searcher<'_, '_>, seed: u64) -> Vec<Vec<f64>> {
    if s.model
        .bundle
        .modal
        .as_deref()
        .is_none_or(|m| crate::diagnose::modal_fit::usable(m).is_empty())
    {
        return vec![];
    }
    s.modal_only = true;
    let d = s.model.priors.len();
    let us = design(MODAL_PER_DIM * d, d, seed ^ 0x6d6f64616c);
    let f: Vec<f64> = s
        .judge_all(&us)
        .iter()
        .map(|j| j.as_ref().map_or(f64::INFINITY, |j| j.neg_log_lik(&[])))
        .collect();
    let order = ranked(&f);
    let mut out = Vec::new();
    for &k in order.iter().take(MODAL_STARTS).filter(|k| f[**k].is_finite()) {
        if let Some(at) = s.levenberg_marquardt(&us[k], ITERATIONS) {
            tracing::debug!(
                f = at.f,
                spent = s.spent,
                model_hz = ?at.judged.modal.as_ref().map(|m| m.model_hz.clone()),
                "linear stage: a frequency fit ended"
            );
            out.push(at.u);
        }
    }
    out
}

/// A maximin Latin hypercube of `n` points in `d` dimensions.
fn design(n: usize, d: usize, seed: u64) -> Vec<Vec<f64>> {
    let design = draw(DesignMethod::MaximinLhs, n, d, seed);
    (0..design.n()).map(|i| design.row(i).to_vec()).collect()
}

/// The linear model at the physical values `values` (by name; the others
/// at [`nominal`]) on the linear runs of `cal_runs`, without a search: what
/// a given linear form explains. Err for an unknown name or a value
/// outside its prior.
pub fn linear_at(
    b: &Bundle,
    cal_runs: &[usize],
    values: &[(String, f64)],
) -> Result<LinearStage, String> {
    let priors = linear_priors(b);
    let mut theta = nominal(&priors);
    for (name, v) in values {
        let k = priors.iter().position(|p| p.name == name).ok_or_else(|| {
            let known: Vec<&str> = priors.iter().map(|p| p.name).collect();
            format!("{name}: not a parameter of the linear stage (known: {})", known.join(", "))
        })?;
        let p = &priors[k];
        if !(*v >= p.low && *v <= p.high) {
            return Err(format!("{name} = {v}: expected {} to {} {}", p.low, p.high, p.unit));
        }
        theta[k] = *v;
    }
    let model = LinearModel { bundle: b, runs: linear_runs(b, cal_runs), priors };
    let u: Vec<f64> = model.priors.iter().zip(&theta).map(|(p, v)| p.unit(*v)).collect();
    let judged = model.judge(&u)?;
    let n_eff = effective_sizes(&judged.channels);
    let f = judged.neg_log_lik(&n_eff);
    conclude(&model, Located { u, f, judged, gauss_newton: None }, n_eff, 0)
}

/// The stage's outcome at the point `at`.
fn conclude(
    model: &LinearModel<'_>,
    at: Located,
    n_eff: Vec<f64>,
    evaluations: usize,
) -> Result<LinearStage, String> {
    let (sims, judged) = model.simulate(&at.u)?;
    let sd_unit = laplace_sd(at.gauss_newton.as_ref(), at.u.len());
    Ok(LinearStage {
        priors: model.priors.clone(),
        runs: model.runs.clone(),
        theta: model.theta(&at.u),
        u: at.u,
        sd_unit,
        neg_log_lik: judged.neg_log_lik(&n_eff),
        n_eff,
        judged,
        sims,
        evaluations: evaluations + 1,
    })
}

/// √diag(H⁻¹) of a Gauss–Newton matrix (NaN where it is singular or absent).
fn laplace_sd(h: Option<&nalgebra::DMatrix<f64>>, d: usize) -> Vec<f64> {
    let inv = h.and_then(|h| h.clone().try_inverse());
    (0..d)
        .map(|i| inv.as_ref().map_or(f64::NAN, |m| m[(i, i)]).max(0.0).sqrt())
        .map(|v| if v.is_finite() { v } else { f64::NAN })
        .collect()
}

/// Weight 1 for each channel of `j`: the design's ranking before the
/// residuals' autocorrelation is known.
fn ones(j: &Judged) -> Vec<f64> {
    vec![1.0; j.channels.len()]
}

/// Indices of `f` from lowest to highest.
fn ranked(f: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..f.len()).collect();
    order.sort_by(|a, b| f[*a].total_cmp(&f[*b]));
    order
}
