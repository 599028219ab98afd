//! Levenberg–Marquardt on −log L of a calibration: forward-difference
//! Jacobians of the channel residuals, the Gauss–Newton system weighted per
//! channel, damped steps clamped to the unit cube.
//!
//! The search is sequential: a Jacobian at the centre, then damped trials
//! judged in turn. To hand an executor batches as wide as it runs at once
//! ([`Budget::threads`](super::calibrate::Budget::threads)), each batch of
//! trials carries the Jacobian's stepped points of the first trials ahead
//! of their verdict ([`stencil_trials`]): when one is taken, the next
//! Jacobian is already run (and a taken trial is the next Jacobian's centre,
//! not run again). What the search keeps, where it goes and the FE runs it
//! counts against its budget are those of trying one trial after the other
//! (a taken trial counted again as its Jacobian's centre); points run ahead
//! and not taken are dropped unseen (a store keeps them). Batches are then
//! about as wide as the executor (a trial and its d stepped points at a
//! time, so a little wider where d + 1 does not divide it).

use super::band_likelihood::model_band_pass;
use super::calibrate::{evaluate_full, Calibration, Full, Point, Residuals, Scale, Search};
use super::ensemble::difference_step;
use super::executor::ExecutorError;
use super::fit::Evaluation;
use super::likelihood::Likelihood;
use nalgebra::{DMatrix, DVector};

impl Search<'_, '_> {
    /// Levenberg–Marquardt on −log L = Σ n_c/2 · log SSR_c over the `active`
    /// dimensions, from `start`, on the time histories (n_c = n_eff), the
    /// windowed misfits (n_c = windows) or the time histories filtered to
    /// the model's band (n_c = in-band degrees of freedom, the search's
    /// weights): forward-difference Jacobians of the
    /// residuals (one FE run per active dimension, in parallel with the
    /// centre), the Gauss–Newton matrix Σ n_c/SSR_c · JᵀJ, steps clamped to
    /// the unit cube; stops when `local` FE runs are spent or a step gains
    /// < 0.01 nats. Returns the final point and the Gauss–Newton matrix
    /// there (zero outside the active dimensions).
    pub(super) fn levenberg_marquardt(
        &mut self,
        cal: &mut Calibration,
        scale: Scale,
        start: Vec<f64>,
        active: &[usize],
        local: usize,
        progress: &mut dyn FnMut(usize),
    ) -> Result<(Vec<f64>, Option<DMatrix<f64>>), ExecutorError> {
        let k = active.len();
        let ext = self.own.len() < cal.priors.len();
        let steps: Vec<f64> =
            active.iter().map(|i| difference_step(ext && self.own.contains(i))).collect();
        let width = self.budget.threads.max(1);
        let set = LmSettings { scale, active, steps, local, width };
        let mut state = LmState { u: start, lambda: 1e-3, spent: 0, gn: None, ahead: None };
        while k > 0 && state.spent + k < local {
            let Some(centre) = self.linearise(cal, &set, &mut state)? else { break };
            state.gn = Some(embed_matrix(&centre.jt_j, active, cal.priors.len()));
            progress(cal.points.len());
            if self.damped_steps(cal, &set, &centre, &mut state, progress)? != LmStep::Moved {
                break;
            }
        }
        Ok((state.u, state.gn))
    }

    /// Runs the FE model at the centre `state.u` and its forward-difference
    /// points and linearises −log L there; keeps the points in `cal` when
    /// the Jacobian is complete (None when the centre or a stepped point
    /// failed: nothing is kept).
    fn linearise(
        &mut self,
        cal: &mut Calibration,
        set: &LmSettings<'_>,
        state: &mut LmState,
    ) -> Result<Option<Centre>, ExecutorError> {
        let (active, scale) = (set.active, set.scale);
        let us = difference_points(&state.u, active, &set.steps);
        // A taken trial brings its own evaluation, and its Jacobian's
        // stepped points when they were run ahead; the rest run now.
        let mut evals = match state.ahead.take() {
            Some((u, have)) if u == state.u => have,
            _ => Vec::new(),
        };
        if evals.len() < us.len() {
            evals.extend(evaluate_full(self.ev, &us[evals.len()..], self.exec)?);
        }
        let u = &state.u;
        state.spent += evals.len();
        let f = scale.objective(&evals[0].0, self.n_eff);
        let dt_s = channel_dt_s(self.ev, &evals[0].0);
        let Some(r0) = evals[0].1.as_ref().map(|r| scale.residuals(r, &dt_s)) else {
            return Ok(None);
        };
        let stepped: Vec<Option<Residuals>> = evals[1..]
            .iter()
            .map(|(_, ri)| ri.as_ref().map(|r| scale.residuals(r, &dt_s)))
            .collect();
        let h: Vec<f64> = (0..active.len()).map(|a| us[a + 1][active[a]] - u[active[a]]).collect();
        let Some(cols) = jacobian_columns(&r0, stepped, &h) else { return Ok(None) };
        let (jt_j, jt_r) = normal_equations(&r0, &cols, scale, self.n_eff);
        cal.points.extend(evals.into_iter().map(|(p, _)| p));
        Ok(Some(Centre { f, jt_j, jt_r }))
    }

    /// Up to four damped steps from `centre` ([`lm_trial`]), λ growing
    /// tenfold after each that does not lower the objective and shrinking
    /// to 0.3 λ (at least 1e-6) when one does; several run at once, with
    /// the Jacobian's points of the first ahead ([`stencil_trials`]).
    /// Returns how the round ended.
    fn damped_steps(
        &mut self,
        cal: &mut Calibration,
        set: &LmSettings<'_>,
        centre: &Centre,
        state: &mut LmState,
        progress: &mut dyn FnMut(usize),
    ) -> Result<LmStep, ExecutorError> {
        let (active, limit) = (set.active, set.local + set.active.len());
        let (jt_j, jt_r) = (&centre.jt_j, &centre.jt_r);
        let mut attempt = 0;
        while attempt < 4 && state.spent < limit {
            // The later attempts (10 λ, 100 λ, …) run beside the first, so
            // that workers are not idle while it is judged.
            // λ grows by the same products as one trial after the other
            // (λ·10·10 is not always λ·100 in floating point).
            let (mut trials, mut lambda) = (Vec::new(), state.lambda);
            while trials.len() < set.trials(attempt, state.spent, limit) {
                match lm_trial(&state.u, active, jt_j, jt_r, lambda) {
                    Some(t) => trials.push(t),
                    None => break,
                }
                lambda *= 10.0;
            }
            if trials.is_empty() {
                break;
            }
            let ahead = set.stencils(trials.len(), state.spent);
            let batch = stencil_trials(&trials, ahead, active, &set.steps);
            let mut evals = evaluate_full(self.ev, &batch, self.exec)?.into_iter();
            let mut judged = Vec::new();
            for (j, trial) in trials.into_iter().enumerate() {
                let Some(eval) = evals.next() else { break };
                let stencil: Vec<Full> = match j < ahead {
                    true => evals.by_ref().take(active.len()).collect(),
                    false => Vec::new(),
                };
                judged.push((trial, eval, stencil));
            }
            for (trial, (p, r), stencil) in judged {
                state.spent += 1;
                attempt += 1;
                let ft = set.scale.objective(&p, self.n_eff);
                let taken = ft < centre.f;
                if taken {
                    let centre_eval = std::iter::once((p.clone(), r));
                    state.ahead = Some((trial.clone(), centre_eval.chain(stencil).collect()));
                }
                cal.points.push(p);
                progress(cal.points.len());
                if taken {
                    let gain = centre.f - ft;
                    state.u = trial;
                    state.lambda = (state.lambda * 0.3).max(1e-6);
                    return Ok(if gain < 0.01 { LmStep::Converged } else { LmStep::Moved });
                }
                state.lambda *= 10.0;
            }
        }
        Ok(LmStep::Stalled)
    }
}

/// The batch of `trials` (in order), each of the first `ahead` followed by
/// its Jacobian's stepped points ([`difference_points`] without the
/// centre, which is the trial itself).
fn stencil_trials(
    trials: &[Vec<f64>],
    ahead: usize,
    active: &[usize],
    steps: &[f64],
) -> Vec<Vec<f64>> {
    let mut batch = Vec::new();
    for (j, t) in trials.iter().enumerate() {
        batch.push(t.clone());
        if j < ahead {
            batch.extend(difference_points(t, active, steps).into_iter().skip(1));
        }
    }
    batch
}

impl Scale {
    /// The objective of `p` at this scale: −log L of the time histories
    /// under weights `n_eff`, of the windowed RMS misfits, or the band
    /// likelihood under in-band degrees of freedom `n_eff`.
    fn objective(self, p: &Point, n_eff: &[f64]) -> f64 {
        match self {
            Scale::Fine => p.neg_log_lik(n_eff),
            Scale::Coarse => p.coarse,
            Scale::Band => p.neg_log_lik_by(&Likelihood::Band(n_eff)),
        }
    }

    /// The residuals fitted at this scale, of (time-history, windowed);
    /// `dt_s` holds each channel's time step (s), which the band's filter
    /// needs ([`model_band_pass`]; the modal frequencies' whitened
    /// residuals past the channels pass unfiltered). Missing readings
    /// (NaN) count as zero in the time histories and as the band fit
    /// counts them in the band.
    fn residuals(self, r: &(Residuals, Residuals), dt_s: &[f64]) -> Residuals {
        match self {
            // Missing readings add nothing to a Jacobian.
            Scale::Fine => (r.0.iter())
                .map(|c| c.iter().map(|v| if v.is_finite() { *v } else { 0.0 }).collect())
                .collect(),
            Scale::Coarse => r.1.clone(),
            Scale::Band => (r.0.iter().enumerate())
                .map(|(c, rc)| {
                    dt_s.get(c).map_or_else(|| rc.clone(), |dt| model_band_pass(rc, *dt))
                })
                .collect(),
        }
    }

    /// The weight n_c of channel `c` with residuals `r`: its `n_eff` on the
    /// time histories (its in-band degrees of freedom on the band's), its
    /// windows on the misfits. The time histories'
    /// residuals past the channels are the modal frequencies' whitened ones
    /// (Gaussian: weight 1 each, so n_c = their SSR).
    fn channel_weight(self, c: usize, r: &[f64], n_eff: &[f64]) -> f64 {
        match self {
            Scale::Fine | Scale::Band => {
                n_eff.get(c).copied().unwrap_or_else(|| r.iter().map(|x| x * x).sum())
            }
            Scale::Coarse => r.len() as f64,
        }
    }
}

/// The time step (s) of each channel of `p`'s fits, in their order (NaN
/// for a run the bundle does not hold; none when `p` failed).
fn channel_dt_s(ev: &Evaluation<'_>, p: &Point) -> Vec<f64> {
    let step = |run: &str| ev.bundle.runs.iter().find(|r| r.id == run).map_or(f64::NAN, |r| r.dt_s);
    p.fit.as_ref().map_or_else(|_| Vec::new(), |ch| ch.iter().map(|c| step(&c.run)).collect())
}

/// Settings of one Levenberg–Marquardt search
/// ([`Search::levenberg_marquardt`]).
struct LmSettings<'s> {
    /// Which residuals it fits.
    scale: Scale,
    /// The dimensions it moves.
    active: &'s [usize],
    /// Forward-difference step of each active dimension (unit cube,
    /// [`difference_step`]).
    steps: Vec<f64>,
    /// FE runs it may spend.
    local: usize,
    /// FE runs the executor runs at once ([`Budget::threads`](super::calibrate::Budget::threads)).
    width: usize,
}

impl LmSettings<'_> {
    /// Trials of one batch at attempt `attempt` with `spent` of `limit`
    /// FE runs spent: as many as carry their Jacobian's points ahead
    /// ([`stencils`](Self::stencils)), at least two (a second worker
    /// judges the next damping while the first is judged), within the four
    /// attempts and the budget.
    fn trials(&self, attempt: usize, spent: usize, limit: usize) -> usize {
        let wide = self.width.div_ceil(self.active.len() + 1).max(2);
        wide.min(4 - attempt.min(4)).min(limit.saturating_sub(spent))
    }

    /// How many of `trials` trials carry their Jacobian's points: enough
    /// to fill the executor's width with each trial and its d stepped
    /// points (at least one), and none when a taken trial would end the
    /// search before its next Jacobian (the budget spent).
    fn stencils(&self, trials: usize, spent: usize) -> usize {
        let k = self.active.len();
        let fill = self.width.div_ceil(k + 1).max(1).min(trials);
        // A trial taken as the j-th (from 0) leaves spent + j + 1; the
        // next Jacobian runs only while that plus k stays below `local`.
        (0..fill).take_while(|j| spent + j + 1 + k < self.local).count()
    }
}

/// Where a Levenberg–Marquardt search stands.
struct LmState {
    /// The current point (unit cube).
    u: Vec<f64>,
    /// The damping λ (1e-3 at the start).
    lambda: f64,
    /// FE runs spent.
    spent: usize,
    /// The Gauss–Newton matrix at the last centre (zero outside the active
    /// dimensions).
    gn: Option<DMatrix<f64>>,
    /// The taken trial and its Jacobian's evaluations (centre first), run
    /// ahead of its verdict ([`stencil_trials`]).
    ahead: Option<(Vec<f64>, Vec<Full>)>,
}

/// −log L and its Gauss–Newton system at a Levenberg–Marquardt centre.
struct Centre {
    /// The objective at the centre.
    f: f64,
    /// Σ n_c/SSR_c · JᵀJ, (active) × (active).
    jt_j: DMatrix<f64>,
    /// Σ n_c/SSR_c · Jᵀr, (active).
    jt_r: DVector<f64>,
}

/// How a round of damped Levenberg–Marquardt steps ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum LmStep {
    /// A step lowered the objective by 0.01 nats or more: the search goes on.
    Moved,
    /// A step lowered it by less: the search ends there.
    Converged,
    /// No step lowered it: the search ends at the centre.
    Stalled,
}

/// The centre `u` then one point per `active` dimension stepped by its
/// `steps` entry, forwards, or backwards where forwards leaves the unit cube.
fn difference_points(u: &[f64], active: &[usize], steps: &[f64]) -> Vec<Vec<f64>> {
    let mut us = vec![u.to_vec()];
    for (a, i) in active.iter().enumerate() {
        let h = steps[a];
        let mut v = u.to_vec();
        v[*i] = if v[*i] + h <= 1.0 { v[*i] + h } else { v[*i] - h };
        us.push(v);
    }
    us
}

/// Forward-difference Jacobian columns (r_a − r_0)/h_a, (active)(channels)
/// (samples), from the centre's residuals `r0` and each stepped point's
/// residuals (None: it failed, and so does the Jacobian) and signed step `h`.
fn jacobian_columns(
    r0: &Residuals,
    stepped: Vec<Option<Residuals>>,
    h: &[f64],
) -> Option<Vec<Residuals>> {
    let cols: Vec<Option<Residuals>> = stepped
        .into_iter()
        .zip(h)
        .map(|(ri, step)| {
            ri.map(|ri| {
                ri.iter()
                    .zip(r0)
                    .map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y) / step).collect())
                    .collect()
            })
        })
        .collect();
    cols.into_iter().collect()
}

/// The Gauss–Newton system (JᵀWJ, JᵀWr) of −log L = Σ n_c/2 · log SSR_c at
/// residuals `r0` (channels) with Jacobian columns `cols` (active)(channels),
/// W = n_c/SSR_c per channel ([`Scale::channel_weight`]; SSR at least 1e-300;
/// W = 1 on the whitened modal residuals).
fn normal_equations(
    r0: &Residuals,
    cols: &[Residuals],
    scale: Scale,
    n_eff: &[f64],
) -> (DMatrix<f64>, DVector<f64>) {
    let k = cols.len();
    let ssr: Vec<f64> =
        r0.iter().map(|c| c.iter().map(|x| x * x).sum::<f64>().max(1e-300)).collect();
    let mut jt_r = DVector::zeros(k);
    let mut jt_j = DMatrix::zeros(k, k);
    for (c, r) in r0.iter().enumerate() {
        let w = scale.channel_weight(c, r, n_eff) / ssr[c];
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
    (jt_j, jt_r)
}

/// The Levenberg–Marquardt step from `u` on the `active` dimensions with
/// damping `lambda`: (JᵀJ + λ diag JᵀJ) δ = −Jᵀr, clamped to the unit cube
/// (None when the damped matrix is not positive definite).
fn lm_trial(
    u: &[f64],
    active: &[usize],
    jt_j: &DMatrix<f64>,
    jt_r: &DVector<f64>,
    lambda: f64,
) -> Option<Vec<f64>> {
    let mut a = jt_j.clone();
    for i in 0..active.len() {
        a[(i, i)] *= 1.0 + lambda;
        a[(i, i)] += 1e-12;
    }
    let delta = a.cholesky()?.solve(&(-jt_r));
    let mut out = u.to_vec();
    active.iter().zip(delta.iter()).for_each(|(i, d)| out[*i] = (u[*i] + d).clamp(0.0, 1.0));
    Some(out)
}

/// `m` (over the `dims` of a `k`-dimensional space) as a k × k matrix, zero
/// outside them.
fn embed_matrix(m: &DMatrix<f64>, dims: &[usize], k: usize) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(k, k);
    for (a, i) in dims.iter().enumerate() {
        for (b, j) in dims.iter().enumerate() {
            out[(*i, *j)] = m[(a, b)];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::calibrate::Budget;
    use super::super::cause::BASELINE_PRIORS;
    use super::super::cause::{Cause, Demand};
    use super::super::executor::{FeExecutor, Sims, ThreadExecutor};
    use super::super::farm_executor_tests::tiny_bundle;
    use super::super::fit::effective_sizes;
    use super::super::pipeline::split_runs;
    use super::*;
    use proptest::prelude::*;

    /// Threads that record the size of every batch they are handed.
    struct Recording(ThreadExecutor, Vec<usize>);

    impl FeExecutor for Recording {
        fn simulate(
            &mut self,
            ev: &Evaluation<'_>,
            thetas: &[Vec<f64>],
        ) -> Result<Vec<Sims>, ExecutorError> {
            self.1.push(thetas.len());
            self.0.simulate(ev, thetas)
        }

        fn demand(
            &mut self,
            ev: &Evaluation<'_>,
            theta: &[f64],
        ) -> Result<Result<Demand, String>, ExecutorError> {
            self.0.demand(ev, theta)
        }

        fn simulated(&self) -> usize {
            self.0.simulated()
        }
    }

    #[test]
    fn what_a_search_keeps_does_not_depend_on_how_wide_its_batches_are() {
        let dir = tempfile::tempdir().unwrap();
        let b = tiny_bundle(dir.path());
        let (runs, _) = split_runs(&b);
        let priors = BASELINE_PRIORS.to_vec();
        let ev = Evaluation::baseline(&b, &priors, &runs);
        let mut exec = ThreadExecutor::new(2);
        let centre = evaluate_full(&ev, &[vec![0.5, 0.5]], &mut exec).unwrap();
        let n_eff = effective_sizes(centre[0].0.fit.as_ref().unwrap());
        let search = |width: usize| {
            let budget = Budget { threads: width, ..Budget::default() };
            let mut rec = Recording(ThreadExecutor::new(2), Vec::new());
            let mut cal = Calibration {
                cause: Cause::NONE,
                priors: priors.clone(),
                free: vec![0, 1],
                points: Vec::new(),
                demand: None,
                gauss_newton: None,
                committed_share: 0.0,
            };
            let own: Vec<usize> = vec![0, 1];
            let mut s =
                Search { ev: &ev, n_eff: &n_eff, budget: &budget, exec: &mut rec, own: &own };
            let end = s
                .levenberg_marquardt(
                    &mut cal,
                    Scale::Fine,
                    vec![0.2, 0.8],
                    &[0, 1],
                    24,
                    &mut |_| {},
                )
                .unwrap();
            let kept: Vec<(Vec<f64>, f64)> =
                cal.points.iter().map(|p| (p.u.clone(), p.neg_log_lik(&n_eff))).collect();
            (end, kept, rec.1)
        };
        let (narrow, wide) = (search(1), search(9));
        assert_eq!(narrow.0, wide.0, "where it ended and its Gauss–Newton matrix");
        assert_eq!(narrow.1, wide.1, "the points it kept");
        assert!(narrow.1.len() > 6, "a search of one step: {:?}", narrow.1.len());
        // 9 wide: after the first Jacobian, three trials each with its
        // Jacobian's two stepped points (fewer where the budget ends); 1
        // wide: two trials, the first with them.
        assert!(wide.2.len() >= 3 && wide.2[0] == 3, "{:?}", wide.2);
        assert!(wide.2[1..wide.2.len() - 2].iter().all(|n| *n == 9), "{:?}", wide.2);
        assert!(narrow.2.iter().all(|n| *n <= 4), "{:?}", narrow.2);
        assert!(wide.2.len() <= narrow.2.len(), "{:?} vs {:?}", wide.2, narrow.2);
    }

    #[test]
    fn a_matrix_over_some_dimensions_embeds_with_zeros_elsewhere() {
        let m = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 5.0]);
        let e = embed_matrix(&m, &[1, 3], 4);
        assert_eq!((e[(1, 1)], e[(1, 3)], e[(3, 1)], e[(3, 3)]), (1.0, 2.0, 2.0, 5.0));
        assert_eq!(e.iter().filter(|x| **x != 0.0).count(), 4);
    }

    proptest! {
        /// A step on some dimensions leaves the others where they were,
        /// and with no damping solves the Gauss–Newton system on the
        /// active ones (inside the cube).
        #[test]
        fn a_step_moves_only_the_active_dimensions(
            u in proptest::collection::vec(0.3f64..0.7, 4),
            a in proptest::collection::vec(-1.0f64..1.0, 4),
            g in proptest::collection::vec(-0.01f64..0.01, 2),
            pick in 0usize..6,
        ) {
            let pairs = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];
            let active = pairs[pick];
            let m = DMatrix::from_row_slice(2, 2, &a);
            let jt_j = &m * m.transpose() + DMatrix::identity(2, 2);
            let jt_r = DVector::from_row_slice(&g);
            let next = lm_trial(&u, &active, &jt_j, &jt_r, 0.0).unwrap();
            for i in (0..4).filter(|i| !active.contains(i)) {
                prop_assert_eq!(next[i], u[i]);
            }
            let delta = DVector::from_iterator(2, active.iter().map(|i| next[*i] - u[*i]));
            let res = &jt_j * &delta + &jt_r;
            prop_assert!(res.norm() < 1e-9, "{}", res);
        }
    }
}
