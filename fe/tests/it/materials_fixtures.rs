//! Every OpenSees material fixture in `shared/verification/materials/`
//! reproduced: the material of `materials.json` driven through its protocol,
//! one committed step per row, force within 1e-6 of the fixture's peak
//! |force| on every row. Tangents are compared and reported too.

use crate::common::verification_dir;
use std::path::Path;

use fe::materials::driver::read_protocol_file;
use fe::materials::{drive, MaterialSpec};

/// Rows (deformation, force, tangent) of a fixture CSV.
fn read_fixture(path: &Path) -> Vec<(f64, f64, f64)> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
            (v[0], v[1], v[2])
        })
        .collect()
}

/// Drives fixture `name` and returns (max |force error| / peak, tangent
/// rows differing by more than 1e-6 of the peak tangent, max tangent error).
fn check_fixture(name: &str) -> (f64, usize, f64) {
    let dir = verification_dir().join("materials");
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("materials.json")).unwrap())
            .unwrap();
    let fixture = meta["fixtures"].as_array().unwrap().iter().find(|f| f["name"] == name).unwrap();
    let spec: MaterialSpec = serde_json::from_value(fixture["material"].clone()).unwrap();
    let protocol_name = fixture["protocol"].as_str().unwrap();
    let protocol_file = meta["protocols"][protocol_name]["file"].as_str().unwrap();
    let d = read_protocol_file(&dir.join(protocol_file)).unwrap();
    let expected = read_fixture(&dir.join(fixture["file"].as_str().unwrap()));
    assert_eq!(d.len(), expected.len(), "{name}: protocol and fixture lengths");
    let got = drive(&spec, &d).unwrap();
    let peak_f = expected.iter().fold(0.0_f64, |m, r| m.max(r.1.abs()));
    let peak_k = expected.iter().fold(0.0_f64, |m, r| m.max(r.2.abs()));
    let mut worst = (0.0_f64, 0usize);
    let (mut k_bad, mut k_worst) = (0usize, 0.0_f64);
    for (i, (g, e)) in got.iter().zip(&expected).enumerate() {
        assert!((g.0 - e.0).abs() < 1e-9, "{name}: row {i} deformation {} vs {}", g.0, e.0);
        let err = (g.1 - e.1).abs() / peak_f;
        if err > worst.0 {
            worst = (err, i);
        }
        let k_err = (g.2 - e.2).abs();
        k_worst = k_worst.max(k_err);
        if k_err > 1e-6 * peak_k {
            k_bad += 1;
        }
    }
    let i = worst.1;
    println!(
        "{name}: {} rows, max |force error| / peak = {:.3e} (row {i}: got {}, fixture {}); \
         tangent rows off by > 1e-6 peak: {k_bad}, max tangent error {k_worst:.3e} N/mm",
        got.len(),
        worst.0,
        got[i].1,
        expected[i].1
    );
    (worst.0, k_bad, k_worst)
}

#[test]
fn pinching4_cjsa() {
    let (err, _, _) = check_fixture("pinching4_cjsa");
    assert!(err <= 1e-6, "pinching4_cjsa: {err:e}");
}

#[test]
fn steel01_friction() {
    let (err, _, _) = check_fixture("steel01_friction");
    assert!(err <= 1e-6, "steel01_friction: {err:e}");
}

#[test]
fn impact_k300_k100_gap13p3() {
    let (err, _, _) = check_fixture("impact_k300_k100_gap13p3");
    assert!(err <= 1e-6, "impact: {err:e}");
}

#[test]
fn gap_k588_gap19() {
    let (err, _, _) = check_fixture("gap_k588_gap19");
    assert!(err <= 1e-6, "gap: {err:e}");
}
