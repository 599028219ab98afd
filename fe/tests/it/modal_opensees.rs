//! Modal analysis against the OpenSees fixtures in `shared/verification/`:
//! the 2.4 m grid (12 modes, frequencies to 1e-6 relative, MAC > 0.9999 on
//! the translations of every listed node) and the 150 m² type-C grid (10
//! modes to 1e-6 of `perf_results.json`). The sparse Lanczos result is also
//! checked against the dense condensed solver on the small grid.

use crate::common::{csv_rows, mac, verification_dir};
use fe::assembly::Structure;
use fe::eigen::{dense_eigen, modal_analysis, LanczosSettings};
use fe::model::read_model;

#[test]
fn ceiling_2p4_matches_opensees_frequencies_and_shapes() {
    let dir = verification_dir().join("models");
    let model = read_model(&dir.join("ceiling_2p4_linear.json")).unwrap();
    let (s, res) = modal_analysis(&model, 12, &LanczosSettings::default()).unwrap();
    let expected: Vec<f64> = csv_rows(&dir.join("ceiling_2p4_eigen.csv"))
        .iter()
        .map(|r| r[1].parse().unwrap())
        .collect();
    assert_eq!(expected.len(), 12);
    for (k, (f, e)) in res.freq_hz.iter().zip(&expected).enumerate() {
        let rel = (f - e).abs() / e;
        assert!(rel < 1e-6, "mode {}: {f} Hz vs OpenSees {e} Hz (rel {rel:.2e})", k + 1);
    }
    let shapes = csv_rows(&dir.join("ceiling_2p4_modeshapes.csv"));
    for mode in 1..=12usize {
        let (mut a, mut b) = (vec![], vec![]);
        for r in shapes.iter().filter(|r| r[0] == mode.to_string()) {
            let node: u64 = r[1].parse().unwrap();
            let eqs = s.dofs.node_eqs(node);
            for d in 0..3 {
                b.push(r[4 + d].parse::<f64>().unwrap());
                a.push(eqs[d].map_or(0.0, |e| res.shapes[mode - 1][e]));
            }
        }
        assert!(!a.is_empty());
        let m = mac(&a, &b);
        assert!(m > 0.9999, "mode {mode}: MAC {m}");
    }
}

#[test]
fn lanczos_agrees_with_the_dense_solver_on_the_small_grid() {
    let dir = verification_dir().join("models");
    let model = read_model(&dir.join("ceiling_2p4_linear.json")).unwrap();
    let s = Structure::new(&model).unwrap();
    let k = s.initial_stiffness();
    let dense = dense_eigen(&s.pattern, &k, &s.mass).unwrap();
    let (_, res) = modal_analysis(&model, 12, &LanczosSettings::default()).unwrap();
    for (w2, d) in res.omega2.iter().zip(&dense.omega2) {
        assert!((w2 - d).abs() < 1e-9 * d, "{w2} vs dense {d}");
    }
}

#[test]
fn type_c_grid_matches_opensees_first_ten_frequencies() {
    let dir = verification_dir().join("perf");
    let model = read_model(&dir.join("ceiling_typeC_nonlinear.json")).unwrap();
    let (s, res) = modal_analysis(&model, 10, &LanczosSettings::default()).unwrap();
    assert_eq!(s.dofs.n_free, 2748);
    let perf: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("perf_results.json")).unwrap())
            .unwrap();
    let expected = perf["eigen"]["-genBandArpack"]["f_hz"].as_array().unwrap();
    for (k, (f, e)) in res.freq_hz.iter().zip(expected).enumerate() {
        let e = e.as_f64().unwrap();
        let rel = (f - e).abs() / e;
        assert!(rel < 1e-6, "mode {}: {f} Hz vs OpenSees {e} Hz (rel {rel:.2e})", k + 1);
    }
}
