//! Multinomial resampling, the scheme the genealogy variance estimator assumes.

use rand::Rng;

/// N ancestor indices drawn independently with probabilities `weights`
/// (non-negative, not all zero; normalised here), in ascending order.
/// O(N) from sorted uniforms built from exponential spacings.
pub fn multinomial(weights: &[f64], rng: &mut dyn rand::RngCore) -> Vec<usize> {
    let n = weights.len();
    let total: f64 = weights.iter().sum();
    // n + 1 exponential spacings give n sorted uniforms on (0, 1)
    let spacings: Vec<f64> = (0..=n).map(|_| -(1.0 - rng.random::<f64>()).ln()).collect();
    let sum: f64 = spacings.iter().sum();
    let mut out = Vec::with_capacity(n);
    let (mut u, mut cum, mut j) = (0.0, weights.first().copied().unwrap_or(0.0) / total, 0);
    for s in &spacings[..n] {
        u += s / sum;
        while u > cum && j + 1 < n {
            j += 1;
            cum += weights[j] / total;
        }
        out.push(j);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn frequencies_follow_the_weights() {
        let w = [0.1, 0.0, 0.6, 0.3];
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut count = [0usize; 4];
        for _ in 0..200 {
            for a in multinomial(&w, &mut rng) {
                count[a] += 1;
            }
        }
        let n = 800.0;
        assert_eq!(count[1], 0, "a zero weight is never drawn");
        for (k, &c) in count.iter().enumerate() {
            // binomial sd at most sqrt(800 * 0.25) ≈ 14; five sd
            assert!((c as f64 - w[k] * n).abs() < 71.0, "{k}: {c} vs {}", w[k] * n);
        }
    }

    #[test]
    fn indices_are_sorted_and_in_range() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let a = multinomial(&[1.0, 2.0, 3.0, 0.5, 0.0], &mut rng);
        assert_eq!(a.len(), 5);
        assert!(a.windows(2).all(|p| p[0] <= p[1]));
        assert!(a.iter().all(|&i| i < 4));
    }
}
