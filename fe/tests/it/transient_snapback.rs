//! A run with no equilibrium to find ends as a recorded failure with its
//! time and reason, within seconds. The model, built in code: a massless
//! node 2 held to the ground by a softening Takeda spring (100 N at 1 mm,
//! then −50 N/mm without end) and to a 1 kg mass (node 3) by a 10 N/mm
//! spring. In series they snap back: past the Takeda peak the mass's
//! displacement u3 = u2 + f(u2)/10 is largest, 11 mm, at u2 = 1 mm, so no
//! state of node 2 balances u3 > 11 mm. A 200 N ground-motion load (20.4 g on
//! 1 kg) drives the mass there in about 0.011 s (static 22 mm, dynamic
//! 22 (1 − cos ωt) with ω = 95 rad/s); no sub-step can pass that point.

use std::path::PathBuf;
use std::time::Instant;

use fe::materials::{MaterialSpec, TakedaSpec};
use fe::model::{validate, Analysis, Fixity, Mass, MaterialDef, Model, Node, Spring, Units};
use fe::transient::{run_model, TransientError, TransientOptions};
use serde_json::json;

fn scratch_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ceilfarm_fe_{name}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn spring(id: u64, i: u64, j: u64, mat: u64) -> Spring {
    Spring { id, i, j, dof: 1, mat, rayleigh: false, group: None, side: None, member: None }
}

fn snap_back_model() -> Model {
    let takeda = TakedaSpec {
        ePd: vec![1.0, 2.0],
        ePf: vec![100.0, 50.0],
        eNd: vec![-1.0, -2.0],
        eNf: vec![-100.0, -50.0],
        alpha: 0.0,
    };
    let block = json!({
        "excitation": {"type": "uniform_base_acceleration", "dof": 1, "record_csv": "step.csv",
                       "dt": 0.1, "npts": 2, "scale": 1.0},
        "integrator": {"type": "Newmark", "gamma": 0.5, "beta": 0.25},
        "dt": 0.001, "n_steps": 100,
        "recorders": [{"name": "u3_mm", "node": 3, "dof": 1, "response": "disp"},
                      {"name": "takeda_N", "element": 10, "response": "force"}],
    });
    let serde_json::Value::Object(map) = block else { unreachable!() };
    let free_x = [false, true, true, true, true, true];
    Model {
        format: fe::model::FORMAT_NAME.into(),
        format_version: fe::model::FORMAT_VERSION,
        name: "snap_back".into(),
        description: "softening spring in series with an elastic one, massless middle node".into(),
        units: Units::standard(),
        ndm: 3,
        ndf: 6,
        nodes: (1..=3).map(|id| Node { id, xyz_mm: [0.0; 3] }).collect(),
        fixities: vec![
            Fixity { node: 1, fixed: [true; 6] },
            Fixity { node: 2, fixed: free_x },
            Fixity { node: 3, fixed: free_x },
        ],
        materials: vec![
            MaterialDef { id: 1, spec: MaterialSpec::Takeda(Box::new(takeda)) },
            MaterialDef { id: 2, spec: MaterialSpec::Elastic { k: 10.0 } },
        ],
        beams: vec![],
        springs: vec![spring(10, 1, 2, 1), spring(11, 2, 3, 2)],
        masses: vec![Mass { node: 3, m_t: [0.001, 0.0, 0.0, 0.0, 0.0, 0.0] }],
        damping: None,
        analysis: Some(Analysis::Transient(map)),
        meta: None,
    }
}

#[test]
fn snap_back_without_mass_fails_with_time_reason_and_history() {
    let dir = scratch_dir("snap_back");
    std::fs::write(dir.join("step.csv"), "t_s,ag_mm_s2\n0,-200000\n0.1,-200000\n").unwrap();
    let model = snap_back_model();
    validate(&model).unwrap();
    let t0 = Instant::now();
    let err = run_model(&model, &TransientOptions::new(&dir), &mut |_| {}).unwrap_err();
    let secs = t0.elapsed().as_secs_f64();
    eprintln!("{err} ({secs:.3} s)");
    assert!(secs < 5.0, "took {secs} s");
    let TransientError::NoConvergence { t_s, step, history, .. } = &err else {
        panic!("expected NoConvergence, got {err:?}")
    };
    // The limit is reached after about 0.011 s, well before the record ends.
    assert!(*t_s > 0.005 && *t_s < 0.05, "failed at t = {t_s} s");
    assert!(*step > 5 && *step < 50, "step {step}");
    assert_eq!(history.rows.len(), *step, "rows for t = 0 and every converged step");
    let u3 = history.column("u3_mm").unwrap();
    let last = u3.last().unwrap().abs();
    assert!(last > 5.0 && last <= 11.0 + 1e-9, "last converged |u3| = {last} mm");
}
