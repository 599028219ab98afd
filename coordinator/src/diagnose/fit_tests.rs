use super::cause::Cause;
use super::fit::{least_squares_offset, ChannelFit, Evaluation};
use super::noise_floor::excess_nrmse;
use super::testkit::pounding_diagnosis;
use proptest::prelude::*;

proptest! {
    #[test]
    fn the_fitted_offset_is_the_constant_between_the_series(
        s in prop::collection::vec(-1e3..1e3f64, 1..200),
        c in -1e3..1e3f64,
        gap in 0usize..200,
    ) {
        let mut m: Vec<f64> = s.iter().map(|v| v + c).collect();
        if gap < m.len() {
            m[gap] = f64::NAN;
        }
        if let Some(fitted) = least_squares_offset(&m, &s) {
            prop_assert!((fitted - c).abs() <= 1e-9 * (1.0 + c.abs()), "{fitted} vs {c}");
        } else {
            prop_assert!(m.iter().all(|v| v.is_nan()));
        }
    }
}

/// Excess NRMSE of one channel fit with its own nugget as the noise.
fn excess(c: &ChannelFit) -> f64 {
    excess_nrmse(c.ssr / c.n as f64, c.rms_meas * c.rms_meas, c.noise_var)
}

#[test]
fn a_disturbed_lead_in_does_not_count_against_a_models_prediction() {
    // The validation run of the pounding campaign, seen by the true model,
    // with its displacement record's first 0.5 s disturbed by two noise SDs (0.1 mm).
    let (mut b, d) = pounding_diagnosis(true, true);
    let truth = &d.candidates[1].validation_sims;
    let (_, d1) = b.runs[2].sensors.iter_mut().find(|(id, _)| id == "D1").unwrap();
    d1[..50].iter_mut().for_each(|v| *v += 0.1);
    let priors = Cause::None.priors();
    let ev =
        Evaluation { bundle: &b, cause: Cause::None, priors: &priors, runs: &[2], demand: None };
    let at = |fits: Vec<ChannelFit>| fits.into_iter().find(|c| c.sensor == "D1").unwrap();
    let (fitted, pre_event) = (at(ev.validation_channels(truth)), at(ev.channels(truth)));
    assert!(excess(&fitted) < 0.01, "fitted offset: {}", excess(&fitted));
    assert!(excess(&pre_event) > 0.03, "pre-event offset: {}", excess(&pre_event));
    assert_eq!(fitted.rms_meas, pre_event.rms_meas, "the signal is the same under both");
}
