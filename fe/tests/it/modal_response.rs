//! The linear response by modal superposition against the FE transient on
//! the same linear model: with every mode that carries mass the two agree
//! to round-off (the projection is exact and both integrate by Newmark
//! average acceleration from rest); with the lowest modes only the error is
//! the quasi-static response of the modes left out, measured here.

use fe::ceiling::{
    simulate, simulate_linear, sine_sweep, BaseInput, Direction, Sensor, SensorKind, SimOptions,
    SineSweep,
};
use fe::generator::{CeilingSpec, Parameters};

fn spec(lx: f64, ly: f64) -> CeilingSpec {
    let text = format!(
        r#"
        [structure]
        length_x_m = {lx}
        length_y_m = {ly}
        module_m = 0.6
        main_tee_spacing_m = 1.2
        hanger_spacing_m = 1.2
        hanger_length_m = 1.0
        panel_mass_kg = 1.2
        boundary = "semi-free"
        nominal_gap_mm = 19.0
    "#
    );
    CeilingSpec::from_toml_str(&text, std::path::Path::new("test")).unwrap()
}

fn sensors() -> Vec<Sensor> {
    let s =
        |id: &str, kind, x_m, y_m, direction| Sensor { id: id.into(), kind, x_m, y_m, direction };
    vec![
        s("ax", SensorKind::Acceleration, 1.2, 1.8, Direction::X),
        s("ay", SensorKind::Acceleration, 0.6, 1.2, Direction::Y),
        s("dx", SensorKind::Displacement, 1.5, 1.8, Direction::X),
        s("dy", SensorKind::Displacement, 1.8, 0.6, Direction::Y),
    ]
}

/// A 12 → 1 Hz sweep in x and a 1 → 12 Hz one in y, 8 s at 200 Hz.
fn input() -> BaseInput {
    let sweep = |a, b| {
        let s = SineSweep {
            f_start_hz: a,
            f_end_hz: b,
            duration_s: 8.0,
            amplitude_m_s2: 0.5,
            ramp_s: 1.0,
        };
        sine_sweep(&s, 0.005)
    };
    BaseInput { dt_s: 0.005, x_m_s2: Some(sweep(12.0, 1.0)), y_m_s2: Some(sweep(1.0, 12.0)) }
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// Largest RMS(modal − FE) / RMS(FE) over the sensors.
fn worst_error(params: &Parameters, n_modes: usize, opts: &SimOptions) -> f64 {
    let (sp, inp, sen) = (spec(2.4, 3.6), input(), sensors());
    let fe = simulate(&sp, params, &inp, &sen, opts, &mut |_| {}).unwrap();
    let lin = simulate_linear(&sp, params, &inp, &sen, opts, n_modes).unwrap();
    // More modes asked of Lanczos move the first ones by its tolerance only.
    let close = |a: f64, b: f64| (a - b).abs() < 1e-9 * b.abs();
    assert!(lin.simulation.freq_hz.iter().zip(&fe.freq_hz).all(|(a, b)| close(*a, *b)));
    assert!(close(lin.simulation.rayleigh.beta_k_s, fe.rayleigh.beta_k_s));
    let e = fe
        .sensors
        .iter()
        .zip(&lin.simulation.sensors)
        .map(|(a, b)| {
            assert_eq!(a.values.len(), b.values.len());
            let diff: Vec<f64> = a.values.iter().zip(&b.values).map(|(x, y)| x - y).collect();
            rms(&diff) / rms(&a.values)
        })
        .fold(0.0, f64::max);
    let label = if n_modes == usize::MAX { "every".to_string() } else { n_modes.to_string() };
    eprintln!("{label} modes: worst relative RMS error {e:.3e}");
    e
}

fn elastic_opts() -> SimOptions {
    SimOptions {
        damping_ratio: 0.03,
        rayleigh_groups: vec!["perimeter_friction".into()],
        ..SimOptions::default()
    }
}

#[test]
fn every_mode_reproduces_the_transient() {
    let params = Parameters::prior_midpoints_for(&spec(2.4, 3.6));
    let e = worst_error(&params, usize::MAX, &elastic_opts());
    assert!(e < 1e-7, "relative RMS error {e}");
}

#[test]
fn every_mode_reproduces_the_transient_of_another_linear_form() {
    let mut params = Parameters::prior_midpoints_for(&spec(2.4, 3.6));
    for (name, value) in [
        ("K_friction", 30.0),
        ("K_across", 150.0),
        ("member_mass_factor", 1.0),
        ("panel_mass_factor", 0.9),
        ("rod_bending_factor", 0.25),
        ("grid_axial_factor", 0.1),
        ("grid_bending_factor", 0.5),
    ] {
        params.set(name, value).unwrap();
    }
    let opts = SimOptions { damping_mass_share: 0.8, ..elastic_opts() };
    let e = worst_error(&params, usize::MAX, &opts);
    assert!(e < 1e-7, "relative RMS error {e}");
}

#[test]
fn the_lowest_forty_modes_miss_little() {
    let params = Parameters::prior_midpoints_for(&spec(2.4, 3.6));
    let e = worst_error(&params, 40, &elastic_opts());
    // Measured 1.6e-7 on this 2.4 m x 3.6 m grid.
    assert!(e < 1e-5, "relative RMS error {e}");
}
