//! `ceilfarm gp fit` / `gp predict` end to end: fit the borehole benchmark
//! (n = 200) and predict at fresh points computed from the formula; the
//! model file is self-describing and predictions carry sds.

use crate::common::{ceilfarm, ceilfarm_ok, s, shared};
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

/// `gp fit` then `calibrate` with `kind = "gp"`: two emulated outputs
/// a + b and a − b, observed as 1.0 and 0.2 with sds 0.05 from a data
/// column. The exact posterior is a = 0.6, b = 0.4, each sd 0.05 / sqrt 2,
/// uncorrelated; the emulators' variance is negligible at 40 training runs.
#[test]
fn calibrate_on_a_gp_file_recovers_a_linear_posterior() {
    let dir = tempfile::tempdir().unwrap();
    let mut train = String::from("a,b,sum,diff\n");
    for i in 0..40 {
        let (a, b) = ((i as f64 * 0.618034) % 1.0, (i as f64 * 0.754878 + 0.1) % 1.0);
        train += &format!("{a},{b},{},{}\n", a + b, a - b);
    }
    std::fs::write(dir.path().join("train.csv"), train).unwrap();
    std::fs::write(dir.path().join("data.csv"), "row,y,sd\n1,1.0,0.05\n2,0.2,0.05\n").unwrap();
    let gp = dir.path().join("gp.json");
    let t = dir.path().join("train.csv");
    ceilfarm_ok(&["gp", "fit", s(&t), "--inputs", "a,b", "--outputs", "sum,diff", "--out", s(&gp)]);
    let cfg = dir.path().join("cal.toml");
    std::fs::write(
        &cfg,
        r#"
[simulator]
kind = "gp"
file = "gp.json"
outputs = ["sum", "diff"]

[data]
file = "data.csv"
x = ["row"]
y = "y"

[[parameters]]
name = "b"
low = 0.0
high = 1.0

[[parameters]]
name = "a"
low = 0.0
high = 1.0

[noise]
sd_column = "sd"

[method]
kind = "bbvi-fullrank"
seed = 3
"#,
    )
    .unwrap();
    let out = dir.path().join("post");
    ceilfarm_ok(&["calibrate", s(&cfg), "--out", s(&out)]);
    let text = std::fs::read_to_string(out.join("posterior.json")).unwrap();
    let post: serde_json::Value = serde_json::from_str(&text).unwrap();
    let sd = 0.05 / 2f64.sqrt();
    for (name, mean) in [("a", 0.6), ("b", 0.4)] {
        let p = &post["parameters"][name];
        let (m, s) = (p["mean"].as_f64().unwrap(), p["sd"].as_f64().unwrap());
        assert!((m - mean).abs() < 0.2 * sd, "{name}: mean {m} vs {mean}");
        assert!((s / sd - 1.0).abs() < 0.1, "{name}: sd {s} vs {sd}");
    }
    let r = post["correlation"]["matrix"][0][1].as_f64().unwrap();
    assert!(r.abs() < 0.1, "correlation {r}");

    std::fs::write(&cfg, std::fs::read_to_string(&cfg).unwrap().replace("\"diff\"]", "\"dif\"]"))
        .unwrap();
    let bad = ceilfarm(&["calibrate", s(&cfg), "--out", s(&out)]);
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && err.contains("simulator.outputs") && err.contains("dif"),
        "{err}"
    );
}
