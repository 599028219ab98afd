//! Levenberg–Marquardt on the linear stage's −log L = Σ_c n_c/2 · log SSR_c
//! plus the frequencies' −log L, over the unit cube: forward-difference
//! Jacobians of every channel's residual and of the whitened frequency
//! residuals (one linear evaluation per dimension, all on the threads at
//! once, each stepped point's modes by Rayleigh–Ritz on the centre's:
//! [`LinearModel::basis`]), the Gauss–Newton system
//! Σ_c n_c/SSR_c · J_cᵀJ_c + J_mᵀJ_m, steps clamped to the cube, two
//! damping factors tried at once.

use super::model::{Judged, LinearModel};
use crate::diagnose::executor::on_threads;
use nalgebra::{DMatrix, DVector};

/// Forward-difference step in unit-cube coordinates (the linear model is
/// smooth in every parameter; 1e-3 of a prior's width moves a frequency
/// by far more than round-off and far less than its curvature).
const STEP: f64 = 1e-3;

/// A search's stopping rule: a step that gains less than this many nats
/// ends it (a hundredth of a nat changes no odds that matter), scaled by
/// the weights' share of a channel's samples when the channels are
/// weighted alike ([`Searcher::min_gain`]).
const MIN_GAIN_NATS: f64 = 0.01;

/// Where a search stands.
#[derive(Debug, Clone)]
pub struct Located {
    /// Unit-cube point.
    pub u: Vec<f64>,
    /// −log L there.
    pub f: f64,
    /// What the point gave.
    pub judged: Judged,
    /// The Gauss–Newton matrix at the last linearisation (unit cube).
    pub gauss_newton: Option<DMatrix<f64>>,
}

/// The search's context: the model, the channel weights, the threads, and
/// a count of the linear evaluations spent.
pub struct Searcher<'m, 'a> {
    /// The linear model.
    pub model: &'m LinearModel<'a>,
    /// Channel weights n_eff.
    pub n_eff: Vec<f64>,
    /// Evaluations at once.
    pub threads: usize,
    /// Linear evaluations spent.
    pub spent: usize,
    /// Judge the frequencies alone ([`LinearModel::judge_modal`]).
    pub modal_only: bool,
}

/// A point's gradient and Gauss–Newton matrix.
struct Centre {
    g: DVector<f64>,
    h: DMatrix<f64>,
}

impl Searcher<'_, '_> {
    /// Judges every point on the threads.
    pub fn judge_all(&mut self, us: &[Vec<f64>]) -> Vec<Result<Judged, String>> {
        self.spent += us.len();
        if self.modal_only {
            on_threads(us, self.threads, |u| self.model.judge_modal(u))
        } else {
            on_threads(us, self.threads, |u| self.model.judge(u))
        }
    }

    /// Judges points near `centre` on the threads, their modes by
    /// Rayleigh–Ritz on the centre's ([`LinearModel::basis`]; one modal
    /// analysis, counted as an evaluation); exactly, as
    /// [`judge_all`](Self::judge_all), when the centre's modes fail.
    fn judge_near(&mut self, centre: &[f64], us: &[Vec<f64>]) -> Vec<Result<Judged, String>> {
        let Ok(basis) = self.model.basis(centre, self.modal_only) else {
            return self.judge_all(us);
        };
        self.spent += us.len() + 1;
        if self.modal_only {
            on_threads(us, self.threads, |u| self.model.judge_modal_near(u, &basis))
        } else {
            on_threads(us, self.threads, |u| self.model.judge_near(u, &basis))
        }
    }

    /// The least gain a step must make: [`MIN_GAIN_NATS`] under
    /// effective-sample weights; under weights of about one a channel (the
    /// searches before the residuals are known) the same share of a
    /// channel's samples, [`MIN_GAIN_NATS`] over the samples of a channel.
    fn min_gain(&self) -> f64 {
        let mean_weight = self.n_eff.iter().sum::<f64>() / self.n_eff.len().max(1) as f64;
        if self.modal_only || mean_weight > 1.0 {
            return MIN_GAIN_NATS;
        }
        let samples = self.model.runs.iter().map(|k| self.model.bundle.runs[*k].n_samples()).max();
        MIN_GAIN_NATS / samples.unwrap_or(1).max(1) as f64
    }

    /// Levenberg–Marquardt from `start` for at most `iterations`
    /// linearisations; None when the start itself cannot be evaluated.
    pub fn levenberg_marquardt(&mut self, start: &[f64], iterations: usize) -> Option<Located> {
        let judged = self.judge_all(&[start.to_vec()]).pop()?.ok()?;
        let f = judged.neg_log_lik(&self.n_eff);
        let mut at = Located { u: start.to_vec(), f, judged, gauss_newton: None };
        let mut lambda = 1e-3;
        for _ in 0..iterations {
            let Some(c) = self.linearise(&at) else { break };
            at.gauss_newton = Some(c.h.clone());
            let (mut moved, mut gain) = (false, 0.0);
            while lambda < 1e10 {
                let lambdas = [lambda, 10.0 * lambda];
                let trials: Vec<Vec<f64>> = lambdas.iter().map(|l| step(&at.u, &c, *l)).collect();
                let judged = self.judge_all(&trials);
                let best = trials
                    .into_iter()
                    .zip(judged)
                    .zip(lambdas)
                    .filter_map(|((u, j), l)| j.ok().map(|j| (u, j.neg_log_lik(&self.n_eff), j, l)))
                    .filter(|(_, f, _, _)| f.is_finite() && *f < at.f)
                    .min_by(|a, b| a.1.total_cmp(&b.1));
                match best {
                    Some((u, f, judged, l)) => {
                        gain = at.f - f;
                        at = Located { u, f, judged, gauss_newton: at.gauss_newton.take() };
                        lambda = (0.3 * l).max(1e-7);
                        moved = true;
                        break;
                    }
                    None => lambda *= 100.0,
                }
            }
            tracing::trace!(f = at.f, gain, spent = self.spent, "linear stage: a search's step");
            if !moved || gain < self.min_gain() {
                break;
            }
        }
        Some(at)
    }

    /// The Gauss–Newton system at `at` from forward differences (backward
    /// where the forward step would leave the cube); None when a stepped
    /// point fails.
    fn linearise(&mut self, at: &Located) -> Option<Centre> {
        let d = at.u.len();
        let mut hs = Vec::with_capacity(d);
        let stepped: Vec<Vec<f64>> = (0..d)
            .map(|i| {
                let h = if at.u[i] + STEP <= 1.0 { STEP } else { -STEP };
                hs.push(h);
                let mut u = at.u.clone();
                u[i] += h;
                u
            })
            .collect();
        let judged = self.judge_near(&at.u, &stepped);
        let rows0 = rows(&at.judged, &at.judged, &self.n_eff);
        let mut jac = DMatrix::zeros(rows0.len(), d);
        for (i, (j, h)) in judged.iter().zip(&hs).enumerate() {
            let ri = rows(j.as_ref().ok()?, &at.judged, &self.n_eff);
            if ri.len() != rows0.len() {
                return None;
            }
            for (k, (a, b)) in ri.iter().zip(&rows0).enumerate() {
                jac[(k, i)] = (a - b) / h;
            }
        }
        let r0 = DVector::from_vec(rows0);
        Some(Centre { g: jac.transpose() * &r0, h: jac.transpose() * &jac })
    }
}

/// The weighted residual rows of `j`: each channel's residual times
/// √(n_c / SSR_c) of the centre `c` (missing readings 0), then the
/// frequency residuals over the centre's standard deviations, then the
/// line factors' whitened prior, so that
/// ½|rows|² linearises −log L at the centre.
fn rows(j: &Judged, c: &Judged, n_eff: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    for ((r, ch), n) in j.residuals.iter().zip(&c.channels).zip(n_eff) {
        let w = if ch.ssr > 0.0 { (n / ch.ssr).sqrt() } else { 0.0 };
        out.extend(r.iter().map(|v| if v.is_finite() { w * v } else { 0.0 }));
    }
    if let (Some(m), Some(mc)) = (&j.modal, &c.modal) {
        for (r, s) in m.residuals_hz().iter().zip(mc.sd_hz()) {
            out.push(r / s);
        }
    }
    out.extend(&j.prior_rows);
    out
}

/// u + δ clamped to the cube, (H + λ diag H + ε I) δ = −g on the free
/// dimensions: a dimension on a face of the cube whose gradient pushes out
/// of it stays where it is (the active set of a bounded search), so that
/// the step along the others is not spoilt by a clamp.
fn step(u: &[f64], c: &Centre, lambda: f64) -> Vec<f64> {
    let d = u.len();
    let pinned = |i: usize| (u[i] <= 0.0 && c.g[i] > 0.0) || (u[i] >= 1.0 && c.g[i] < 0.0);
    let free: Vec<usize> = (0..d).filter(|i| !pinned(*i)).collect();
    let n = free.len();
    let mut a = DMatrix::zeros(n, n);
    let mut rhs = DVector::zeros(n);
    for (r, &i) in free.iter().enumerate() {
        rhs[r] = -c.g[i];
        for (k, &j) in free.iter().enumerate() {
            a[(r, k)] = c.h[(i, j)];
        }
        a[(r, r)] += lambda * c.h[(i, i)].max(1e-12) + 1e-12;
    }
    let delta = a.lu().solve(&rhs).unwrap_or_else(|| DVector::zeros(n));
    let mut out = u.to_vec();
    for (r, &i) in free.iter().enumerate() {
        out[i] = (u[i] + delta[r]).clamp(0.0, 1.0);
    }
    out
}
