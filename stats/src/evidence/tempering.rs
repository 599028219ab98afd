//! The next temperature of a tempered sequence: the largest step whose
//! incremental weights keep a target coefficient of variation.

/// Coefficient of variation (sd / mean, population sd) of exp(Δβ · ln_l).
pub fn incremental_weight_cov(ln_l: &[f64], d_beta: f64) -> f64 {
    let m = ln_l.iter().copied().filter(|v| v.is_finite()).fold(f64::NEG_INFINITY, f64::max);
    if !m.is_finite() || ln_l.is_empty() {
        return f64::INFINITY;
    }
    let w: Vec<f64> = ln_l.iter().map(|&l| (d_beta * (l - m)).exp()).collect();
    let n = w.len() as f64;
    let mean = w.iter().sum::<f64>() / n;
    if mean <= 0.0 {
        return f64::INFINITY;
    }
    let var = w.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    var.sqrt() / mean
}

/// The β' in (β, 1] at which the incremental weights' coefficient of variation
/// equals `target_cov` (1 when even β' = 1 stays below it), found by bisection
/// to 1e-12 in β. The weights' effective sample size is then N / (1 + cov²).
pub fn next_temperature(ln_l: &[f64], beta: f64, target_cov: f64) -> f64 {
    if incremental_weight_cov(ln_l, 1.0 - beta) <= target_cov {
        return 1.0;
    }
    let (mut lo, mut hi) = (0.0, 1.0 - beta);
    while hi - lo > 1e-12 {
        let mid = 0.5 * (lo + hi);
        if incremental_weight_cov(ln_l, mid) > target_cov {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    // a step of at least the bisection's resolution, so that the sequence ends
    (beta + lo.max(1e-12)).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn step_meets_the_target(ln_l in prop::collection::vec(-500.0..0.0f64, 20..200), beta in 0.0..0.9f64) {
            let b = next_temperature(&ln_l, beta, 1.0);
            prop_assert!(b > beta && b <= 1.0);
            let cov = incremental_weight_cov(&ln_l, b - beta);
            if b < 1.0 {
                prop_assert!((cov - 1.0).abs() < 1e-6, "cov {cov} at beta {b}");
            } else {
                prop_assert!(cov <= 1.0 + 1e-9);
            }
        }

        #[test]
        fn cov_grows_with_the_step(ln_l in prop::collection::vec(-50.0..0.0f64, 5..50), a in 0.0..1.0f64, b in 0.0..1.0f64) {
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            prop_assert!(incremental_weight_cov(&ln_l, lo) <= incremental_weight_cov(&ln_l, hi) + 1e-12);
        }
    }

    #[test]
    fn flat_likelihood_goes_straight_to_one() {
        assert_eq!(next_temperature(&[-3.0; 10], 0.0, 1.0), 1.0);
    }

    #[test]
    fn zero_likelihoods_do_not_count_as_weight() {
        let mut l = vec![f64::NEG_INFINITY; 10];
        l[0] = 0.0;
        l[1] = -1.0;
        let b = next_temperature(&l, 0.0, 1.0);
        assert!(b > 0.0 && b <= 1.0);
    }
}
