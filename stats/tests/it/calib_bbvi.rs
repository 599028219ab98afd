//! BBVI on the oscillator calibration benchmark (shared benchmarks §3):
//! full-rank reaches every exact posterior mean within 0.2 sd and every sd
//! within 10 %, with the k–m correlation; mean-field is reported.

use crate::calib_common::*;
use stats::bbvi::{Bbvi, BbviFit, BbviSettings, FamilyKind};
use stats::calibration::{Likelihood, LogDensity, Posterior, PosteriorSummary};

/// Physical-unit summary of 20 000 draws from the fitted q.
fn summarise<L: Likelihood>(post: &Posterior<L>, fit: &BbviFit) -> PosteriorSummary {
    use rand::SeedableRng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(99);
    let l = fit.q.cholesky();
    let draws: Vec<Vec<f64>> =
        (0..20_000).map(|_| post.to_physical(&fit.q.sample(&l, &mut rng).1)).collect();
    PosteriorSummary::from_draws(&post.prior().names, &draws)
}

fn fit<T: LogDensity>(post: &T, family: FamilyKind, seed: u64) -> BbviFit {
    let t = std::time::Instant::now();
    let fit = Bbvi::new(post, BbviSettings::reparam(family, seed)).run(&[0.0; 3], &mut []).unwrap();
    println!(
        "{family:?}: {} iterations, converged {}, ELBO {:.3}, {:.3} s",
        fit.iterations,
        fit.converged,
        fit.elbo,
        t.elapsed().as_secs_f64()
    );
    fit
}

fn report(label: &str, s: &PosteriorSummary, e: &Exact) {
    for j in 0..3 {
        let m = &s.marginals[j];
        println!(
            "{label} {}: {:.4} ± {:.4} (exact {:.4} ± {:.4}; mean off {:.2} sd, sd ratio {:.3})",
            s.names[j],
            m.mean,
            m.sd,
            e.mean[j],
            e.sd[j],
            (m.mean - e.mean[j]) / e.sd[j],
            m.sd / e.sd[j]
        );
    }
    println!(
        "{label} corr(k,m) {:.4} (exact {:.4}), corr(k,c) {:.4} (exact {:.4})",
        s.correlation[(0, 2)],
        e.corr[0][2],
        s.correlation[(0, 1)],
        e.corr[0][1]
    );
}

fn assert_close(label: &str, s: &PosteriorSummary, e: &Exact) {
    for j in 0..3 {
        let m = &s.marginals[j];
        assert!(
            (m.mean - e.mean[j]).abs() < 0.2 * e.sd[j],
            "{label} {} mean {} vs {}",
            s.names[j],
            m.mean,
            e.mean[j]
        );
        assert!(
            (m.sd / e.sd[j] - 1.0).abs() < 0.1,
            "{label} {} sd {} vs {}",
            s.names[j],
            m.sd,
            e.sd[j]
        );
    }
    assert!(
        (s.correlation[(0, 2)] - e.corr[0][2]).abs() < 0.05,
        "{label} corr(k,m) {} vs {}",
        s.correlation[(0, 2)],
        e.corr[0][2]
    );
}

#[test]
fn full_rank_matches_exact_posterior_without_discrepancy() {
    let post = plain_posterior("calib_nodisc.csv");
    let exact = quadrature(post.likelihood(), [1.1924, 0.3023, 1.0073], [0.25, 0.06, 0.22], 64);
    let s = summarise(&post, &fit(&post, FamilyKind::FullRank, 1));
    report("full-rank", &s, &exact);
    assert_close("full-rank", &s, &exact);
    let mf = summarise(&post, &fit(&post, FamilyKind::MeanField, 1));
    report("mean-field", &mf, &exact);
}

#[test]
fn full_rank_matches_exact_posterior_with_discrepancy() {
    let post = koh_posterior("calib_disc.csv");
    let exact = quadrature(post.likelihood(), [1.1378, 0.2969, 0.9601], [0.55, 0.09, 0.48], 64);
    let s = summarise(&post, &fit(&post, FamilyKind::FullRank, 2));
    report("KOH full-rank", &s, &exact);
    assert_close("KOH full-rank", &s, &exact);
}

#[test]
fn ignoring_discrepancy_is_confidently_wrong() {
    let post = plain_posterior("calib_disc.csv");
    let exact = quadrature(post.likelihood(), [1.1345, 0.30, 1.0], [0.25, 0.06, 0.22], 64);
    let s = summarise(&post, &fit(&post, FamilyKind::FullRank, 3));
    report("no-discrepancy model on disc data", &s, &exact);
    assert_close("ignored", &s, &exact);
    // Benchmark: k ≈ 1.1345 ± 0.0299, narrower than the KOH answer 1.1378 ± 0.0756.
    let k = &s.marginals[0];
    assert!((k.mean - 1.1345).abs() < 0.2 * 0.0299 && (k.sd / 0.0299 - 1.0).abs() < 0.1, "{k:?}");
    assert!(k.sd < 0.5 * 0.0756);
}

/// The seed's estimator (score function, control variates; Algorithm 6.2)
/// with a full-rank family meets the same tolerances; the mean-field
/// Rao–Blackwellised variant is reported.
#[test]
fn score_function_estimator_matches_exact_posterior() {
    let post = plain_posterior("calib_nodisc.csv");
    let exact = quadrature(post.likelihood(), [1.1924, 0.3023, 1.0073], [0.25, 0.06, 0.22], 64);
    for family in [FamilyKind::FullRank, FamilyKind::MeanField] {
        let t = std::time::Instant::now();
        let fit = Bbvi::new(&post, BbviSettings::score(family, 4)).run(&[0.0; 3], &mut []).unwrap();
        println!(
            "score {family:?}: {} iterations, converged {}, {:.3} s",
            fit.iterations,
            fit.converged,
            t.elapsed().as_secs_f64()
        );
        let s = summarise(&post, &fit);
        report(&format!("score {family:?}"), &s, &exact);
        if family == FamilyKind::FullRank {
            assert_close("score full-rank", &s, &exact);
        }
    }
}
