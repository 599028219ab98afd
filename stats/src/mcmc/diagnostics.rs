//! Convergence diagnostics of several chains (BDA3 §11.4–11.5):
//! split R-hat and the effective sample size with Geyer's initial monotone
//! sequence over the multi-chain autocorrelation.

/// (mean, unbiased variance) of `x`.
fn mean_var(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    (m, x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0))
}

/// (W, var+) of equal-length chains: within-chain variance and the pooled estimate.
fn within_and_pooled(chains: &[&[f64]]) -> (f64, f64) {
    let m = chains.len() as f64;
    let n = chains[0].len() as f64;
    let stats: Vec<(f64, f64)> = chains.iter().map(|c| mean_var(c)).collect();
    let grand = stats.iter().map(|s| s.0).sum::<f64>() / m;
    let b = n / (m - 1.0) * stats.iter().map(|s| (s.0 - grand).powi(2)).sum::<f64>();
    let w = stats.iter().map(|s| s.1).sum::<f64>() / m;
    (w, (n - 1.0) / n * w + b / n)
}

/// Split R-hat of one coordinate over chains (each split in half).
pub fn split_rhat(chains: &[Vec<f64>]) -> f64 {
    let n = chains.iter().map(Vec::len).min().unwrap_or(0) / 2;
    if n < 2 {
        return f64::NAN;
    }
    let halves: Vec<&[f64]> = chains.iter().flat_map(|c| [&c[..n], &c[n..2 * n]]).collect();
    let (w, var_plus) = within_and_pooled(&halves);
    (var_plus / w).sqrt()
}

/// Autocovariance of `x` at lag `t` (divided by n).
fn autocov(x: &[f64], mean: f64, t: usize) -> f64 {
    let n = x.len();
    (0..n - t).map(|i| (x[i] - mean) * (x[i + t] - mean)).sum::<f64>() / n as f64
}

/// Effective sample size of one coordinate over chains.
pub fn ess(chains: &[Vec<f64>]) -> f64 {
    let n = chains.iter().map(Vec::len).min().unwrap_or(0);
    let m = chains.len();
    if n < 4 || m < 1 {
        return f64::NAN;
    }
    let cs: Vec<&[f64]> = chains.iter().map(|c| &c[..n]).collect();
    let (w, var_plus) =
        if m > 1 { within_and_pooled(&cs) } else { (mean_var(cs[0]).1, mean_var(cs[0]).1) };
    let means: Vec<f64> = cs.iter().map(|c| mean_var(c).0).collect();
    let rho = |t: usize| {
        let acov = cs.iter().zip(&means).map(|(c, mu)| autocov(c, *mu, t)).sum::<f64>() / m as f64;
        1.0 - (w - acov) / var_plus
    };
    let (mut tau, mut prev_pair, mut t) = (-1.0, f64::INFINITY, 0);
    while t + 1 < n {
        let pair = (rho(t) + rho(t + 1)).min(prev_pair);
        if pair <= 0.0 {
            break;
        }
        tau += 2.0 * pair;
        prev_pair = pair;
        t += 2;
    }
    (m * n) as f64 / tau.max(1.0 / ((m * n) as f64).ln().max(1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn ar1(phi: f64, n: usize, seed: u64, shift: f64) -> Vec<f64> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut x = 0.0;
        (0..n)
            .map(|_| {
                x = phi * x + rng.sample::<f64, _>(rand_distr::StandardNormal);
                x + shift
            })
            .collect()
    }

    #[test]
    fn ar1_ess_matches_theory() {
        // ESS of AR(1) is N (1 − phi) / (1 + phi).
        let chains: Vec<Vec<f64>> = (0..4).map(|s| ar1(0.5, 20_000, s, 0.0)).collect();
        let e = ess(&chains);
        let expected = 80_000.0 / 3.0;
        assert!((e / expected - 1.0).abs() < 0.1, "{e} vs {expected}");
        assert!(split_rhat(&chains) < 1.01);
    }

    #[test]
    fn shifted_chain_raises_rhat() {
        let mut chains: Vec<Vec<f64>> = (0..4).map(|s| ar1(0.5, 2000, s, 0.0)).collect();
        chains[3] = ar1(0.5, 2000, 9, 2.0);
        assert!(split_rhat(&chains) > 1.1);
    }
}
