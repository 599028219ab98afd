use super::*;
use proptest::prelude::*;
use std::f64::consts::{PI, TAU};

const DT: f64 = 0.01;

fn sine(n: usize, amp: f64, cycles_per_seg: usize, seg: usize, phase: f64) -> Vec<f64> {
    (0..n)
        .map(|i| amp * (2.0 * PI * (cycles_per_seg * i) as f64 / seg as f64 + phase).sin())
        .collect()
}

proptest! {
    /// Parseval: the bins of each segment sum to the windowed mean square
    /// per unit window power.
    #[test]
    fn bins_sum_to_the_windowed_mean_square(
        x in prop::collection::vec(-10.0f64..10.0, 64..300),
        log_seg in 3u32..7,
        hop in 1usize..40,
    ) {
        let seg = 1usize << log_seg;
        let s = spectrogram(&x, DT, seg, hop).unwrap();
        let w: Vec<f64> = (0..seg).map(|i| 0.5 - 0.5 * (2.0 * PI * i as f64 / seg as f64).cos()).collect();
        let w2: f64 = w.iter().map(|v| v * v).sum();
        for (it, p) in s.power.iter().enumerate() {
            let part = &x[it * hop..it * hop + seg];
            let mean = part.iter().sum::<f64>() / seg as f64;
            let want: f64 = part.iter().zip(&w).map(|(v, w)| ((v - mean) * w).powi(2)).sum::<f64>() / w2;
            let got: f64 = p.iter().sum();
            prop_assert!((got - want).abs() <= 1e-9 * want.max(1e-12), "{got} vs {want}");
        }
        prop_assert_eq!(s.power.len(), (x.len() - seg) / hop + 1);
    }

    /// A sine with a whole number k of cycles per segment peaks at bin k in
    /// every segment, and its bins sum to A²/2 exactly (2 ≤ k ≤ seg/2 − 2,
    /// where the Hann window's cross terms vanish).
    #[test]
    fn a_sine_peaks_at_its_bin_with_power_half_its_amplitude_squared(
        log_seg in 4u32..9,
        k_share in 0.0f64..1.0,
        amp in 0.01f64..100.0,
        phase in 0.0f64..TAU,
    ) {
        let seg = 1usize << log_seg;
        let k = 2 + (k_share * (seg / 2 - 4) as f64) as usize;
        let x = sine(4 * seg, amp, k, seg, phase);
        let s = spectrogram(&x, DT, seg, seg / 2).unwrap();
        for p in &s.power {
            let top = (0..p.len()).max_by(|a, b| p[*a].total_cmp(&p[*b])).unwrap();
            prop_assert_eq!(top, k);
            let total: f64 = p.iter().sum();
            prop_assert!((total - amp * amp / 2.0).abs() < 1e-9 * amp * amp, "{total}");
        }
        prop_assert!((s.freq_hz[k] - k as f64 / (seg as f64 * DT)).abs() < 1e-12);
    }
}

#[test]
fn a_missing_reading_blanks_only_the_segments_that_hold_it() {
    let mut x = sine(256, 1.0, 4, 32, 0.3);
    x[100] = f64::NAN;
    let s = spectrogram(&x, DT, 32, 32).unwrap();
    // Segments of 32: the reading at 100 lies in segment 3 (96..128) only.
    for (it, p) in s.power.iter().enumerate() {
        if it == 3 {
            assert!(p.iter().all(|v| v.is_nan()));
        } else {
            assert!(p.iter().all(|v| v.is_finite()));
        }
    }
    assert!((s.t_s[0] - 15.5 * DT).abs() < 1e-12);
}

#[test]
fn bad_steps_and_short_records_are_refused() {
    assert_eq!(spectrogram(&[0.0; 64], 0.0, 16, 8), Err(SpectrumError::Step(0.0)));
    assert_eq!(
        spectrogram(&[0.0; 10], DT, 16, 8),
        Err(SpectrumError::TooShort { segment: 16, n: 10 })
    );
    assert!(spectrogram(&[0.0; 64], DT, 16, 0).is_err());
    assert_eq!(segment_for(0.64, 0.01), 64);
    assert_eq!(segment_for(0.64, 0.005), 128);
    assert_eq!(segment_for(0.01, 0.01), 8);
}
