//! How far the validation runs drive the specimen beyond the calibration
//! runs, read off the measurements alone (any sensor: a displacement that
//! grows, or the acceleration spikes of contact): physics that acts only above the
//! calibration runs' amplitude (a gap that closes, a slip force that is
//! reached) cannot be calibrated on them, and a diagnosis whose validation
//! runs go there measures extrapolation.

use super::fit::pre_event_offset;
use crate::bundle::Bundle;

/// Share of a channel's samples whose |value| lies below its robust peak.
const PEAK_QUANTILE: f64 = 0.995;

/// The sensor whose validation peak most exceeds its calibration peak.
#[derive(Debug, Clone, PartialEq)]
pub struct Reach {
    /// Sensor id.
    pub sensor: String,
    /// Robust peak over the validation runs over that over the calibration runs.
    pub ratio: f64,
}

/// The robust peak of |m − pre-event offset| (the [`PEAK_QUANTILE`]
/// quantile, so that a lone spike of noise does not set it); None without
/// finite samples.
pub fn robust_peak(m: &[f64], dt_s: f64) -> Option<f64> {
    let off = pre_event_offset(m, dt_s);
    let mut a: Vec<f64> = m.iter().filter(|v| v.is_finite()).map(|v| (v - off).abs()).collect();
    if a.is_empty() {
        return None;
    }
    a.sort_by(f64::total_cmp);
    let k = ((a.len() - 1) as f64 * PEAK_QUANTILE).round() as usize;
    Some(a[k])
}

/// The largest ratio, over the sensors, of a sensor's robust peak over the
/// validation runs `val` to its robust peak over the calibration runs `cal`
/// (run indices); None when no sensor has a positive peak in both.
pub fn validation_reach(b: &Bundle, cal: &[usize], val: &[usize]) -> Option<Reach> {
    let peak = |runs: &[usize], id: &str| -> Option<f64> {
        let peaks = runs.iter().filter_map(|&k| {
            let run = b.runs.get(k)?;
            robust_peak(run.sensor(id)?, run.dt_s)
        });
        peaks.reduce(f64::max).filter(|p| *p > 0.0)
    };
    b.manifest
        .sensors
        .iter()
        .filter_map(|s| {
            let ratio = peak(val, &s.id)? / peak(cal, &s.id)?;
            ratio.is_finite().then(|| Reach { sensor: s.id.clone(), ratio })
        })
        .max_by(|a, b| a.ratio.total_cmp(&b.ratio))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::testkit::pounding_diagnosis;

    #[test]
    fn a_lone_spike_does_not_set_the_peak() {
        // 1 s at rest (the pre-event offset, 0.2), then a unit sine.
        let mut m: Vec<f64> =
            (0..2000).map(|k| 0.2 + if k < 100 { 0.0 } else { (k as f64 * 0.05).sin() }).collect();
        m[1500] = 50.0;
        let p = robust_peak(&m, 0.01).unwrap();
        assert!((0.95..=1.0).contains(&p), "{p}");
        assert_eq!(robust_peak(&[f64::NAN; 10], 0.01), None);
    }

    #[test]
    fn validation_runs_beyond_the_calibration_ones_are_measured() {
        // The campaign's runs 0 and 1 calibrate, run 2 validates.
        let (b, _) = pounding_diagnosis(true, true);
        let r = validation_reach(&b, &[0, 1], &[2]).expect("sensors");
        let peak = |id: &str, k: usize| {
            robust_peak(b.runs[k].sensor(id).unwrap(), b.runs[k].dt_s).unwrap()
        };
        let ratio = |id: &str| peak(id, 2) / peak(id, 0).max(peak(id, 1));
        let largest = ["A1", "A2", "D1"].into_iter().map(ratio).fold(0.0, f64::max);
        assert!(r.ratio > 1.0 && (r.ratio - largest).abs() < 1e-12, "{r:?}");
        assert!((r.ratio - ratio(&r.sensor)).abs() < 1e-12, "{r:?}");
        assert_eq!(validation_reach(&b, &[], &[2]), None);
    }
}
