//! Runs recorded faster than the simulation needs, brought down to it: a
//! lab may sample at 1 kHz or more, the FE model integrates at the
//! sampling step, and the ceiling's response of interest lies below 30 Hz.
//! A run sampled at `q` ≥ 2 times the simulation's rate
//! ([`SIMULATION_RATE_HZ`] by default; q whole, the largest that keeps the
//! rate at or above it) is low-passed by a zero-phase windowed-sinc filter
//! below the new Nyquist frequency and every q-th sample kept, its input
//! and its sensors alike, so that the simulation and the measurements it
//! is compared with see the same band.

use crate::bundle::{Bundle, RunData};

/// The sampling rate a diagnosis simulates at by default when a run is
/// recorded at least twice as fast (Hz).
pub const SIMULATION_RATE_HZ: f64 = 200.0;

/// Filter corner over the new Nyquist frequency (80 Hz at 200 Hz).
const CORNER_OVER_NYQUIST: f64 = 0.8;

/// Filter half-length in new samples (taps = 2 · HALF_LENGTH · q + 1): a
/// Blackman transition of about 5.5 / taps of the old rate, 34 Hz at 200
/// Hz, so that content above the new Nyquist frequency does not alias
/// and the band below 60 Hz passes within 0.1 %.
const HALF_LENGTH: usize = 16;

/// One run brought down to the simulation's rate.
#[derive(Debug, Clone, PartialEq)]
pub struct Decimated {
    /// Run id.
    pub run: String,
    /// Recorded rate (Hz).
    pub from_hz: f64,
    /// Rate simulated and compared at (Hz).
    pub to_hz: f64,
}

/// The whole factor that brings a run sampled every `dt_s` down to the
/// rate nearest `rate_hz` from above (1: left as it is).
pub fn decimation_factor(dt_s: f64, rate_hz: f64) -> usize {
    if !(dt_s > 0.0 && dt_s.is_finite() && rate_hz > 0.0 && rate_hz.is_finite()) {
        return 1;
    }
    let q = (1.0 / (dt_s * rate_hz) + 1e-9).floor();
    if q >= 2.0 {
        q as usize
    } else {
        1
    }
}

/// The bundle with every run sampled at twice `rate_hz` or faster
/// decimated, and what was done to which run.
pub fn for_simulation(b: &Bundle, rate_hz: f64) -> (Bundle, Vec<Decimated>) {
    let mut out = b.clone();
    let mut done = Vec::new();
    for run in &mut out.runs {
        let q = decimation_factor(run.dt_s, rate_hz);
        if q < 2 {
            continue;
        }
        let from_hz = 1.0 / run.dt_s;
        decimate_run(run, q);
        done.push(Decimated { run: run.id.clone(), from_hz, to_hz: from_hz / q as f64 });
    }
    (out, done)
}

/// Decimates a run's inputs and sensors by `q` in place.
fn decimate_run(run: &mut RunData, q: usize) {
    let kernel = low_pass_kernel(q);
    for column in [&mut run.input_x_m_s2, &mut run.input_y_m_s2].into_iter().flatten() {
        *column = decimate(column, q, &kernel);
    }
    for (_, samples) in &mut run.sensors {
        *samples = decimate(samples, q, &kernel);
    }
    run.dt_s *= q as f64;
}

/// Blackman-windowed sinc low-pass for decimation by `q`: corner at
/// [`CORNER_OVER_NYQUIST`] of the new Nyquist frequency, unit gain at 0 Hz.
pub fn low_pass_kernel(q: usize) -> Vec<f64> {
    let half = HALF_LENGTH * q.max(1);
    let fc = CORNER_OVER_NYQUIST * 0.5 / q.max(1) as f64;
    let n = 2 * half;
    let pi = std::f64::consts::PI;
    let mut k: Vec<f64> = (0..=n)
        .map(|i| {
            let m = i as f64 - half as f64;
            let sinc = if m == 0.0 { 2.0 * fc } else { (2.0 * pi * fc * m).sin() / (pi * m) };
            let w = 0.42 - 0.5 * (2.0 * pi * i as f64 / n as f64).cos()
                + 0.08 * (4.0 * pi * i as f64 / n as f64).cos();
            sinc * w
        })
        .collect();
    let sum: f64 = k.iter().sum();
    k.iter_mut().for_each(|v| *v /= sum);
    k
}

/// Every `q`-th sample of `x` low-passed by `kernel` (odd length, centred):
/// missing readings (NaN) are bridged linearly for the filter and stay
/// missing where the kept sample was; near the ends the kernel's part
/// inside the record is rescaled to unit gain.
pub fn decimate(x: &[f64], q: usize, kernel: &[f64]) -> Vec<f64> {
    let q = q.max(1);
    let filled = bridged(x);
    let half = kernel.len() / 2;
    (0..x.len())
        .step_by(q)
        .map(|i| {
            if !x[i].is_finite() {
                return f64::NAN;
            }
            let lo = i.saturating_sub(half);
            let hi = (i + half).min(x.len() - 1);
            let (mut acc, mut weight) = (0.0, 0.0);
            for (j, v) in filled[lo..=hi].iter().enumerate() {
                let w = kernel[lo + j + half - i];
                acc += w * v;
                weight += w;
            }
            acc / weight
        })
        .collect()
}

/// `x` with each run of NaN replaced by the line between its finite
/// neighbours (the nearest finite value at an end; zeros if none is).
fn bridged(x: &[f64]) -> Vec<f64> {
    let finite: Vec<usize> = (0..x.len()).filter(|&i| x[i].is_finite()).collect();
    let (Some(&first), Some(&last)) = (finite.first(), finite.last()) else {
        return vec![0.0; x.len()];
    };
    let mut out = x.to_vec();
    out[..first].fill(x[first]);
    out[last + 1..].fill(x[last]);
    for pair in finite.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        for (k, v) in out.iter_mut().enumerate().take(b).skip(a + 1) {
            let t = (k - a) as f64 / (b - a) as f64;
            *v = x[a] + t * (x[b] - x[a]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn sine(f_hz: f64, rate_hz: f64, n: usize) -> Vec<f64> {
        (0..n).map(|k| (2.0 * std::f64::consts::PI * f_hz * k as f64 / rate_hz).sin()).collect()
    }

    #[test]
    fn the_factor_keeps_the_rate_at_or_above_the_simulations() {
        let q = |rate_hz: f64| decimation_factor(1.0 / rate_hz, SIMULATION_RATE_HZ);
        assert_eq!(q(1000.0), 5);
        assert_eq!(q(2048.0), 10);
        assert_eq!(q(500.0), 2);
        assert_eq!(q(400.0), 2);
        for rate in [100.0, 200.0, 256.0, 399.0] {
            assert_eq!(q(rate), 1, "{rate} Hz");
        }
        assert_eq!(decimation_factor(1e-3, 500.0), 2);
        assert_eq!(decimation_factor(0.0, 200.0), 1);
        assert_eq!(decimation_factor(f64::NAN, 200.0), 1);
        assert_eq!(decimation_factor(1e-3, 0.0), 1);
    }

    /// A 10 Hz tone at 1 kHz decimated by 5 is the tone sampled at 200 Hz
    /// (to 1e-4 away from the ends); a 130 Hz tone, above the new Nyquist
    /// frequency, is gone (below 1e-3) instead of aliasing to 70 Hz.
    #[test]
    fn the_band_below_passes_and_the_band_above_does_not_alias() {
        let kernel = low_pass_kernel(5);
        let low = decimate(&sine(10.0, 1000.0, 5000), 5, &kernel);
        let expect = sine(10.0, 200.0, 1000);
        assert_eq!(low.len(), 1000);
        let interior = 20..980;
        let err = interior.clone().map(|k| (low[k] - expect[k]).abs()).fold(0.0, f64::max);
        assert!(err < 1e-4, "pass-band error {err}");
        let high = decimate(&sine(130.0, 1000.0, 5000), 5, &kernel);
        let peak = interior.map(|k| high[k].abs()).fold(0.0, f64::max);
        assert!(peak < 1e-3, "stop-band leak {peak}");
    }

    #[test]
    fn missing_readings_stay_missing_and_do_not_spread() {
        let mut x = sine(5.0, 1000.0, 2000);
        for k in [500, 501, 502, 503, 504, 505, 1003] {
            x[k] = f64::NAN;
        }
        let y = decimate(&x, 5, &low_pass_kernel(5));
        let missing: Vec<usize> = (0..y.len()).filter(|&k| y[k].is_nan()).collect();
        assert_eq!(missing, vec![100, 101]);
        let expect = sine(5.0, 200.0, 400);
        // Bridging a 7 ms hole in a 5 Hz tone errs by at most
        // (2π 5)² (0.007)² / 8 = 6e-3 there, and the filter spreads it
        // over its half-length (16 kept samples) only.
        let err = |near: bool| {
            (20..380)
                .filter(|k| !missing.contains(k))
                .filter(|k| (k.abs_diff(100) <= 17 || k.abs_diff(201) <= 17) == near)
                .map(|k| (y[k] - expect[k]).abs())
                .fold(0.0, f64::max)
        };
        assert!(err(true) < 6e-3, "{}", err(true));
        assert!(err(false) < 1e-4, "{}", err(false));
        assert!(decimate(&[f64::NAN; 20], 5, &low_pass_kernel(5)).iter().all(|v| v.is_nan()));
    }

    #[test]
    fn only_runs_recorded_twice_as_fast_or_more_are_decimated() {
        let dir = tempfile::tempdir().unwrap();
        let mut b = super::super::farm_executor_tests::tiny_bundle(dir.path());
        b.runs[1].dt_s = 1e-3;
        let (out, done) = for_simulation(&b, SIMULATION_RATE_HZ);
        assert_eq!(done, vec![Decimated { run: b.runs[1].id.clone(), from_hz: 1e3, to_hz: 200.0 }]);
        let n = b.runs[1].n_samples();
        assert_eq!(out.runs[1].n_samples(), (n - 1) / 5 + 1);
        assert!((out.runs[1].dt_s - 5e-3).abs() < 1e-15);
        for (s, t) in out.runs[1].sensors.iter().zip(&b.runs[1].sensors) {
            assert_eq!((&s.0, s.1.len()), (&t.0, (n - 1) / 5 + 1));
        }
        // Untouched (compared as printed: a missing reading is NaN).
        for k in [0, 2] {
            assert_eq!(format!("{:?}", out.runs[k]), format!("{:?}", b.runs[k]));
        }
    }

    proptest! {
        /// A constant record stays constant to the last sample, and every
        /// q-th sample is kept, for any factor and length.
        #[test]
        fn constants_pass_unchanged(c in -1e3f64..1e3, q in 2usize..12, n in 1usize..400) {
            let y = decimate(&vec![c; n], q, &low_pass_kernel(q));
            prop_assert_eq!(y.len(), (n - 1) / q + 1);
            for v in y {
                prop_assert!((v - c).abs() <= 1e-9 * c.abs().max(1.0));
            }
        }
    }
}
