//! Sensor imperfections added to a simulated reading: white noise, a
//! constant offset per sensor and run, and readings left empty (NaN).

use super::spec::Noise;
use crate::bundle::SensorKind;
use rand::Rng;
use rand_distr::{Distribution, Normal};

/// Adds noise and offset to `values` (bundle units: m/s², mm) and blanks
/// a fraction of readings.
pub fn degrade<R: Rng>(values: &mut [f64], kind: SensorKind, noise: &Noise, rng: &mut R) {
    let (rms, offset) = match kind {
        SensorKind::Acceleration => (noise.accel_rms_m_s2, noise.accel_offset_m_s2),
        SensorKind::Displacement => (noise.disp_rms_mm, noise.disp_offset_mm),
    };
    let bias =
        if offset > 0.0 { Normal::new(0.0, offset).map_or(0.0, |d| d.sample(rng)) } else { 0.0 };
    let white = Normal::new(0.0, rms.max(0.0)).ok();
    for v in values.iter_mut() {
        *v += bias + white.as_ref().map_or(0.0, |d| d.sample(rng));
        if noise.missing_fraction > 0.0 && rng.random::<f64>() < noise.missing_fraction {
            *v = f64::NAN;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn noise_has_its_rms_offset_and_missing_share() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let noise = Noise {
            accel_rms_m_s2: 0.2,
            disp_rms_mm: 0.0,
            accel_offset_m_s2: 0.0,
            disp_offset_mm: 0.0,
            missing_fraction: 0.1,
        };
        let mut v = vec![1.0; 20000];
        degrade(&mut v, SensorKind::Acceleration, &noise, &mut rng);
        let kept: Vec<f64> = v.iter().copied().filter(|x| !x.is_nan()).collect();
        let missing = 1.0 - kept.len() as f64 / v.len() as f64;
        assert!((missing - 0.1).abs() < 0.01, "{missing}");
        let mean = kept.iter().sum::<f64>() / kept.len() as f64;
        let sd = (kept.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / kept.len() as f64).sqrt();
        assert!((mean - 1.0).abs() < 0.01 && (sd - 0.2).abs() < 0.01, "{mean} {sd}");
    }
}
