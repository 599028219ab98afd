//! `ceilfarm pipeline` on a shrunk copy of configs/seed-ch6.toml (60 runs
//! instead of 1000, smaller Sobol' and selection budgets): every stage
//! writes its file, the emulators reproduce held-out FE runs, J_cross and
//! J_main are screened out as in the seed, the calibrated model with its
//! discrepancy reproduces the measured frequencies, subsets with more
//! parameters than frequencies are reported as not identifiable, and a
//! rerun resumes the sweep (no new runs) and gives the same posterior.

use crate::common::*;
use std::path::Path;

/// The shipped config with a smaller budget, its specimens copied beside it
/// (a study reads files inside its own folder only).
fn small_config(dir: &Path) -> std::path::PathBuf {
    let text = std::fs::read_to_string(repo().join("configs/seed-ch6.toml")).unwrap();
    std::fs::create_dir_all(dir.join("specimens")).unwrap();
    for entry in std::fs::read_dir(repo().join("configs/specimens")).unwrap() {
        let entry = entry.unwrap().path();
        std::fs::copy(&entry, dir.join("specimens").join(entry.file_name().unwrap())).unwrap();
    }
    let text = text
        .replace("n = 1000\n", "n = 60\n")
        .replace("n = 4096 ", "n = 1024 ")
        .replace("draws = 4000", "draws = 1000")
        .replace("qmc_points = 512", "qmc_points = 128");
    assert!(text.contains("n = 60\n") && text.contains("n = 1024 "), "config layout changed");
    let path = dir.join("seed-ch6-small.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    serde_json::from_str(&text).unwrap()
}

#[test]
fn seed_chapter_6_pipeline_runs_end_to_end_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = small_config(dir.path());
    let out = dir.path().join("out");
    ceilfarm_ok(&["pipeline", s(&cfg), "--out", s(&out), "--workers", "2", "--quiet"]);
    for f in ["sweep.db", "emulators.json", "sobol.json", "posterior.json", "samples.csv"] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["sweep"]["tasks"], 60);
    for e in summary["emulators"].as_array().unwrap() {
        let r2 = e["test"]["r2"].as_f64().unwrap();
        assert!(r2 > 0.99, "{}: test R2 {r2}", e["output"]);
    }
    let sobol = json(&out.join("sobol.json"));
    let dropped: Vec<&str> =
        sobol["drop"].as_array().unwrap().iter().map(|v| v.as_str().unwrap()).collect();
    assert!(dropped.contains(&"J_cross") && dropped.contains(&"J_main"), "{dropped:?}");
    let kept: Vec<&str> =
        sobol["keep"].as_array().unwrap().iter().map(|v| v.as_str().unwrap()).collect();
    assert!(kept.contains(&"K_friction"), "{kept:?}");

    let post = json(&out.join("posterior.json"));
    for name in kept.iter().chain(&["alpha", "disc_sd", "disc_length"]) {
        let p = &post["parameters"][*name];
        let (q05, q50, q95) =
            (p["q05"].as_f64().unwrap(), p["q50"].as_f64().unwrap(), p["q95"].as_f64().unwrap());
        assert!(q05 <= q50 && q50 <= q95 && p["sd"].as_f64().unwrap() > 0.0, "{name}: {p}");
    }
    for p in post["predictive"].as_array().unwrap() {
        let (y, sd, fit) = (
            p["measured"].as_f64().unwrap(),
            p["sd"].as_f64().unwrap(),
            p["corrected"].as_f64().unwrap(),
        );
        assert!(
            (fit - y).abs() < 4.0 * sd,
            "{}: model + discrepancy {fit} vs {y} +- {sd}",
            p["output"]
        );
    }

    let criteria = json(&out.join("criteria.json"));
    for c in criteria["candidates"].as_array().unwrap() {
        let k = c["free_parameters"].as_array().unwrap().len();
        assert_eq!(c["identifiable"].as_bool().unwrap(), k <= 6, "{}", c["name"]);
        assert_eq!(c["mdl"].is_null(), k > 6, "{}", c["name"]);
    }
    let mdl = criteria["selected"]["mdl"].as_str().unwrap();
    assert!(mdl.starts_with("top-"), "MDL picked {mdl}");

    let without_time = |mut v: serde_json::Value| {
        v["diagnostics"]["wall_s"] = serde_json::Value::Null;
        v
    };
    let before = without_time(post);
    ceilfarm_ok(&["pipeline", s(&cfg), "--out", s(&out), "--workers", "2", "--quiet"]);
    let again = json(&out.join("summary.json"));
    assert_eq!(again["sweep"]["already_done"], 60);
    assert_eq!(again["sweep"]["ok"], 0);
    assert_eq!(without_time(json(&out.join("posterior.json"))), before);
}

#[test]
fn bad_pipeline_keys_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = small_config(dir.path());
    let text = std::fs::read_to_string(&cfg).unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, text.replace("draws = 1000", "draws = 1000\nsteps = 3")).unwrap();
    let out = ceilfarm(&["pipeline", s(&bad), "--out", s(&dir.path().join("o"))]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("steps") && err.contains("bad.toml"), "{err}");
    std::fs::write(&bad, text.replace("values = [7.5, 8.1,", "values = [7.5,")).unwrap();
    let out = ceilfarm(&["pipeline", s(&bad), "--out", s(&dir.path().join("o"))]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("observations") && err.contains("equal lengths"), "{err}");
}
