//! The sensor-noise floor of a normalised error. A model that reproduced
//! the specimen exactly would still miss every reading by the sensor's
//! noise, so a raw NRMSE cannot reach 0 and a gain computed from it is
//! capped by the sensors, not the model (a 0.5 mm displacement read with
//! 0.05 mm noise never falls below 0.1). The noise variance of a channel
//! is read off its residual r = simulated − measured, which is a smooth
//! model error s (a structure's band-limited response) plus white sensor
//! noise e: the variogram γ(h) = ½ E(r_{t+h} − r_t)² is σ² + var(s)(1 −
//! ρ_s(h)) ≈ σ² + a h² at small lags, and the two-lag extrapolation
//! σ² ≈ (4 γ(1) − γ(2)) / 3 (the nugget) removes the smooth part (a
//! difference-based variance estimator: Gasser, Sroka and
//! Jennen-Steinmetz, Biometrika 1986; Hall, Kay and Titterington,
//! Biometrika 1990). Model error near the Nyquist frequency is partly taken
//! for noise, so the estimate is an upper bound in practice; the smallest
//! one over the candidate models of a channel is the one used.

/// Nugget estimate of the white-noise variance in a residual series
/// (missing readings as non-finite values, pairs across them skipped);
/// between 0 and the mean square of the series. None with fewer than
/// three pairs at lag 2.
pub fn nugget_variance(r: &[f64]) -> Option<f64> {
    let gamma = |h: usize| -> Option<f64> {
        let (mut s, mut n) = (0.0, 0usize);
        for (a, b) in r.iter().zip(r.iter().skip(h)) {
            if a.is_finite() && b.is_finite() {
                s += (b - a) * (b - a);
                n += 1;
            }
        }
        (n >= 3).then(|| 0.5 * s / n as f64)
    };
    let (g1, g2) = (gamma(1)?, gamma(2)?);
    let finite: Vec<f64> = r.iter().copied().filter(|v| v.is_finite()).collect();
    let mean_square = finite.iter().map(|v| v * v).sum::<f64>() / finite.len().max(1) as f64;
    Some(((4.0 * g1 - g2) / 3.0).clamp(0.0, mean_square))
}

/// RMS error in excess of the noise over the RMS signal in excess of the
/// noise: √max(mse − σ², 0) / √(ms − σ²) (0 for a model that misses by the
/// noise alone; the raw NRMSE when σ² = 0).
pub fn excess_nrmse(mse: f64, mean_square_meas: f64, noise_var: f64) -> f64 {
    let signal = (mean_square_meas - noise_var).max(1e-6 * mean_square_meas).max(1e-300);
    ((mse - noise_var).max(0.0) / signal).sqrt()
}

/// The share of a channel's measured mean square that is signal, not
/// noise: max(ms − σ², 0) / ms, in [0, 1] (0 for an empty channel). A
/// channel that reads mostly noise (a displacement of a few hundredths of a
/// millimetre read with 0.05 mm noise) says little about a model, and its
/// excess error is mostly the error of its noise estimate: a 5 % error in
/// σ² on a channel with signal share 0.3 reads as an excess NRMSE of 0.25.
pub fn signal_share(mean_square_meas: f64, noise_var: f64) -> f64 {
    if mean_square_meas > 0.0 {
        ((mean_square_meas - noise_var) / mean_square_meas).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use rand_distr::StandardNormal;

    fn noise(n: usize, sd: f64, seed: u64) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n).map(|_| sd * rng.sample::<f64, _>(StandardNormal)).collect()
    }

    proptest! {
        #[test]
        fn the_signal_share_is_a_fraction(ms in 0.0..1e6f64, var in 0.0..1e6f64) {
            let w = signal_share(ms, var);
            prop_assert!((0.0..=1.0).contains(&w));
            if var >= ms {
                prop_assert_eq!(w, 0.0);
            }
            if ms > 0.0 && var == 0.0 {
                prop_assert_eq!(w, 1.0);
            }
        }
    }

    #[test]
    fn white_noise_alone_is_all_noise() {
        let r = noise(20_000, 0.3, 1);
        let v = nugget_variance(&r).unwrap();
        assert!((v / 0.09 - 1.0).abs() < 0.04, "{v}");
    }

    #[test]
    fn a_smooth_error_alone_is_almost_no_noise() {
        // 2 Hz at 100 Hz sampling: (4γ1 − γ2)/3 leaves O(h⁴) of var(s).
        let r: Vec<f64> =
            (0..5000).map(|i| (2.0 * std::f64::consts::PI * 0.02 * i as f64).sin()).collect();
        let v = nugget_variance(&r).unwrap();
        assert!(v < 1e-3 * 0.5, "{v}");
    }

    #[test]
    fn missing_readings_are_skipped() {
        let mut r = noise(20_000, 1.0, 2);
        for k in (0..r.len()).step_by(97) {
            r[k] = f64::NAN;
        }
        let v = nugget_variance(&r).unwrap();
        assert!((v - 1.0).abs() < 0.04, "{v}");
        assert_eq!(nugget_variance(&[1.0, f64::NAN, 2.0, 3.0]), None);
    }

    #[test]
    fn excess_error_is_zero_at_the_noise_and_raw_without_it() {
        assert_eq!(excess_nrmse(0.01, 1.0, 0.01), 0.0);
        assert!((excess_nrmse(0.04, 1.0, 0.0) - 0.2).abs() < 1e-15);
        assert!((excess_nrmse(0.05, 1.01, 0.01) - 0.2).abs() < 1e-15);
    }

    proptest! {
        #[test]
        fn recovers_the_noise_under_a_slow_model_error(
            sd in 0.01..1.0f64, amp in 0.0..10.0f64, f in 0.001..0.05f64, seed in 0u64..1000,
        ) {
            let e = noise(8000, sd, seed);
            let r: Vec<f64> = e
                .iter()
                .enumerate()
                .map(|(i, v)| v + amp * (2.0 * std::f64::consts::PI * f * i as f64).sin())
                .collect();
            let v = nugget_variance(&r).unwrap();
            // The estimator's relative sd on white noise is 2/√n (var of
            // (4γ1 − γ2)/3 from the lag-1 and lag-2 squared differences;
            // 1.99/√n measured over 3000 series), 0.022 at n = 8000: allow
            // 5.4 sd, plus twice the O((2πf)⁴) leak of the smooth part,
            // A²(2πf)⁴/12 to leading order.
            let leak = amp * amp * (2.0 * std::f64::consts::PI * f).powi(4) / 12.0;
            prop_assert!((v - sd * sd).abs() < 0.12 * sd * sd + 2.0 * leak, "{v} vs {}", sd * sd);
        }
    }
}
