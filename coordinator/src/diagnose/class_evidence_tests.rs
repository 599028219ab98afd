//! The class evidence of a small FE campaign (the tiny campaign: 2.4 m x
//! 2.4 m, two 2 s calibration runs at 50 Hz, `modal.csv`; the baseline's
//! two parameters) against brute-force quadrature of the same likelihood
//! over the FE model itself, and the policy's refusals.

use super::super::calibrate::{calibrate, evaluate_points, Budget};
use super::super::cause::{Cause, BASELINE_PRIORS};
use super::super::executor::ThreadExecutor;
use super::super::farm_executor_tests::tiny_bundle;
use super::super::fit::{effective_sizes, Evaluation};
use super::super::likelihood::band_sizes;
use super::super::pipeline::split_runs;
use super::super::resume::peak_search;
use super::*;
use nalgebra::{DMatrix, DVector};

/// Cells (per axis) of each quadrature grid.
const GRID: usize = 14;
/// A grid's next box holds its cells within this many nats of its best.
const WINDOW_NATS: f64 = 25.0;

/// A box of the unit square: (low, high) per axis.
type Box2 = [(f64, f64); 2];

/// Midpoints of a `g` x `g` grid over `b`, row by row (x outer).
fn midpoints(b: &Box2, g: usize) -> Vec<Vec<f64>> {
    let at = |(lo, hi): (f64, f64), i: usize| lo + (hi - lo) * (i as f64 + 0.5) / g as f64;
    (0..g).flat_map(|i| (0..g).map(move |j| vec![at(b[0], i), at(b[1], j)])).collect()
}

/// ln Σ exp(v_k) + ln w (−∞ for an empty or all −∞ sum).
fn ln_sum(v: &[f64], ln_w: f64) -> f64 {
    let m = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if m == f64::NEG_INFINITY {
        return m;
    }
    m + v.iter().map(|x| (x - m).exp()).sum::<f64>().ln() + ln_w
}

/// Whether point `u` lies in box `b`.
fn inside(b: &Box2, u: &[f64]) -> bool {
    (0..2).all(|k| u[k] > b[k].0 && u[k] < b[k].1)
}

/// The box of `b`'s `g`-grid cells whose values are within [`WINDOW_NATS`]
/// of the best, grown by one cell each way (inside the unit square).
fn next_box(b: &Box2, g: usize, us: &[Vec<f64>], f: &[f64]) -> Box2 {
    let best = f.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut out = [(f64::INFINITY, f64::NEG_INFINITY); 2];
    for (u, v) in us.iter().zip(f) {
        if *v >= best - WINDOW_NATS {
            for k in 0..2 {
                let h = (b[k].1 - b[k].0) / g as f64;
                out[k].0 = out[k].0.min(u[k] - 1.5 * h).max(0.0);
                out[k].1 = out[k].1.max(u[k] + 1.5 * h).min(1.0);
            }
        }
    }
    out
}

/// ln ∫ exp(ln_l(u)) du over the unit square by nested midpoint grids: a
/// [`GRID`]² grid over the square, then over the box of its cells near the
/// best, and so on while the box shrinks to under half on some axis; the
/// last box once more on a grid twice as fine. Each level's cells outside
/// the next box count at their level's resolution (nothing is dropped).
/// Returns ln Z, the last two grids' difference on the last box (the
/// rule's error there) and the evaluations spent.
fn quadrature(ln_l: &mut dyn FnMut(&[Vec<f64>]) -> Vec<f64>) -> (f64, f64, usize) {
    let mut b: Box2 = [(0.0, 1.0), (0.0, 1.0)];
    let mut outside = Vec::new();
    let mut spent = 0;
    for _ in 0..12 {
        let us = midpoints(&b, GRID);
        let f = ln_l(&us);
        spent += us.len();
        let ln_cell = ((b[0].1 - b[0].0) * (b[1].1 - b[1].0) / (GRID * GRID) as f64).ln();
        let nb = next_box(&b, GRID, &us, &f);
        let shrinks = (0..2).any(|k| nb[k].1 - nb[k].0 < 0.5 * (b[k].1 - b[k].0));
        if !shrinks {
            let coarse = ln_sum(&f, ln_cell);
            let fine_us = midpoints(&b, 2 * GRID);
            let fine = ln_sum(&ln_l(&fine_us), ln_cell - 4f64.ln());
            spent += fine_us.len();
            let total = ln_sum(&[outside, vec![fine]].concat(), 0.0);
            return (total, (fine - coarse).abs(), spent);
        }
        let out: Vec<f64> =
            us.iter().zip(&f).filter(|(u, _)| !inside(&nb, u)).map(|(_, v)| *v).collect();
        outside.push(ln_sum(&out, ln_cell));
        b = nb;
    }
    panic!("the quadrature's box still shrank after 12 grids: {b:?}");
}

/// ln L of the baseline class on the tiny campaign's calibration runs at
/// unit-cube points, through `exec`, under likelihood `lik`.
fn exact_ln_l(
    ev: &Evaluation<'_>,
    lik: &Likelihood<'_>,
    exec: &mut dyn FeExecutor,
    us: &[Vec<f64>],
) -> Vec<f64> {
    let pts = evaluate_points(ev, us, exec).unwrap();
    pts.iter().map(|p| -p.neg_log_lik_by(lik)).collect()
}

#[test]
fn evidence_of_a_small_fe_campaign_matches_quadrature_over_the_fe_model() {
    matches_quadrature(LikelihoodKind::Time);
}

#[test]
fn band_evidence_of_a_small_fe_campaign_matches_quadrature_over_the_fe_model() {
    // The calibration minimised the time likelihood: the band evidence
    // starts from the band likelihood's own search.
    matches_quadrature(LikelihoodKind::Band);
}

/// The evidence under likelihood `kind` against quadrature of the same
/// likelihood, from the calibration and its search of that likelihood
/// ([`peak_search`]), and from its best point alone with a curvature 30
/// times off either way.
fn matches_quadrature(kind: LikelihoodKind) {
    let dir = tempfile::tempdir().unwrap();
    let b = tiny_bundle(dir.path());
    let (cal_runs, _) = split_runs(&b);
    let priors = BASELINE_PRIORS.to_vec();
    let ev = Evaluation::baseline(&b, &priors, &cal_runs);
    let mut exec = ThreadExecutor::new(2);
    // The channel weights: the residuals' at the prior's centre, held fixed.
    let centre = evaluate_points(&ev, &[vec![0.5, 0.5]], &mut exec).unwrap();
    let n_eff = effective_sizes(centre[0].fit.as_ref().unwrap());
    let band_dof = band_sizes(centre[0].fit.as_ref().unwrap());
    let w = ChannelWeights { n_eff: &n_eff, band_dof: &band_dof };
    let lik = kind.with(w);

    let t = std::time::Instant::now();
    let (ln_z_quad, quad_err, quad_runs) =
        quadrature(&mut |us| exact_ln_l(&ev, &lik, &mut exec, us));
    let quad_s = t.elapsed().as_secs_f64();
    let t = std::time::Instant::now();
    let budget = Budget { threads: 2, ..Budget::default() };
    let class = (Cause::NONE, &priors[..]);
    let mut cal =
        calibrate(&b, class, &cal_runs, &n_eff, &budget, None, &mut exec, &mut |_, _| {}).unwrap();
    let policy = EvidencePolicy { likelihood: kind, ..EvidencePolicy::default() };
    let from = cal.points[cal.best_by(&lik).unwrap()].u.clone();
    let local = policy.resume_runs(2);
    let data = (&b, &cal_runs[..]);
    let h =
        peak_search(&mut cal, from, data, (kind, w), &budget, local, &mut exec).unwrap().unwrap();
    let got = class_evidence(&cal, &h, (&b, &cal_runs), w, &mut exec, &policy).unwrap();
    let smc_s = t.elapsed().as_secs_f64();
    eprintln!(
        "{kind:?}: quadrature ln Z {ln_z_quad:.3} (grid difference {quad_err:.3}, {quad_runs} FE points, {quad_s:.1} s); \
         class_evidence {:.3} ± {:.3} (k̂ {:.2}, converged {}, Laplace {:.3}; {} + {} FE points, {} rounds, {smc_s:.1} s)",
        got.ln_evidence,
        got.ln_evidence_sd,
        got.k_hat,
        got.converged,
        got.laplace_ln_evidence,
        cal.fe_points(),
        got.fe_points,
        got.rounds.len(),
    );
    for (k, r) in got.rounds.iter().enumerate() {
        eprintln!("  round {}: {r:?}", k + 1);
    }
    assert!(quad_err < 0.1, "the quadrature itself is unresolved: {quad_err}");
    assert!(got.converged, "{:?}", got.rounds);
    let diff = got.ln_evidence - ln_z_quad;
    assert!(
        diff.abs() <= 1.0,
        "ln Z {} vs quadrature {ln_z_quad}: {diff:+.3} nat",
        got.ln_evidence
    );
    let spent = cal.fe_points() + got.fe_points;
    assert!(spent < quad_runs / 4, "{spent} FE points vs the quadrature's {quad_runs}");

    // A start with its best point alone (no other point to refit the
    // quadratic from) and a curvature wrong by a factor of 30 either way (a
    // Laplace form 5.5 times too wide or too narrow): the rounds must still
    // reach the quadrature's evidence.
    let best = cal.best_by(&lik).unwrap();
    for factor in [1.0 / 30.0, 30.0] {
        let mut off = cal.clone();
        off.points = vec![cal.points[best].clone()];
        let got =
            class_evidence(&off, &(&h * factor), (&b, &cal_runs), w, &mut exec, &policy).unwrap();
        eprintln!(
            "{kind:?}, curvature x {factor:.3}: {:.3} ± {:.3} (k̂ {:.2}, converged {}, Laplace {:.3}; {} FE points, {} rounds)",
            got.ln_evidence,
            got.ln_evidence_sd,
            got.k_hat,
            got.converged,
            got.laplace_ln_evidence,
            got.fe_points,
            got.rounds.len()
        );
        for (k, r) in got.rounds.iter().enumerate() {
            eprintln!("  round {}: {r:?}", k + 1);
        }
        assert!(got.converged, "curvature x {factor}: {:?}", got.rounds);
        let diff = got.ln_evidence - ln_z_quad;
        assert!(diff.abs() <= 1.0, "curvature x {factor}: {diff:+.3} nat");
    }
    from_short_of_the_mode((&cal, &h), (&b, &cal_runs), w, &mut exec, &policy, ln_z_quad);
    annealed_alone((&cal, &h), (&b, &cal_runs), w, &mut exec, &policy, ln_z_quad);
}

/// The annealing alone: one round from the best point with a curvature 30
/// times too small (the emulator the Laplace form alone, its posterior 5.5
/// times too wide), then the annealing from its emulated posterior; it must reach the FE posterior and the quadrature's
/// `ln_z_quad` within 1 nat.
fn annealed_alone(
    (cal, h): (&Calibration, &DMatrix<f64>),
    data: (&Bundle, &[usize]),
    w: ChannelWeights<'_>,
    exec: &mut ThreadExecutor,
    policy: &EvidencePolicy,
    ln_z_quad: f64,
) {
    let lik = policy.likelihood.with(w);
    let mut off = cal.clone();
    off.points = vec![cal.points[cal.best_by(&lik).unwrap()].clone()];
    // Without the scale check, which would mend the form first.
    let never = EvidencePolicy { rounds: 1, scale_tries: 0, ..policy.clone() };
    let got = class_evidence(&off, &(h / 30.0), data, w, exec, &never).unwrap();
    let a = got.annealed.clone().expect("the rounds did not settle: the annealing runs");
    let (ln_z, sd) = a.estimate.unwrap_or((f64::NAN, f64::NAN));
    eprintln!(
        "{:?}, annealed: {:.3} ± {:.3} ({} stages, {} FE runs, β {}; rounds {:?})",
        policy.likelihood,
        ln_z,
        sd,
        a.stages,
        a.fe_points,
        a.beta,
        got.rounds.iter().map(|r| r.corrected.as_ref().map(|c| c.ln_evidence)).collect::<Vec<_>>()
    );
    assert!(a.estimate.is_some(), "β reached 1: {a:?}");
    assert!(got.converged, "{a:?}");
    assert_eq!(got.ln_evidence, ln_z);
    let diff = ln_z - ln_z_quad;
    assert!(diff.abs() <= 1.0, "annealed: {diff:+.3} nat");
    // The same annealing cut one stage short (its stages are the same up
    // to there) bounds the quadrature's ln Z on both sides.
    assert!(a.stages >= 2, "one stage reached the FE posterior: nothing to cut ({a:?})");
    let per_stage = never.checks * never.anneal_steps;
    let cut = EvidencePolicy { anneal_runs: (a.stages - 1) * per_stage, ..never.clone() };
    let got = class_evidence(&off, &(h / 30.0), data, w, exec, &cut).unwrap();
    let a = got.annealed.clone().expect("the annealing runs");
    let (Some((lower, lower_sd)), Some((upper, upper_sd))) = (a.lower, a.upper) else {
        panic!("cut short, the annealing bounds ln Z: {a:?}");
    };
    eprintln!(
        "{:?}, cut at β {:.3}: {lower:.3} ± {lower_sd:.3} ≤ {ln_z_quad:.3} ≤ {upper:.3} ± {upper_sd:.3}",
        policy.likelihood, a.beta
    );
    assert!(!got.converged && a.beta < 1.0, "{a:?}");
    assert!(lower - 2.0 * lower_sd <= ln_z_quad, "lower bound above the quadrature: {a:?}");
    assert!(upper + 2.0 * upper_sd >= ln_z_quad, "upper bound below the quadrature: {a:?}");
    assert_eq!(got.counted_ln_evidence(), Some(lower - 2.0 * lower_sd));
    assert_eq!(got.ln_evidence_at_most(), Some(upper + 2.0 * upper_sd));
}

/// A calibration that stopped short of the mode (its one point the
/// calibration's nearest to [`SHORT_NATS`] below its best) and a first
/// search that does not move (the curvature at the best): the rounds must
/// stop for the higher ground their checks find, the search resume there,
/// and the evidence started again reach the quadrature's `ln_z_quad`.
fn from_short_of_the_mode(
    (cal, h): (&Calibration, &DMatrix<f64>),
    data: (&Bundle, &[usize]),
    w: ChannelWeights<'_>,
    exec: &mut ThreadExecutor,
    policy: &EvidencePolicy,
    ln_z_quad: f64,
) {
    let lik = policy.likelihood.with(w);
    let value = |k: usize| -cal.points[k].neg_log_lik_by(&lik);
    let top = value(cal.best_by(&lik).unwrap());
    let gap = |k: usize| (top - value(k) - SHORT_NATS).abs();
    let short = (0..cal.points.len()).min_by(|a, b| gap(*a).total_cmp(&gap(*b))).unwrap();
    let mut off = cal.clone();
    off.points = vec![cal.points[short].clone()];
    let budget = Budget { threads: 2, ..Budget::default() };
    let mut first = true;
    let mut search = |c: &mut Calibration, u: Vec<f64>, e: &mut dyn FeExecutor| {
        if std::mem::take(&mut first) {
            return Ok(Some(h.clone()));
        }
        let local = policy.resume_runs(c.priors.len());
        peak_search(c, u, data, (policy.likelihood, w), &budget, local, e)
    };
    let got = settled_evidence(&mut off, data, w, exec, policy, &mut search).unwrap();
    eprintln!(
        "{:?}, from {:.1} nat below the best: {:.3} ± {:.3} (k̂ {:.2}, converged {}, {} restarts; {} + {} FE points, {} rounds in the last start)",
        policy.likelihood,
        top - value(short),
        got.ln_evidence,
        got.ln_evidence_sd,
        got.k_hat,
        got.converged,
        got.restarts,
        off.fe_points() - 1,
        got.fe_points,
        got.rounds.len()
    );
    assert!(got.restarts >= 1, "no restart from {} nat below the mode", top - value(short));
    assert!(got.converged, "{:?}", got.rounds);
    let diff = got.ln_evidence - ln_z_quad;
    assert!(diff.abs() <= 1.0, "from short of the mode: {diff:+.3} nat");
}

/// How far below the best point the short start lies (nat): far beyond the
/// rise limit (1 nat for two parameters), within the emulator's window.
const SHORT_NATS: f64 = 15.0;

#[test]
fn a_policy_out_of_range_is_refused_with_its_key() {
    let bad = [
        EvidencePolicy { rounds: 1, anneal_runs: 0, ..EvidencePolicy::default() },
        EvidencePolicy { checks: 1, ..EvidencePolicy::default() },
        EvidencePolicy { floor_nats: (0.0, 10.0), ..EvidencePolicy::default() },
        EvidencePolicy { floor_nats: (20.0, f64::NAN), ..EvidencePolicy::default() },
    ];
    let keys = ["rounds", "checks", "floor_nats", "floor_nats"];
    for (p, key) in bad.iter().zip(keys) {
        match p.check() {
            Err(ClassEvidenceError::Policy { key: k, .. }) => assert_eq!(k, key),
            other => panic!("{key}: {other:?}"),
        }
    }
    assert!(EvidencePolicy::default().check().is_ok());
    assert_eq!(EvidencePolicy::default().floor(2), 40.0);
}

/// A Laplace form at `mode` with curvature `h` (unit cube).
fn laplace_at(mode: Vec<f64>, value: f64, h: DMatrix<f64>) -> Laplace {
    let lt = h.cholesky().unwrap().l().transpose();
    Laplace { mode: (mode, value), lt }
}

#[test]
fn a_refit_recovers_an_exact_quadratic_from_another_start() {
    // ln L = 10 − ½ (u − c)ᵀ H (u − c), sampled on a grid about c; the
    // start is off in place (0.05) and curvature (4 and 1/4 per axis).
    let c = [0.42, 0.57];
    let h = DMatrix::from_row_slice(2, 2, &[900.0, 200.0, 200.0, 400.0]);
    let ln_l = |u: &[f64]| {
        let du = DVector::from_iterator(2, u.iter().zip(c).map(|(a, b)| a - b));
        10.0 - 0.5 * (du.transpose() * &h * &du)[0]
    };
    let ledger: Vec<Entry> = (0..7)
        .flat_map(|i| {
            (0..7)
                .map(move |j| vec![c[0] + 0.02 * (i as f64 - 3.0), c[1] + 0.03 * (j as f64 - 3.0)])
        })
        .map(|u| {
            let v = ln_l(&u);
            (u, v, true)
        })
        .collect();
    let start = laplace_at(
        vec![0.47, 0.52],
        9.0,
        DMatrix::from_diagonal(&DVector::from_vec(vec![3600.0, 100.0])),
    );
    let got = start.refit(&ledger, 100.0).expect("49 points, 6 coefficients");
    assert!((got.mode.1 - 10.0).abs() < 1e-8, "{}", got.mode.1);
    for (got_k, c_k) in got.mode.0.iter().zip(c) {
        assert!((got_k - c_k).abs() < 1e-8, "{:?}", got.mode.0);
    }
    let hu = got.lt.transpose() * &got.lt;
    assert!((hu - &h).abs().max() < 1e-6 * h.abs().max(), "{}", got.lt);
    // Laplace's ln Z of a Gaussian: 10 + ln 2π − ½ ln det H.
    let want = 10.0 + (2.0 * std::f64::consts::PI).ln() - 0.5 * h.determinant().ln();
    assert!((got.ln_evidence() - want).abs() < 1e-8);
}

#[test]
fn a_refit_is_refused_when_too_few_points_convex_or_peaking_outside_them() {
    let start = laplace_at(vec![0.5, 0.5], 0.0, DMatrix::identity(2, 2) * 100.0);
    let grid = |f: &dyn Fn(f64, f64) -> f64| -> Vec<Entry> {
        (0..5)
            .flat_map(|i| (0..5).map(move |j| (0.4 + 0.05 * i as f64, 0.4 + 0.05 * j as f64)))
            .map(|(x, y)| (vec![x, y], f(x, y), true))
            .collect()
    };
    // Eleven points for six coefficients: too few.
    let few: Vec<Entry> =
        grid(&|x, y| -(x - 0.5).powi(2) - (y - 0.5).powi(2)).into_iter().take(11).collect();
    assert!(start.refit(&few, 100.0).is_none());
    // A bowl (convex): no maximum.
    assert!(start.refit(&grid(&|x, y| (x - 0.5).powi(2) + (y - 0.5).powi(2)), 100.0).is_none());
    // A peak at (0.9, 0.5), beyond the points (0.4 to 0.6).
    assert!(start
        .refit(&grid(&|x, y| -50.0 * (x - 0.9).powi(2) - 50.0 * (y - 0.5).powi(2)), 100.0)
        .is_none());
}
