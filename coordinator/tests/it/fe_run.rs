//! `ceilfarm fe run` end to end: the 2.4 m grid fixture's 12 frequencies
//! within 1e-6 of OpenSees, mode shapes with MAC > 0.9999, `--modes`
//! override, and a clear error for an invalid file.

use crate::common::*;

use std::path::{Path, PathBuf};

/// The shared verification folder.
fn verification() -> PathBuf {
    shared().join("verification")
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ceilfarm-fe-run-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn rows(path: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines().skip(1).map(|l| l.split(',').map(str::to_string).collect()).collect()
}

fn mac(a: &[f64], b: &[f64]) -> f64 {
    let ab: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let aa: f64 = a.iter().map(|x| x * x).sum();
    let bb: f64 = b.iter().map(|x| x * x).sum();
    ab * ab / (aa * bb)
}

#[test]
fn fe_run_reproduces_the_opensees_eigen_fixture() {
    let models = verification().join("models");
    let out = scratch("2p4");
    let model = models.join("ceiling_2p4_linear.json");
    ceilfarm_ok(&["fe", "run", model.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let got = rows(&out.join("eigen.csv"));
    let want = rows(&models.join("ceiling_2p4_eigen.csv"));
    assert_eq!(got.len(), 12);
    for (g, w) in got.iter().zip(&want) {
        let (f, e): (f64, f64) = (g[1].parse().unwrap(), w[1].parse().unwrap());
        assert!((f - e).abs() / e < 1e-6, "mode {}: {f} vs {e}", g[0]);
    }
    let got = rows(&out.join("modeshapes.csv"));
    let want = rows(&models.join("ceiling_2p4_modeshapes.csv"));
    for mode in 1..=12 {
        let pick = |r: &Vec<Vec<String>>| -> Vec<(String, [f64; 3])> {
            r.iter()
                .filter(|r| r[0] == mode.to_string())
                .map(|r| (r[1].clone(), [4, 5, 6].map(|c| r[c].parse().unwrap())))
                .collect()
        };
        let (g, w) = (pick(&got), pick(&want));
        let mut a = vec![];
        let mut b = vec![];
        for (node, v) in &w {
            let (_, u) = g.iter().find(|(n, _)| n == node).expect("node in modeshapes.csv");
            a.extend(u);
            b.extend(v);
        }
        let m = mac(&a, &b);
        assert!(m > 0.9999, "mode {mode}: MAC {m}");
    }
}

#[test]
fn fe_run_modes_override_and_bad_file() {
    let models = verification().join("models");
    let out = scratch("override");
    let model = models.join("ceiling_2p4_nonlinear_sweep_0p02g.json");
    // A transient file runs as eigen when --modes is given.
    ceilfarm_ok(&[
        "fe",
        "run",
        model.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--modes",
        "3",
    ]);
    assert_eq!(rows(&out.join("eigen.csv")).len(), 3);
    // A file with no analysis block is refused with the reason.
    let text = std::fs::read_to_string(&model).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json.as_object_mut().unwrap().remove("analysis");
    let none = out.join("none.json");
    std::fs::write(&none, json.to_string()).unwrap();
    let o = ceilfarm(&["fe", "run", none.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("analysis `none`"), "{err}");
    // An invalid model names the item.
    let text = std::fs::read_to_string(models.join("ceiling_2p4_linear.json")).unwrap();
    let bad = out.join("bad.json");
    std::fs::write(&bad, text.replace("\"length\": \"mm\"", "\"length\": \"m\"")).unwrap();
    let o = ceilfarm(&["fe", "run", bad.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("units.length = `m`: expected `mm`"), "{err}");
}

#[test]
fn fe_mesh_writes_a_model_that_fe_run_reads() {
    let out = scratch("mesh");
    let spec = repo().join("configs/specimens/type-c.toml");
    let model = out.join("type-c.json");
    ceilfarm_ok(&[
        "fe",
        "mesh",
        spec.to_str().unwrap(),
        "--set",
        "A_main=38",
        "--set",
        "K_friction=20",
        "--out",
        model.to_str().unwrap(),
    ]);
    ceilfarm_ok(&[
        "fe",
        "run",
        model.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--modes",
        "2",
    ]);
    let f: Vec<f64> = rows(&out.join("eigen.csv")).iter().map(|r| r[1].parse().unwrap()).collect();
    // The perf fixture's first two frequencies (perf_results.json).
    assert!((f[0] - 6.567655664643659).abs() / f[0] < 1e-6, "{f:?}");
    assert!((f[1] - 6.711438020176514).abs() / f[1] < 1e-6, "{f:?}");
    let o = ceilfarm(&[
        "fe",
        "mesh",
        spec.to_str().unwrap(),
        "--set",
        "K_cc1=800",
        "--out",
        model.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("K_cc1"));
}

#[test]
fn fe_plot_modes_draws_an_svg() {
    let models = verification().join("models");
    let out = scratch("plot");
    let model = models.join("ceiling_2p4_linear.json");
    ceilfarm_ok(&["fe", "run", model.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let svg = out.join("modes.svg");
    ceilfarm_ok(&["fe", "plot-modes", out.to_str().unwrap(), "--out", svg.to_str().unwrap()]);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.starts_with("<svg") && text.contains("mode 1: 15.145 Hz"),
        "{}",
        &text[..200.min(text.len())]
    );
}

fn table(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(str::to_string).collect();
    let rows = lines.map(|l| l.split(',').map(|v| v.parse::<f64>().unwrap()).collect()).collect();
    (header, rows)
}

#[test]
fn fe_run_writes_the_transient_history_opensees_wrote() {
    let models = verification().join("models");
    let out = scratch("sweep002");
    let model = models.join("ceiling_2p4_nonlinear_sweep_0p02g.json");
    ceilfarm_ok(&["fe", "run", model.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"]);
    let (h, got) = table(&out.join("history.csv"));
    let (hw, want) = table(&models.join("ceiling_2p4_nonlinear_sweep_0p02g_history.csv"));
    assert_eq!(h, hw, "same header");
    assert_eq!(got.len(), want.len(), "one row per output step from t = 0");
    for c in 0..h.len() {
        let peak = |rows: &[Vec<f64>]| rows.iter().fold(0.0f64, |m, r| m.max(r[c].abs()));
        let (pg, pw) = (peak(&got), peak(&want));
        assert!((pg - pw).abs() <= 0.01 * pw + 1e-9, "{}: peak {pg} vs OpenSees {pw}", h[c]);
    }
}

#[test]
fn fe_run_refuses_a_transient_whose_record_is_missing() {
    let models = verification().join("models");
    let dir = scratch("norecord");
    let text =
        std::fs::read_to_string(models.join("ceiling_2p4_nonlinear_sweep_0p02g.json")).unwrap();
    let model = dir.join("m.json");
    std::fs::write(&model, text).unwrap();
    let out = dir.join("out");
    let res = ceilfarm(&["fe", "run", model.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(!res.status.success());
    let err = String::from_utf8_lossy(&res.stderr);
    assert!(err.contains("sweep_x_unit_1g.csv"), "{err}");
}
