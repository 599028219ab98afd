//! Short-time power spectrum of a record (Hann-windowed segments, each with
//! its own mean removed): where in time and frequency a signal, or the
//! residual of a model, holds its energy.
//!
//! Each segment's one-sided periodogram is scaled so that its bins sum to
//! the mean square of the windowed segment per unit window power,
//! Σ_k P_k = Σ_n (w_n x_n)² / Σ_n w_n² (Parseval), in the signal's units
//! squared. A segment with a missing reading (NaN) gives a column of NaN,
//! never a spectrum of zeros.

use super::spectrum::SpectrumError;
use rustfft::{num_complex::Complex64, FftPlanner};

/// Power per time segment and frequency bin.
#[derive(Debug, Clone, PartialEq)]
pub struct Spectrogram {
    /// Segment centres (s from the first sample).
    pub t_s: Vec<f64>,
    /// Bin frequencies (Hz), 0 to the Nyquist frequency.
    pub freq_hz: Vec<f64>,
    /// `power[it][ik]` in signal units²; NaN for segments with missing readings.
    pub power: Vec<Vec<f64>>,
}

/// Short-time spectrum with segments of `seg` samples every `hop` samples.
pub fn spectrogram(
    x: &[f64],
    dt_s: f64,
    seg: usize,
    hop: usize,
) -> Result<Spectrogram, SpectrumError> {
    if dt_s.is_nan() || dt_s <= 0.0 {
        return Err(SpectrumError::Step(dt_s));
    }
    if seg < 8 || hop == 0 || x.len() < seg {
        return Err(SpectrumError::TooShort { segment: seg, n: x.len() });
    }
    let fft = FftPlanner::<f64>::new().plan_fft_forward(seg);
    let window: Vec<f64> = (0..seg)
        .map(|i| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / seg as f64).cos())
        .collect();
    let w2: f64 = window.iter().map(|w| w * w).sum();
    let half = seg / 2 + 1;
    let (mut t_s, mut power) = (Vec::new(), Vec::new());
    let mut start = 0;
    while start + seg <= x.len() {
        let s = &x[start..start + seg];
        t_s.push((start as f64 + 0.5 * (seg - 1) as f64) * dt_s);
        power.push(if s.iter().all(|v| v.is_finite()) {
            periodogram(s, &window, w2, fft.as_ref())
        } else {
            vec![f64::NAN; half]
        });
        start += hop;
    }
    let freq_hz = (0..half).map(|k| k as f64 / (seg as f64 * dt_s)).collect();
    Ok(Spectrogram { t_s, freq_hz, power })
}

/// One-sided periodogram of one finite segment, scaled as the module says.
fn periodogram(s: &[f64], window: &[f64], w2: f64, fft: &dyn rustfft::Fft<f64>) -> Vec<f64> {
    let n = s.len();
    let mean = s.iter().sum::<f64>() / n as f64;
    let mut buf: Vec<Complex64> =
        s.iter().zip(window).map(|(v, w)| Complex64::new((v - mean) * w, 0.0)).collect();
    fft.process(&mut buf);
    (0..n / 2 + 1)
        .map(|k| {
            let both_sides = if k == 0 || 2 * k == n { 1.0 } else { 2.0 };
            both_sides * buf[k].norm_sqr() / (n as f64 * w2)
        })
        .collect()
}

/// Largest power of two not above `n` and at least 8 (the segment length
/// of a short-time spectrum resolving `window_s` seconds at step `dt_s`).
pub fn segment_for(window_s: f64, dt_s: f64) -> usize {
    let n = (window_s / dt_s).max(8.0) as usize;
    let mut s = 8usize;
    while s * 2 <= n {
        s *= 2;
    }
    s
}

#[cfg(test)]
#[path = "spectrogram_tests.rs"]
mod tests;
