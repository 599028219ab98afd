//! Posterior of a calibrated variant by black-box variational inference
//! (full-rank Gaussian, reparameterisation gradients; stats::bbvi) on an
//! emulator of −log L built from the FE evaluations the calibration made:
//! the Gauss–Newton quadratic at the estimate plus a GP through what it
//! misses at every evaluated point, which bends the quadratic along the
//! valleys a hysteretic model's likelihood has. Both are capped at
//! [`CAP_NATS`] above the best: the posterior lives within a few tens of
//! nats of it, and the cap keeps in view the evaluations far worse than
//! the quadratic says (a connection driven past its backbone's peak, a
//! support that slips away), which a GP trained on the near points alone
//! would extrapolate over into a posterior where the FE misfit is
//! thousands of nats above the best. The prior is uniform on the prior
//! box (unit cube); q lives on the logit of the unit cube, centred at the
//! estimate and scaled by the Laplace spread, so that the box is respected
//! and q starts near its answer. No FE run is made here: the emulator's
//! excess at q's mean and a few of its draws ([`VariationalPosterior::probes`])
//! is what [`super::posterior_check`] compares with the FE model.

use super::calibrate::{unit_cube_gp, Calibration};
use super::mdl::gn_sd;
use nalgebra::DMatrix;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use stats::bbvi::{Bbvi, BbviSettings, FamilyKind};
use stats::calibration::LogDensity;
use stats::gp::Gp;

/// Excess −log L (nats above the best) at which the emulator's quadratic
/// and its training targets are capped: far above where the posterior has
/// mass (e^−100), low enough that a GP can follow a cliff to it.
pub const CAP_NATS: f64 = 100.0;
/// Draws from q kept for the summaries and plots.
const DRAWS: usize = 2000;
/// Smallest distance of the estimate from a bound of the unit cube (logit).
const EDGE: f64 = 1e-4;
/// Points where the emulator is to be checked: q's mean and this many
/// draws less one.
pub const PROBES: usize = 5;

/// The variational posterior of one variant, in prior (physical) units.
#[derive(Debug, Clone, PartialEq)]
pub struct VariationalPosterior {
    /// Parameter names, prior order.
    pub names: Vec<String>,
    /// Their units.
    pub units: Vec<String>,
    /// Posterior means.
    pub mean: Vec<f64>,
    /// Posterior standard deviations.
    pub sd: Vec<f64>,
    /// 2.5 % quantiles.
    pub q025: Vec<f64>,
    /// 97.5 % quantiles.
    pub q975: Vec<f64>,
    /// Draws per parameter (for the marginal plots).
    pub draws: Vec<Vec<f64>>,
    /// FE evaluations that trained the GP correction (0: quadratic only).
    pub emulator_points: usize,
    /// BBVI iterations and whether they converged.
    pub iterations: usize,
    /// Whether BBVI met its convergence test.
    pub converged: bool,
    /// Relative change of the last two window averages of q's parameters
    /// (Adam's steps keep it near lr·√window once the gradient is noise).
    pub rel_change: f64,
    /// ELBO of the fit (nats, relative to the best evaluated −log L).
    pub elbo: f64,
    /// The best evaluated −log L, which the excesses are relative to.
    pub best_neg_log_lik: f64,
    /// Unit-cube points where the emulator can be checked against the FE
    /// model: q's mean, then draws from q.
    pub probes: Vec<Vec<f64>>,
    /// The emulated excess −log L at each probe (nats above the best,
    /// capped at [`CAP_NATS`]).
    pub probe_excess: Vec<f64>,
    /// How the emulator fared against the FE model at its probes (None:
    /// not checked).
    pub check: Option<EmulatorCheck>,
}

/// The emulator of a posterior against the FE model at its probes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmulatorCheck {
    /// FE parameter points the checks ran, every round's.
    pub fe_points: usize,
    /// Largest |FE − emulated| excess −log L at the reported posterior's
    /// probes (nats, both capped at [`CAP_NATS`]).
    pub gap_nats: f64,
    /// Whether that gap is within the check's tolerance.
    pub confirmed: bool,
}

/// Emulated −log L − f̂ over the unit cube.
struct Emulated {
    u0: Vec<f64>,
    h: DMatrix<f64>,
    correction: Option<Correction>,
}

/// The GP through what the capped quadratic misses, with the range of
/// its training targets and its value at the estimate.
struct Correction {
    gp: Gp,
    low: f64,
    high: f64,
    at_estimate: f64,
}

impl Correction {
    /// The correction at `u`, relative to its value at the estimate (where
    /// the FE excess is 0 by definition; a GP that smooths over a needle-
    /// sharp optimum sits several nats above it there).
    fn at(&self, u: &[f64]) -> f64 {
        self.raw(u) - self.at_estimate
    }

    /// The GP's mean held to its targets' range (a GP far from its points
    /// can swing thousands of nats beyond them), and a dip below the
    /// quadratic counted only as far as the GP is sure of it (mean + 2 sd),
    /// so that the posterior does not settle where no FE run found the fit
    /// better.
    fn raw(&self, u: &[f64]) -> f64 {
        let Ok(p) = self.gp.predict(u, false) else { return 0.0 };
        let mean = p.mean[0].clamp(self.low, self.high);
        if mean < 0.0 {
            (mean + 2.0 * p.sd[0]).min(0.0)
        } else {
            mean
        }
    }
}

impl Emulated {
    /// min(½ dᵀHd, [`CAP_NATS`]) + GP correction at `u`, never below the
    /// best FE point (0): a better fit than any FE run found is an
    /// extrapolation, which the FE checks ([`super::posterior_check`]) test.
    fn excess(&self, u: &[f64]) -> f64 {
        let c = self.correction.as_ref().map_or(0.0, |c| c.at(u));
        (self.quadratic(u).min(CAP_NATS) + c).max(0.0)
    }

    /// ½ dᵀHd at `u`.
    fn quadratic(&self, u: &[f64]) -> f64 {
        let d: Vec<f64> = u.iter().zip(&self.u0).map(|(a, b)| a - b).collect();
        let k = d.len();
        let mut q = 0.0;
        for i in 0..k {
            for j in 0..k {
                q += d[i] * self.h[(i, j)] * d[j];
            }
        }
        0.5 * q
    }
}

/// The target of BBVI: w with u = σ(z₀ + s ⊙ w).
struct Target {
    emu: Emulated,
    z0: Vec<f64>,
    scale: Vec<f64>,
}

impl Target {
    fn unit(&self, w: &[f64]) -> Vec<f64> {
        w.iter().zip(&self.z0).zip(&self.scale).map(|((w, z), s)| sigmoid(z + s * w)).collect()
    }
}

impl LogDensity for Target {
    fn dim(&self) -> usize {
        self.z0.len()
    }

    fn log_density(&self, w: &[f64]) -> f64 {
        let u = self.unit(w);
        // Uniform prior on the cube; log |du/dz| = Σ log u(1−u).
        let jac: f64 = u.iter().map(|u| (u * (1.0 - u)).max(1e-300).ln()).sum();
        -self.emu.excess(&u) + jac
    }
}

fn sigmoid(z: f64) -> f64 {
    1.0 / (1.0 + (-z).exp())
}

fn logit(u: f64) -> f64 {
    let u = u.clamp(EDGE, 1.0 - EDGE);
    (u / (1.0 - u)).ln()
}

/// The variational posterior of `cal` under channel weights `n_eff`.
pub fn variational_posterior(
    cal: &Calibration,
    n_eff: &[f64],
    seed: u64,
) -> Result<VariationalPosterior, String> {
    let best = cal.best(n_eff).ok_or("no FE evaluation succeeded")?;
    let h = cal
        .gauss_newton
        .clone()
        .ok_or("the calibration ended without a Gauss–Newton matrix at its estimate")?;
    let u0 = cal.points[best].u.clone();
    let f = cal.objective(n_eff);
    let f0 = f[best];
    let (correction, used) = gp_correction(cal, &f, f0, &u0, &h);
    let sd = gn_sd(&h);
    let z0: Vec<f64> = u0.iter().map(|u| logit(*u)).collect();
    let scale: Vec<f64> = u0
        .iter()
        .zip(&sd)
        .map(|(u, s)| {
            let u = u.clamp(EDGE, 1.0 - EDGE);
            (s / (u * (1.0 - u))).clamp(1e-6, 10.0)
        })
        .collect();
    let target = Target { emu: Emulated { u0, h, correction }, z0, scale };
    let settings = BbviSettings {
        samples: 32,
        max_iters: 3000,
        window: 200,
        init_sd: 1.0,
        ..BbviSettings::reparam(FamilyKind::FullRank, seed)
    };
    let d = target.dim();
    let fit =
        Bbvi::new(&target, settings).run(&vec![0.0; d], &mut []).map_err(|e| e.to_string())?;
    let l = fit.q.cholesky();
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x9e37_79b9);
    let mut draws = vec![Vec::with_capacity(DRAWS); d];
    for _ in 0..DRAWS {
        let u = target.unit(&fit.q.sample(&l, &mut rng).1);
        for (k, p) in cal.priors.iter().enumerate() {
            draws[k].push(p.at(u[k]));
        }
    }
    let mut post = summarise(cal, draws, used, &fit, f0);
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x7f4a_7c15);
    post.probes = std::iter::once(target.unit(fit.q.mean()))
        .chain((1..PROBES).map(|_| target.unit(&fit.q.sample(&l, &mut rng).1)))
        .collect();
    post.probe_excess = post.probes.iter().map(|u| target.emu.excess(u).min(CAP_NATS)).collect();
    Ok(post)
}

/// GP through what the capped quadratic misses of the capped misfit,
/// min(f − f₀, [`CAP_NATS`]) − min(½ dᵀHd, [`CAP_NATS`]), at every
/// distinct evaluated point where either is below the cap (elsewhere it
/// misses nothing) (None when too few).
fn gp_correction(
    cal: &Calibration,
    f: &[f64],
    f0: f64,
    u0: &[f64],
    h: &DMatrix<f64>,
) -> (Option<Correction>, usize) {
    let k = u0.len();
    let quad = Emulated { u0: u0.to_vec(), h: h.clone(), correction: None };
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for (p, v) in cal.points.iter().zip(f) {
        let q = quad.quadratic(&p.u);
        let informative = v - f0 < CAP_NATS || q < CAP_NATS;
        if v.is_finite() && informative && !x.chunks(k).any(|o: &[f64]| o == p.u.as_slice()) {
            x.extend_from_slice(&p.u);
            y.push((v - f0).min(CAP_NATS) - q.min(CAP_NATS));
        }
    }
    if y.len() < k + 3 {
        return (None, 0);
    }
    let low = y.iter().copied().fold(f64::INFINITY, f64::min);
    let high = y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    match unit_cube_gp(&x, k, &y) {
        Some(gp) => {
            let mut c = Correction { gp, low, high, at_estimate: 0.0 };
            c.at_estimate = c.raw(u0);
            (Some(c), y.len())
        }
        None => (None, 0),
    }
}

fn summarise(
    cal: &Calibration,
    draws: Vec<Vec<f64>>,
    used: usize,
    fit: &stats::bbvi::BbviFit,
    best_neg_log_lik: f64,
) -> VariationalPosterior {
    let n = DRAWS as f64;
    let mean: Vec<f64> = draws.iter().map(|d| d.iter().sum::<f64>() / n).collect();
    let sd = draws
        .iter()
        .zip(&mean)
        .map(|(d, m)| (d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt())
        .collect();
    let quantile = |d: &[f64], p: f64| {
        let mut s = d.to_vec();
        s.sort_by(f64::total_cmp);
        s[((p * (s.len() - 1) as f64).round() as usize).min(s.len() - 1)]
    };
    VariationalPosterior {
        names: cal.priors.iter().map(|p| p.name.to_string()).collect(),
        units: cal.priors.iter().map(|p| p.unit.to_string()).collect(),
        mean,
        sd,
        q025: draws.iter().map(|d| quantile(d, 0.025)).collect(),
        q975: draws.iter().map(|d| quantile(d, 0.975)).collect(),
        draws,
        emulator_points: used,
        iterations: fit.iterations,
        converged: fit.converged,
        rel_change: fit.rel_change,
        elbo: fit.elbo,
        best_neg_log_lik,
        probes: Vec::new(),
        probe_excess: Vec::new(),
        check: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::calibrate::Point;
    use crate::diagnose::cause::{Cause, Prior};
    use crate::diagnose::fit::ChannelFit;

    const PRIORS: [Prior; 2] = [
        Prior { name: "a", unit: "-", low: 0.0, high: 1.0, log: false, reference: None },
        Prior { name: "b", unit: "-", low: 0.0, high: 1.0, log: false, reference: None },
    ];

    /// A calibration whose −log L (one channel, n_eff 2: −log L = log SSR)
    /// is `nll`, evaluated at `us`, with Gauss–Newton matrix `h`.
    fn calibration(nll: &dyn Fn(&[f64]) -> f64, us: &[Vec<f64>], h: DMatrix<f64>) -> Calibration {
        let point = |u: &Vec<f64>| Point {
            u: u.clone(),
            fit: Ok(vec![ChannelFit::with_neg_log_lik(nll(u))]),
            coarse: 0.0,
            modal: None,
        };
        Calibration {
            cause: Cause::NONE,
            priors: PRIORS.to_vec(),
            free: vec![0, 1],
            points: us.iter().map(point).collect(),
            demand: None,
            gauss_newton: Some(h),
            committed_share: 0.0,
        }
    }

    fn around(c: &[f64], r: f64) -> Vec<Vec<f64>> {
        let design = crate::design::draw(crate::study::DesignMethod::MaximinLhs, 30, 2, 3);
        let mut us = vec![c.to_vec()];
        us.extend(
            (0..design.n()).map(|i| {
                design.row(i).iter().zip(c).map(|(x, c)| c + r * (2.0 * x - 1.0)).collect()
            }),
        );
        us
    }

    /// A Gaussian likelihood well inside the box: the posterior is that
    /// Gaussian (mean c, covariance A⁻¹), and the GP correction to the
    /// exact quadratic is null.
    #[test]
    fn gaussian_likelihood_gives_its_own_mean_and_spread() {
        let c = [0.4, 0.6];
        let a = DMatrix::from_row_slice(2, 2, &[4e4, 1e4, 1e4, 2e4]);
        let nll = |u: &[f64]| {
            let d = [u[0] - c[0], u[1] - c[1]];
            -20.0
                + 0.5
                    * (a[(0, 0)] * d[0] * d[0]
                        + 2.0 * a[(0, 1)] * d[0] * d[1]
                        + a[(1, 1)] * d[1] * d[1])
        };
        let cal = calibration(&nll, &around(&c, 0.03), a.clone());
        let post = variational_posterior(&cal, &[2.0], 11).unwrap();
        let cov = a.try_inverse().unwrap();
        for k in 0..2 {
            let sd = cov[(k, k)].sqrt();
            assert!((post.mean[k] - c[k]).abs() < 0.1 * sd, "mean {k}: {:?}", post.mean);
            assert!((post.sd[k] / sd - 1.0).abs() < 0.1, "sd {k}: {} vs {sd}", post.sd[k]);
            let half = 1.959_964 * sd;
            assert!((post.q975[k] - post.q025[k] - 2.0 * half).abs() < 0.15 * 2.0 * half);
        }
        assert!(post.emulator_points >= 5);
    }

    /// A likelihood whose optimum sits on a bound (a half-Gaussian of sd
    /// 0.01 in u₀): every draw stays in the prior box, and the posterior
    /// keeps the half-Gaussian's scale. Near the bound a Gaussian on the
    /// logit is a log-normal, which KL(q‖p) makes narrower than the
    /// half-Gaussian, hence the bands: mean within 0.4–1.5 of sd·√(2/π),
    /// 97.5 % quantile below 1.5 × the half-Gaussian's (2.24 sd).
    #[test]
    fn optimum_on_a_bound_keeps_the_posterior_in_the_box() {
        let c = [0.0, 0.5];
        let a = DMatrix::from_row_slice(2, 2, &[1e4, 0.0, 0.0, 1e4]);
        let nll = |u: &[f64]| 0.5 * 1e4 * ((u[0] - c[0]).powi(2) + (u[1] - c[1]).powi(2));
        let us: Vec<Vec<f64>> =
            around(&[0.02, 0.5], 0.02).into_iter().chain([c.to_vec()]).collect();
        let cal = calibration(&nll, &us, a);
        let post = variational_posterior(&cal, &[2.0], 5).unwrap();
        assert!(post.draws[0].iter().all(|v| (0.0..=1.0).contains(v)));
        let half_mean = 0.01 * (2.0 / std::f64::consts::PI).sqrt();
        let r = post.mean[0] / half_mean;
        assert!((0.4..1.5).contains(&r), "mean {:?}: {r} of the half-Gaussian's", post.mean);
        assert!(post.q975[0] < 1.5 * 2.24 * 0.01, "97.5 %: {}", post.q975[0]);
        assert!((post.mean[1] - 0.5).abs() < 0.002, "free coordinate: {}", post.mean[1]);
    }

    /// A likelihood that stops growing 40 nats above its optimum (a model
    /// that no longer changes far from it), evaluated near the optimum and
    /// on a ring far out: the GP through what the quadratic (capped at 100)
    /// misses learns −60 on the ring and bends below the best between; the
    /// posterior must stay the Gaussian at the optimum, and no probe may be
    /// emulated below the best FE point.
    #[test]
    fn a_saturating_likelihood_gives_no_mode_between_its_points() {
        let c = [0.5, 0.5];
        let a = DMatrix::from_row_slice(2, 2, &[2e4, 0.0, 0.0, 2e4]);
        let quad = |u: &[f64]| 0.5 * 2e4 * ((u[0] - c[0]).powi(2) + (u[1] - c[1]).powi(2));
        let nll = |u: &[f64]| quad(u).min(40.0);
        let mut us = around(&c, 0.02);
        for k in 0..16 {
            let t = k as f64 * std::f64::consts::PI / 8.0;
            us.push(vec![c[0] + 0.35 * t.cos(), c[1] + 0.35 * t.sin()]);
            us.push(vec![c[0] + 0.2 * t.cos(), c[1] + 0.2 * t.sin()]);
        }
        let cal = calibration(&nll, &us, a);
        let post = variational_posterior(&cal, &[2.0], 7).unwrap();
        let sd = (1.0 / 2e4_f64).sqrt();
        for ((m, s), c) in post.mean.iter().zip(&post.sd).zip(c) {
            assert!((m - c).abs() < 0.5 * sd, "mean {:?} (sd {sd})", post.mean);
            assert!(*s < 2.0 * sd, "sd {:?} vs {sd}", post.sd);
        }
        assert_eq!(post.probes.len(), PROBES);
        assert!(post.probe_excess.iter().all(|e| *e >= 0.0), "{:?}", post.probe_excess);
        let f = cal.objective(&[2.0]);
        let f0 = f.iter().copied().fold(f64::INFINITY, f64::min);
        let h = cal.gauss_newton.clone().unwrap();
        let (correction, _) = gp_correction(&cal, &f, f0, &c, &h);
        let correction = correction.expect("enough points for a GP");
        let (low, high) = (correction.low, correction.high);
        let shift = correction.at_estimate;
        assert!(low < -50.0 && high < 1.0, "targets {low} to {high}");
        let emu = Emulated { u0: c.to_vec(), h, correction: Some(correction) };
        for i in 0..=40 {
            for j in 0..=40 {
                let u = [i as f64 / 40.0, j as f64 / 40.0];
                let g = emu.correction.as_ref().unwrap().at(&u) + shift;
                assert!((low..=high.max(0.0)).contains(&g), "correction {g} at {u:?}");
                assert!(emu.excess(&u) >= 0.0, "excess {} at {u:?}", emu.excess(&u));
            }
        }
    }

    /// A likelihood with a cliff 0.02 below the optimum in u₀ (a
    /// connection driven past its backbone's peak: 500 nats more) and flat
    /// on that side up to it, under a Gauss–Newton matrix ten times too weak
    /// in u₀ (sd 0.03): the evaluations beyond the cliff keep the posterior
    /// on the near side of it.
    #[test]
    fn evaluations_past_a_cliff_keep_the_posterior_off_it() {
        let c = [0.5, 0.5];
        let edge = c[0] - 0.02;
        let nll = |u: &[f64]| {
            let right = (u[0] - c[0]).max(0.0);
            let cliff = if u[0] < edge { 500.0 } else { 0.0 };
            0.5 * 1e4 * (right * right + (u[1] - c[1]).powi(2)) + cliff
        };
        let a = DMatrix::from_row_slice(2, 2, &[1e3, 0.0, 0.0, 1e4]);
        let cal = calibration(&nll, &around(&c, 0.06), a);
        let post = variational_posterior(&cal, &[2.0], 3).unwrap();
        let beyond = post.draws[0].iter().filter(|v| **v < edge - 0.005).count();
        assert!(
            beyond < post.draws[0].len() / 50,
            "{beyond} draws past the cliff: {:?}",
            post.mean
        );
        assert!(post.q025[0] > edge - 0.005, "2.5 %: {} (cliff at {edge})", post.q025[0]);
    }
}
