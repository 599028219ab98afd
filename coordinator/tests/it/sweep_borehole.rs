//! The shipped borehole study runs end to end on two in-process workers, and
//! its export holds 200 rows whose `y` is the borehole formula
//! (Morris, Mitchell & Ylvisaker 1993) to 1e-12 relative.

use crate::common::*;

fn borehole(x: &[f64]) -> f64 {
    let (rw, r, tu, hu, tl, hl, l, kw) = (x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]);
    let lnr = (r / rw).ln();
    2.0 * std::f64::consts::PI * tu * (hu - hl)
        / (lnr * (1.0 + 2.0 * l * tu / (lnr * rw * rw * kw) + tu / tl))
}

#[test]
fn borehole_sweep_exports_the_formula() {
    let dir = tempfile::tempdir().unwrap();
    let store = dir.path().join("a.db");
    let csv_path = dir.path().join("a.csv");
    ceilfarm_ok(&[
        "run",
        s(&repo().join("configs/borehole.toml")),
        "--store",
        s(&store),
        "--workers",
        "2",
        "--quiet",
    ]);
    ceilfarm_ok(&["export", s(&store), "--format", "csv", "--out", s(&csv_path)]);
    let mut rdr = csv::Reader::from_path(&csv_path).unwrap();
    let header: Vec<String> = rdr.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(
        header,
        ["task_id", "rw", "r", "Tu", "Hu", "Tl", "Hl", "L", "Kw", "y", "status", "reason"]
    );
    let mut n = 0;
    for rec in rdr.records() {
        let rec = rec.unwrap();
        let x: Vec<f64> = (1..9).map(|i| rec[i].parse().unwrap()).collect();
        let y: f64 = rec[9].parse().unwrap();
        let exact = borehole(&x);
        assert!(((y - exact) / exact).abs() <= 1e-12, "row {n}: {y} vs {exact}");
        assert_eq!(&rec[10], "ok");
        assert_eq!(rec[0].parse::<usize>().unwrap(), n, "rows in task order");
        n += 1;
    }
    assert_eq!(n, 200);
}

#[test]
fn design_command_matches_the_stored_design() {
    let dir = tempfile::tempdir().unwrap();
    let design = dir.path().join("d.csv");
    let store = dir.path().join("a.db");
    let export = dir.path().join("a.csv");
    let study = repo().join("configs/borehole.toml");
    ceilfarm_ok(&["design", s(&study), "--out", s(&design)]);
    ceilfarm_ok(&["run", s(&study), "--store", s(&store), "--workers", "1", "--quiet"]);
    ceilfarm_ok(&["export", s(&store), "--out", s(&export)]);
    let inputs = |p: &std::path::Path| -> Vec<Vec<String>> {
        let mut r = csv::Reader::from_path(p).unwrap();
        r.records().map(|rec| rec.unwrap().iter().take(9).map(String::from).collect()).collect()
    };
    assert_eq!(inputs(&design), inputs(&export));
}
