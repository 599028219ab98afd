//! The seed's three stages of a semi-free ceiling under a sine sweep (seed
//! 4.2.2.2: pre-slipping, slipping, pounding) on the 2.4 m verification
//! model with friction and gap springs (`models/ceiling_2p4_nonlinear_*`),
//! with the sweep's peak scaled to 0.02 g, 0.3 g and 0.5 g.
//!
//! Stages are read from the perimeter springs on the x walls (the sweep is
//! along x): stuck while every friction spring stays below the Steel01 yield
//! deformation Fy / E0 = 2 N / 20 N/mm = 0.1 mm; slipping when they go well
//! past it (here > 1 mm) while no gap spring ever carries force; pounding
//! when a gap spring does.

use crate::common::verification_dir;
use fe::model::{read_model, Analysis, Model};
use fe::transient::{run_model, History, TransientOptions};
use serde_json::{json, Value};

/// Peak |friction deformation| (mm) and peak |gap force| (N) over the x walls.
struct Stage {
    friction_mm: f64,
    gap_n: f64,
}

/// The 0.02 g fixture with its sweep scaled to `peak_g` and recorders on
/// every friction and gap spring of the x walls.
fn model_at(peak_g: f64) -> Model {
    let path = verification_dir().join("models/ceiling_2p4_nonlinear_sweep_0p02g.json");
    let mut m = read_model(&path).unwrap();
    let mut recs = vec![];
    for s in &m.springs {
        let x_wall = matches!(s.side.as_deref(), Some("x0" | "x1"));
        match s.group.as_deref() {
            Some("perimeter_friction") if x_wall => recs.push(
                json!({"name": format!("friction_{}", s.id), "element": s.id, "response": "deformation"}),
            ),
            Some("perimeter_gap") if x_wall => recs.push(
                json!({"name": format!("gap_{}", s.id), "element": s.id, "response": "force"}),
            ),
            _ => {}
        }
    }
    let Some(Analysis::Transient(map)) = &mut m.analysis else { panic!("no transient block") };
    map["excitation"]["scale"] = json!(peak_g);
    map.insert("recorders".into(), Value::Array(recs));
    m
}

fn peak(h: &History, prefix: &str) -> f64 {
    let cols: Vec<usize> =
        (0..h.columns.len()).filter(|&c| h.columns[c].starts_with(prefix)).collect();
    assert!(!cols.is_empty(), "no {prefix} columns");
    h.rows.iter().flat_map(|r| cols.iter().map(move |&c| r[c].abs())).fold(0.0, f64::max)
}

fn stage_at(peak_g: f64) -> Stage {
    let m = model_at(peak_g);
    let dir = verification_dir().join("models");
    let t0 = std::time::Instant::now();
    let h = run_model(&m, &TransientOptions::new(&dir), &mut |_| {}).unwrap();
    let s = Stage { friction_mm: peak(&h, "friction_"), gap_n: peak(&h, "gap_") };
    eprintln!(
        "{peak_g} g: peak friction deformation {:.4} mm, peak gap force {:.2} N ({:.1} s)",
        s.friction_mm,
        s.gap_n,
        t0.elapsed().as_secs_f64()
    );
    s
}

#[test]
fn sweep_amplitudes_show_stuck_slipping_and_pounding() {
    let yield_mm = 2.0 / 20.0;
    let stuck = stage_at(0.02);
    assert!(stuck.friction_mm < yield_mm, "0.02 g: {} mm", stuck.friction_mm);
    assert_eq!(stuck.gap_n, 0.0);
    let slipping = stage_at(0.3);
    assert!(slipping.friction_mm > 10.0 * yield_mm, "0.3 g: {} mm", slipping.friction_mm);
    assert_eq!(slipping.gap_n, 0.0, "0.3 g: the gaps stay open");
    let pounding = stage_at(0.5);
    assert!(pounding.gap_n > 0.0, "0.5 g: a gap closes");
    assert!(pounding.friction_mm >= 19.0, "0.5 g: the grid end reaches the wall");
}
