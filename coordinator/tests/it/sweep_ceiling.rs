//! The shipped ceiling study runs end to end on two in-process workers: its
//! export holds 8 rows, each with six frequencies that rise with K_friction
//! alone (the modes use the initial stiffness; damping does not move them)
//! and one stored history per sensor whose peak is the row's `peak_<id>`.

use crate::common::*;

const SENSORS: [(&str, &str); 3] = [
    ("A_centre", "A_centre_accel_m_s2"),
    ("A_edge", "A_edge_accel_m_s2"),
    ("D_centre", "D_centre_disp_m"),
];

#[test]
fn ceiling_sweep_stores_and_exports_sensor_histories() {
    let dir = tempfile::tempdir().unwrap();
    let store = dir.path().join("c.db");
    let csv_path = dir.path().join("c.csv");
    let hist = dir.path().join("hist");
    let study = repo().join("configs/ceiling.toml");
    ceilfarm_ok(&["run", s(&study), "--store", s(&store), "--workers", "2", "--quiet"]);
    ceilfarm_ok(&["export", s(&store), "--out", s(&csv_path), "--histories", s(&hist)]);
    let mut rdr = csv::Reader::from_path(&csv_path).unwrap();
    let header: Vec<String> = rdr.headers().unwrap().iter().map(String::from).collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
    };
    let mut k_f1 = Vec::new();
    for rec in rdr.records() {
        let rec = rec.unwrap();
        assert_eq!(&rec[col("status")], "ok", "{rec:?}");
        let task: usize = rec[col("task_id")].parse().unwrap();
        let num = |name: &str| rec[col(name)].parse::<f64>().unwrap();
        k_f1.push((num("K_friction"), num("f1_hz")));
        for (id, channel) in SENSORS {
            let path = hist.join(format!("task_{task:06}_{id}.csv"));
            let mut h = csv::Reader::from_path(&path).unwrap();
            assert_eq!(h.headers().unwrap().iter().collect::<Vec<_>>(), ["t_s", channel]);
            let v: Vec<f64> = h.records().map(|r| r.unwrap()[1].parse().unwrap()).collect();
            // 10 s at 0.005 s, both ends included.
            assert_eq!(v.len(), 2001, "{path:?}");
            let peak = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let stored = num(&format!("peak_{id}"));
            assert!(
                (peak - stored).abs() <= 1e-12 * stored && stored > 0.0,
                "{id}: {peak} {stored}"
            );
        }
    }
    assert_eq!(k_f1.len(), 8);
    k_f1.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(k_f1.windows(2).all(|w| w[1].1 > w[0].1), "f1 against K_friction: {k_f1:?}");
}
