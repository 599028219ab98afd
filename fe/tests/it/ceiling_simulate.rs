//! A simulated shaking-table run of a small generated ceiling: the base
//! input reaches the sensors as physics says it must.

use fe::ceiling::{simulate, sine_sweep, BaseInput, Direction, Sensor, SensorKind, SimOptions};
use fe::generator::{CeilingSpec, Parameters};

fn spec() -> CeilingSpec {
    let text = r#"
        [structure]
        length_x_m = 3.6
        length_y_m = 3.6
        module_m = 0.6
        main_tee_spacing_m = 1.2
        hanger_spacing_m = 1.2
        hanger_length_m = 1.0
        panel_mass_kg = 1.2
        boundary = "semi-free"
        nominal_gap_mm = 19.0
    "#;
    CeilingSpec::from_toml_str(text, std::path::Path::new("test")).unwrap()
}

fn sensor(id: &str, kind: SensorKind, x_m: f64, y_m: f64, direction: Direction) -> Sensor {
    Sensor { id: id.into(), kind, x_m, y_m, direction }
}

fn harmonic(f_hz: f64, amp: f64, dt: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 * dt;
            let ramp = (t / 1.0).min(1.0);
            amp * ramp * (2.0 * std::f64::consts::PI * f_hz * t).sin()
        })
        .collect()
}

fn peak(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

#[test]
fn slow_shaking_moves_the_ceiling_with_the_base() {
    let dt = 0.005;
    let input = BaseInput { dt_s: dt, x_m_s2: Some(harmonic(0.5, 1.0, dt, 1200)), y_m_s2: None };
    let sensors = [
        sensor("ax", SensorKind::Acceleration, 1.8, 1.8, Direction::X),
        sensor("ay", SensorKind::Acceleration, 1.8, 1.8, Direction::Y),
        sensor("dx", SensorKind::Displacement, 1.5, 1.8, Direction::X),
    ];
    let opts =
        SimOptions { spring_groups: vec!["perimeter_friction".into()], ..Default::default() };
    let params = Parameters::prior_midpoints();
    let sim = simulate(&spec(), &params, &input, &sensors, &opts, &mut |_| {}).unwrap();
    assert!(sim.freq_hz[0] > 2.0, "{:?}", sim.freq_hz);
    let ax = &sim.sensors[0].values;
    assert_eq!(ax.len(), 1200);
    // Far below resonance: |H| = 1 + (f/f1)^2 / (1 - (f/f1)^2) ≈ 1 within 2 %.
    let ratio = peak(&ax[400..]) / peak(&input.x_m_s2.as_ref().unwrap()[400..]);
    assert!((ratio - 1.0).abs() < 0.02, "ratio {ratio}");
    // Symmetric specimen, x input: no y response.
    assert!(peak(&sim.sensors[1].values) < 1e-6 * peak(ax), "{}", peak(&sim.sensors[1].values));
    // Relative displacement ≈ a / ω1² (quasi-static) to within 10 %.
    let w1 = 2.0 * std::f64::consts::PI * sim.rayleigh.fx_hz;
    let d = peak(&sim.sensors[2].values[400..]);
    assert!((d * w1 * w1 - 1.0).abs() < 0.1, "d {d} m, omega1^2 d = {}", d * w1 * w1);
    // Elastic perimeter springs: peak force = K_friction x peak deformation;
    // 5 cross-tee ends on each x wall and 5 y-line ends on each y wall.
    let p = &sim.spring_peaks[0];
    assert_eq!(p.count, 20);
    let k = params.get("K_friction");
    assert!((p.force_n - k * p.deformation_mm).abs() < 1e-9 * p.force_n, "{p:?}");
    assert!((p.deformation_mm - 1e3 * peak(&sim.sensors[2].values)).abs() < 0.1 * p.deformation_mm);
}

#[test]
fn resonance_amplifies_about_one_over_two_zeta() {
    let dt = 0.005;
    let probe = BaseInput { dt_s: dt, x_m_s2: Some(vec![0.0; 2]), y_m_s2: None };
    let opts = SimOptions::default();
    let sensors = [sensor("ax", SensorKind::Acceleration, 1.8, 1.8, Direction::X)];
    let params = Parameters::prior_midpoints();
    let fx =
        simulate(&spec(), &params, &probe, &sensors, &opts, &mut |_| {}).unwrap().rayleigh.fx_hz;
    let input = BaseInput { dt_s: dt, x_m_s2: Some(harmonic(fx, 0.1, dt, 3000)), y_m_s2: None };
    let sim = simulate(&spec(), &params, &input, &sensors, &opts, &mut |_| {}).unwrap();
    let amp = peak(&sim.sensors[0].values[2000..]) / 0.1;
    // SDOF at resonance: |H_abs| = sqrt(1 + (2ζ)^2) / 2ζ = 10.05 at ζ = 0.05; a
    // multi-mode grid with the sensor at mid-span reads close to it.
    assert!(amp > 7.0 && amp < 13.0, "amplification {amp}");
}

#[test]
fn sweep_in_both_directions_runs_and_bad_input_is_refused() {
    let dt = 0.01;
    let sweep = fe::ceiling::SineSweep::seed(4.0, 0.5);
    let a = sine_sweep(&sweep, dt);
    let input = BaseInput { dt_s: dt, x_m_s2: Some(a.clone()), y_m_s2: Some(a) };
    let sensors = [
        sensor("x", SensorKind::Acceleration, 0.6, 1.2, Direction::X),
        sensor("y", SensorKind::Acceleration, 0.6, 1.2, Direction::Y),
    ];
    let p = Parameters::prior_midpoints();
    let o = SimOptions::default();
    let sim = simulate(&spec(), &p, &input, &sensors, &o, &mut |_| {}).unwrap();
    assert!(peak(&sim.sensors[0].values) > 0.1 && peak(&sim.sensors[1].values) > 0.1);
    let outside = [sensor("far", SensorKind::Acceleration, 4.0, 1.0, Direction::X)];
    let e = simulate(&spec(), &p, &input, &outside, &o, &mut |_| {}).unwrap_err();
    assert!(e.to_string().contains("sensor far") && e.to_string().contains("outside"), "{e}");
    let bad = BaseInput { dt_s: dt, x_m_s2: Some(vec![0.0, f64::NAN, 0.0]), y_m_s2: None };
    let e = simulate(&spec(), &p, &bad, &sensors, &o, &mut |_| {}).unwrap_err();
    assert!(e.to_string().contains("sample 1"), "{e}");
}
