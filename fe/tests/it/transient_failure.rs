//! A run that cannot converge ends as an error with the time and the reason,
//! quickly, never a hang or a panic: a massless DOF whose two springs have
//! tangents k and −k has zero effective stiffness, so no step size helps.

use std::path::PathBuf;
use std::time::Instant;

use fe::model::parse_model;
use fe::transient::{run_model, TransientError, TransientOptions};

fn scratch_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ceilfarm_fe_{name}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

const MODEL: &str = r#"{
 "format": "ceiling-fe-model", "format_version": 1, "name": "singular",
 "units": {"force": "N", "length": "mm", "time": "s", "mass": "t"}, "ndm": 3, "ndf": 6,
 "nodes": [[1, 0, 0, 0], [2, 0, 0, 0], [3, 0, 0, 0]],
 "fixities": [[1, 1, 1, 1, 1, 1, 1], [2, 0, 1, 1, 1, 1, 1], [3, 0, 1, 1, 1, 1, 1]],
 "materials": [{"id": 1, "type": "Elastic", "k": 100.0}, {"id": 2, "type": "Elastic", "k": -100.0}],
 "beams": [],
 "springs": [{"id": 10, "i": 1, "j": 2, "dof": 1, "mat": 1},
             {"id": 11, "i": 1, "j": 2, "dof": 1, "mat": 2},
             {"id": 12, "i": 1, "j": 3, "dof": 1, "mat": 1}],
 "masses": [{"node": 3, "m": [0.001, 0, 0, 0, 0, 0]}],
 "analysis": {"type": "transient",
   "excitation": {"type": "uniform_base_acceleration", "dof": 1, "record_csv": "rec.csv",
                  "dt": 0.01, "npts": 3, "scale": 1.0},
   "integrator": {"type": "Newmark", "gamma": 0.5, "beta": 0.25},
   "dt": 0.01, "n_steps": 2,
   "recorders": [{"name": "u3_mm", "node": 3, "dof": 1, "response": "disp"}]}
}"#;

#[test]
fn zero_stiffness_massless_dof_fails_with_time_and_reason() {
    let dir = scratch_dir("singular");
    std::fs::write(dir.join("rec.csv"), "t_s,ag_mm_s2\n0,0\n0.01,1000\n0.02,1000\n").unwrap();
    let model = parse_model(MODEL, &dir.join("m.json")).unwrap();
    let t0 = Instant::now();
    let err = run_model(&model, &TransientOptions::new(&dir), &mut |_| {}).unwrap_err();
    let secs = t0.elapsed().as_secs_f64();
    assert!(secs < 5.0, "took {secs} s");
    match &err {
        TransientError::NoConvergence { t_s, step, history, .. } => {
            assert_eq!(*step, 1);
            assert_eq!(*t_s, 0.0);
            assert_eq!(history.rows.len(), 1, "only the t = 0 row");
        }
        other => panic!("expected NoConvergence, got {other:?}"),
    }
    let text = err.to_string();
    assert!(text.contains("t = 0 s"), "{text}");
    eprintln!("{text}");
}
