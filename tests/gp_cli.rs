//! `ceilfarm gp fit` / `gp predict` end to end: fit the borehole benchmark
//! (n = 200) and predict at fresh points computed from the formula; the
//! model file is self-describing and predictions carry sds.

mod common;
use common::{ceilfarm, ceilfarm_ok, s, shared};
use std::f64::consts::PI;

fn borehole(x: &[f64]) -> f64 {
    let lr = (x[1] / x[0]).ln();
    2.0 * PI * x[2] * (x[3] - x[5])
        / (lr * (1.0 + 2.0 * x[6] * x[2] / (lr * x[0] * x[0] * x[7]) + x[2] / x[4]))
}

const NAMES: &str = "rw,r,Tu,Hu,Tl,Hl,L,Kw";

#[test]
fn fit_then_predict_borehole_200() {
    let dir = tempfile::tempdir().unwrap();
    let train = shared().join("benchmarks/borehole_train_200.csv");
    let model = dir.path().join("model.json");
    ceilfarm_ok(&["gp", "fit", s(&train), "--inputs", NAMES, "--outputs", "y", "--out", s(&model)]);
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(m["format"], "ceilfarm-gp/2");
    assert_eq!(m["outputs"][0]["gp"]["kernel"]["kind"], "squared-exponential");
    assert_eq!(m["training_sha256"].as_str().unwrap().len(), 64);

    // Fresh points on a grid inside the design box, with an extra column.
    let lo = [0.05, 100.0, 63070.0, 990.0, 63.1, 700.0, 1120.0, 9855.0];
    let hi = [0.15, 50000.0, 115600.0, 1110.0, 116.0, 820.0, 1680.0, 12045.0];
    let mut text = format!("id,{NAMES}\n");
    let mut truth = Vec::new();
    for i in 0..50 {
        let u = |k: usize| ((i * (2 * k + 3) + k) % 50) as f64 / 49.0;
        let x: Vec<f64> = (0..8).map(|k| lo[k] + u(k) * (hi[k] - lo[k])).collect();
        truth.push(borehole(&x));
        text += &format!("{i},{}\n", x.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(","));
    }
    let points = dir.path().join("points.csv");
    std::fs::write(&points, text).unwrap();
    let pred = dir.path().join("pred.csv");
    ceilfarm_ok(&["gp", "predict", s(&model), s(&points), "--out", s(&pred)]);
    let out = std::fs::read_to_string(&pred).unwrap();
    let mut lines = out.lines();
    assert_eq!(lines.next().unwrap(), format!("{NAMES},y_mean,y_sd"));
    let mut se = 0.0;
    for (line, t) in lines.zip(&truth) {
        let v: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
        assert_eq!(v.len(), 10);
        assert!(v[9] > 0.0);
        se += (v[8] - t).powi(2);
    }
    let rmse = (se / truth.len() as f64).sqrt();
    // The output sd is 44 m³/yr; an n = 200 SE fit is accurate to ~0.1.
    assert!(rmse < 0.5, "rmse {rmse}");
}

#[test]
fn missing_input_column_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let train = dir.path().join("t.csv");
    std::fs::write(&train, "a,y\n0,1\n1,2\n").unwrap();
    let out = ceilfarm(&[
        "gp",
        "fit",
        s(&train),
        "--inputs",
        "a,b",
        "--outputs",
        "y",
        "--out",
        s(&dir.path().join("m.json")),
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no column \"b\""));
}
