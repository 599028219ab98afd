//! Newton variants reach the same motion as full Newton on the whole
//! structure: Krylov-accelerated iterations on a kept factorization
//! (`NewtonSettings::stale_max_iter`) and steps condensed onto the nonlinear
//! springs (`NewtonSettings::condense`). The specimen: 3.6 m x 3.6 m,
//! friction-pounding perimeter with Pinching4 connections, whose tangent
//! changes in dozens of springs every step, under the first 6 s of the
//! verification sweep at 0.5 g (dt 0.005 s).

use crate::common::verification_dir;
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

/// Full Newton on the whole structure (no condensation, no Krylov).
fn full_newton() -> NewtonSettings {
    NewtonSettings { condense: false, ..NewtonSettings::default() }
}

/// Solver counts of a run.
#[derive(Debug, Default)]
struct Counts {
    factorizations: usize,
    stale: usize,
    dense: usize,
}

/// History and solver counts with `newton`.
fn run(m: &Model, newton: NewtonSettings) -> (History, Counts) {
    let mut opts = TransientOptions::new(&verification_dir().join("models"));
    opts.newton = newton;
    let (mut c, mut substeps) = (Counts::default(), 0);
    let h = run_model(m, &opts, &mut |s| {
        c = Counts {
            factorizations: s.factorizations,
            stale: s.stale_iterations,
            dense: s.dense_factorizations,
        };
        substeps += s.substeps;
    })
    .unwrap();
    assert_eq!(substeps, STEPS);
    (h, c)
}

/// Largest difference of two histories per column, over the column's peak.
fn max_relative_difference(a: &History, b: &History) -> f64 {
    assert_eq!(a.columns, b.columns);
    let mut worst = 0.0f64;
    for c in 2..a.columns.len() {
        let peak = a.rows.iter().map(|r| r[c].abs()).fold(0.0, f64::max).max(1e-300);
        for (x, y) in a.rows.iter().zip(&b.rows) {
            worst = worst.max((x[c] - y[c]).abs() / peak);
        }
    }
    worst
}

#[test]
fn krylov_on_a_kept_factor_follows_full_newton() {
    let m = pinching4_model();
    let (h_newton, newton) = run(&m, full_newton());
    let (h_krylov, krylov) = run(&m, NewtonSettings { stale_max_iter: 14, ..full_newton() });
    let (f_newton, s_newton) = (newton.factorizations, newton.stale);
    let (f_krylov, s_krylov) = (krylov.factorizations, krylov.stale);
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

#[test]
fn condensed_steps_follow_full_newton() {
    let m = pinching4_model();
    let (h_full, full) = run(&m, full_newton());
    let (h_cond, cond) = run(&m, NewtonSettings::default());
    let worst = max_relative_difference(&h_full, &h_cond);
    eprintln!("full: {full:?}; condensed: {cond:?}; largest difference {worst:.2e} of a peak");
    assert_eq!(full.dense, 0);
    // One sparse factorization per step size, dense solves instead.
    assert!(cond.dense > 0 && cond.factorizations < 5 && full.factorizations > 100);
    assert!(worst <= 1e-6, "{worst}");
}
