//! The evidence against exact answers: closed-form linear-Gaussian
//! problems and a bimodal likelihood integrated by quadrature.

use super::*;
use crate::calibration::UniformBox;
use nalgebra::{DMatrix, DVector};
use std::convert::Infallible;

/// y = G θ + ε, θ ~ N(m0, S0), ε ~ N(0, σ² I): the evidence is N(y; G m0, G S0 Gᵀ + σ² I).
struct LinearGaussian {
    g: DMatrix<f64>,
    y: DVector<f64>,
    sigma: f64,
    prior: GaussianPrior,
    exact_ln_z: f64,
}

fn ln_normal(r: &DVector<f64>, cov: &DMatrix<f64>) -> f64 {
    let ch = cov.clone().cholesky().unwrap();
    let z = ch.l().solve_lower_triangular(r).unwrap();
    let ln_det: f64 = 2.0 * (0..r.len()).map(|i| ch.l()[(i, i)].ln()).sum::<f64>();
    -0.5 * (r.len() as f64 * (2.0 * std::f64::consts::PI).ln() + ln_det + z.norm_squared())
}

fn linear_gaussian(d: usize, n: usize, sigma: f64, prior_sd: f64) -> LinearGaussian {
    // a fixed, well-conditioned design and data (no randomness in the problem)
    let g =
        DMatrix::from_fn(n, d, |i, j| ((i + 1) as f64 * 0.37 + (j + 1) as f64 * 1.13).sin() * 2.0);
    let theta = DVector::from_fn(d, |j, _| 0.5 - 0.3 * j as f64);
    let y = &g * &theta + DVector::from_fn(n, |i, _| sigma * ((i as f64) * 2.1).cos());
    let m0 = vec![0.2; d];
    let s0 = DMatrix::from_fn(d, d, |i, j| prior_sd * prior_sd * if i == j { 1.0 } else { 0.3 });
    let cov = &g * &s0 * g.transpose() + DMatrix::identity(n, n) * sigma * sigma;
    let exact_ln_z = ln_normal(&(&y - &g * DVector::from_vec(m0.clone())), &cov);
    LinearGaussian { prior: GaussianPrior::new(m0, s0).unwrap(), g, y, sigma, exact_ln_z }
}

impl LinearGaussian {
    fn ln_l(&self, x: &[Vec<f64>]) -> Result<Vec<f64>, Infallible> {
        let n = self.y.len() as f64;
        Ok(x.iter()
            .map(|t| {
                let r = &self.y - &self.g * DVector::from_column_slice(t);
                -0.5 * r.norm_squared() / (self.sigma * self.sigma)
                    - n * (self.sigma.ln() + 0.5 * (2.0 * std::f64::consts::PI).ln())
            })
            .collect())
    }
}

fn run(opts: SmcOptions, p: &LinearGaussian) -> SmcRun {
    TemperedSmc::new(opts).run(&p.prior, &mut |x: &[Vec<f64>]| p.ln_l(x)).unwrap()
}

#[test]
fn linear_gaussian_evidence_within_half_a_nat() {
    for (d, n, sigma, prior_sd) in [(1, 5, 0.3, 1.0), (3, 12, 0.1, 2.0), (6, 30, 0.05, 3.0)] {
        let p = linear_gaussian(d, n, sigma, prior_sd);
        let r = run(SmcOptions { seed: 11, ..SmcOptions::default() }, &p);
        let err = r.ln_evidence - p.exact_ln_z;
        eprintln!("linear-Gaussian d={d}: error {err:.4} nat, claimed sd {:.4}, {} stages, {} evaluations", r.ln_evidence_sd, r.stages.len(), r.evaluations);
        assert!(
            err.abs() < 0.5,
            "d={d}: ln Z {} vs exact {} (sd {})",
            r.ln_evidence,
            p.exact_ln_z,
            r.ln_evidence_sd
        );
        assert!(
            err.abs() < 4.0 * r.ln_evidence_sd + 0.05,
            "d={d}: error {err} vs its sd {}",
            r.ln_evidence_sd
        );
        assert!(r.stages.len() > 2, "d={d}: a posterior this sharp needs several stages");
    }
}

#[test]
fn the_error_estimate_matches_the_spread_of_replicates() {
    let p = linear_gaussian(3, 12, 0.1, 2.0);
    let runs: Vec<SmcRun> = (0..24)
        .map(|s| {
            run(
                SmcOptions {
                    particles: 300,
                    mcmc_steps: 5,
                    seed: 100 + s,
                    ..SmcOptions::default()
                },
                &p,
            )
        })
        .collect();
    let z: Vec<f64> = runs.iter().map(|r| r.ln_evidence).collect();
    let mean = z.iter().sum::<f64>() / z.len() as f64;
    let spread = (z.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (z.len() - 1) as f64).sqrt();
    let claimed = runs.iter().map(|r| r.ln_evidence_sd).sum::<f64>() / runs.len() as f64;
    eprintln!(
        "24 replicates: sd {spread:.4}, claimed {claimed:.4}, mean error {:.4}",
        mean - p.exact_ln_z
    );
    assert!(
        claimed > 0.5 * spread && claimed < 2.0 * spread,
        "claimed sd {claimed:.4} vs replicates' sd {spread:.4}"
    );
    assert!(
        (mean - p.exact_ln_z).abs() < 3.0 * spread / (z.len() as f64).sqrt() + 0.02,
        "mean {mean} vs {}",
        p.exact_ln_z
    );
}

/// Two needles in a 10 x 10 box, of masses 1 and 0.5.
fn bimodal(width: f64) -> impl Fn(&[f64]) -> f64 {
    move |t: &[f64]| {
        let g = |a: f64, b: f64| {
            (-((t[0] - a).powi(2) + (t[1] - b).powi(2)) / (2.0 * width * width)).exp()
        };
        (g(-2.5, 1.0) + 0.5 * g(3.0, -2.0)).ln()
    }
}

/// ∫∫ L(θ) p(θ) dθ by the trapezoid rule on a grid 8 points per width (the
/// rule converges geometrically on Gaussian bumps: the closed form agrees to 1e-6).
fn quadrature_ln_z(ln_l: &dyn Fn(&[f64]) -> f64, width: f64) -> f64 {
    let h = width / 8.0;
    let m = (10.0 / h).round() as usize;
    let mut total = 0.0;
    for i in 0..=m {
        for j in 0..=m {
            let wgt =
                if i == 0 || i == m { 0.5 } else { 1.0 } * if j == 0 || j == m { 0.5 } else { 1.0 };
            total += wgt * ln_l(&[-5.0 + i as f64 * h, -5.0 + j as f64 * h]).exp();
        }
    }
    (total * h * h / 100.0).ln()
}

#[test]
fn bimodal_evidence_within_half_a_nat_of_quadrature() {
    let prior =
        UniformBox::new(vec!["a".into(), "b".into()], vec![-5.0, -5.0], vec![5.0, 5.0]).unwrap();
    for width in [0.2, 0.03] {
        let f = bimodal(width);
        let exact = quadrature_ln_z(&f, width);
        let closed = (1.5 * 2.0 * std::f64::consts::PI * width * width / 100.0).ln();
        assert!((exact - closed).abs() < 1e-6, "quadrature {exact} vs closed form {closed}");
        let r = TemperedSmc::new(SmcOptions { seed: 5, ..SmcOptions::default() })
            .run(&prior, &mut |x: &[Vec<f64>]| {
                Ok::<_, Infallible>(x.iter().map(|t| f(t)).collect())
            })
            .unwrap();
        let left =
            r.particles.iter().filter(|t| t[0] < 0.0).count() as f64 / r.particles.len() as f64;
        eprintln!("bimodal width {width}: error {:.4} nat, claimed sd {:.4}, heavier share {left:.3}, {} stages", r.ln_evidence - exact, r.ln_evidence_sd, r.stages.len());
        assert!((r.ln_evidence - exact).abs() < 0.5, "width {width}: {} vs {exact}", r.ln_evidence);
        // the posterior keeps both modes in proportion 2 : 1
        assert!((left - 2.0 / 3.0).abs() < 0.08, "width {width}: share of the heavier mode {left}");
    }
}

#[test]
fn stages_report_batches_as_wide_as_the_population() {
    let p = linear_gaussian(2, 6, 0.2, 1.0);
    let r = run(SmcOptions { particles: 200, seed: 3, ..SmcOptions::default() }, &p);
    for s in &r.stages {
        assert!(s.evaluations as f64 / s.batches as f64 > 100.0, "{s:?}");
        assert!(s.ess_fraction >= 0.5 - 1e-6, "{s:?}");
    }
    assert_eq!(r.stages.last().unwrap().beta, 1.0);
}

#[test]
fn bad_likelihoods_and_options_are_named() {
    let p = linear_gaussian(1, 3, 0.3, 1.0);
    let e = TemperedSmc::new(SmcOptions { particles: 50, ..SmcOptions::default() })
        .run(&p.prior, &mut |x: &[Vec<f64>]| Ok::<_, Infallible>(vec![f64::NAN; x.len()]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("log-likelihood NaN"), "{e}");
    let e = TemperedSmc::new(SmcOptions { particles: 1, ..SmcOptions::default() })
        .run(&p.prior, &mut |x: &[Vec<f64>]| p.ln_l(x))
        .unwrap_err()
        .to_string();
    assert!(e.contains("particles = 1"), "{e}");
    let e = TemperedSmc::new(SmcOptions { particles: 50, ..SmcOptions::default() })
        .run(&p.prior, &mut |x: &[Vec<f64>]| Ok::<_, Infallible>(vec![f64::NEG_INFINITY; x.len()]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("zero likelihood"), "{e}");
}

#[test]
fn an_emulator_corrected_by_exact_checks_gives_the_exact_evidence() {
    let p = linear_gaussian(3, 12, 0.1, 2.0);
    // an emulator wrong by a smooth, sizeable bias: 1.5 nat plus a tilt
    let bias = |t: &[f64]| 1.5 + 0.8 * t[0] - 0.5 * t[1];
    let emulated = |x: &[Vec<f64>]| {
        let exact = p.ln_l(x).unwrap();
        Ok::<_, Infallible>(x.iter().zip(exact).map(|(t, l)| l + bias(t)).collect())
    };
    let run = TemperedSmc::new(SmcOptions { seed: 21, ..SmcOptions::default() })
        .run(&p.prior, &mut { emulated })
        .unwrap();
    let off = run.ln_evidence - p.exact_ln_z;
    let idx = check_indices(&run, 40);
    assert_eq!(idx.len(), 40);
    let exact: Vec<f64> =
        p.ln_l(&idx.iter().map(|&i| run.particles[i].clone()).collect::<Vec<_>>()).unwrap();
    let c = correct_evidence(&run, &idx, &exact).unwrap();
    let err = c.ln_evidence - p.exact_ln_z;
    eprintln!(
        "emulator off by {off:.3} nat; corrected by 40 exact checks: error {err:.4} nat, sd {:.4}, k-hat {:.2}",
        c.ln_evidence_sd, c.k_hat
    );
    assert!(
        off.abs() > 1.0,
        "the emulator's bias must matter for the test to mean anything: {off}"
    );
    assert!(
        err.abs() < 0.5 && err.abs() < 4.0 * c.ln_evidence_sd + 0.05,
        "{err} (sd {})",
        c.ln_evidence_sd
    );
    assert!(c.k_hat < 0.7, "{}", c.k_hat);
}

#[test]
fn a_correction_without_checks_is_refused() {
    let p = linear_gaussian(1, 3, 0.3, 1.0);
    let run = run(SmcOptions { particles: 50, seed: 2, ..SmcOptions::default() }, &p);
    assert!(correct_evidence(&run, &[], &[]).is_none());
    assert!(correct_evidence(&run, &[0], &[f64::NAN]).is_none());
    assert!(correct_evidence(&run, &[999], &[0.0]).is_none());
}

#[test]
fn a_run_from_base_draws_gives_the_evidence_under_the_base() {
    // Base N(0, I₂), likelihood N(y; x, σ² I): Z = N(y; 0, (1 + σ²) I).
    // Exact base draws, a likelihood 10 times narrower than the base.
    let (sigma, y) = (0.1, [1.0, -0.5]);
    let ln_n = |r2: f64, var: f64| -0.5 * r2 / var - (2.0 * std::f64::consts::PI * var).ln();
    let ln_l = |x: &[f64]| {
        let r2: f64 = x.iter().zip(&y).map(|(a, b)| (a - b).powi(2)).sum();
        ln_n(r2, sigma * sigma)
    };
    let exact = ln_n(y.iter().map(|v| v * v).sum(), 1.0 + sigma * sigma);
    let base = GaussianPrior::new(vec![0.0; 2], DMatrix::identity(2, 2)).unwrap();
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(7);
    let x: Vec<Vec<f64>> = (0..2000).map(|_| base.sample(&mut rng)).collect();
    let start = Start { ln_l: x.iter().map(|v| ln_l(v)).collect(), x, ln_z: 0.0 };
    let smc = TemperedSmc::new(SmcOptions { seed: 3, ..SmcOptions::default() });
    let mut batch = |xs: &[Vec<f64>]| Ok::<_, Infallible>(xs.iter().map(|v| ln_l(v)).collect());
    let run = smc.run_from(start.clone(), &|v| base.ln_density(v), &mut batch).unwrap();
    let err = run.ln_evidence - exact;
    assert!(
        err.abs() < 0.2,
        "ln Z {} vs {exact}: {err:+.3} (sd {})",
        run.ln_evidence,
        run.ln_evidence_sd
    );
    // The base's normaliser carries through.
    let shifted = Start { ln_z: 2.5, ..start };
    let run2 = smc.run_from(shifted, &|v| base.ln_density(v) + 2.5, &mut batch).unwrap();
    assert!((run2.ln_evidence - run.ln_evidence - 2.5).abs() < 1e-9);
    // A population and likelihoods of different lengths are refused.
    let bad = Start { x: vec![vec![0.0, 0.0]; 3], ln_l: vec![0.0; 2], ln_z: 0.0 };
    assert!(matches!(
        smc.run_from(bad, &|v| base.ln_density(v), &mut batch),
        Err(SmcError::BatchSize { asked: 3, got: 2 })
    ));
}

#[test]
fn a_run_stopped_short_bounds_the_evidence_below_by_its_tangent_and_above_by_its_best() {
    // Base N(0, 1), L = exp(−x²/2σ²): Z(β) = (1 + β/σ²)^(−1/2), so
    // ln Z(β) = −½ ln(1 + β/σ²) and its slope −1/(2(σ² + β)).
    let sigma2: f64 = 1e-4;
    let ln_z = |b: f64| -0.5 * (1.0 + b / sigma2).ln();
    let slope = |b: f64| -0.5 / (sigma2 + b);
    let exact = ln_z(1.0);
    let base = GaussianPrior::new(vec![0.0], DMatrix::identity(1, 1)).unwrap();
    let ln_l = |x: &[f64]| -0.5 * x[0] * x[0] / sigma2;
    let mut batch = |xs: &[Vec<f64>]| Ok::<_, Infallible>(xs.iter().map(|v| ln_l(v)).collect());
    let mut gaps = Vec::new();
    for (stages, seed) in [(2, 5), (3, 6), (4, 7)] {
        let o = SmcOptions { particles: 2000, max_stages: stages, seed, ..SmcOptions::default() };
        let Err(SmcError::Stages { beta, bounds: Some(b), .. }) =
            TemperedSmc::new(o).run(&base, &mut batch)
        else {
            panic!("{stages} stages should not reach β = 1 on a likelihood 100 times narrower");
        };
        let tangent = ln_z(beta) + (1.0 - beta) * slope(beta);
        assert!(b.sd > 0.0, "{stages} stages: sd {}", b.sd);
        assert!(
            (b.ln_evidence - tangent).abs() < 3.0 * b.sd + 0.05,
            "{stages} stages, β {beta:.4}: bound {:.3} ± {:.3} vs tangent {tangent:.3}",
            b.ln_evidence,
            b.sd
        );
        assert!((b.ln_evidence_at_beta - ln_z(beta)).abs() < 3.0 * b.sd + 0.05, "{b:?}");
        assert!(b.ln_evidence < exact + 2.0 * b.sd, "bound {b:?} above ln Z = {exact:.3}");
        // sup ln L = 0 (at x = 0): the upper bound is ln Z(β) less what the
        // particles miss of the peak, above ln Z(1) as ln Z falls with β.
        assert!(b.ln_evidence_upper > exact - 2.0 * b.upper_sd, "upper {b:?} below {exact:.3}");
        assert!((b.ln_evidence_upper - ln_z(beta)).abs() < 3.0 * b.upper_sd + 0.05, "{b:?}");
        gaps.push((exact - b.ln_evidence, b.ln_evidence_upper - exact));
    }
    // Both bounds tighten as β nears 1 (seen: the lower 82 nat below, then
    // under 1 nat at β 0.28).
    let (below, above): (Vec<f64>, Vec<f64>) = gaps.iter().copied().unzip();
    assert!(below.windows(2).all(|g| g[1] < g[0]) && below[2] < 1.0, "{gaps:?}");
    assert!(above.windows(2).all(|g| g[1] < g[0]), "{gaps:?}");
}
