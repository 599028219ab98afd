//! Krylov-accelerated iterations on a kept factorization
//! (`NewtonSettings::stale_max_iter`) reach the same motion as full Newton:
//! a 3.6 m x 3.6 m friction-pounding specimen with Pinching4 connections,
//! whose tangent changes in dozens of springs every step, under the first
//! 6 s of the verification sweep at 0.5 g (dt 0.005 s).

mod common;

use common::verification_dir;
use fe::generator::{generate, CeilingSpec, Connections, ModelOptions, Parameters, Perimeter};
use fe::model::{Analysis, Damping, Model};
use fe::transient::{run_model, History, NewtonSettings, TransientOptions};
use serde_json::json;

const STEPS: usize = 1200;

fn pinching4_model() -> Model {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut spec =
        CeilingSpec::from_toml_file(&root.join("configs/specimens/type-c.toml")).unwrap();
    spec.structure.length_x_m = 3.6;
    spec.structure.length_y_m = 3.6;
    let spec =
        spec.with_model(ModelOptions::new(Perimeter::FrictionPounding, Connections::Pinching4));
    let mut m = generate(&spec, &Parameters::prior_midpoints_for(&spec)).unwrap();
    m.damping = Some(Damping {
        kind: "rayleigh".into(),
        alpha_m_per_s: 4.7639975198557405,
        beta_k_s: 0.0005247684902613158,
        extra: Default::default(),
    });
    let mut recorders = vec![json!({"name": "u_x_mm", "node": m.masses[m.masses.len() / 2].node,
                                    "dof": 1, "response": "disp"})];
    for s in &m.springs {
        let (name, response) = match s.group.as_deref() {
            Some("perimeter_friction") => (format!("friction_{}", s.id), "deformation"),
            Some("perimeter_gap") => (format!("gap_{}", s.id), "force"),
            Some("connection_axial") => (format!("joint_{}", s.id), "deformation"),
            _ => continue,
        };
        recorders.push(json!({"name": name, "element": s.id, "response": response}));
    }
    let block = json!({
        "excitation": {"type": "uniform_base_acceleration", "dof": 1,
                       "record_csv": "sweep_x_unit_1g.csv", "dt": 0.002, "npts": 10001,
                       "scale": 0.5},
        "integrator": {"type": "Newmark", "gamma": 0.5, "beta": 0.25},
        "dt": 0.005, "n_steps": STEPS, "recorders": recorders,
    });
    let serde_json::Value::Object(map) = block else { unreachable!() };
    m.analysis = Some(Analysis::Transient(map));
    m
}

/// History, factorizations and Krylov iterations with `stale_max_iter`.
fn run(m: &Model, stale_max_iter: usize) -> (History, usize, usize) {
    let mut opts = TransientOptions::new(&verification_dir().join("models"));
    opts.newton = NewtonSettings { stale_max_iter, ..NewtonSettings::default() };
    let (mut facts, mut stale, mut substeps) = (0, 0, 0);
    let h = run_model(m, &opts, &mut |s| {
        facts = s.factorizations;
        stale = s.stale_iterations;
        substeps += s.substeps;
    })
    .unwrap();
    assert_eq!(substeps, STEPS);
    (h, facts, stale)
}

#[test]
fn krylov_on_a_kept_factor_follows_full_newton() {
    let m = pinching4_model();
    let (h_newton, f_newton, s_newton) = run(&m, 0);
    let (h_krylov, f_krylov, s_krylov) = run(&m, 14);
    eprintln!(
        "full Newton: {f_newton} factorizations; Krylov: {f_krylov} factorizations, \
         {s_krylov} accelerated iterations"
    );
    assert_eq!(s_newton, 0);
    assert!(s_krylov > 0 && f_krylov < f_newton);
    for c in 2..h_newton.columns.len() {
        let peak = h_newton.rows.iter().map(|r| r[c].abs()).fold(0.0, f64::max);
        for (a, b) in h_newton.rows.iter().zip(&h_krylov.rows) {
            assert!(
                (a[c] - b[c]).abs() <= 1e-6 * peak + 1e-9,
                "{}: {} vs {} (peak {peak})",
                h_newton.columns[c],
                a[c],
                b[c]
            );
        }
    }
}
