//! How much FE work one parameter point of a campaign costs, and when a
//! campaign is large enough for the calibration to trim its costliest
//! stages: the lower-damping path ([`super::damping_path`]) and the longer
//! search of an extension with three parameters of its own
//! ([`super::calibrate`]), so that a diagnosis of a 6 m x 4.8 m ceiling
//! with three 30 s runs stays near 10 minutes on two cores.

use crate::bundle::Bundle;

/// Largest [`campaign_work`] that is not large. A 6 m x 4.8 m campaign
/// calibrated on two 30 s runs at 200 Hz (960 000) spent 430 s of its
/// diagnosis's 780 s wall time on 2 cores in connection hysteresis's first
/// path, which the lower-damping path lengthened by 300 s; the 3.6 m x
/// 3.6 m campaigns of 4 and 6 s runs the full stages were measured on are
/// 72 000.
pub const LARGE_WORK: f64 = 250_000.0;

/// FE work of simulating one parameter point of a campaign, in grid
/// module-samples: modules of the ceiling's plan (every layer) times the
/// samples of calibration runs `runs` of `bundle`.
pub fn campaign_work(bundle: &Bundle, runs: &[usize]) -> f64 {
    let s = &bundle.manifest.structure;
    let per_side = |l: f64| (l / s.module_m).round().max(1.0);
    let modules = per_side(s.length_x_m) * per_side(s.length_y_m) * f64::from(s.layers.max(1));
    let samples: usize =
        runs.iter().filter_map(|r| bundle.runs.get(*r)).map(|r| r.n_samples()).sum();
    modules * samples as f64
}

/// Whether a campaign of [`campaign_work`] `work` is large.
pub fn is_large(work: f64) -> bool {
    work > LARGE_WORK
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn campaign_work_counts_modules_times_calibration_samples() {
        let dir = tempfile::tempdir().unwrap();
        let b = super::super::farm_executor_tests::tiny_bundle(dir.path());
        // 2.4 m x 2.4 m at 0.6 m: 16 modules; 2 s at 50 Hz: 101 samples.
        assert_eq!(b.runs.iter().map(|r| r.n_samples()).collect::<Vec<_>>(), [101; 3]);
        assert_eq!(campaign_work(&b, &[0, 1]), 16.0 * 202.0);
        assert_eq!(campaign_work(&b, &[2]), 16.0 * 101.0);
        // An index past the runs adds nothing.
        assert_eq!(campaign_work(&b, &[2, 9]), 16.0 * 101.0);
    }

    #[test]
    fn the_size_check_campaign_is_large_and_the_test_campaigns_are_not() {
        // 6 m x 4.8 m at 0.6 m, two 30 s runs at 200 Hz.
        assert!(is_large(80.0 * 2.0 * 6001.0));
        // 3.6 m x 3.6 m, a 4 s and a 6 s run at 200 Hz.
        assert!(!is_large(36.0 * (801.0 + 1201.0)));
        assert!(!is_large(LARGE_WORK));
    }
}
