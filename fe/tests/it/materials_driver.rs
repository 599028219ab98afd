//! The `fe material` driver end to end on files: a shared fixture's material
//! and protocol in, a response CSV out that matches the OpenSees fixture.

use crate::common;
use std::path::PathBuf;

use fe::materials::driver::{run_files, DriverError};

fn materials_dir() -> PathBuf {
    common::verification_dir().join("materials")
}

fn columns(text: &str) -> (String, Vec<[f64; 3]>) {
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_string();
    let rows = lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    (header, rows)
}

#[test]
fn steel01_files_round_trip_to_the_fixture() {
    let dir = materials_dir();
    let tmp = std::env::temp_dir().join(format!("ceilfarm-materials-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let material = tmp.join("steel01.json");
    std::fs::write(&material, r#"{"id": 1, "type": "Steel01", "Fy": 2.0, "E0": 20.0, "b": 0.05}"#)
        .unwrap();
    let out = tmp.join("out.csv");
    let n = run_files(&material, &dir.join("protocol_friction_cyclic.csv"), &out).unwrap();
    assert_eq!(n, 4801);
    let (header, got) = columns(&std::fs::read_to_string(&out).unwrap());
    let (_, want) = columns(&std::fs::read_to_string(dir.join("steel01_friction.csv")).unwrap());
    assert_eq!(header, "deformation_mm,force_N,tangent_N_per_mm");
    for (g, w) in got.iter().zip(&want) {
        assert!((g[1] - w[1]).abs() <= 1e-6 * 6.9 && g[2] == w[2], "{g:?} vs {w:?}");
    }
    std::fs::remove_dir_all(&tmp).ok();
}

#[test]
fn bad_inputs_are_reported_with_their_place() {
    let tmp = std::env::temp_dir().join(format!("ceilfarm-materials-bad-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let material = tmp.join("m.json");
    std::fs::write(&material, r#"{"type": "Gap", "k": 1.0}"#).unwrap();
    let protocol = tmp.join("p.csv");
    std::fs::write(&protocol, "step,deformation_mm\n0,0\n1,x\n").unwrap();
    let out = tmp.join("o.csv");
    assert!(matches!(run_files(&material, &protocol, &out), Err(DriverError::Spec { .. })));
    std::fs::write(&material, r#"{"type": "Gap", "k": 1.0, "gap": -2}"#).unwrap();
    std::fs::write(&protocol, "step,deformation_mm\n0,0\n").unwrap();
    let err = run_files(&material, &protocol, &out).unwrap_err();
    assert!(err.to_string().contains("gap = -2"), "{err}");
    std::fs::write(&material, r#"{"type": "Gap", "k": 1.0, "gap": 2}"#).unwrap();
    std::fs::write(&protocol, "step,deformation_mm\n0,0\n1,x\n").unwrap();
    let err = run_files(&material, &protocol, &out).unwrap_err();
    assert!(matches!(err, DriverError::Protocol { line: 3, .. }), "{err}");
    std::fs::remove_dir_all(&tmp).ok();
}
