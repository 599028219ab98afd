//! Fitting a GP: settings → `check()` → hyperparameters by maximising the
//! log marginal likelihood with the bounded L-BFGS, from a default start and
//! a scrambled-Sobol' set of further starts run in parallel threads.

use super::error::GpError;
use super::kernel::{Kernel, KernelKind};
use super::lbfgs::{minimise, resume, LbfgsResult, LbfgsSettings};
use super::likelihood::{factor, lml_from_factor};
use super::lml_workspace::LmlWorkspace;
use super::mean::{MeanKind, Trend};
use super::model::{FitReport, Gp, GpModel};
use super::scaling::{InputScaling, OutputScaling};
use super::warp::InputWarp;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Settings of a GP fit.
#[derive(Debug, Clone, PartialEq)]
pub struct GpSettings {
    /// Covariance family.
    pub kernel: KernelKind,
    /// Prior mean.
    pub mean: MeanKind,
    /// Extra optimiser starts after the default one (0 = one start).
    pub restarts: usize,
    /// Seed of the space-filling start set.
    pub seed: u32,
    /// Bounds of length scales (scaled inputs), natural scale.
    pub length_bounds: (f64, f64),
    /// Bounds of the signal variance (standardised output).
    pub variance_bounds: (f64, f64),
    /// Bounds of the white-noise variance (standardised output).
    pub noise_bounds: (f64, f64),
    /// Learn a power warp (identity to log scale) of every input whose
    /// lower bound is positive, with the kernel (see [`InputWarp`]).
    pub warp: bool,
    /// Bounds of the warp exponents λ (1 = identity, 0 = log scale).
    pub warp_bounds: (f64, f64),
    /// Worker threads for the starts (0 = available parallelism).
    pub threads: usize,
    /// Optimiser settings.
    pub lbfgs: LbfgsSettings,
}

impl Default for GpSettings {
    fn default() -> Self {
        GpSettings {
            kernel: KernelKind::SquaredExponential,
            mean: MeanKind::Constant,
            restarts: 0,
            seed: 0,
            length_bounds: (1e-3, 1e5),
            variance_bounds: (1e-4, 1e5),
            noise_bounds: (1e-10, 10.0),
            warp: true,
            warp_bounds: (-2.0, 3.0),
            threads: 0,
            lbfgs: LbfgsSettings::default(),
        }
    }
}

impl GpSettings {
    /// Validate the settings.
    pub fn check(&self) -> Result<(), GpError> {
        for (key, (lo, hi)) in [
            ("length_bounds", self.length_bounds),
            ("variance_bounds", self.variance_bounds),
            ("noise_bounds", self.noise_bounds),
        ] {
            if !(lo > 0.0 && hi > lo && hi.is_finite()) {
                return Err(GpError::Setting {
                    key,
                    value: format!("({lo}, {hi})"),
                    expected: "0 < lo < hi < inf",
                });
            }
        }
        let (lo, hi) = self.warp_bounds;
        if !(lo.is_finite() && hi.is_finite() && lo <= 1.0 && 1.0 <= hi && lo < hi) {
            return Err(GpError::Setting {
                key: "warp_bounds",
                value: format!("({lo}, {hi})"),
                expected: "finite lo <= 1 <= hi, lo < hi",
            });
        }
        Ok(())
    }

    /// Bounds of θ = [ln l.., ln s², (ln α), λ.. (nw of them), ln σ²].
    fn log_bounds(&self, d: usize, nw: usize) -> (Vec<f64>, Vec<f64>) {
        let mut lo = vec![self.length_bounds.0.ln(); d];
        let mut hi = vec![self.length_bounds.1.ln(); d];
        lo.push(self.variance_bounds.0.ln());
        hi.push(self.variance_bounds.1.ln());
        if self.kernel == KernelKind::RationalQuadratic {
            lo.push(1e-3f64.ln());
            hi.push(1e4f64.ln());
        }
        lo.extend(std::iter::repeat_n(self.warp_bounds.0, nw));
        hi.extend(std::iter::repeat_n(self.warp_bounds.1, nw));
        lo.push(self.noise_bounds.0.ln());
        hi.push(self.noise_bounds.1.ln());
        (lo, hi)
    }

    /// Default start (no warp: λ = 1) then `restarts` scrambled-Sobol'
    /// starts in a central box.
    fn starts(&self, d: usize, nw: usize) -> Vec<Vec<f64>> {
        let rq = self.kernel == KernelKind::RationalQuadratic;
        let mut first = vec![0.5f64.ln(); d];
        first.push(0.0);
        if rq {
            first.push(1.0f64.ln());
        }
        first.extend(std::iter::repeat_n(1.0, nw));
        first.push(1e-4f64.ln());
        let mut box_lo = vec![0.05f64.ln(); d];
        let mut box_hi = vec![5.0f64.ln(); d];
        box_lo.push(0.1f64.ln());
        box_hi.push(10.0f64.ln());
        if rq {
            box_lo.push(0.3f64.ln());
            box_hi.push(30.0f64.ln());
        }
        box_lo.extend(std::iter::repeat_n(self.warp_bounds.0.max(-0.5), nw));
        box_hi.extend(std::iter::repeat_n(self.warp_bounds.1.min(1.5), nw));
        box_lo.push(1e-8f64.ln());
        box_hi.push(1e-1f64.ln());
        let mut starts = vec![first];
        for s in 0..self.restarts {
            let p = (0..box_lo.len())
                .map(|k| {
                    let u = sobol_burley::sample(s as u32, k as u32, self.seed) as f64;
                    box_lo[k] + u * (box_hi[k] - box_lo[k])
                })
                .collect();
            starts.push(p);
        }
        starts
    }
}

/// Check shapes and finiteness of (n, d) inputs and n outputs.
fn check_data(x: &[f64], d: usize, y: &[f64]) -> Result<(), GpError> {
    if d == 0 || y.is_empty() || x.len() != y.len() * d {
        return Err(GpError::Shape {
            what: "x (n rows of d inputs)",
            expected: y.len() * d.max(1),
            found: x.len(),
        });
    }
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(GpError::NonFinite { what: "x", row: i / d });
    }
    if let Some(i) = y.iter().position(|v| !v.is_finite()) {
        return Err(GpError::NonFinite { what: "y", row: i });
    }
    Ok(())
}

/// Residual after the mean trend, standardised: (trend, scaling, y_s).
fn standardise(
    xs: &[f64],
    d: usize,
    y: &[f64],
    mean: MeanKind,
) -> (Option<Trend>, OutputScaling, Vec<f64>) {
    let trend = (mean == MeanKind::Linear).then(|| Trend::fit_linear(xs, d, y));
    let resid: Vec<f64> = match &trend {
        Some(t) => y.iter().enumerate().map(|(i, v)| v - t.eval(&xs[i * d..(i + 1) * d])).collect(),
        None => y.to_vec(),
    };
    let out = OutputScaling::from_data(&resid, mean != MeanKind::Zero);
    let ys = resid.iter().map(|v| (v - out.mean) / out.sd).collect();
    (trend, out, ys)
}

/// Fit a GP to physical inputs `x` ((n, d) row-major) and outputs `y`,
/// scaling inputs with `scaling` (design bounds) or the data range.
pub fn fit(
    x: &[f64],
    d: usize,
    y: &[f64],
    scaling: Option<InputScaling>,
    set: &GpSettings,
) -> Result<Gp, GpError> {
    Ok(fit_shared(x, d, &[y.to_vec()], scaling, set)?.remove(0))
}

/// Fit several outputs (each (n)) with one shared kernel and noise, chosen
/// by maximising the sum of their log marginal likelihoods; one GP each.
pub fn fit_shared(
    x: &[f64],
    d: usize,
    ys: &[Vec<f64>],
    scaling: Option<InputScaling>,
    set: &GpSettings,
) -> Result<Vec<Gp>, GpError> {
    set.check()?;
    if ys.is_empty() {
        return Err(GpError::Shape { what: "outputs", expected: 1, found: 0 });
    }
    for y in ys {
        check_data(x, d, y)?;
    }
    let scaling = scaling.unwrap_or_else(|| InputScaling::from_data(x, d));
    let xs = scaling.apply(x);
    let prepared: Vec<_> = ys.iter().map(|y| standardise(&xs, d, y, set.mean)).collect();
    let targets: Vec<Vec<f64>> = prepared.iter().map(|p| p.2.clone()).collect();
    let ratios = if set.warp { InputWarp::candidates(&scaling) } else { Vec::new() };
    let (theta, report) = optimise(&xs, d, &targets, &ratios, set)?;
    let np = theta.len() - 1;
    let nk = set.kernel.n_params(d);
    prepared
        .into_iter()
        .map(|(trend, out, y)| {
            Gp::from_model(GpModel {
                kernel: Kernel::from_log(set.kernel, &theta[..nk]),
                warp: InputWarp::from_parts(&ratios, &theta[nk..np]),
                noise_var: theta[np].exp(),
                mean: set.mean,
                trend,
                input_scaling: scaling.clone(),
                output_scaling: out,
                x: xs.clone(),
                y,
                dim: d,
                report: report.clone(),
            })
        })
        .collect()
}

/// Iterations every start gets before the starts are pruned.
pub const PROBE_ITERATIONS: usize = 15;
/// Starts that continue after the probe (the best by LML).
pub const SURVIVORS: usize = 2;

/// Maximise the LML over θ from all starts; the best θ and a report. With
/// more than [`SURVIVORS`] starts, every start first runs
/// [`PROBE_ITERATIONS`] L-BFGS iterations and only the [`SURVIVORS`] best
/// continue to convergence (successive halving: a start that is far
/// behind after the probe seldom overtakes, and each start costs O(n³)
/// per evaluation).
fn optimise(
    xs: &[f64],
    d: usize,
    ys: &[Vec<f64>],
    ratios: &[Option<f64>],
    set: &GpSettings,
) -> Result<(Vec<f64>, FitReport), GpError> {
    let nw = ratios.iter().filter(|r| r.is_some()).count();
    let starts = set.starts(d, nw);
    let problem = Problem { xs, d, ys, ratios, set, bounds: set.log_bounds(d, nw) };
    let fresh: Vec<Job> = starts.iter().map(|x| Job::Start(x.clone())).collect();
    let mut results = if starts.len() > SURVIVORS {
        let probe = LbfgsSettings { max_iter: PROBE_ITERATIONS, ..set.lbfgs };
        let mut first = problem.run(&fresh, &probe);
        let mut order: Vec<usize> = (0..first.len()).filter(|i| first[*i].is_some()).collect();
        order.sort_by(|a, b| f_of(&first[*a]).total_cmp(&f_of(&first[*b])));
        order.truncate(SURVIVORS);
        let from: Vec<Job> =
            order.iter().filter_map(|i| first[*i].clone().map(Job::Resume)).collect();
        let rest = LbfgsSettings {
            max_iter: set.lbfgs.max_iter.saturating_sub(PROBE_ITERATIONS),
            ..set.lbfgs
        };
        for (i, r) in order.into_iter().zip(problem.run(&from, &rest)) {
            first[i] = r;
        }
        first
    } else {
        problem.run(&fresh, &set.lbfgs)
    };
    let evaluations = results.iter().flatten().map(|r| r.evaluations).sum();
    let lmls: Vec<Option<f64>> = results.iter().map(|r| r.as_ref().map(|r| -r.f)).collect();
    let best = (0..results.len())
        .filter(|i| results[*i].is_some())
        .min_by(|a, b| f_of(&results[*a]).total_cmp(&f_of(&results[*b])))
        .ok_or(GpError::NoFiniteStart { starts: starts.len() })?;
    let r = results.swap_remove(best).expect("finite");
    let report = FitReport {
        starts: starts.len(),
        best_start: best,
        lml: -r.f,
        start_lmls: lmls,
        evaluations,
        jitter: 0.0,
    };
    Ok((r.x, report))
}

/// One optimiser run: from a start, or on from where a run left off.
#[derive(Clone)]
enum Job {
    Start(Vec<f64>),
    Resume(LbfgsResult),
}

/// The minimised value of a start (+∞ when it failed).
fn f_of(r: &Option<LbfgsResult>) -> f64 {
    r.as_ref().map_or(f64::INFINITY, |r| r.f)
}

/// The negative LML to minimise, with its data and bounds.
struct Problem<'a> {
    xs: &'a [f64],
    d: usize,
    ys: &'a [Vec<f64>],
    ratios: &'a [Option<f64>],
    set: &'a GpSettings,
    bounds: (Vec<f64>, Vec<f64>),
}

impl Problem<'_> {
    /// Runs every job on the configured threads (results in job order;
    /// None where the LML is undefined at the start).
    fn run(&self, starts: &[Job], lbfgs: &LbfgsSettings) -> Vec<Option<LbfgsResult>> {
        let refs: Vec<&[f64]> = self.ys.iter().map(|y| y.as_slice()).collect();
        let next = AtomicUsize::new(0);
        let results = Mutex::new(Vec::new());
        let threads = if self.set.threads == 0 {
            std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
        } else {
            self.set.threads
        }
        .min(starts.len());
        let (lo, hi) = &self.bounds;
        std::thread::scope(|scope| {
            for _ in 0..threads {
                scope.spawn(|| loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= starts.len() {
                        break;
                    }
                    let mut ws = LmlWorkspace::default();
                    let obj = |t: &[f64]| {
                        ws.lml_and_grad(self.set.kernel, self.ratios, t, self.xs, self.d, &refs)
                            .ok()
                            .map(|(v, g)| (-v, g.into_iter().map(|x| -x).collect()))
                    };
                    let r = match &starts[i] {
                        Job::Start(x0) => minimise(obj, x0, lo, hi, lbfgs),
                        Job::Resume(from) => Some(resume(obj, from.clone(), lo, hi, lbfgs)),
                    };
                    results.lock().expect("results lock").push((i, r));
                });
            }
        });
        let mut results = results.into_inner().expect("results lock");
        results.sort_by_key(|(i, _)| *i);
        results.into_iter().map(|(_, r)| r).collect()
    }
}

/// Log marginal likelihood of the standardised training data at the
/// model's hyperparameters.
pub fn model_lml(model: &GpModel) -> Result<f64, GpError> {
    let xw = model.warp.apply(&model.x, model.dim);
    let f = factor(&model.kernel, model.noise_var, &xw, model.dim, &model.y)?;
    Ok(lml_from_factor(&f, &model.y))
}
