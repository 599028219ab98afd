use super::*;
use crate::diagnose::testkit::{sdof, white_noise};

const DT: f64 = 1.0 / 200.0;

#[test]
fn an_oscillator_under_white_noise_shows_its_frequency_and_damping() {
    let ag = white_noise(60 * 200, 1.0, 7);
    for (f, zeta) in [(5.0, 0.03), (8.0, 0.05)] {
        let (acc, _) = sdof(&ag, DT, f, zeta, None);
        let t = transfer_h1(&ag, &acc, DT, 2048).unwrap();
        let r = resonance(&t, 1.0, 30.0).unwrap();
        // The absolute-acceleration transmissibility peaks at f sqrt(1 - 2 zeta^2)
        // approximately; within 1 % of f for these dampings.
        assert!((r.freq_hz / f - 1.0).abs() < 0.01, "f {f}: {r:?}");
        let z = r.damping_ratio.expect("both half-power points");
        assert!((z / zeta - 1.0).abs() < 0.2, "zeta {zeta}: {r:?}");
        assert!((r.gain - 1.0 / (2.0 * zeta)).abs() / (1.0 / (2.0 * zeta)) < 0.2, "{r:?}");
    }
}

#[test]
fn coherence_is_near_one_for_a_linear_system_and_drops_with_noise() {
    let ag = white_noise(30 * 200, 1.0, 3);
    let (acc, _) = sdof(&ag, DT, 6.0, 0.04, None);
    let t = transfer_h1(&ag, &acc, DT, 1024).unwrap();
    // Off resonance: at the peak itself the window's finite resolution biases
    // H1 coherence low (a property of the estimator, not of the system).
    for f in [3.0, 12.0] {
        let k = t.freq_hz.iter().position(|&x| x >= f).unwrap();
        assert!(t.coherence[k] > 0.95, "{f} Hz: {}", t.coherence[k]);
    }
    let noise = white_noise(acc.len(), 20.0, 4);
    let noisy: Vec<f64> = acc.iter().zip(&noise).map(|(a, n)| a + n).collect();
    let t = transfer_h1(&ag, &noisy, DT, 1024).unwrap();
    let k30 = t.freq_hz.iter().position(|&f| f >= 30.0).unwrap();
    assert!(t.coherence[k30] < 0.5, "{}", t.coherence[k30]);
}

#[test]
fn missing_readings_skip_their_segments_and_bad_input_is_refused() {
    let ag = white_noise(8192, 1.0, 5);
    let (mut acc, _) = sdof(&ag, DT, 5.0, 0.03, None);
    let full = transfer_h1(&ag, &acc, DT, 1024).unwrap().segments;
    acc[100] = f64::NAN;
    let t = transfer_h1(&ag, &acc, DT, 1024).unwrap();
    assert!(t.segments < full && t.segments > 0);
    assert!(t.gain.iter().all(|g| g.is_finite()));
    assert_eq!(
        transfer_h1(&ag[..10], &acc[..11], DT, 1024),
        Err(SpectrumError::Lengths { input: 10, response: 11 })
    );
    assert!(matches!(transfer_h1(&ag, &acc, 0.0, 1024), Err(SpectrumError::Step(_))));
    let all_nan = vec![f64::NAN; 64];
    assert!(matches!(
        transfer_h1(&all_nan, &all_nan, DT, 1024),
        Err(SpectrumError::TooShort { .. })
    ));
}
