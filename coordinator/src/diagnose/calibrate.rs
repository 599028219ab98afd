//! Calibration of one model variant on the calibration runs, on a budget:
//! a maximin Latin hypercube over the variant's priors (unit cube), a GP
//! emulator of −log L over the cube, then rounds that run the FE model where
//! the emulator puts the minimum; the estimate is the best point the FE
//! model itself evaluated. Every FE evaluation is kept (its channel fits) so
//! that the likelihood can be re-weighted without re-running anything.

use super::campaign_size::SizeTrims;
use super::cause::{Cause, Demand, Prior};
use super::damping_path::{DampingPath, DampingPathUse};
use super::envelope::envelope_neg_log_lik;
use super::executor::{ExecutorError, FeExecutor, Sims};
use super::fit::{ChannelFit, Evaluation};
use super::likelihood::Likelihood;
use super::modal_fit::ModalFit;
use crate::bundle::Bundle;
use crate::design::draw;
use crate::study::DesignMethod;
use nalgebra::{DMatrix, DVector};
use stats::gp::{fit, Gp, GpSettings, InputScaling};

/// Budget of a calibration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Budget {
    /// Design points per parameter.
    pub per_dim: usize,
    /// Extra design points.
    pub extra: usize,
    /// Rounds of emulator-guided FE runs.
    pub rounds: usize,
    /// FE runs per round.
    pub per_round: usize,
    /// FE runs of the final local pattern search over every parameter.
    pub local: usize,
    /// FE simulations run at once (threads, or farm workers): how wide the
    /// local searches' batches are ([`super::levenberg`]); designs go to
    /// the executor whole.
    pub threads: usize,
    /// Seed of the design.
    pub seed: u64,
    /// Walks along the least-determined direction after an extension's
    /// local search (one costs ~8 to 14 FE runs).
    pub valley_walks: usize,
    /// Walks the extension a diagnosis names gets after every variant is
    /// calibrated ([`super::refine`]; ~20 FE runs each).
    pub refine_walks: usize,
    /// When an extension with three or more parameters of its own also
    /// takes the lower-damping path ([`Search::damping_path`], ~50 FE runs).
    pub damping_path: DampingPathUse,
    /// What the campaign's size trims ([`SizeTrims`]; none by default: a
    /// diagnosis sets them from its bundle).
    pub trims: SizeTrims,
}

impl Default for Budget {
    fn default() -> Self {
        Budget {
            per_dim: 5,
            extra: 2,
            rounds: 2,
            per_round: 2,
            local: 24,
            threads: 2,
            seed: 1,
            valley_walks: 0,
            refine_walks: 2,
            damping_path: DampingPathUse::WhenContending,
            trims: SizeTrims::NONE,
        }
    }
}

/// One FE evaluation: unit-cube point and its channel fits (None: failed).
#[derive(Debug, Clone)]
pub struct Point {
    /// Unit-cube coordinates.
    pub u: Vec<f64>,
    /// Channel fits, or why the simulation failed.
    pub fit: Result<Vec<ChannelFit>, String>,
    /// −log L of the windowed RMS misfits (+∞ when the simulation failed).
    pub coarse: f64,
    /// The fit of the model's frequencies to `modal.csv` (None: the bundle
    /// has none, or the simulation failed).
    pub modal: Option<ModalFit>,
}

impl Point {
    /// −log L of the time histories under weights `n_eff`, and of the
    /// identified frequencies when the bundle has them (+∞ when the
    /// simulation failed).
    pub fn neg_log_lik(&self, n_eff: &[f64]) -> f64 {
        self.neg_log_lik_by(&Likelihood::Time(n_eff))
    }

    /// −log L under likelihood `lik`, the identified frequencies' term
    /// included (+∞ when the simulation failed).
    pub fn neg_log_lik_by(&self, lik: &Likelihood<'_>) -> f64 {
        let modal = self.modal.as_ref().map_or(0.0, |m| m.neg_log_lik);
        self.fit.as_ref().map_or(f64::INFINITY, |ch| lik.channels(ch) + modal)
    }
}

/// All FE evaluations of one variant.
#[derive(Debug, Clone)]
pub struct Calibration {
    /// The variant.
    pub cause: Cause,
    /// Its priors.
    pub priors: Vec<Prior>,
    /// The dimensions this calibration varied (the others held at the
    /// baseline's estimate); while the design and emulator rounds run, the
    /// ones they explore.
    pub free: Vec<usize>,
    /// Every evaluation, in order.
    pub points: Vec<Point>,
    /// The baseline demand extension parameters were scaled by.
    pub demand: Option<Demand>,
    /// Gauss–Newton matrix of −log L (unit cube) at the final local step.
    pub gauss_newton: Option<DMatrix<f64>>,
    /// Share of the flagged springs' Rayleigh stiffness term on their
    /// committed tangent in every simulation (0: the initial stiffness;
    /// [`super::damping_form`]).
    pub committed_share: f64,
}

impl Calibration {
    /// A calibration of the same variant, form and demand with no points
    /// yet, varying `free`.
    pub fn restarted(&self, free: Vec<usize>) -> Calibration {
        Calibration {
            cause: self.cause,
            priors: self.priors.clone(),
            free,
            points: Vec::new(),
            demand: self.demand,
            gauss_newton: None,
            committed_share: self.committed_share,
        }
    }

    /// How many of its parameters are the baseline's (they come first).
    pub fn n_base(&self) -> usize {
        self.priors.len() - self.cause.extra_priors().len()
    }

    /// Indices of the extension's own parameters: those after the baseline's.
    pub fn own_parameters(&self) -> Vec<usize> {
        (self.n_base()..self.priors.len()).collect()
    }

    /// Its variant judged on `runs` of `bundle`.
    pub fn evaluation<'a>(&'a self, bundle: &'a Bundle, runs: &'a [usize]) -> Evaluation<'a> {
        Evaluation {
            bundle,
            cause: self.cause,
            priors: &self.priors,
            runs,
            demand: self.demand,
            committed_share: self.committed_share,
        }
    }

    /// FE parameter points evaluated (each simulating every calibration run).
    pub fn fe_points(&self) -> usize {
        self.points.len()
    }

    /// −log L of each point under weights `n_eff` (failed: +∞).
    pub fn objective(&self, n_eff: &[f64]) -> Vec<f64> {
        self.objective_by(&Likelihood::Time(n_eff))
    }

    /// −log L of each point under likelihood `lik` (failed: +∞).
    pub fn objective_by(&self, lik: &Likelihood<'_>) -> Vec<f64> {
        self.points.iter().map(|p| p.neg_log_lik_by(lik)).collect()
    }

    /// The last evaluation of unit-cube point `u`, if any.
    pub fn last_at(&self, u: &[f64]) -> Option<&Point> {
        self.points.iter().rev().find(|p| p.u == u)
    }

    /// Index of the best evaluated point under `n_eff`.
    pub fn best(&self, n_eff: &[f64]) -> Option<usize> {
        self.best_by(&Likelihood::Time(n_eff))
    }

    /// Index of the best evaluated point under likelihood `lik`.
    pub fn best_by(&self, lik: &Likelihood<'_>) -> Option<usize> {
        let f = self.objective_by(lik);
        (0..f.len()).filter(|k| f[*k].is_finite()).min_by(|a, b| f[*a].total_cmp(&f[*b]))
    }

    /// Physical values of point `k`.
    pub fn theta(&self, k: usize) -> Vec<f64> {
        self.points[k].u.iter().zip(&self.priors).map(|(u, p)| p.at(*u)).collect()
    }

    /// GP emulator of −log L over the free dimensions of the unit cube
    /// (finite points only).
    pub fn emulator(&self, n_eff: &[f64]) -> Option<Gp> {
        let d = self.free.len();
        let f = self.objective(n_eff);
        let (mut x, mut y) = (Vec::new(), Vec::new());
        for (p, v) in self.points.iter().zip(&f) {
            if v.is_finite() {
                x.extend(self.free.iter().map(|i| p.u[*i]));
                y.push(*v);
            }
        }
        if y.len() < d + 2 {
            return None;
        }
        unit_cube_gp(&x, d, &y)
    }
}

/// A GP through `y` at points `x` ((n, d) row-major) of the unit cube, two
/// optimiser restarts on one thread (None when the fit fails).
pub fn unit_cube_gp(x: &[f64], d: usize, y: &[f64]) -> Option<Gp> {
    let scaling = InputScaling { lo: vec![0.0; d], hi: vec![1.0; d] };
    let set = GpSettings { restarts: 2, threads: 1, ..GpSettings::default() };
    fit(x, d, y, Some(scaling), &set).ok()
}

/// Residual vectors per channel of one evaluation.
pub type Residuals = Vec<Vec<f64>>;

/// Which residuals a local search fits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// The time histories (the likelihood the estimate is judged by).
    Fine,
    /// The windowed RMS misfits (phase-free, broad optimum).
    Coarse,
    /// The time histories filtered to the model's band under the band
    /// likelihood ([`super::likelihood::Likelihood::Band`]: the search's
    /// weights are the channels' in-band degrees of freedom), the one a
    /// class's evidence integrates.
    Band,
}

/// One evaluation with its time-history and windowed residuals.
pub(super) type Full = (Point, Option<(Residuals, Residuals)>);

/// Runs the FE model at unit-cube points through `exec`.
pub fn evaluate_points(
    ev: &Evaluation<'_>,
    us: &[Vec<f64>],
    exec: &mut dyn FeExecutor,
) -> Result<Vec<Point>, ExecutorError> {
    Ok(evaluate_full(ev, us, exec)?.into_iter().map(|(p, _)| p).collect())
}

/// A point that failed to simulate.
fn failed(u: &[f64], why: String) -> Point {
    Point { u: u.to_vec(), fit: Err(why), coarse: f64::INFINITY, modal: None }
}

/// As [`evaluate_points`], keeping each point's time-history and windowed
/// residual vectors.
pub(super) fn evaluate_full(
    ev: &Evaluation<'_>,
    us: &[Vec<f64>],
    exec: &mut dyn FeExecutor,
) -> Result<Vec<Full>, ExecutorError> {
    let thetas: Vec<Vec<f64>> =
        us.iter().map(|u| u.iter().zip(ev.priors).map(|(u, p)| p.at(*u)).collect()).collect();
    let sims = exec.simulate(ev, &thetas)?;
    Ok(us.iter().zip(&thetas).zip(sims).map(|((u, theta), s)| judge(ev, u, theta, s)).collect())
}

/// The point, fits and residuals of one simulated point (unit-cube `u`,
/// physical `theta`). The time-history residuals end with the modal
/// frequencies' whitened ones when the bundle has `modal.csv`
/// ([`super::modal_fit`]).
fn judge(ev: &Evaluation<'_>, u: &[f64], theta: &[f64], sims: Sims) -> Full {
    match sims {
        Ok(sims) => {
            let modal = match ev.modal_fit(theta).transpose() {
                Ok(m) => m,
                Err(e) => return (failed(u, e), None),
            };
            // Missing readings stay NaN: each scale of a local search
            // treats them as its likelihood does ([`Scale`]).
            let (fits, mut residuals) = ev.fits(&sims);
            residuals.extend(modal.as_ref().map(ModalFit::whitened));
            let env = ev.envelope_misfits(&sims);
            let coarse = envelope_neg_log_lik(&env);
            let point = Point { u: u.to_vec(), fit: Ok(fits), coarse, modal };
            (point, Some((residuals, env)))
        }
        Err(e) => (failed(u, e), None),
    }
}

/// What an extension's calibration takes from the variants calibrated
/// before it.
#[derive(Debug, Clone, Copy)]
pub struct Around<'a> {
    /// The calibrated baseline's estimate (unit cube).
    pub base: &'a [f64],
    /// The calibrated baseline's demand the extension's parameters are
    /// scaled by.
    pub demand: Demand,
    /// The lowest −log L (same weights) any variant before it reached.
    pub rival: f64,
    /// Points (unit cube) run after the exploration, among which its local
    /// search may start: a class of several effects' sub-classes' estimates
    /// joined ([`super::joined_start`]); empty for a single effect.
    pub starts: &'a [Vec<f64>],
}

/// Calibrates `cause` on runs `runs` of `bundle`; `n_eff` weights the
/// objective; `progress` hears (points done, points planned). With
/// `around` (the calibrated baseline) an extension is calibrated around
/// the baseline's estimate, so that it nests it and its budget grows with
/// its own dimension only: its design and emulator rounds vary the
/// parameters without a [`Prior::reference`] (the baseline's held at its
/// estimate, the shape parameters at their reference: the seed's model,
/// which the onset of the extra physics is sought in first), its coarse
/// starts move all of its own, and the final local search every parameter
/// (the runs of each stage: [`Stages`]); the lower-damping path
/// ([`Budget::damping_path`]) compares its first path with `around.rival`;
/// the valley walks ([`Budget::valley_walks`]) follow the extension's own.
/// `exec` runs the FE model.
#[allow(clippy::too_many_arguments)] // each a different input of one calibration
pub fn calibrate(
    bundle: &Bundle,
    (cause, base): (Cause, &[Prior]),
    runs: &[usize],
    n_eff: &[f64],
    budget: &Budget,
    around: Option<Around<'_>>,
    exec: &mut dyn FeExecutor,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Calibration, ExecutorError> {
    let demand = around.map(|a| a.demand);
    let priors = cause.priors_on(base);
    let ev = Evaluation { bundle, cause, priors: &priors, runs, demand, committed_share: 0.0 };
    let course = Course::of(&ev, budget, around);
    let mut report = |done| progress(done, course.planned.get());
    // Names the stage before its first batch.
    report(0);
    let mut cal = Calibration {
        cause,
        priors: priors.clone(),
        free: course.dims.explored.clone(),
        points: Vec::new(),
        demand,
        gauss_newton: None,
        committed_share: 0.0,
    };
    let mut search = Search { ev: &ev, n_eff, budget, exec, own: &course.dims.own };
    search.run_design(&mut cal, &course, &mut report)?;
    search.emulator_rounds(&mut cal, &course, &mut report)?;
    if let Some(starts) = around.map(|a| a.starts).filter(|s| !s.is_empty()) {
        course.plan_more(starts.len());
        search.evaluate_into(&mut cal, starts, &mut report)?;
    }
    log_stage(&cal, "design and emulator rounds");
    let start = search.local_start(&mut cal, course.stages.coarse_starts, &mut report)?;
    cal.free = course.dims.own.clone();
    log_stage(&cal, "coarse starts");
    let Some(u) = start else { return Ok(cal) };
    final_searches(&mut search, &mut cal, &course, u, &mut report)?;
    Ok(cal)
}

/// The dimensions each stage of one calibration moves, and where its
/// exploration holds the others.
struct Dims {
    /// The variant's own dimensions (an extension's: beyond the baseline's),
    /// the late shape parameters ([`Cause::late_parameters`]) included.
    own_all: Vec<usize>,
    /// Its own dimensions but the late ones (the coarse starts').
    own: Vec<usize>,
    /// The dimensions the design and emulator rounds explore.
    explored: Vec<usize>,
    /// Every dimension but the late ones (the final local search's).
    all: Vec<usize>,
    /// Unit-cube point the exploration holds the others at ([`held_point`]).
    held: Vec<f64>,
}

impl Dims {
    /// The dimensions of `cause` with `priors`, calibrated around the
    /// baseline's estimate `base` (unit cube) when there is one.
    fn of(cause: Cause, priors: &[Prior], base: Option<&[f64]>) -> Self {
        let fixed = base.map_or(0, <[f64]>::len);
        let own_all: Vec<usize> = (fixed..priors.len()).collect();
        let is_late =
            |i: &usize| base.is_some() && cause.late_parameters().contains(&priors[*i].name);
        let own: Vec<usize> = own_all.iter().copied().filter(|i| !is_late(i)).collect();
        let explored: Vec<usize> = own
            .iter()
            .copied()
            .filter(|i| base.is_none() || priors[*i].reference.is_none())
            .collect();
        let all: Vec<usize> = (0..priors.len()).filter(|i| !is_late(i)).collect();
        let held = held_point(priors, base.unwrap_or(&[]));
        Dims { own_all, own, explored, all, held }
    }

    /// The unit-cube point with the explored dimensions at `x`, the others
    /// held.
    fn embed(&self, x: &[f64]) -> Vec<f64> {
        let mut u = self.held.clone();
        self.explored.iter().zip(x).for_each(|(i, v)| u[*i] = *v);
        u
    }
}

/// What the stages of one calibration follow: its dimensions, its stages,
/// the FE runs planned so far and what its lower-damping path is judged by.
struct Course {
    /// The dimensions each stage moves.
    dims: Dims,
    /// Calibrated around the baseline's estimate.
    extension: bool,
    /// Design points (`per_dim` per explored dimension and `extra`).
    design: usize,
    /// The FE runs of the stages after the design.
    stages: Stages,
    /// The lowest −log L a variant calibrated before it reached (+∞: none).
    rival: f64,
    /// FE runs planned (the progress total; grows when a stage is added).
    planned: std::cell::Cell<usize>,
}

impl Course {
    /// The course of the variant `ev` under `budget`, around the
    /// calibrated baseline when there is one.
    fn of(ev: &Evaluation<'_>, budget: &Budget, around: Option<Around<'_>>) -> Self {
        let base = around.map(|a| a.base);
        let dims = Dims::of(ev.cause, ev.priors, base);
        let d = dims.explored.len();
        let stages = Stages::of(budget, base.is_some(), dims.own.len());
        let design = budget.per_dim * d + budget.extra;
        let planned = std::cell::Cell::new(design + stages.runs(budget, d));
        let rival = around.map_or(f64::INFINITY, |a| a.rival);
        Course { dims, extension: base.is_some(), design, stages, rival, planned }
    }

    /// Adds `runs` FE runs to those planned.
    fn plan_more(&self, runs: usize) {
        self.planned.set(self.planned.get() + runs);
    }
}

/// Logs the end of a calibration's stage `name` with the FE points so far.
fn log_stage(cal: &Calibration, name: &str) {
    tracing::debug!(cause = cal.cause.as_str(), stage = name, fe_points = cal.points.len());
}

/// The searches after the exploration, from `start`: the local search over
/// every dimension but the late ones, the lower-damping path when the course
/// takes it, the valley walks and the search that frees the late shape
/// parameters.
fn final_searches(
    search: &mut Search<'_, '_>,
    cal: &mut Calibration,
    course: &Course,
    start: Vec<f64>,
    progress: &mut dyn FnMut(usize),
) -> Result<(), ExecutorError> {
    let (dims, full) = (&course.dims, course.stages.full);
    let end = search.levenberg_marquardt(cal, Scale::Fine, start, &dims.all, full, progress)?;
    log_stage(cal, "local search");
    let end = lower_damping_stage(search, cal, course, end, progress)?;
    // A valley between an extension's own parameters; one parameter alone
    // is searched by the local search itself.
    let walks =
        if course.extension && dims.own.len() >= 2 { search.budget.valley_walks } else { 0 };
    let (_, gn) = search.valley_walks(cal, end, walks, full / 2, progress)?;
    cal.gauss_newton = gn;
    if walks > 0 {
        log_stage(cal, "valley walk");
    }
    if dims.own_all.len() > dims.own.len() {
        course.plan_more(full / 2);
        search_late(search, cal, full / 2, progress)?;
        cal.free = dims.own_all.clone();
        log_stage(cal, "late shape parameters");
    }
    Ok(())
}

/// The lower-damping path ([`Search::damping_path`]) when the course takes
/// it after a first path that ended at `end`; returns the better end of the
/// two paths (`end` when the path is not taken).
fn lower_damping_stage(
    search: &mut Search<'_, '_>,
    cal: &mut Calibration,
    course: &Course,
    end: SearchEnd,
    progress: &mut dyn FnMut(usize),
) -> Result<SearchEnd, ExecutorError> {
    let n_eff = search.n_eff;
    let (first_path, rival) = (point_value(cal, &end.0, n_eff), course.rival);
    tracing::debug!(cause = cal.cause.as_str(), first_path, rival, "lower-damping path?");
    let path_use = course.stages.damping_path;
    if !path_use.takes(first_path, rival, &search.budget.trims) {
        return Ok(end);
    }
    let dims = &course.dims;
    if path_use != DampingPathUse::Always {
        course.plan_more(DampingPath::runs(search.budget, dims.explored.len()));
    }
    let path = DampingPath { held: &dims.held, explored: &dims.explored, all: &dims.all };
    let mut end = end;
    if let Some((u2, gn2)) = search.damping_path(cal, &path, progress)? {
        if point_value(cal, &u2, n_eff) < point_value(cal, &end.0, n_eff) {
            end = (u2, gn2);
        }
    }
    log_stage(cal, "lower-damping path");
    Ok(end)
}

/// Most own parameters an extension has for two coarse starts. A start
/// spends a Jacobian (one FE run per own parameter and the centre) and a
/// trial per step out of `local / 2` FE runs: with three parameters that is
/// two steps, and the second start mostly ended worse under the
/// time-history likelihood than the best design point, so its runs go to
/// the emulator rounds instead (see [`Stages`]).
pub(super) const COARSE_MAX_DIMS: usize = 2;

/// FE runs of a calibration's stages after its design.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Stages {
    /// Rounds of emulator-guided runs.
    rounds: usize,
    /// Coarse starts (0: none), `local / 2` FE runs each.
    coarse_starts: usize,
    /// FE runs of the final local search.
    full: usize,
    /// When a second path explores the damping below the baseline's
    /// estimate ([`Search::damping_path`]).
    damping_path: DampingPathUse,
}

impl Stages {
    /// The stages of a variant with `own` parameters of its own
    /// (`extension`: calibrated around the baseline). The baseline: emulator
    /// rounds and the local search. An extension with at most
    /// [`COARSE_MAX_DIMS`]: [`COARSE_STARTS`] coarse starts too. One with
    /// more: one coarse start, the other start's runs in emulator rounds,
    /// and a local search half as long again (five or more dimensions with a
    /// needle-sharp optimum: 24 runs are three Levenberg–Marquardt steps);
    /// in a large campaign ([`SizeTrims::long_search`] off) neither.
    fn of(budget: &Budget, extension: bool, own: usize) -> Self {
        let plain = Stages {
            rounds: budget.rounds,
            coarse_starts: 0,
            full: budget.local,
            damping_path: DampingPathUse::Never,
        };
        match (extension, own <= COARSE_MAX_DIMS) {
            (false, _) => plain,
            (true, true) => Stages { coarse_starts: COARSE_STARTS, ..plain },
            (true, false) if !budget.trims.long_search => {
                Stages { coarse_starts: 1, damping_path: budget.damping_path, ..plain }
            }
            (true, false) => Stages {
                rounds: budget.rounds + (budget.local / 2) / budget.per_round.max(1),
                coarse_starts: 1,
                full: budget.local + budget.local / 2,
                damping_path: budget.damping_path,
            },
        }
    }

    /// FE runs planned after the design of `d` explored dimensions (the
    /// damping path's only when it is always taken).
    fn runs(&self, budget: &Budget, d: usize) -> usize {
        let path = match self.damping_path {
            DampingPathUse::Always => DampingPath::runs(budget, d),
            _ => 0,
        };
        self.rounds * budget.per_round + self.coarse_starts * (budget.local / 2) + self.full + path
    }
}

/// The last local search, over every parameter ([`Cause::late_parameters`]
/// freed), from the best point so far with `runs` FE runs; its
/// Gauss–Newton matrix replaces the calibration's when it has one.
fn search_late(
    search: &mut Search<'_, '_>,
    cal: &mut Calibration,
    runs: usize,
    progress: &mut dyn FnMut(usize),
) -> Result<(), ExecutorError> {
    let Some(best) = cal.best(search.n_eff) else { return Ok(()) };
    let start = cal.points[best].u.clone();
    let every: Vec<usize> = (0..cal.priors.len()).collect();
    let (_, gn) = search.levenberg_marquardt(cal, Scale::Fine, start, &every, runs, progress)?;
    if gn.is_some() {
        cal.gauss_newton = gn;
    }
    Ok(())
}

/// −log L at the last evaluation of point `u` (+∞ when never evaluated).
pub(super) fn point_value(cal: &Calibration, u: &[f64], n_eff: &[f64]) -> f64 {
    cal.last_at(u).map_or(f64::INFINITY, |p| p.neg_log_lik(n_eff))
}

/// Where a local search ended and its Gauss–Newton matrix there.
pub(super) type SearchEnd = (Vec<f64>, Option<DMatrix<f64>>);

/// The unit-cube point an extension's exploration starts from: the
/// baseline's estimate `base` on its dimensions, each shape parameter at its
/// reference, the others at the middle of their prior (replaced by the
/// design).
fn held_point(priors: &[Prior], base: &[f64]) -> Vec<f64> {
    priors
        .iter()
        .enumerate()
        .map(|(i, p)| base.get(i).copied().unwrap_or_else(|| held_unit(p)))
        .collect()
}

/// Where an extension's exploration holds a parameter the baseline does not
/// have (unit cube): its reference (a shape parameter's seed value), else
/// the middle of its prior.
pub(super) fn held_unit(p: &Prior) -> f64 {
    p.reference.map_or(0.5, |r| p.unit(r).clamp(0.0, 1.0))
}

/// Distances (unit cube) probed each way along the least-determined direction.
pub(super) const SLOPPY_STEPS: [f64; 4] = [0.03, 0.06, 0.12, 0.24];

/// What the final searches share: the variant, the weights, the budget and
/// who runs the FE model.
pub(super) struct Search<'e, 'a> {
    /// The variant and the runs it is judged on.
    pub(super) ev: &'e Evaluation<'a>,
    /// Channel weights of −log L.
    pub(super) n_eff: &'e [f64],
    /// The calibration budget.
    pub(super) budget: &'e Budget,
    /// Who runs the FE model.
    pub(super) exec: &'e mut dyn FeExecutor,
    /// The variant's own dimensions (an extension's: beyond the baseline's).
    pub(super) own: &'e [usize],
}

/// Distinct starts of the coarse search.
const COARSE_STARTS: usize = 2;

impl Search<'_, '_> {
    /// Runs the FE model at `us`, keeps the points in `cal` and tells
    /// `progress` how many it holds; returns the new points.
    pub(super) fn evaluate_into<'c>(
        &mut self,
        cal: &'c mut Calibration,
        us: &[Vec<f64>],
        progress: &mut dyn FnMut(usize),
    ) -> Result<&'c [Point], ExecutorError> {
        let first = cal.points.len();
        cal.points.extend(evaluate_points(self.ev, us, &mut *self.exec)?);
        progress(cal.points.len());
        Ok(&cal.points[first..])
    }

    /// Runs the course's design: a maximin Latin hypercube over the
    /// explored dimensions, in one batch.
    fn run_design(
        &mut self,
        cal: &mut Calibration,
        course: &Course,
        progress: &mut dyn FnMut(usize),
    ) -> Result<(), ExecutorError> {
        let (dims, budget) = (&course.dims, self.budget);
        let design =
            draw(DesignMethod::MaximinLhs, course.design, dims.explored.len(), budget.seed);
        let us: Vec<Vec<f64>> = (0..design.n()).map(|i| dims.embed(design.row(i))).collect();
        self.evaluate_into(cal, &us, progress)?;
        Ok(())
    }

    /// The course's emulator rounds: each runs the FE model at the
    /// [`proposals`] of a GP emulator of −log L over the explored
    /// dimensions; they stop early when no emulator can be fitted.
    fn emulator_rounds(
        &mut self,
        cal: &mut Calibration,
        course: &Course,
        progress: &mut dyn FnMut(usize),
    ) -> Result<(), ExecutorError> {
        let (dims, budget, n_eff) = (&course.dims, self.budget, self.n_eff);
        let d = dims.explored.len();
        for round in 0..course.stages.rounds {
            let Some(gp) = cal.emulator(n_eff) else { break };
            let best = cal
                .best(n_eff)
                .map(|k| cal.free.iter().map(|i| cal.points[k].u[*i]).collect::<Vec<_>>());
            let next =
                proposals(&gp, d, best.as_deref(), budget.per_round, budget.seed + round as u64);
            let next: Vec<Vec<f64>> = next.iter().map(|x| dims.embed(x)).collect();
            self.evaluate_into(cal, &next, progress)?;
        }
        Ok(())
    }

    /// Where the final local search starts: the best end of `n`
    /// [`coarse_start`](Self::coarse_start)s (none when `n` is 0), else the
    /// best point evaluated so far.
    fn local_start(
        &mut self,
        cal: &mut Calibration,
        n: usize,
        progress: &mut dyn FnMut(usize),
    ) -> Result<Option<Vec<f64>>, ExecutorError> {
        let start = match n {
            0 => None,
            n => self.coarse_start(cal, n, progress)?,
        };
        Ok(start.or_else(|| cal.best(self.n_eff).map(|k| cal.points[k].u.clone())))
    }

    /// Coarse-to-fine start of an extension's final search: Levenberg–Marquardt
    /// on the windowed RMS misfits over the extension's own parameters (the
    /// baseline's stay at its estimate: the final search moves them) from the
    /// `n` distinct points where they are smallest (the
    /// extension's time-history optimum is too sharp for a design to land
    /// near), then the best under −log L of where those searches ended and
    /// the best point evaluated before them.
    fn coarse_start(
        &mut self,
        cal: &mut Calibration,
        n: usize,
        progress: &mut dyn FnMut(usize),
    ) -> Result<Option<Vec<f64>>, ExecutorError> {
        let n_eff = self.n_eff;
        let Some(best) = cal.best(n_eff) else { return Ok(None) };
        let mut order: Vec<usize> =
            (0..cal.points.len()).filter(|k| cal.points[*k].coarse.is_finite()).collect();
        order.sort_by(|a, b| cal.points[*a].coarse.total_cmp(&cal.points[*b].coarse));
        let mut starts: Vec<Vec<f64>> = Vec::new();
        for k in order {
            let u = &cal.points[k].u;
            if starts.len() < n && starts.iter().all(|s| crate::design::sq_dist(s, u).sqrt() > 0.15)
            {
                starts.push(u.clone());
            }
        }
        let mut pick = cal.points[best].u.clone();
        let mut f_pick = cal.objective(n_eff)[best];
        let active = self.own.to_vec();
        for from in starts {
            // A start only has to reach the envelopes' broad basin.
            let local = self.budget.local / 2;
            let (end, _) =
                self.levenberg_marquardt(cal, Scale::Coarse, from, &active, local, progress)?;
            let f = cal.objective(n_eff);
            let at_end = cal.points.iter().position(|p| p.u == end).map_or(f64::INFINITY, |k| f[k]);
            if at_end < f_pick {
                (pick, f_pick) = (end, at_end);
            }
        }
        Ok(Some(pick))
    }

    /// Probes the valley a local search stopped in: points at
    /// ±[`SLOPPY_STEPS`] from `u` along [`sloppy_direction`] (the
    /// combination of the extension's parameters the data pin down least,
    /// the others following; a hysteretic model's likelihood has a long,
    /// narrow, bumpy floor there that finite-difference steps stall on), all
    /// at once. Returns the best probe if it beats `u` by 0.01 nats.
    fn sloppy_walk(
        &mut self,
        cal: &mut Calibration,
        u: &[f64],
        gn: &DMatrix<f64>,
        progress: &mut dyn FnMut(usize),
    ) -> Result<Option<Vec<f64>>, ExecutorError> {
        let Some(v) = sloppy_direction(gn, &cal.free) else { return Ok(None) };
        let probes: Vec<Vec<f64>> = SLOPPY_STEPS
            .iter()
            .flat_map(|t| [*t, -*t])
            .map(|t| u.iter().zip(v.iter()).map(|(x, d)| (x + t * d).clamp(0.0, 1.0)).collect())
            .collect();
        let n_eff = self.n_eff;
        let f_u = point_value(cal, u, n_eff);
        let best = self
            .evaluate_into(cal, &probes, progress)?
            .iter()
            .map(|p| (p.neg_log_lik(n_eff), &p.u))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .filter(|(f, _)| *f < f_u - 0.01)
            .map(|(_, u)| u.clone());
        Ok(best)
    }

    /// Up to `walks` rounds of a [`sloppy_walk`](Self::sloppy_walk) from
    /// where a local search ended (`end`: the point and its Gauss–Newton
    /// matrix) followed by a local search of `local` FE runs over every
    /// dimension from the probe that gained; stops early when a walk finds
    /// nothing better. Returns where the last search ended.
    pub(super) fn valley_walks(
        &mut self,
        cal: &mut Calibration,
        end: SearchEnd,
        walks: usize,
        local: usize,
        progress: &mut dyn FnMut(usize),
    ) -> Result<SearchEnd, ExecutorError> {
        let (mut u, mut gn) = end;
        let all: Vec<usize> = (0..cal.priors.len()).collect();
        for _ in 0..walks {
            let Some(g) = gn.as_ref() else { break };
            let Some(from) = self.sloppy_walk(cal, &u, g, progress)? else { break };
            let (next, g) =
                self.levenberg_marquardt(cal, Scale::Fine, from, &all, local, progress)?;
            let Some(g) = g else { break };
            (u, gn) = (next, Some(g));
        }
        Ok((u, gn))
    }
}

/// The least-determined direction of the `free` parameters when the others
/// follow it (the smallest eigenvector of the Schur complement of the
/// Gauss–Newton matrix `gn` on `free`, extended by the others' conditional
/// optimum −H_bb⁻¹ H_be v), of unit length over `free`.
pub fn sloppy_direction(gn: &DMatrix<f64>, free: &[usize]) -> Option<DVector<f64>> {
    let k = gn.nrows();
    let held: Vec<usize> = (0..k).filter(|i| !free.contains(i)).collect();
    let sub =
        |r: &[usize], c: &[usize]| DMatrix::from_fn(r.len(), c.len(), |i, j| gn[(r[i], c[j])]);
    let (h_ee, h_eb, h_bb) = (sub(free, free), sub(free, &held), sub(&held, &held));
    let ridge = 1e-9 * (h_bb.trace().abs() + 1.0);
    let h_bb = h_bb + DMatrix::identity(held.len(), held.len()) * ridge;
    let solve = |m: &DMatrix<f64>| h_bb.clone().cholesky().map(|c| c.solve(m));
    let schur = if held.is_empty() { h_ee } else { &h_ee - &h_eb * solve(&h_eb.transpose())? };
    let eig = nalgebra::SymmetricEigen::new(schur);
    let min = (0..eig.eigenvalues.len())
        .filter(|i| eig.eigenvalues[*i].is_finite())
        .min_by(|a, b| eig.eigenvalues[*a].total_cmp(&eig.eigenvalues[*b]))?;
    let v_e = DMatrix::from_iterator(free.len(), 1, eig.eigenvectors.column(min).iter().copied());
    let v_b =
        if held.is_empty() { DMatrix::zeros(0, 1) } else { -solve(&(h_eb.transpose() * &v_e))? };
    let mut v = DVector::zeros(k);
    free.iter().zip(v_e.iter()).for_each(|(i, x)| v[*i] = *x);
    held.iter().zip(v_b.iter()).for_each(|(i, x)| v[*i] = *x);
    Some(v)
}

/// Points where the emulator's mean is lowest: the minimiser from a dense
/// quasi-random search polished by a shrinking pattern search, then the
/// best points of the search that are not too close to each other.
pub(super) fn proposals(
    gp: &Gp,
    d: usize,
    best: Option<&[f64]>,
    n: usize,
    seed: u64,
) -> Vec<Vec<f64>> {
    let cand = draw(DesignMethod::Sobol, 512, d, seed);
    let mut pts: Vec<Vec<f64>> = (0..cand.n()).map(|i| cand.row(i).to_vec()).collect();
    if let Some(b) = best {
        pts.push(b.to_vec());
    }
    let flat: Vec<f64> = pts.iter().flatten().copied().collect();
    let Ok(pred) = gp.predict(&flat, false) else { return vec![] };
    let mut order: Vec<usize> = (0..pts.len()).collect();
    order.sort_by(|a, b| pred.mean[*a].total_cmp(&pred.mean[*b]));
    let mut out: Vec<Vec<f64>> = vec![polish(gp, &pts[order[0]])];
    for &k in &order[1..] {
        if out.len() >= n {
            break;
        }
        let far = out.iter().all(|o| crate::design::sq_dist(o, &pts[k]).sqrt() > 0.15);
        if far {
            out.push(pts[k].clone());
        }
    }
    out
}

/// Pattern search on the emulator mean inside the unit cube.
pub fn polish(gp: &Gp, start: &[f64]) -> Vec<f64> {
    let f = |x: &[f64]| gp.predict(x, false).map_or(f64::INFINITY, |p| p.mean[0]);
    let mut x = start.to_vec();
    let mut fx = f(&x);
    let mut step = 0.1;
    while step > 1e-3 {
        let mut moved = false;
        for i in 0..x.len() {
            for s in [step, -step] {
                let mut y = x.clone();
                y[i] = (y[i] + s).clamp(0.0, 1.0);
                let fy = f(&y);
                if fy < fx {
                    (x, fx, moved) = (y, fy, true);
                }
            }
        }
        if !moved {
            step *= 0.5;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn sloppy_direction_of_a_two_parameter_quadratic() {
        // Schur complement on parameter 1: 3 − 2·2/4 = 2; the held one
        // follows by −2/4.
        let h = DMatrix::from_row_slice(2, 2, &[4.0, 2.0, 2.0, 3.0]);
        let v = sloppy_direction(&h, &[1]).unwrap();
        // (1e-8: the ridge that keeps H_bb invertible)
        assert!((v[1].abs() - 1.0).abs() < 1e-12 && (v[0] / v[1] + 0.5).abs() < 1e-8, "{v}");
    }

    #[test]
    fn an_extension_is_explored_from_the_baseline_and_the_seed_shape() {
        let priors = Cause::PERIMETER_POUNDING.priors();
        let held = held_point(&priors, &[0.3, 0.7]);
        assert_eq!(&held[..3], &[0.3, 0.7, 0.5]);
        // impact_factor's reference is the seed's 0.4 EA/L: factor 1.
        assert!((priors[3].at(held[3]) - 1.0).abs() < 1e-12, "{}", priors[3].at(held[3]));
        // The baseline has no reference: every parameter is explored.
        assert_eq!(held_point(&Cause::NONE.priors(), &[]), vec![0.5, 0.5]);
    }

    #[test]
    fn an_extension_with_three_parameters_keeps_one_coarse_start_and_searches_longer() {
        let b = Budget::default();
        let baseline = Stages::of(&b, false, 2);
        let never = DampingPathUse::Never;
        let plain =
            Stages { rounds: b.rounds, coarse_starts: 0, full: b.local, damping_path: never };
        assert_eq!(baseline, plain);
        let two = Stages::of(&b, true, 2);
        assert_eq!(two, Stages { coarse_starts: COARSE_STARTS, ..baseline });
        let three = Stages::of(&b, true, 3);
        assert_eq!(three.coarse_starts, 1);
        assert_eq!((three.damping_path, two.damping_path), (b.damping_path, never));
        let b = Budget { damping_path: never, ..b };
        let three = Stages::of(&b, true, 3);
        let always = DampingPathUse::Always;
        let with = |b: &Budget, own| Stages::of(&Budget { damping_path: always, ..*b }, true, own);
        assert!(with(&b, 3).damping_path == always && with(&b, 2).damping_path == never);
        assert!(three.rounds > two.rounds && three.full > two.full, "{three:?}");
        // The second start's runs go to the rounds; the search grows by half.
        assert_eq!(three.rounds * b.per_round, two.rounds * b.per_round + b.local / 2);
        // The damping path: a design over one more dimension, its rounds and
        // a local search.
        let path = b.per_dim * 4 + b.extra + b.rounds * b.per_round + b.local;
        assert_eq!(with(&b, 3).runs(&b, 3), two.runs(&b, 3) + b.local / 2 + path);
        // Rounds of 5 take 10 of the second start's 12 runs.
        let five = Stages::of(&Budget { per_round: 5, ..b }, true, 3);
        assert_eq!(five.rounds, b.rounds + 2);
    }

    #[test]
    fn in_a_large_campaign_three_parameters_get_the_plain_stages_and_one_start() {
        let b = Budget::default();
        let trims = SizeTrims::for_work(2.0 * super::super::campaign_size::LARGE_WORK);
        let l = Budget { trims, ..b };
        let large = Stages::of(&l, true, 3);
        let plain = Stages::of(&l, false, 3);
        assert_eq!(large, Stages { coarse_starts: 1, damping_path: b.damping_path, ..plain });
        assert!(large.runs(&b, 3) + 24 == Stages::of(&b, true, 3).runs(&b, 3));
        // Two parameters and the baseline keep their stages.
        assert_eq!(Stages::of(&l, true, 2), Stages::of(&b, true, 2));
        assert_eq!(plain, Stages::of(&b, false, 3));
    }

    proptest! {
        /// Along the direction the held parameters stay at their
        /// conditional optimum (H v vanishes on them), and the curvature
        /// vᵀHv is the smallest over unit directions of the free ones.
        #[test]
        fn sloppy_direction_follows_the_valley(
            a in proptest::collection::vec(-1.0f64..1.0, 16),
            nfree in 1usize..4,
        ) {
            let m = DMatrix::from_row_slice(4, 4, &a);
            let h = &m * m.transpose() + DMatrix::identity(4, 4) * 0.1;
            let free: Vec<usize> = (4 - nfree..4).collect();
            let v = sloppy_direction(&h, &free).unwrap();
            let hv = &h * &v;
            for i in 0..4 - nfree {
                prop_assert!(hv[i].abs() < 1e-8 * h.norm(), "H v on held {i}: {}", hv[i]);
            }
            let norm: f64 = free.iter().map(|i| v[*i] * v[*i]).sum::<f64>().sqrt();
            prop_assert!((norm - 1.0).abs() < 1e-10);
            let curv = v.dot(&hv);
            for j in 0..nfree {
                // Any other free direction, the held following optimally,
                // curves at least as much.
                let mut e = DMatrix::zeros(nfree, 1);
                e[j] = 1.0;
                let held: Vec<usize> = (0..4 - nfree).collect();
                let sub = |r: &[usize], c: &[usize]| DMatrix::from_fn(r.len(), c.len(), |x, y| h[(r[x], c[y])]);
                let s = sub(&free, &free) - sub(&free, &held) * sub(&held, &held).try_inverse().unwrap() * sub(&held, &free);
                prop_assert!((e.transpose() * &s * &e)[0] >= curv - 1e-9 * h.norm());
            }
        }
    }
}
