//! Newton's convergence test with very stiff springs: a 2.4 m x 4.8 m
//! specimen with elastic connections whose main-tee splices (axial,
//! transverse, vertical, rotation) are 1e10 N/mm (N·mm/rad) springs, under
//! 1 s of the verification sweep at 0.5 g (dt 0.005 s). With only the
//! absolute test ‖Δu‖₂ < 1e-10 mm the increments wander at the round-off
//! floor (1e-10–1e-9 mm) and steps iterate to the limit and subdivide; with
//! the round-off residual test every step converges in a few iterations and
//! the histories agree. At ordinary stiffness the round-off test only ends
//! steps one solve earlier. These are tests of Newton on the whole structure
//! (`condense: false`); a condensed step solves the elastic springs, however
//! stiff, in its one sparse factorization and has no such floor.

use crate::common::verification_dir;
use fe::generator::{generate, CeilingSpec, Connections, ModelOptions, Parameters, Perimeter};
use fe::materials::MaterialSpec;
use fe::model::{Analysis, Damping, Model};
use fe::transient::{run_model, History, NewtonSettings, TransientError, TransientOptions};
use serde_json::json;

const STEPS: usize = 200;

/// The type-C members on 2.4 m x 4.8 m (two splices), splices at `k`.
fn stiff_splice_model(k: f64) -> Model {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut spec =
        CeilingSpec::from_toml_file(&root.join("configs/specimens/type-c.toml")).unwrap();
    spec.structure.length_x_m = 2.4;
    spec.structure.length_y_m = 4.8;
    let spec =
        spec.with_model(ModelOptions::new(Perimeter::FrictionPounding, Connections::Elastic));
    let mut m = generate(&spec, &Parameters::prior_midpoints_for(&spec)).unwrap();
    let splice_mats: Vec<u64> = m
        .springs
        .iter()
        .filter(|s| s.group.as_deref().is_some_and(|g| g.starts_with("splice")))
        .map(|s| s.mat)
        .collect();
    assert!(!splice_mats.is_empty(), "the specimen has splices");
    for d in &mut m.materials {
        if let (true, MaterialSpec::Elastic { k: kd }) = (splice_mats.contains(&d.id), &mut d.spec)
        {
            *kd = k;
        }
    }
    m.damping = Some(Damping {
        kind: "rayleigh".into(),
        alpha_m_per_s: 4.7639975198557405,
        beta_k_s: 0.0005247684902613158,
        extra: Default::default(),
    });
    let mut recorders = vec![json!({"name": "u_x_mm", "node": m.masses[m.masses.len() / 2].node,
                                    "dof": 1, "response": "disp"})];
    for s in &m.springs {
        if s.group.as_deref() == Some("perimeter_friction") {
            recorders.push(json!({"name": format!("friction_{}", s.id), "element": s.id,
                                  "response": "deformation"}));
        }
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

/// History, total sub-steps and Newton iterations, or the failure.
fn run(
    m: &Model,
    newton: NewtonSettings,
    max_halvings: u32,
) -> Result<(History, usize, usize), TransientError> {
    let mut opts = TransientOptions::new(&verification_dir().join("models"));
    opts.newton = newton;
    opts.max_halvings = max_halvings;
    let (mut substeps, mut iterations) = (0, 0);
    let h = run_model(m, &opts, &mut |s| {
        substeps += s.substeps;
        iterations += s.iterations;
    })?;
    Ok((h, substeps, iterations))
}

/// Newton on the whole structure with the round-off test.
fn whole() -> NewtonSettings {
    NewtonSettings { condense: false, ..NewtonSettings::default() }
}

/// Newton on the whole structure with the absolute test alone.
fn absolute_only() -> NewtonSettings {
    NewtonSettings { floor_factor: 0.0, ..whole() }
}

#[test]
fn stiff_splices_converge_without_subdividing() {
    let m = stiff_splice_model(1e10);
    let (h, substeps, iterations) = run(&m, whole(), 6).unwrap();
    let (_, substeps_abs, iterations_abs) = run(&m, absolute_only(), 6).unwrap();
    eprintln!(
        "1e10 N/mm splices, {STEPS} steps: {substeps} sub-steps, {iterations} iterations; \
         absolute test only: {substeps_abs} sub-steps, {iterations_abs} iterations"
    );
    assert_eq!(substeps, STEPS, "no step subdivides");
    assert!(iterations <= 3 * STEPS, "{iterations} Newton iterations");
    // Without subdivision the absolute test alone fails on the floor...
    let Err(TransientError::NoConvergence { step, reason, history, .. }) =
        run(&m, absolute_only(), 0)
    else {
        panic!("the absolute test alone converged every step");
    };
    eprintln!("absolute test only, no subdivision: step {step}: {reason}");
    assert!(reason.contains("Newton iterations"), "{reason}");
    // ...and up to there both follow the same motion.
    let peak = h.rows.iter().flat_map(|r| r[2..].iter()).fold(0.0f64, |a, x| a.max(x.abs()));
    assert!(history.rows.len() > 1);
    for (a, b) in h.rows.iter().zip(&history.rows) {
        for (x, y) in a[2..].iter().zip(&b[2..]) {
            assert!((x - y).abs() < 1e-9 * peak, "{x} vs {y} (peak {peak} mm)");
        }
    }
    // Condensed onto the friction and gap springs, the absolute test alone
    // converges every step: the splices are inside the sparse factor. The
    // two solutions differ by round-off that grows with the splices'
    // stiffness (largest difference over the peak, 200 steps: 5.8e-11 at
    // 1e7 N/mm, 7.3e-10 at 1e8, 1.2e-8 at 1e9, 1.0e-8 at 1e10).
    let condensed = NewtonSettings { floor_factor: 0.0, ..NewtonSettings::default() };
    let (hc, substeps_c, iterations_c) = run(&m, condensed, 0).unwrap();
    eprintln!("condensed, absolute test only: {substeps_c} sub-steps, {iterations_c} iterations");
    assert!(iterations_c <= 3 * STEPS, "{iterations_c} Newton iterations");
    for (a, b) in h.rows.iter().zip(&hc.rows) {
        for (x, y) in a[2..].iter().zip(&b[2..]) {
            assert!((x - y).abs() < 5e-8 * peak, "{x} vs {y} (peak {peak} mm)");
        }
    }
}

#[test]
fn at_ordinary_stiffness_the_floor_ends_steps_early_on_the_same_motion() {
    // At the generator's 1e7 N/mm the absolute test converges every step
    // too; the round-off test ends a step once the state after an increment
    // is in equilibrium, skipping the solve that would confirm it, and the
    // motion is the same to round-off.
    let m = stiff_splice_model(1e7);
    let (h, substeps, iterations) = run(&m, whole(), 6).unwrap();
    let (h_abs, substeps_abs, iterations_abs) = run(&m, absolute_only(), 6).unwrap();
    eprintln!("1e7 N/mm splices: {iterations} iterations; absolute test only: {iterations_abs}");
    assert_eq!((substeps, substeps_abs), (STEPS, STEPS));
    assert!(iterations < iterations_abs, "{iterations} vs {iterations_abs} iterations");
    let peak = h.rows.iter().flat_map(|r| r[2..].iter()).fold(0.0f64, |a, x| a.max(x.abs()));
    // The condensed step (the default) follows the same motion.
    let (h_cond, substeps_cond, _) = run(&m, NewtonSettings::default(), 6).unwrap();
    assert_eq!(substeps_cond, STEPS);
    for other in [&h_abs, &h_cond] {
        assert_eq!(h.rows.len(), other.rows.len());
        for (a, b) in h.rows.iter().zip(&other.rows) {
            for (x, y) in a[2..].iter().zip(&b[2..]) {
                assert!((x - y).abs() < 1e-9 * peak, "{x} vs {y} (peak {peak} mm)");
            }
        }
    }
}
