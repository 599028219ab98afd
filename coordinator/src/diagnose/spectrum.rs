//! Frequency response from a run: Welch-averaged H1 estimate of the transfer
//! function from the platform input to a sensor, its coherence, and the
//! resonance it shows (frequency by parabolic peak interpolation, damping by
//! the half-power bandwidth).

use rustfft::{num_complex::Complex64, FftPlanner};

/// Why a spectrum cannot be estimated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpectrumError {
    /// Input and response differ in length.
    #[error("input has {input} samples, response {response}: expected the same")]
    Lengths {
        /// Input samples.
        input: usize,
        /// Response samples.
        response: usize,
    },
    /// Not one whole segment without missing readings.
    #[error("no segment of {segment} samples free of missing readings (run of {n} samples)")]
    TooShort {
        /// Segment length used.
        segment: usize,
        /// Run length.
        n: usize,
    },
    /// Sampling step not positive.
    #[error("sampling step {0} s: expected > 0")]
    Step(f64),
}

/// An estimated transfer function on a frequency grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Transfer {
    /// Frequencies (Hz), from 0 to the Nyquist frequency.
    pub freq_hz: Vec<f64>,
    /// |H1(f)|, response over input.
    pub gain: Vec<f64>,
    /// Magnitude-squared coherence, 0..1.
    pub coherence: Vec<f64>,
    /// Segments averaged.
    pub segments: usize,
}

/// A resonance read off a transfer function.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resonance {
    /// Peak frequency (Hz).
    pub freq_hz: f64,
    /// Peak gain.
    pub gain: f64,
    /// Damping ratio from the half-power bandwidth, if both sides are in band.
    pub damping_ratio: Option<f64>,
}

/// Largest power of two not above `n`, capped at `max`.
fn segment_len(n: usize, max: usize) -> usize {
    let mut s = 1usize;
    while s * 2 <= n.min(max) {
        s *= 2;
    }
    s
}

/// H1 transfer estimate with Hann windows of up to `max_segment` samples, 50 % overlap.
pub fn transfer_h1(
    input: &[f64],
    response: &[f64],
    dt_s: f64,
    max_segment: usize,
) -> Result<Transfer, SpectrumError> {
    if input.len() != response.len() {
        return Err(SpectrumError::Lengths { input: input.len(), response: response.len() });
    }
    if dt_s.is_nan() || dt_s <= 0.0 {
        return Err(SpectrumError::Step(dt_s));
    }
    let n = input.len();
    let seg = segment_len(n, max_segment.max(16));
    let fft = FftPlanner::<f64>::new().plan_fft_forward(seg);
    let window: Vec<f64> = (0..seg)
        .map(|i| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / seg as f64).cos())
        .collect();
    let half = seg / 2 + 1;
    let (mut sxx, mut syy) = (vec![0.0; half], vec![0.0; half]);
    let mut sxy = vec![Complex64::new(0.0, 0.0); half];
    let mut segments = 0;
    let mut start = 0;
    while seg >= 16 && start + seg <= n {
        let (x, y) = (&input[start..start + seg], &response[start..start + seg]);
        start += seg / 2;
        if x.iter().chain(y).any(|v| !v.is_finite()) {
            continue;
        }
        let mut bx = windowed(x, &window);
        let mut by = windowed(y, &window);
        fft.process(&mut bx);
        fft.process(&mut by);
        for k in 0..half {
            sxx[k] += bx[k].norm_sqr();
            syy[k] += by[k].norm_sqr();
            sxy[k] += bx[k].conj() * by[k];
        }
        segments += 1;
    }
    if segments == 0 {
        return Err(SpectrumError::TooShort { segment: seg, n });
    }
    let df = 1.0 / (seg as f64 * dt_s);
    let gain = (0..half).map(|k| if sxx[k] > 0.0 { sxy[k].norm() / sxx[k] } else { 0.0 }).collect();
    let coherence = (0..half)
        .map(|k| {
            let d = sxx[k] * syy[k];
            if d > 0.0 {
                (sxy[k].norm_sqr() / d).min(1.0)
            } else {
                0.0
            }
        })
        .collect();
    let freq_hz = (0..half).map(|k| k as f64 * df).collect();
    Ok(Transfer { freq_hz, gain, coherence, segments })
}

/// Mean-removed, windowed copy of a segment as complex samples.
fn windowed(x: &[f64], window: &[f64]) -> Vec<Complex64> {
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    x.iter().zip(window).map(|(v, w)| Complex64::new((v - mean) * w, 0.0)).collect()
}

/// The highest peak of `t` between `lo_hz` and `hi_hz`, if any.
pub fn resonance(t: &Transfer, lo_hz: f64, hi_hz: f64) -> Option<Resonance> {
    let band: Vec<usize> = (1..t.freq_hz.len() - 1)
        .filter(|&k| t.freq_hz[k] >= lo_hz && t.freq_hz[k] <= hi_hz)
        .collect();
    let &k = band.iter().max_by(|&&a, &&b| t.gain[a].total_cmp(&t.gain[b]))?;
    let df = t.freq_hz[1] - t.freq_hz[0];
    let (g0, g1, g2) = (t.gain[k - 1], t.gain[k], t.gain[k + 1]);
    let curv = g0 - 2.0 * g1 + g2;
    let shift = if curv < 0.0 { (0.5 * (g0 - g2) / curv).clamp(-0.5, 0.5) } else { 0.0 };
    let freq_hz = t.freq_hz[k] + shift * df;
    let gain = g1 - 0.25 * (g0 - g2) * shift;
    let level = gain / std::f64::consts::SQRT_2;
    let left = crossing(t, k, level, -1, lo_hz, hi_hz);
    let right = crossing(t, k, level, 1, lo_hz, hi_hz);
    let damping_ratio = match (left, right) {
        (Some(a), Some(b)) => Some((b - a) / (2.0 * freq_hz)),
        _ => None,
    };
    Some(Resonance { freq_hz, gain, damping_ratio })
}

/// Where the gain first falls below `level` walking from bin `k` in `dir`.
fn crossing(t: &Transfer, k: usize, level: f64, dir: isize, lo: f64, hi: f64) -> Option<f64> {
    let mut i = k as isize;
    loop {
        let j = i + dir;
        if j < 0 || j as usize >= t.gain.len() {
            return None;
        }
        let (a, b) = (i as usize, j as usize);
        if t.freq_hz[b] < lo || t.freq_hz[b] > hi {
            return None;
        }
        if t.gain[b] < level {
            let frac = (t.gain[a] - level) / (t.gain[a] - t.gain[b]);
            return Some(t.freq_hz[a] + frac * (t.freq_hz[b] - t.freq_hz[a]));
        }
        i = j;
    }
}

#[cfg(test)]
#[path = "spectrum_tests.rs"]
mod tests;
