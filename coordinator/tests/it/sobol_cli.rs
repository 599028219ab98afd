//! `ceilfarm sobol --function ... --json`: indices of Ishigami and the G
//! function against the exact values of the benchmark README.

use crate::common;
use crate::common::ceilfarm_ok;

fn indices(function: &str, n: &str) -> serde_json::Value {
    let out = ceilfarm_ok(&["sobol", "--function", function, "--n", n, "--seed", "1", "--json"]);
    serde_json::from_slice(&out.stdout).expect("JSON on stdout")
}

fn close(v: &serde_json::Value, key: &str, exact: &[f64], tol: f64) {
    let got: Vec<f64> = v[key].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    assert_eq!(got.len(), exact.len(), "{key}");
    for (g, e) in got.iter().zip(exact) {
        assert!((g - e).abs() < tol, "{key}: {g} vs exact {e}");
    }
}

#[test]
fn ishigami_json_matches_exact_indices() {
    let v = indices("ishigami", "8192");
    assert_eq!(v["names"], serde_json::json!(["x1", "x2", "x3"]));
    assert_eq!(v["runs"], 8192 * 5);
    close(&v, "S1", &[0.3139, 0.4424, 0.0], 3e-3);
    close(&v, "ST", &[0.5576, 0.4424, 0.2437], 3e-3);
    assert!(v["S1_conf"].as_array().unwrap().iter().all(|c| c.as_f64().unwrap() > 0.0));
}

#[test]
fn sobol_g_screens_out_the_four_inert_inputs() {
    let v = indices("sobol-g", "8192");
    close(&v, "ST", &[0.7871, 0.2422, 0.0343, 0.0105, 0.0001, 0.0001, 0.0001, 0.0001], 3e-3);
    assert_eq!(v["screening"]["drop"], serde_json::json!(["x5", "x6", "x7", "x8"]));
}

#[test]
fn unknown_function_is_refused() {
    let out = common::ceilfarm(&["sobol", "--function", "nope", "--json"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("ishigami"));
}
