use super::*;
use crate::diagnose::testkit::pounding_diagnosis;

fn reading(e: &Evidence, key: &str) -> [f64; 3] {
    let s = e.symptoms.iter().find(|s| s.key == key).unwrap_or_else(|| panic!("no {key}"));
    s.readings.clone().map(|r| r.or_nan())
}

#[test]
fn the_symptoms_of_a_pounding_campaign_point_to_pounding() {
    let (b, d) = pounding_diagnosis(true, true);
    let e = evidence(&b, &d);
    for s in &e.symptoms {
        eprintln!("{:28} {:?}", s.key, s.readings);
    }
    assert_eq!(e.focus_run.as_deref(), Some("strong"));
    assert_eq!((e.accel.as_deref(), e.disp.as_deref()), (Some("A1"), Some("D1")));
    // Every number is there for all three sources (the residual's
    // measured column is the reference).
    for s in &e.symptoms {
        for (k, r) in s.readings.iter().enumerate() {
            // The transfer of a 20 s record has 0.098 Hz per bin: too coarse
            // for the 0.18 Hz half-power bandwidth of 3 Hz at ζ = 0.03.
            let ok = matches!(r, Reading::Value(v) if v.is_finite())
                || (s.key == "residual_energy_db" && k == 0 && *r == Reading::Reference)
                || (s.key == "half_power_damping_ratio"
                    && matches!(r, Reading::NotComputable(w) if w.contains("3 bins")));
            assert!(ok, "{} {k}: {r:?}", s.key);
        }
    }
    let [m, b0, x] = reading(&e, "spike_share");
    assert!(m > 5.0 * b0 && x > 5.0 * b0, "spikes: measured {m}, baseline {b0}, extended {x}");
    let [m, b0, x] = reading(&e, "peak_over_gap");
    assert!(m < 1.3 && x < 1.3 && b0 > 1.6, "peak/gap: {m} {b0} {x}");
    let [m, b0, _] = reading(&e, "plateau_saturation");
    assert!(m > b0, "saturation: {m} {b0}");
    let [m, b0, x] = reading(&e, "apparent_frequency_strong_over_weak");
    // The linear baseline stays within one bin (0.098 Hz of 3 Hz) of 1;
    // contact with a stop 200 times stiffer raises the apparent frequency.
    assert!(m > 2.0 && x > 2.0 && (b0 - 1.0).abs() < 0.098 / 3.0, "f strong/weak: {m} {b0} {x}");
    // An elastic stop stores strain energy without dissipating: the loop
    // damping of the strong run falls below the weak run's.
    let [m, b0, x] = reading(&e, "loop_damping_strong_over_weak");
    assert!(m < 0.5 && x < 0.5 && (b0 - 1.0).abs() < 0.05, "damping growth: {m} {b0} {x}");
    let [_, b0, x] = reading(&e, "residual_energy_db");
    assert!(x < b0 - 6.0, "residual energy: baseline {b0} dB, extended {x} dB");
    // Three runs in the frequency plot, all simulated.
    assert_eq!(e.frequency.len(), 3);
    assert!(
        e.frequency.iter().all(|p| p.freq_hz.iter().all(|f| f.is_finite())),
        "{:?}",
        e.frequency
    );
    // The baseline's residual map holds the impacts: its high-frequency
    // band (above 15 Hz) is louder than the extension's.
    assert_eq!(e.maps.len(), 2);
    let band = |m: &ResidualMap| {
        let ks: Vec<usize> = (0..m.freq_hz.len()).filter(|k| m.freq_hz[*k] > 15.0).collect();
        let cells: Vec<f64> = m
            .level_db
            .iter()
            .flat_map(|c| ks.iter().map(|k| c[*k]))
            .filter(|v| v.is_finite())
            .collect();
        cells.iter().sum::<f64>() / cells.len() as f64
    };
    assert!(band(&e.maps[0]) > band(&e.maps[1]) + 6.0, "{} {}", band(&e.maps[0]), band(&e.maps[1]));
}

#[test]
fn a_linear_campaign_shows_no_pounding_symptoms() {
    // Measured = the linear oscillator itself (plus noise): the measured
    // numbers agree with the baseline's.
    let (b, d) = pounding_diagnosis(false, true);
    let e = evidence(&b, &d);
    let [m, b0, _] = reading(&e, "spike_share");
    assert!(m < 3.0 * b0 + 0.02, "spikes: {m} {b0}");
    let [m, b0, _] = reading(&e, "apparent_frequency_strong_over_weak");
    assert!((m - b0).abs() < 0.03, "f strong/weak: {m} {b0}");
    let [m, b0, _] = reading(&e, "loop_damping_ratio");
    assert!((m - b0).abs() < 0.25 * b0, "loop damping: {m} {b0}");
}

#[test]
fn without_a_displacement_sensor_the_displacement_symptoms_say_why() {
    let (b, d) = pounding_diagnosis(true, false);
    let e = evidence(&b, &d);
    assert_eq!(e.disp, None);
    for key in ["spike_share", "peak_over_gap", "residual_drift_mm", "loop_damping_ratio"] {
        let s = e.symptoms.iter().find(|s| s.key == key).unwrap();
        for r in &s.readings {
            match r {
                Reading::NotComputable(why) => {
                    assert!(why.contains("no displacement sensor"), "{key}: {why}")
                }
                other => panic!("{key}: {other:?}"),
            }
        }
    }
    // The accelerometer symptoms are still there.
    assert!(reading(&e, "apparent_frequency_strong_over_weak").iter().all(|v| v.is_finite()));
}

#[test]
fn short_gaps_are_bridged_and_long_ones_kept() {
    let nan = f64::NAN;
    let x = [1.0, nan, 3.0, nan, nan, nan, nan, 8.0, nan];
    let y = bridge_short_gaps(&x);
    assert_eq!(&y[..3], &[1.0, 2.0, 3.0]);
    assert!(y[3..7].iter().all(|v| v.is_nan()) && y[8].is_nan());
    let z = bridge_short_gaps(&[0.0, nan, nan, nan, 4.0]);
    assert_eq!(z, vec![0.0, 1.0, 2.0, 3.0, 4.0]);
}
