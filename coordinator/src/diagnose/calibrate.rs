//! Calibration of one model variant on the calibration runs, on a budget:
//! a maximin Latin hypercube over the variant's priors (unit cube), a GP
//! emulator of −log L over the cube, then rounds that run the FE model where
//! the emulator puts the minimum; the estimate is the best point the FE
//! model itself evaluated. Every FE evaluation is kept (its channel fits) so
//! that the likelihood can be re-weighted without re-running anything.

use super::cause::{Cause, Demand, Prior};
use super::fit::{neg_log_lik, ChannelFit, Evaluation};
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
    /// Threads running FE simulations.
    pub threads: usize,
    /// Seed of the design.
    pub seed: u64,
}

impl Default for Budget {
    fn default() -> Self {
        Budget { per_dim: 5, extra: 2, rounds: 2, per_round: 2, local: 24, threads: 2, seed: 1 }
    }
}

/// One FE evaluation: unit-cube point and its channel fits (None: failed).
#[derive(Debug, Clone)]
pub struct Point {
    /// Unit-cube coordinates.
    pub u: Vec<f64>,
    /// Channel fits, or why the simulation failed.
    pub fit: Result<Vec<ChannelFit>, String>,
}

/// All FE evaluations of one variant.
#[derive(Debug, Clone)]
pub struct Calibration {
    /// The variant.
    pub cause: Cause,
    /// Its priors.
    pub priors: Vec<Prior>,
    /// The dimensions this calibration varied (the others held at the
    /// baseline's estimate).
    pub free: Vec<usize>,
    /// Every evaluation, in order.
    pub points: Vec<Point>,
    /// The baseline demand extension parameters were scaled by.
    pub demand: Option<Demand>,
    /// Gauss–Newton matrix of −log L (unit cube) at the final local step.
    pub gauss_newton: Option<DMatrix<f64>>,
}

impl Calibration {
    /// FE parameter points evaluated (each simulating every calibration run).
    pub fn fe_points(&self) -> usize {
        self.points.len()
    }

    /// −log L of each point under weights `n_eff` (failed: +∞).
    pub fn objective(&self, n_eff: &[f64]) -> Vec<f64> {
        self.points
            .iter()
            .map(|p| p.fit.as_ref().map_or(f64::INFINITY, |ch| neg_log_lik(ch, n_eff)))
            .collect()
    }

    /// Index of the best evaluated point under `n_eff`.
    pub fn best(&self, n_eff: &[f64]) -> Option<usize> {
        let f = self.objective(n_eff);
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
        let scaling = InputScaling { lo: vec![0.0; d], hi: vec![1.0; d] };
        let set = GpSettings { restarts: 2, threads: 1, ..GpSettings::default() };
        fit(&x, d, &y, Some(scaling), &set).ok()
    }
}

/// Residual vectors per channel of one evaluation.
pub type Residuals = Vec<Vec<f64>>;

/// Runs the FE model at unit-cube points on `threads` threads.
pub fn evaluate_points(ev: &Evaluation<'_>, us: &[Vec<f64>], threads: usize) -> Vec<Point> {
    evaluate_full(ev, us, threads).into_iter().map(|(p, _)| p).collect()
}

/// As [`evaluate_points`], keeping each point's residual vectors.
pub fn evaluate_full(
    ev: &Evaluation<'_>,
    us: &[Vec<f64>],
    threads: usize,
) -> Vec<(Point, Option<Residuals>)> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    type Slot = std::sync::Mutex<Option<(Point, Option<Residuals>)>>;
    let slots: Vec<Slot> = us.iter().map(|_| std::sync::Mutex::new(None)).collect();
    std::thread::scope(|s| {
        for _ in 0..threads.max(1).min(us.len().max(1)) {
            s.spawn(|| loop {
                let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                if k >= us.len() {
                    break;
                }
                let theta: Vec<f64> = us[k].iter().zip(ev.priors).map(|(u, p)| p.at(*u)).collect();
                let out = match ev.simulate(&theta) {
                    Ok(sims) => {
                        let (fits, mut residuals) = ev.fits(&sims);
                        // Missing readings add nothing to a Jacobian.
                        residuals
                            .iter_mut()
                            .flatten()
                            .filter(|r| !r.is_finite())
                            .for_each(|r| *r = 0.0);
                        (Point { u: us[k].clone(), fit: Ok(fits) }, Some(residuals))
                    }
                    Err(e) => (Point { u: us[k].clone(), fit: Err(e) }, None),
                };
                if let Ok(mut slot) = slots[k].lock() {
                    *slot = Some(out);
                }
            });
        }
    });
    slots
        .into_iter()
        .zip(us)
        .map(|(m, u)| {
            m.into_inner().ok().flatten().unwrap_or_else(|| {
                (Point { u: u.clone(), fit: Err("evaluation thread panicked".into()) }, None)
            })
        })
        .collect()
}

/// Calibrates `cause` on runs `runs` of `bundle`; `n_eff` weights the
/// objective; `progress` hears (points done, points planned). With `base`
/// (the baseline's estimate, unit cube) an extension varies only its own
/// parameters, the baseline's held there: the extension then nests the
/// calibrated baseline, and its budget grows with its own dimension only.
pub fn calibrate(
    bundle: &Bundle,
    cause: Cause,
    runs: &[usize],
    n_eff: &[f64],
    budget: &Budget,
    base: Option<(&[f64], Demand)>,
    progress: &mut dyn FnMut(usize, usize),
) -> Calibration {
    let (base, demand) = match base {
        Some((u, d)) => (Some(u), Some(d)),
        None => (None, None),
    };
    let priors = cause.priors();
    let fixed = base.map_or(0, <[f64]>::len);
    let free: Vec<usize> = (fixed..priors.len()).collect();
    let d = free.len();
    let ev = Evaluation { bundle, cause, priors: &priors, runs, demand };
    let n0 = budget.per_dim * d + budget.extra;
    let planned = n0 + budget.rounds * budget.per_round + budget.local;
    let design = draw(DesignMethod::MaximinLhs, n0, d, budget.seed);
    let embed = |x: &[f64]| -> Vec<f64> { base.unwrap_or(&[]).iter().chain(x).copied().collect() };
    let us: Vec<Vec<f64>> = (0..design.n()).map(|i| embed(design.row(i))).collect();
    let mut cal = Calibration {
        cause,
        priors: priors.clone(),
        free,
        points: Vec::new(),
        demand,
        gauss_newton: None,
    };
    for chunk in us.chunks(budget.threads.max(1) * 2) {
        cal.points.extend(evaluate_points(&ev, chunk, budget.threads));
        progress(cal.points.len(), planned);
    }
    for round in 0..budget.rounds {
        let Some(gp) = cal.emulator(n_eff) else { break };
        let best = cal
            .best(n_eff)
            .map(|k| cal.free.iter().map(|i| cal.points[k].u[*i]).collect::<Vec<_>>());
        let next = proposals(&gp, d, best.as_deref(), budget.per_round, budget.seed + round as u64);
        let next: Vec<Vec<f64>> = next.iter().map(|x| embed(x)).collect();
        cal.points.extend(evaluate_points(&ev, &next, budget.threads));
        progress(cal.points.len(), planned);
    }
    cal.gauss_newton =
        levenberg_marquardt(&mut cal, &ev, n_eff, budget, &mut |done| progress(done, planned));
    cal
}

/// Levenberg–Marquardt on −log L = Σ n_eff/2 · log SSR over every
/// parameter (an extension re-tunes the baseline's too), from the best
/// point: forward-difference Jacobians of the residuals (k + 1 FE runs in
/// parallel), the Gauss–Newton matrix Σ n_eff/SSR · JᵀJ, steps clamped to
/// the unit cube; stops when the budget is spent or a step gains < 0.01 nats.
/// Returns the Gauss–Newton matrix at the final point.
fn levenberg_marquardt(
    cal: &mut Calibration,
    ev: &Evaluation<'_>,
    n_eff: &[f64],
    budget: &Budget,
    progress: &mut dyn FnMut(usize),
) -> Option<DMatrix<f64>> {
    let k = cal.priors.len();
    let start = cal.best(n_eff)?;
    let mut u = cal.points[start].u.clone();
    let mut f = cal.objective(n_eff)[start];
    let (mut lambda, mut spent, mut gn): (f64, usize, Option<DMatrix<f64>>) = (1e-3, 0, None);
    // Extension parameters switch contact or slip on and off: a wider
    // difference step averages over the jumps that a narrow one would see.
    let ext = cal.free.len() < k;
    let steps: Vec<f64> =
        (0..k).map(|i| if ext && cal.free.contains(&i) { 2e-2 } else { 2e-3 }).collect();
    while spent + k + 1 <= budget.local {
        let mut us = vec![u.clone()];
        for i in 0..k {
            let h = steps[i];
            let mut v = u.clone();
            v[i] = if v[i] + h <= 1.0 { v[i] + h } else { v[i] - h };
            us.push(v);
        }
        let evals = evaluate_full(ev, &us, budget.threads);
        spent += evals.len();
        let Some(r0) = evals[0].1.clone() else { break };
        let ssr: Vec<f64> =
            r0.iter().map(|c| c.iter().map(|x| x * x).sum::<f64>().max(1e-300)).collect();
        let mut jt_r = DVector::zeros(k);
        let mut jt_j = DMatrix::zeros(k, k);
        let mut cols: Vec<Option<Residuals>> = Vec::with_capacity(k);
        for (i, (_, ri)) in evals[1..].iter().enumerate() {
            let step = us[i + 1][i] - u[i];
            cols.push(ri.as_ref().map(|ri| {
                ri.iter()
                    .zip(&r0)
                    .map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y) / step).collect())
                    .collect()
            }));
        }
        if cols.iter().any(Option::is_none) {
            break;
        }
        let cols: Vec<Residuals> = cols.into_iter().flatten().collect();
        for (c, r) in r0.iter().enumerate() {
            let w = n_eff.get(c).copied().unwrap_or(0.0) / ssr[c];
            for a in 0..k {
                jt_r[a] += w * cols[a][c].iter().zip(r).map(|(x, y)| x * y).sum::<f64>();
                for b in a..k {
                    let v = w * cols[a][c].iter().zip(&cols[b][c]).map(|(x, y)| x * y).sum::<f64>();
                    jt_j[(a, b)] += v;
                    if a != b {
                        jt_j[(b, a)] += v;
                    }
                }
            }
        }
        for (p, _) in &evals {
            cal.points.push(p.clone());
        }
        gn = Some(jt_j.clone());
        progress(cal.points.len());
        let mut moved = false;
        for _ in 0..4 {
            if spent + 1 > budget.local + k {
                break;
            }
            let mut a = jt_j.clone();
            for i in 0..k {
                a[(i, i)] *= 1.0 + lambda;
                a[(i, i)] += 1e-12;
            }
            let Some(delta): Option<DVector<f64>> = a.cholesky().map(|c| c.solve(&(-&jt_r))) else {
                break;
            };
            let trial: Vec<f64> = u
                .iter()
                .zip(delta.iter())
                .map(|(x, d): (&f64, &f64)| (x + d).clamp(0.0, 1.0))
                .collect();
            let p = evaluate_points(ev, &[trial.clone()], 1).remove(0);
            spent += 1;
            let ft = p.fit.as_ref().map_or(f64::INFINITY, |ch| neg_log_lik(ch, n_eff));
            cal.points.push(p);
            progress(cal.points.len());
            if ft < f {
                let gain = f - ft;
                (u, f, moved) = (trial, ft, true);
                lambda = (lambda * 0.3).max(1e-6);
                if gain < 0.01 {
                    return gn;
                }
                break;
            }
            lambda *= 10.0;
        }
        if !moved {
            break;
        }
    }
    gn
}

/// Points where the emulator's mean is lowest: the minimiser from a dense
/// quasi-random search polished by a shrinking pattern search, then the
/// best points of the search that are not too close to each other.
fn proposals(gp: &Gp, d: usize, best: Option<&[f64]>, n: usize, seed: u64) -> Vec<Vec<f64>> {
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
