//! A channel's likelihood over the model's band, in the frequency domain
//! (Whittle 1953): the residual's periodogram I_k at the Fourier frequencies
//! k / T within the band, each an exponential variable whose mean is the
//! residual's spectral level S_b there, profiled per sub-band b of a given
//! width: −ln L = Σ_b K_b (ln mean_b I + 1), constants dropped.
//!
//! K_b, the bins in sub-band b, is T times its width whatever the sampling
//! rate: a record twice as dense adds bins only above the band, where the
//! model is not asked to predict. (A white sensor noise's level within the
//! band falls as the rate rises, as averaging more samples does; a
//! misfit's does not.) The time-domain weights of
//! [`super::fit::effective_sizes`] count every sample of a residual that is
//! mostly white sensor noise as independent, so their nats double with the
//! rate (measured on the demo campaign: pounding over `none` by 3201 nats
//! at 100 Hz, 6380 at 200 Hz). A spectral level per sub-band is the
//! residual's own discrepancy-plus-noise model, coarse in frequency: a
//! misfit near a resonance raises its sub-band's level and counts there
//! only. The same pass gives the residual's mean square within the band
//! and the Satterthwaite degrees of freedom of that mean square, the
//! rate-free weights of [`super::likelihood::Likelihood::Band`]; the
//! per-sub-band likelihood itself is [`super::likelihood::Likelihood::Whittle`]
//! (see there why it is not the default).

use rustfft::{num_complex::Complex64, FftPlanner};

/// The model's band's upper edge (Hz): the ceilings' modes of interest lie
/// below 25 Hz (the seed's specimens 5 to 20 Hz) and a simulation at 100 Hz
/// resolves 40 Hz within its 0.8 Nyquist filter corner
/// ([`super::resample`]); records sampled at 100 Hz or faster are then all
/// judged on the same band, so their likelihoods count the same bins.
pub const MODEL_BAND_TOP_HZ: f64 = 40.0;

/// Width of the sub-bands whose spectral level is profiled (Hz): the
/// half-power bandwidth of a mode with 5 % damping at 20 Hz, so that a
/// misfit about one resonance raises the level of its own sub-band and
/// counts there.
pub const SUB_BAND_HZ: f64 = 2.0;

/// The model's band for a record sampled every `dt_s`: from the first
/// Fourier bin to [`MODEL_BAND_TOP_HZ`] or 0.8 of the Nyquist frequency,
/// whichever is lower.
pub fn model_band_hz(dt_s: f64) -> (f64, f64) {
    (0.0, MODEL_BAND_TOP_HZ.min(0.8 * 0.5 / dt_s))
}

/// [`band_neg_log_lik`] of residual `r` over the model's band
/// ([`model_band_hz`]) in sub-bands of [`SUB_BAND_HZ`].
pub fn model_band_fit(r: &[f64], dt_s: f64) -> Option<BandFit> {
    band_neg_log_lik(r, dt_s, model_band_hz(dt_s), SUB_BAND_HZ)
}

/// Residual `r` (step `dt_s`) filtered to the model's band: the Fourier
/// bins [`model_band_fit`] counts kept, every other (the mean among them)
/// zeroed; missing readings (NaN) count as zero after the mean of those
/// present is removed, as there. Its mean square is that fit's
/// [`BandFit::mean_square`] (Parseval), so the band likelihood's
/// Σ_c dof_c / 2 · ln(mean square_c) is a weighted sum of log sums of
/// squares of these residuals, whose forward differences give its
/// Gauss–Newton matrix ([`super::levenberg`]). Empty when the band holds no
/// bin or the inputs are not usable.
pub fn model_band_pass(r: &[f64], dt_s: f64) -> Vec<f64> {
    let (lo, hi) = model_band_hz(dt_s);
    let present: Vec<f64> = r.iter().copied().filter(|v| v.is_finite()).collect();
    if !(dt_s > 0.0 && dt_s.is_finite()) || r.len() < 2 || present.is_empty() {
        return Vec::new();
    }
    let mean = present.iter().sum::<f64>() / present.len() as f64;
    let n = r.len();
    let mut x: Vec<Complex64> =
        r.iter().map(|v| Complex64::new(if v.is_finite() { v - mean } else { 0.0 }, 0.0)).collect();
    let mut planner = FftPlanner::new();
    planner.plan_fft_forward(n).process(&mut x);
    let t_s = n as f64 * dt_s;
    let kept = |k: usize| {
        let k = k.min(n - k);
        let f_hz = k as f64 / t_s;
        k >= 1 && 2 * k < n && f_hz >= lo && f_hz <= hi
    };
    if !(1..n).any(kept) {
        return Vec::new();
    }
    x.iter_mut()
        .enumerate()
        .filter(|(k, _)| !kept(*k))
        .for_each(|(_, c)| *c = Complex64::default());
    planner.plan_fft_inverse(n).process(&mut x);
    x.iter().map(|c| c.re / n as f64).collect()
}

/// The band likelihood of one residual, and its power within the band.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BandFit {
    /// −ln L (nat, constants dropped).
    pub neg_log_lik: f64,
    /// Fourier bins within the band (the likelihood's sample count).
    pub bins: usize,
    /// The residual's mean square within the band (Parseval: (2 / T) Σ I_k,
    /// its square units).
    pub mean_square: f64,
    /// Degrees of freedom of that mean square (Satterthwaite):
    /// 2 (Σ_b K_b S_b)² / Σ_b K_b S_b², S_b the mean periodogram of
    /// sub-band b; 2 × bins for a residual white within the band, about
    /// 2 K_b for one whose power lies in one sub-band. Fixed by the band and
    /// the residual's spectral shape, not by the sampling rate.
    pub dof: f64,
}

/// The band likelihood of residual `r` (step `dt_s`) over `band_hz` =
/// (low, high), its spectral level profiled per sub-band of `width_hz`
/// (the last one takes what is left). Missing readings (NaN) count as zero
/// residual after the mean is removed. None when no bin falls in the band,
/// the inputs are not finite and positive, or the residual is all missing.
pub fn band_neg_log_lik(
    r: &[f64],
    dt_s: f64,
    band_hz: (f64, f64),
    width_hz: f64,
) -> Option<BandFit> {
    let (lo, hi) = band_hz;
    let ok = dt_s > 0.0 && width_hz > 0.0 && lo >= 0.0 && hi > lo;
    if !ok || ![dt_s, width_hz, lo, hi].iter().all(|v| v.is_finite()) || r.len() < 2 {
        return None;
    }
    let present: Vec<f64> = r.iter().copied().filter(|v| v.is_finite()).collect();
    if present.is_empty() {
        return None;
    }
    let mean = present.iter().sum::<f64>() / present.len() as f64;
    let n = r.len();
    let mut x: Vec<Complex64> =
        r.iter().map(|v| Complex64::new(if v.is_finite() { v - mean } else { 0.0 }, 0.0)).collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut x);
    let t_s = n as f64 * dt_s;
    let mut acc = Accumulated::default();
    let mut band = Vec::new();
    let mut edge = lo + width_hz;
    for (k, c) in x.iter().enumerate().take(n / 2 + 1).skip(1) {
        let f_hz = k as f64 / t_s;
        if f_hz < lo || f_hz > hi {
            continue;
        }
        if f_hz > edge && !band.is_empty() {
            acc.add(&band);
            band.clear();
            edge += width_hz * ((f_hz - edge) / width_hz).ceil().max(1.0);
        }
        band.push(c.norm_sqr() * dt_s / n as f64);
    }
    if !band.is_empty() {
        acc.add(&band);
    }
    (acc.bins > 0).then(|| BandFit {
        neg_log_lik: acc.nll,
        bins: acc.bins,
        mean_square: 2.0 * acc.power / t_s,
        dof: if acc.power_sq > 0.0 { 2.0 * acc.power * acc.power / acc.power_sq } else { 0.0 },
    })
}

/// Sums over the sub-bands seen so far.
#[derive(Default)]
struct Accumulated {
    /// Σ_b K_b (ln S_b + 1).
    nll: f64,
    /// Σ_b K_b.
    bins: usize,
    /// Σ_b K_b S_b (= Σ I_k).
    power: f64,
    /// Σ_b K_b S_b².
    power_sq: f64,
}

impl Accumulated {
    /// Adds one sub-band's periodogram values (a zero level counts as the
    /// smallest positive one in the likelihood).
    fn add(&mut self, values: &[f64]) {
        let k = values.len() as f64;
        let mean = values.iter().sum::<f64>() / k;
        self.nll += k * (mean.max(f64::MIN_POSITIVE).ln() + 1.0);
        self.bins += values.len();
        self.power += k * mean;
        self.power_sq += k * mean * mean;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::testkit::white_noise;

    /// A band-limited residual: one sinusoid in each 5 Hz sub-band of
    /// 0.55 to 20.55 Hz, on whole cycles of the 10 s record, sampled at
    /// `rate_hz`.
    fn residual(rate_hz: f64) -> Vec<f64> {
        let n = (10.0 * rate_hz) as usize;
        (0..n)
            .map(|i| {
                let t = i as f64 / rate_hz;
                let w = |f: f64| (2.0 * std::f64::consts::PI * f * t).sin();
                0.3 * w(2.0) + 0.1 * w(7.3) + 0.05 * w(12.1) + 0.02 * w(17.6)
            })
            .collect()
    }

    #[test]
    fn the_same_band_counts_the_same_bins_and_nats_at_any_rate() {
        let band = (0.55, 20.55);
        let a = band_neg_log_lik(&residual(100.0), 0.01, band, 5.0).unwrap();
        let b = band_neg_log_lik(&residual(200.0), 0.005, band, 5.0).unwrap();
        let c = band_neg_log_lik(&residual(1000.0), 0.001, band, 5.0).unwrap();
        // Bins at k / 10 s from 0.6 to 20.5 Hz: 200.
        assert_eq!((a.bins, b.bins, c.bins), (200, 200, 200));
        assert!((a.neg_log_lik - b.neg_log_lik).abs() < 1e-6, "{a:?} {b:?}");
        assert!((a.neg_log_lik - c.neg_log_lik).abs() < 1e-6, "{a:?} {c:?}");
    }

    #[test]
    fn scaling_the_residual_by_two_costs_k_ln_4() {
        let r: Vec<f64> = white_noise(2000, 1.0, 3);
        let twice: Vec<f64> = r.iter().map(|v| 2.0 * v).collect();
        let a = band_neg_log_lik(&r, 0.01, (1.0, 30.0), 2.0).unwrap();
        let b = band_neg_log_lik(&twice, 0.01, (1.0, 30.0), 2.0).unwrap();
        assert!((b.neg_log_lik - a.neg_log_lik - a.bins as f64 * 4f64.ln()).abs() < 1e-8);
    }

    #[test]
    fn white_noise_level_is_its_variance_times_the_step() {
        // Uniform on [−1, 1]: variance 1/3; the mean periodogram ≈ σ² dt.
        let r = white_noise(40_000, 1.0, 5);
        let fit = band_neg_log_lik(&r, 0.01, (0.0, 50.0), 50.0).unwrap();
        let level = (fit.neg_log_lik / fit.bins as f64 - 1.0).exp();
        assert!((level / (0.01 / 3.0) - 1.0).abs() < 0.03, "{level}");
    }

    #[test]
    fn mean_square_and_dof_of_a_band_limited_residual_hold_at_any_rate() {
        let band = (0.55, 20.55);
        let a = band_neg_log_lik(&residual(100.0), 0.01, band, 5.0).unwrap();
        let b = band_neg_log_lik(&residual(200.0), 0.005, band, 5.0).unwrap();
        // Σ amplitude² / 2 of the four sinusoids.
        let ms = (0.09 + 0.01 + 0.0025 + 0.0004) / 2.0;
        assert!((a.mean_square / ms - 1.0).abs() < 1e-9, "{a:?}");
        assert!((b.mean_square - a.mean_square).abs() < 1e-12 && (b.dof - a.dof).abs() < 1e-9);
        // Sub-band powers p_b = a_b² / 2 in 50 bins each: 2 (Σ p)² / Σ p² / 50.
        let p = [0.09, 0.01, 0.0025, 0.0004].map(|a2: f64| a2 / 2.0);
        let dof =
            2.0 * p.iter().sum::<f64>().powi(2) / (p.iter().map(|v| v * v).sum::<f64>() / 50.0);
        assert!((a.dof / dof - 1.0).abs() < 1e-9 && dof < 2.0 * 200.0, "{a:?} vs {dof}");
        // White within the band: about 2 × bins.
        let w = band_neg_log_lik(&white_noise(20_000, 1.0, 9), 0.01, (0.0, 40.0), 2.0).unwrap();
        assert!((w.dof / (2.0 * w.bins as f64) - 1.0).abs() < 0.02, "{w:?}");
        assert!((w.mean_square / (0.8 / 3.0) - 1.0).abs() < 0.03, "{w:?}");
    }

    #[test]
    fn the_band_passed_residual_carries_the_band_fits_mean_square() {
        // White noise at 100 Hz: the band (to 40 Hz) keeps about 0.8 of it.
        for (r, dt_s) in [(white_noise(3001, 1.0, 4), 0.01), (residual(200.0), 0.005)] {
            let fit = model_band_fit(&r, dt_s).unwrap();
            let y = model_band_pass(&r, dt_s);
            let ms = y.iter().map(|v| v * v).sum::<f64>() / y.len() as f64;
            assert_eq!(y.len(), r.len());
            assert!((ms / fit.mean_square - 1.0).abs() < 1e-9, "{ms} vs {fit:?}");
        }
        // A sinusoid inside the band passes whole; one above it not at all.
        let n = 1000;
        let wave = |f_hz: f64| -> Vec<f64> {
            (0..n).map(|i| (2.0 * std::f64::consts::PI * f_hz * i as f64 * 0.005).sin()).collect()
        };
        let inside = wave(12.0);
        let y = model_band_pass(&inside, 0.005);
        assert!(y.iter().zip(&inside).all(|(a, b)| (a - b).abs() < 1e-9));
        assert!(model_band_pass(&wave(60.0), 0.005).iter().all(|v| v.abs() < 1e-9));
        assert!(model_band_pass(&[f64::NAN; 8], 0.01).is_empty());
        assert!(model_band_pass(&inside, 0.0).is_empty());
    }

    #[test]
    fn a_band_without_bins_or_bad_inputs_give_none() {
        let r = residual(100.0);
        assert!(band_neg_log_lik(&r, 0.01, (60.0, 80.0), 5.0).is_none(), "above Nyquist");
        assert!(band_neg_log_lik(&r, 0.0, (0.5, 25.0), 5.0).is_none());
        assert!(band_neg_log_lik(&r, 0.01, (25.0, 0.5), 5.0).is_none());
        assert!(band_neg_log_lik(&r, 0.01, (0.5, 25.0), f64::NAN).is_none());
        assert!(band_neg_log_lik(&[f64::NAN; 10], 0.01, (0.5, 25.0), 5.0).is_none());
        let mut gappy = r.clone();
        gappy[10] = f64::NAN;
        assert!(band_neg_log_lik(&gappy, 0.01, (0.5, 25.0), 5.0).is_some());
    }
}
