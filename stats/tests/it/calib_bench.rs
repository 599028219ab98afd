//! Benchmark (run by `scripts/bench/calibration`, release build): wall time
//! and exact-posterior error of full-rank BBVI and of the adaptive
//! Metropolis reference on the no-discrepancy oscillator problem (shared
//! benchmarks §3). Error: KL(fit ‖ exact) between Gaussians with the fit's
//! and the exact (grid quadrature) moments in physical units.

use crate::calib_common::*;
use nalgebra::{DMatrix, DVector};
use stats::bbvi::{Bbvi, BbviSettings, FamilyKind};
use stats::calibration::{Likelihood, Posterior};
use stats::mcmc::{AdaptiveMetropolis, McmcSettings};

/// Mean and covariance of draws (n, 3).
fn moments(draws: &[Vec<f64>]) -> (DVector<f64>, DMatrix<f64>) {
    let n = draws.len() as f64;
    let mu = DVector::from_fn(3, |j, _| draws.iter().map(|x| x[j]).sum::<f64>() / n);
    let cov = DMatrix::from_fn(3, 3, |a, b| {
        draws.iter().map(|x| (x[a] - mu[a]) * (x[b] - mu[b])).sum::<f64>() / (n - 1.0)
    });
    (mu, cov)
}

/// KL(N(m0, s0) ‖ N(m1, s1)).
fn kl_gauss(m0: &DVector<f64>, s0: &DMatrix<f64>, m1: &DVector<f64>, s1: &DMatrix<f64>) -> f64 {
    let inv = s1.clone().try_inverse().unwrap();
    let d = m1 - m0;
    0.5 * ((&inv * s0).trace() + (d.transpose() * &inv * &d)[0] - 3.0
        + (s1.determinant() / s0.determinant()).ln())
}

fn exact_gaussian(e: &Exact) -> (DVector<f64>, DMatrix<f64>) {
    (
        DVector::from_row_slice(&e.mean),
        DMatrix::from_fn(3, 3, |a, b| e.corr[a][b] * e.sd[a] * e.sd[b]),
    )
}

fn draws_of_q<L: Likelihood>(post: &Posterior<L>, q: &stats::bbvi::GaussianQ) -> Vec<Vec<f64>> {
    use rand::SeedableRng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(123);
    let l = q.cholesky();
    (0..20_000).map(|_| post.to_physical(&q.sample(&l, &mut rng).1)).collect()
}

#[test]
#[ignore = "benchmark: run by scripts/bench/calibration in release"]
fn bench_calibration() {
    let post = plain_posterior("calib_nodisc.csv");
    let exact = quadrature(post.likelihood(), [1.1924, 0.3023, 1.0073], [0.25, 0.06, 0.22], 96);
    let (m1, s1) = exact_gaussian(&exact);
    println!("\nmethod,budget,iterations,wall_s,kl,k_mean,k_sd,c_mean,c_sd,m_mean,m_sd,corr_km");
    let row = |label: &str, budget: usize, iters: usize, wall: f64, draws: &[Vec<f64>]| {
        let (m0, s0) = moments(draws);
        let sd = |j: usize| s0[(j, j)].sqrt();
        println!(
            "{label},{budget},{iters},{wall:.4},{:.5},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.3}",
            kl_gauss(&m0, &s0, &m1, &s1),
            m0[0],
            sd(0),
            m0[1],
            sd(1),
            m0[2],
            sd(2),
            s0[(0, 2)] / (sd(0) * sd(2))
        );
    };
    for budget in [300, 500, 1000, 2000, 5000] {
        for (label, settings) in [
            (
                "bbvi-fullrank",
                BbviSettings {
                    max_iters: budget,
                    ..BbviSettings::reparam(FamilyKind::FullRank, 1)
                },
            ),
            (
                "bbvi-meanfield",
                BbviSettings {
                    max_iters: budget,
                    ..BbviSettings::reparam(FamilyKind::MeanField, 1)
                },
            ),
        ] {
            let t = std::time::Instant::now();
            let fit = Bbvi::new(&post, settings).run(&[0.0; 3], &mut []).unwrap();
            let wall = t.elapsed().as_secs_f64();
            row(label, budget, fit.iterations, wall, &draws_of_q(&post, &fit.q));
        }
    }
    for budget in [5000, 20_000] {
        let s = BbviSettings { max_iters: budget, ..BbviSettings::score(FamilyKind::FullRank, 1) };
        let t = std::time::Instant::now();
        let fit = Bbvi::new(&post, s).run(&[0.0; 3], &mut []).unwrap();
        let wall = t.elapsed().as_secs_f64();
        row("bbvi-score-fullrank", budget, fit.iterations, wall, &draws_of_q(&post, &fit.q));
    }
    for iters in [3000, 6000, 20_000] {
        let s = McmcSettings { iters, warmup: iters / 4, ..McmcSettings::default() };
        let t = std::time::Instant::now();
        let run = AdaptiveMetropolis::new(s).run(&post, &[0.0; 3]).unwrap();
        let wall = t.elapsed().as_secs_f64();
        let draws: Vec<Vec<f64>> = run.draws().iter().map(|z| post.to_physical(z)).collect();
        row("mcmc-am-4chains", iters, iters, wall, &draws);
        println!("#   R-hat {:.4?} ESS {:.0?}", run.rhat, run.ess);
    }
}
