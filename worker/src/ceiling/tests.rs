use super::*;
use fe::transient::History as FeHistory;
use fe::transient::TransientError;
use serde_json::json;

fn spec_path() -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../configs/specimens/small-3p6.toml");
    p.display().to_string()
}

/// A short sweep (2 s, 0.01 s samples) and two sensors at the centre.
fn options(extra: serde_json::Value) -> CeilingOptions {
    let mut v = json!({
        "spec": spec_path(),
        "n_modes": 2,
        "excitation": {"type": "sine-sweep", "pga_g": 0.05, "duration_s": 2.0, "dt_s": 0.01,
                       "direction": "x", "ramp_s": 0.5},
        "sensors": [
            {"id": "A1", "kind": "acceleration", "x_m": 1.8, "y_m": 1.8, "direction": "x"},
            {"id": "D1", "kind": "displacement", "x_m": 1.5, "y_m": 1.8, "direction": "x"},
        ],
    });
    for (k, x) in extra.as_object().unwrap() {
        v[k] = x.clone();
    }
    serde_json::from_value(v).unwrap()
}

fn names(n: &[&str]) -> Vec<String> {
    n.iter().map(|s| s.to_string()).collect()
}

fn build_error(extra: serde_json::Value, study: &[&str]) -> String {
    Ceiling::new(options(extra), &names(study)).err().unwrap().to_string()
}

#[test]
fn outputs_are_named_and_sized() {
    let n = names(&["K_friction", "damping_ratio"]);
    let m = Ceiling::new(options(json!({})), &n).unwrap();
    assert_eq!(m.output_names(), ["f1_hz", "f2_hz", "dir1", "dir2", "peak_A1", "peak_D1"]);
    let out = m.run(&ParamSet::new(&n, &[20.0, 0.03]).unwrap(), &RunContext::default()).unwrap();
    let got: Vec<&str> = out.scalars.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(got, m.output_names());
    assert_eq!(out.histories.len(), 2);
    let samples = m.input().len();
    assert_eq!(samples, 201);
    for (h, (id, ch)) in out.histories.iter().zip([("A1", "A1_accel_m_s2"), ("D1", "D1_disp_m")]) {
        assert_eq!(
            (h.name.as_str(), h.channels.as_slice(), h.dt_s),
            (id, &[ch.to_string()][..], 0.01)
        );
        assert_eq!(h.n_samples(), samples);
        let peak = h.data.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert_eq!(out.scalar(&format!("peak_{id}")), Some(peak));
        assert!(peak > 0.0 && peak.is_finite(), "{id}: {peak}");
    }
    // Stiff in x below its first mode: the centre moves with the base
    // (peak 0.05 g = 0.49 m/s²), millimetres at most relative to it.
    let a = out.scalar("peak_A1").unwrap();
    assert!(a > 0.3 && a < 1.5, "peak_A1 {a} m/s2");
    assert!(out.scalar("peak_D1").unwrap() < 5e-3);
}

#[test]
fn stiffer_friction_raises_the_first_frequency() {
    let n = names(&["K_friction"]);
    let m = Ceiling::new(options(json!({})), &n).unwrap();
    let f1 = |k: f64| {
        let out = m.run(&ParamSet::new(&n, &[k]).unwrap(), &RunContext::default()).unwrap();
        out.scalar("f1_hz").unwrap()
    };
    let (soft, stiff) = (f1(15.0), f1(25.0));
    assert!(stiff > soft && soft > 2.0, "{soft} {stiff}");
}

#[test]
fn sensor_off_the_ceiling_is_refused_with_its_key() {
    let sensors = json!([
        {"id": "A1", "kind": "acceleration", "x_m": 1.8, "y_m": 1.8, "direction": "x"},
        {"id": "A2", "kind": "acceleration", "x_m": 4.0, "y_m": 1.8, "direction": "x"},
    ]);
    let e = build_error(json!({ "sensors": sensors }), &[]);
    assert!(
        e.contains("model.sensors[1] (A2): x_m = 4,")
            && e.contains("outside the ceiling (0..3.6 m"),
        "{e}"
    );
}

#[test]
fn bad_sensor_kind_and_duplicate_ids_are_refused() {
    let s = json!([{"id": "A1", "kind": "velocity", "x_m": 1.8, "y_m": 1.8, "direction": "x"}]);
    let e = build_error(json!({ "sensors": s }), &[]);
    assert!(e.contains("model.sensors[0].kind"), "{e}");
    let one = json!({"id": "A1", "kind": "acceleration", "x_m": 1.8, "y_m": 1.8, "direction": "x"});
    let e = build_error(json!({ "sensors": [one.clone(), one] }), &[]);
    assert!(e.contains("model.sensors[1].id") && e.contains("twice"), "{e}");
}

#[test]
fn unknown_excitation_type_is_refused_with_its_key() {
    let e = build_error(json!({"excitation": {"type": "white-noise", "pga_g": 0.1}}), &[]);
    assert!(e.contains("model.excitation.type") && e.contains("white-noise"), "{e}");
}

#[test]
fn bad_record_units_are_refused_with_their_key() {
    let ex = json!({"type": "record", "csv": "t,a\n0,0\n0.01,1\n", "units": "cm/s2",
                    "direction": "x"});
    let e = build_error(json!({ "excitation": ex }), &[]);
    assert!(e.contains("model.excitation.units") && e.contains("cm/s2"), "{e}");
}

#[test]
fn record_excitation_drives_the_run() {
    // 1 Hz, 0.02 g in the file, ramped in over 1 s, scaled by 2: 0.04 g keeps
    // the perimeter stuck (about 1 N per end against a 2 N slip force).
    let f_hz = 1.0;
    let csv: String = std::iter::once("t_s,ag_g\n".to_string())
        .chain((0..301).map(|k| {
            let t = k as f64 * 0.01;
            let a = 0.02 * t.min(1.0) * (2.0 * std::f64::consts::PI * f_hz * t).sin();
            format!("{t},{a}\n")
        }))
        .collect();
    let ex = json!({"type": "record", "csv": csv, "units": "g", "direction": "x", "scale": 2.0});
    let m = Ceiling::new(options(json!({ "excitation": ex })), &[]).unwrap();
    let out = m.run(&ParamSet::new(&[], &[]).unwrap(), &RunContext::default()).unwrap();
    let h = &out.histories[0];
    assert_eq!(h.n_samples(), 301);
    // Steady state far below the first x mode: |H| = 1 / (1 - (f/f1)^2) for
    // the absolute acceleration of a single mode, within the 5 % that damping
    // and higher modes leave.
    let f1 = (0..2)
        .find(|k| out.scalar(&format!("dir{}", k + 1)) == Some(1.0))
        .map(|k| out.scalar(&format!("f{}_hz", k + 1)).unwrap())
        .unwrap();
    let a = h.data[150..].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let expected = 0.04 * excitation::G_M_S2 / (1.0 - (f_hz / f1).powi(2));
    assert!((a / expected - 1.0).abs() < 0.05, "peak {a} vs {expected} m/s2 (f1 {f1} Hz)");
}

#[test]
fn unmodelled_parameter_and_bad_damping_are_refused() {
    let e = build_error(json!({}), &["K_cc1"]);
    assert!(e.contains("K_cc1"), "{e}");
    let e = build_error(json!({"damping_ratio": 1.5}), &[]);
    assert!(e.contains("damping_ratio = 1.5"), "{e}");
    let n = names(&["damping_ratio"]);
    let m = Ceiling::new(options(json!({})), &n).unwrap();
    let r = m.run(&ParamSet::new(&n, &[-0.1]).unwrap(), &RunContext::default());
    assert!(matches!(r, Err(RunError::Input(ref s)) if s.contains("damping_ratio")), "{r:?}");
}

#[test]
fn failed_transient_is_a_recorded_failure_with_its_reason() {
    let e = CeilingError::Transient(TransientError::NoConvergence {
        t_s: 1.25,
        dt_s: 0.005 / 64.0,
        step: 251,
        reason: "increment norm 3e2 mm after 50 iterations".into(),
        history: Box::new(FeHistory { columns: vec!["t_s".into()], rows: vec![] }),
    });
    match failure(e) {
        RunError::Failed(s) => {
            assert!(s.contains("t = 1.25 s") && s.contains("50 iterations"), "{s}")
        }
        other => panic!("expected Failed, got {other:?}"),
    }
}

/// Pinching4 connections with no strength (CJS-A forces × 1e-9) under an
/// absurd 1e200 g sweep: the increments overflow even at Δt/64, and the run
/// ends as a failure with the time and the reason, without a panic. (Under
/// 1000 g the same specimen once stalled at round-off increments; the
/// round-off residual test now finishes it.)
#[test]
fn transient_without_convergence_comes_back_as_failed() {
    let text = std::fs::read_to_string(spec_path()).unwrap().replace(
        "variant = \"nonlinear\"",
        "perimeter = \"friction-pounding\"\nconnections = \"pinching4\"",
    );
    let ex = json!({"type": "sine-sweep", "pga_g": 1e200, "duration_s": 2.0, "dt_s": 0.01,
                    "direction": "xy", "ramp_s": 0.5});
    let n = names(&["conn_force_scale"]);
    let opts = json!({ "excitation": ex, "spec": null, "spec_toml": text });
    let m = Ceiling::new(options(opts), &n).unwrap();
    let t0 = std::time::Instant::now();
    let r = m.run(&ParamSet::new(&n, &[1e-9]).unwrap(), &RunContext::default());
    let secs = t0.elapsed().as_secs_f64();
    match r {
        Err(RunError::Failed(s)) => assert!(s.contains("no convergence at t = "), "{s}"),
        other => panic!("expected Failed, got {other:?}"),
    }
    assert!(secs < 20.0, "took {secs} s");
}
