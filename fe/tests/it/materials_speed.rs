//! Cost per committed step of the materials that run millions of times in
//! transients (Gap, Impact, Steel01), through the concrete type and through
//! `Box<dyn UniaxialMaterial>`. Ignored by default; run with
//! `cargo test -p ceilfarm-fe --test it materials_speed:: -- --ignored --nocapture`.

use std::time::Instant;

use fe::materials::{
    build, Gap, Impact, ImpactParams, MaterialSpec, Steel01, Steel01Params, UniaxialMaterial,
};

const STEPS: usize = 2_000_000;

/// Sine history of amplitude `amp_mm`, 1000 steps per cycle.
fn history(amp_mm: f64) -> Vec<f64> {
    (0..STEPS).map(|i| amp_mm * (i as f64 * std::f64::consts::TAU / 1000.0).sin()).collect()
}

fn time<M: UniaxialMaterial + ?Sized>(name: &str, m: &mut M, d: &[f64]) {
    let start = Instant::now();
    let mut acc = 0.0;
    for &x in d {
        m.set_trial(x).unwrap();
        acc += m.force() + m.tangent();
        m.commit();
    }
    let ns = start.elapsed().as_nanos() as f64 / d.len() as f64;
    println!("{name}: {ns:.1} ns per step (checksum {acc:.3e})");
}

#[test]
#[ignore]
fn cost_per_step() {
    let d = history(25.0);
    time("Gap", &mut Gap::new(588.0, 19.0).unwrap(), &d);
    let impact = ImpactParams { k1: 300.0, k2: 100.0, dy: 0.1, gap: 13.3 };
    time("Impact", &mut Impact::new(impact).unwrap(), &d);
    let steel = Steel01Params { fy: 2.0, e0: 20.0, b: 0.05 };
    time("Steel01", &mut Steel01::new(steel).unwrap(), &d);
    let mut boxed = build(&MaterialSpec::Steel01 { fy: 2.0, e0: 20.0, b: 0.05 }).unwrap();
    time("Steel01 (dyn)", boxed.as_mut(), &d);
    let mut boxed = build(&MaterialSpec::Gap { k: 588.0, gap: 19.0 }).unwrap();
    time("Gap (dyn)", boxed.as_mut(), &d);
    let wen = MaterialSpec::BoucWen { fy: 2.0, dy: 0.1, exponent: 20.0, ratio: 0.0 };
    time("BoucWen n = 20 (dyn)", build(&wen).unwrap().as_mut(), &d);
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/materials/testdata");
    let index: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("materials.json")).unwrap())
            .unwrap();
    let p4: MaterialSpec = serde_json::from_value(index["pinching4_cjsa_walk"].clone()).unwrap();
    let small: Vec<f64> = d.iter().map(|x| x * 0.6).collect();
    time("Pinching4 CJS-A (dyn)", build(&p4).unwrap().as_mut(), &small);
}
