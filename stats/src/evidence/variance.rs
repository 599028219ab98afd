//! The Monte-Carlo variance of an SMC normalising-constant estimate from a
//! single run, by the particles' genealogy (Lee & Whiteley 2018).

/// Relative variance var(Ẑ) / Z² estimated from the last stage, before its
/// resampling: `eve[i]` is the index, in the first population, of particle
/// i's ancestor; `weights[i]` its last incremental weight (any scale);
/// `resamplings` how many multinomial resamplings preceded the last
/// weighting. It is 1 − (N / (N − 1))^(resamplings + 1) (1 − Σ_k W_k²),
/// W_k the normalised weight of the particles descending from first
/// particle k; with no resampling it is the sample variance of the weights
/// over N, relative. A collapsed genealogy (one ancestor left) gives 1 or
/// more: the run cannot tell its own error.
pub fn relative_variance(eve: &[usize], weights: &[f64], resamplings: usize) -> f64 {
    let n = eve.len();
    if n < 2 {
        return f64::INFINITY;
    }
    let total: f64 = weights.iter().sum();
    let mut by_eve = vec![0.0; n];
    for (&e, &w) in eve.iter().zip(weights) {
        by_eve[e.min(n - 1)] += w / total;
    }
    let concentration: f64 = by_eve.iter().map(|w| w * w).sum();
    let inflation = (n as f64 / (n as f64 - 1.0)).powi(resamplings as i32 + 1);
    1.0 - inflation * (1.0 - concentration)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn importance_sampling_gives_the_sample_variance_over_n() {
        let w = [0.5, 1.5, 2.0, 0.2, 0.8];
        let n = w.len() as f64;
        let mean = w.iter().sum::<f64>() / n;
        let s2 = w.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let eve: Vec<usize> = (0..w.len()).collect();
        let v = relative_variance(&eve, &w, 0);
        assert!((v - s2 / n / (mean * mean)).abs() < 1e-12, "{v}");
    }

    #[test]
    fn a_collapsed_genealogy_says_it_cannot_tell() {
        assert!(relative_variance(&[3; 8], &[1.0; 8], 5) >= 1.0);
    }
}
