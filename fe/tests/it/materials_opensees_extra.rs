//! Further OpenSees 3.8.0 (OpenSeesPy) responses, made for this crate with
//! `testUniaxialMaterial` + `setStrain` exactly like the shared fixtures:
//! Pinching4 with stiffness, reloading and strength degradation under cycle
//! and energy damage, the uForce >= rForce branches, and random-walk
//! protocols with many inner reversals for Pinching4, Steel01 and Impact.
//! Data: `src/materials/testdata/` (`materials.json` holds the parameters,
//! each CSV is `deformation_mm,force_N,tangent_N_per_mm` per committed step).

use std::path::PathBuf;

use fe::materials::{drive, MaterialSpec};

fn testdata() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src/materials/testdata")
}

/// Max |force error| / peak |force| and max |tangent error| / peak |tangent|.
fn compare(name: &str) -> (f64, f64) {
    let index: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(testdata().join("materials.json")).unwrap())
            .unwrap();
    let spec: MaterialSpec = serde_json::from_value(index[name].clone()).unwrap();
    let text = std::fs::read_to_string(testdata().join(format!("{name}.csv"))).unwrap();
    let rows: Vec<[f64; 3]> = text
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    let d: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let got = drive(&spec, &d).unwrap();
    let peak_f = rows.iter().fold(0.0_f64, |m, r| m.max(r[1].abs()));
    let peak_k = rows.iter().fold(0.0_f64, |m, r| m.max(r[2].abs()));
    let (mut ef, mut ek, mut at) = (0.0_f64, 0.0_f64, 0);
    for (i, (g, e)) in got.iter().zip(&rows).enumerate() {
        let err = (g.1 - e[1]).abs() / peak_f;
        if err > ef {
            ef = err;
            at = i;
        }
        ek = ek.max((g.2 - e[2]).abs() / peak_k);
    }
    println!(
        "{name}: {} rows, max |force error| / peak {ef:.3e} (row {at}: d {}, got {}, OpenSees {}), \
         max |tangent error| / peak {ek:.3e}",
        rows.len(),
        d[at],
        got[at].1,
        rows[at][1]
    );
    (ef, ek)
}

macro_rules! case {
    ($name:ident) => {
        #[test]
        fn $name() {
            let (ef, ek) = compare(stringify!($name));
            assert!(ef <= 1e-6, "force error {ef:e}");
            assert!(ek <= 1e-6, "tangent error {ek:e}");
        }
    };
}

case!(pinching4_degrading_cycle);
case!(pinching4_degrading_energy);
case!(pinching4_degrading_walk);
case!(pinching4_uforce_branches);
case!(pinching4_cjsa_walk);
case!(steel01_walk);
case!(impact_walk);

// The SAP2000 Wen link is OpenSees BoucWen with z in mm (alpha = ratio,
// ko = Fy / dy, gamma = beta = 0.5 / dy^n, Ao = 1, no degradation), which
// also integrates by backward Euler with Newton (tolerance set to 1e-14).
case!(bouc_wen_n1_walk);
case!(bouc_wen_n2_walk);
case!(bouc_wen_n10_walk);
