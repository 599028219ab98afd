use super::cause::Cause;
use super::fit::{least_squares_offset, mean_excess_nrmse, ChannelFit, Evaluation};
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
    let priors = Cause::NONE.priors();
    let ev = Evaluation::baseline(&b, &priors, &[2]);
    let at = |fits: Vec<ChannelFit>| fits.into_iter().find(|c| c.sensor == "D1").unwrap();
    let (fitted, pre_event) = (at(ev.validation_channels(truth)), at(ev.channels(truth)));
    assert!(excess(&fitted) < 0.01, "fitted offset: {}", excess(&fitted));
    assert!(excess(&pre_event) > 0.03, "pre-event offset: {}", excess(&pre_event));
    assert_eq!(fitted.rms_meas, pre_event.rms_meas, "the signal is the same under both");
}

/// A shaken channel with `rms_meas` whose residual misses by `rms_res`.
fn channel(rms_meas: f64, rms_res: f64) -> ChannelFit {
    let n = 1000;
    ChannelFit {
        run: "r".into(),
        sensor: "s".into(),
        ssr: rms_res * rms_res * n as f64,
        n,
        rho: 0.0,
        rms_meas,
        excited: true,
        noise_var: 0.0,
        band: None,
    }
}

#[test]
fn a_channel_that_reads_mostly_noise_does_not_set_the_validation_error() {
    // An accelerometer predicted to its noise (signal 2.7, noise 0.02) and a
    // displacement of 0.026 mm read with 0.05 mm noise, its residual 1.4 %
    // above the estimated noise (a 3 % error in the noise variance).
    let acc = channel((2.7f64.powi(2) + 0.02f64.powi(2)).sqrt(), 0.02);
    let disp = channel((0.026f64.powi(2) + 0.05f64.powi(2)).sqrt(), 0.05 * 1.03f64.sqrt());
    let noise = [0.02f64.powi(2), 0.05f64.powi(2)];
    let plain = (0.0 + excess_nrmse(disp.ssr / 1000.0, disp.rms_meas.powi(2), noise[1])) / 2.0;
    let weighted = mean_excess_nrmse(&[acc.clone(), disp], &noise);
    assert!(plain > 0.1, "equal weights: {plain}");
    // Weights 1 and 0.21 (the displacement's signal share) against 1 and 1.
    assert!(weighted < 0.4 * plain, "{weighted} vs {plain}");
    // A channel with no signal over its noise counts for nothing; alone, by
    // equal weights.
    let silent = channel(0.05, 0.06);
    let both = mean_excess_nrmse(&[acc.clone(), silent.clone()], &noise);
    assert!(both.abs() < 1e-12, "{both}");
    let alone = mean_excess_nrmse(&[silent], &noise[1..]);
    assert!(alone > 0.0 && alone.is_finite(), "{alone}");
}
