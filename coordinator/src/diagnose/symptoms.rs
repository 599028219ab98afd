//! Symptoms a structural engineer recognises in shaking-table records, each
//! a number computed the same way on measured and on simulated runs:
//! amplitude-dependent frequency (friction, softening connections), spikes
//! of high-frequency acceleration at displacement peaks (pounding),
//! displacement that dwells at a plateau near the nominal gap (contact),
//! and residual drift after shaking (slip).
//!
//! Missing readings (NaN) are skipped, never read as zero.

use super::filter::Biquad;

/// How a resonance moves with shaking amplitude across runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AmplitudeTrend {
    /// Least-squares slope of ln(frequency) per decade of amplitude
    /// (0: linear system; < 0: softening with amplitude, e.g. slip).
    pub ln_freq_per_decade: f64,
    /// Frequency of the strongest run over that of the weakest.
    pub strong_over_weak: f64,
}

/// Frequency trend over `(amplitude, freq_hz)` pairs of at least two runs
/// with distinct positive amplitudes.
pub fn amplitude_trend(runs: &[(f64, f64)]) -> Option<AmplitudeTrend> {
    let pts: Vec<(f64, f64)> = runs
        .iter()
        .filter(|(a, f)| *a > 0.0 && *f > 0.0 && a.is_finite() && f.is_finite())
        .map(|(a, f)| (a.log10(), f.ln()))
        .collect();
    let n = pts.len() as f64;
    let (mx, my) = pts.iter().fold((0.0, 0.0), |(x, y), p| (x + p.0 / n, y + p.1 / n));
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if pts.len() < 2 || sxx <= 1e-12 {
        return None;
    }
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let weak = pts.iter().min_by(|a, b| a.0.total_cmp(&b.0))?;
    let strong = pts.iter().max_by(|a, b| a.0.total_cmp(&b.0))?;
    Some(AmplitudeTrend {
        ln_freq_per_decade: sxy / sxx,
        strong_over_weak: (strong.1 - weak.1).exp(),
    })
}

/// RMS of the finite values of a slice (0 if none).
pub fn rms(x: &[f64]) -> f64 {
    let (s, n) =
        x.iter().filter(|v| v.is_finite()).fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    if n == 0 {
        0.0
    } else {
        (s / n as f64).sqrt()
    }
}

/// Share of high-frequency content in the acceleration at displacement
/// peaks: the RMS of `accel` high-passed at `fc_hz` over the RMS of `accel`
/// itself, both over the samples where |disp| is at least 80 % of its
/// largest value. Small (filter leakage only) for a linear system driven
/// below `fc_hz`; large when ends strike a stop at the peaks.
pub fn spike_share(accel: &[f64], disp: &[f64], dt_s: f64, fc_hz: f64) -> Option<f64> {
    if accel.len() != disp.len() {
        return None;
    }
    let hp = Biquad::high_pass(fc_hz, dt_s)?;
    // The filter must not see missing readings: bridge them linearly for
    // the filter, and leave their samples out of both averages.
    let high = hp.filtfilt(&bridge_gaps(accel)?);
    let peak = disp.iter().filter(|d| d.is_finite()).fold(0.0f64, |m, d| m.max(d.abs()));
    if peak <= 0.0 {
        return None;
    }
    let (mut hf, mut all) = (Vec::new(), Vec::new());
    for ((h, a), d) in high.iter().zip(accel).zip(disp) {
        if a.is_finite() && d.is_finite() && d.abs() >= 0.8 * peak {
            hf.push(*h);
            all.push(*a);
        }
    }
    let total = rms(&all);
    (total > 0.0).then(|| rms(&hf) / total)
}

/// A copy with runs of missing readings replaced by straight lines between
/// their finite neighbours (held flat at the ends); `None` if nothing is finite.
pub fn bridge_gaps(x: &[f64]) -> Option<Vec<f64>> {
    let known: Vec<usize> = (0..x.len()).filter(|&i| x[i].is_finite()).collect();
    let (&first, &last) = (known.first()?, known.last()?);
    let mut out = x.to_vec();
    out[..first].fill(x[first]);
    out[last + 1..].fill(x[last]);
    for w in known.windows(2) {
        let (a, b) = (w[0], w[1]);
        for (i, o) in (a + 1..b).zip(&mut out[a + 1..b]) {
            *o = x[a] + (x[b] - x[a]) * (i - a) as f64 / (b - a) as f64;
        }
    }
    Some(out)
}

/// How displacement meets a stop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plateau {
    /// Largest |displacement| over the nominal gap.
    pub peak_over_gap: f64,
    /// Share of the half-cycles reaching half the largest peak whose own
    /// peak is within 10 % of the largest: cycle peaks pile up there when
    /// motion is stopped, while a free resonance passes through it.
    pub saturation: f64,
}

/// Peak |value| of every half-cycle (between sign changes) of a record.
pub fn half_cycle_peaks(x: &[f64]) -> Vec<f64> {
    let mut peaks = Vec::new();
    let (mut sign, mut peak) = (0.0f64, 0.0f64);
    for v in x.iter().filter(|v| v.is_finite()) {
        let s = v.signum();
        if s != sign && *v != 0.0 {
            if sign != 0.0 {
                peaks.push(peak);
            }
            (sign, peak) = (s, 0.0);
        }
        peak = peak.max(v.abs());
    }
    if sign != 0.0 {
        peaks.push(peak);
    }
    peaks
}

/// Plateau evidence of a relative displacement record against `gap`
/// (same units).
pub fn plateau(disp: &[f64], gap: f64) -> Option<Plateau> {
    let peaks = half_cycle_peaks(disp);
    let top = peaks.iter().copied().fold(0.0f64, f64::max);
    if top <= 0.0 || gap.is_nan() || gap <= 0.0 {
        return None;
    }
    let large = peaks.iter().filter(|p| **p >= 0.5 * top).count();
    let near = peaks.iter().filter(|p| **p >= 0.9 * top).count();
    Some(Plateau { peak_over_gap: top / gap, saturation: near as f64 / large.max(1) as f64 })
}

/// Mean of the last `share` of a record minus the mean of its first `share`
/// (finite samples only): a permanent offset left by slip.
pub fn residual_drift(disp: &[f64], share: f64) -> Option<f64> {
    let m = ((disp.len() as f64 * share.clamp(0.0, 0.5)) as usize).max(1);
    if disp.len() < 2 * m {
        return None;
    }
    let mean = |s: &[f64]| {
        let f: Vec<f64> = s.iter().copied().filter(|v| v.is_finite()).collect();
        (!f.is_empty()).then(|| f.iter().sum::<f64>() / f.len() as f64)
    };
    Some(mean(&disp[disp.len() - m..])? - mean(&disp[..m])?)
}

#[cfg(test)]
#[path = "symptoms_tests.rs"]
mod tests;
