use super::*;
use crate::diagnose::testkit::{sdof, white_noise};

const DT: f64 = 1.0 / 200.0;

#[test]
fn a_linear_system_has_no_amplitude_trend_and_softening_shows() {
    let flat = amplitude_trend(&[(0.02, 7.5), (0.1, 7.5), (0.5, 7.5)]).unwrap();
    assert!(flat.ln_freq_per_decade.abs() < 1e-12 && (flat.strong_over_weak - 1.0).abs() < 1e-12);
    // 7.5 Hz at 0.02 g, 6.0 Hz at 0.2 g: ln(0.8) per decade.
    let soft = amplitude_trend(&[(0.02, 7.5), (0.2, 6.0)]).unwrap();
    assert!((soft.ln_freq_per_decade - 0.8f64.ln()).abs() < 1e-12, "{soft:?}");
    assert!((soft.strong_over_weak - 0.8).abs() < 1e-12);
    assert!(amplitude_trend(&[(0.1, 7.0)]).is_none());
    assert!(amplitude_trend(&[(0.1, 7.0), (0.1, 7.2)]).is_none());
}

fn sine_sweep(n: usize, amp: f64) -> Vec<f64> {
    // 2 -> 10 Hz linear sweep.
    let t_end = n as f64 * DT;
    (0..n)
        .map(|i| {
            let t = i as f64 * DT;
            let phase = 2.0 * std::f64::consts::PI * (2.0 * t + 4.0 * t * t / t_end);
            amp * phase.sin()
        })
        .collect()
}

#[test]
fn spikes_appear_at_the_displacement_peaks_of_a_pounding_system() {
    let ag = sine_sweep(20 * 200, 3.0);
    let (acc, disp) = sdof(&ag, DT, 5.0, 0.03, None);
    let linear = spike_share(&acc, &disp, DT, 25.0).unwrap();
    let peak = disp.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    let (acc, disp) = sdof(&ag, DT, 5.0, 0.03, Some((0.5 * peak, 200.0)));
    let pounding = spike_share(&acc, &disp, DT, 25.0).unwrap();
    // Linear: only the filter's leakage of the 5 Hz motion, (5/25)^4 = 0.0016.
    assert!(linear < 0.01, "linear {linear}");
    assert!(pounding > 0.1 && pounding > 10.0 * linear, "linear {linear}, pounding {pounding}");
}

#[test]
fn cycle_peaks_pile_up_at_a_stop() {
    let ag = sine_sweep(20 * 200, 3.0);
    let (_, free) = sdof(&ag, DT, 5.0, 0.03, None);
    let peak = free.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    let gap = 0.4 * peak;
    let (_, stopped) = sdof(&ag, DT, 5.0, 0.03, Some((gap, 200.0)));
    let pf = plateau(&free, gap).unwrap();
    let ps = plateau(&stopped, gap).unwrap();
    assert!(pf.peak_over_gap > 2.0, "{pf:?}");
    assert!(ps.peak_over_gap < 1.2, "{ps:?}");
    assert!(ps.saturation > 2.0 * pf.saturation, "free {pf:?} stopped {ps:?}");
    let sine: Vec<f64> = (0..10_000).map(|i| (i as f64 * 0.01 + 0.3).sin()).collect();
    assert_eq!(plateau(&sine, 1.0).unwrap().saturation, 1.0);
    assert_eq!(half_cycle_peaks(&[1.0, 2.0, -1.0, -3.0, 0.5]), vec![2.0, 3.0, 0.5]);
}

#[test]
fn drift_is_the_offset_left_after_shaking() {
    let mut d: Vec<f64> = (0..1000).map(|i| (i as f64 * 0.3).sin()).collect();
    assert!(residual_drift(&d, 0.1).unwrap().abs() < 0.1);
    for (i, v) in d.iter_mut().enumerate().skip(500) {
        *v = 2.5 + (i as f64 * 0.3).sin() * 0.0;
    }
    assert!((residual_drift(&d, 0.1).unwrap() - 2.5).abs() < 0.1);
    d[999] = f64::NAN;
    assert!((residual_drift(&d, 0.1).unwrap() - 2.5).abs() < 0.1);
    assert!(residual_drift(&[1.0], 0.1).is_none());
}

#[test]
fn missing_readings_are_skipped_not_zero() {
    let ag = white_noise(4000, 1.0, 9);
    let (mut acc, disp) = sdof(&ag, DT, 5.0, 0.03, None);
    let clean = spike_share(&acc, &disp, DT, 25.0).unwrap();
    for v in acc.iter_mut().step_by(97) {
        *v = f64::NAN;
    }
    let holes = spike_share(&acc, &disp, DT, 25.0).unwrap();
    assert!(holes.is_finite() && (holes / clean - 1.0).abs() < 0.5, "{clean} {holes}");
    assert_eq!(rms(&[f64::NAN, 3.0, -3.0]), 3.0);
}

#[test]
fn gaps_are_bridged_by_straight_lines() {
    let nan = f64::NAN;
    assert_eq!(
        bridge_gaps(&[nan, 1.0, nan, nan, 4.0, nan]).unwrap(),
        vec![1.0, 1.0, 2.0, 3.0, 4.0, 4.0]
    );
    assert!(bridge_gaps(&[nan, nan]).is_none());
}
