//! Property tests of every uniaxial material over random cyclic histories:
//! the tangent is the slope of the force where the law is smooth, revert
//! restores the committed state exactly, and committing twice is the same
//! as committing once.

use std::fmt::Debug;

use fe::materials::{
    BoucWen, BoucWenParams, Elastic, Gap, Impact, ImpactParams, Pinching4, Pinching4Spec, Pivot,
    PivotSpec, Steel01, Steel01Params, Takeda, TakedaSpec, UniaxialMaterial,
};
use proptest::prelude::*;

/// The CJS-A Pinching4 set of seed Table 5.4 with some degradation switched on.
fn pinching4(dmg: &str, degrade: f64) -> Pinching4 {
    Pinching4::new(&Pinching4Spec {
        ePf: [150.0, 651.0, 1001.0, 458.0],
        ePd: [0.5, 5.5, 10.5, 13.8],
        eNf: [-200.0, -620.0, -1248.0, -556.0],
        eNd: [-0.5, -5.0, -12.7, -16.0],
        rDispP: 0.6,
        rForceP: 0.2,
        uForceP: -0.01,
        rDispN: 0.6,
        rForceN: 0.2,
        uForceN: -0.01,
        gK: [degrade, degrade, 1.0, 1.0],
        gKLim: 0.9 * degrade,
        gD: [degrade, degrade, 1.0, 1.0],
        gDLim: 0.5 * degrade,
        gF: [degrade, degrade, 1.0, 1.0],
        gFLim: 0.9 * degrade,
        gE: 10.0,
        dmgType: dmg.to_string(),
    })
    .unwrap()
}

/// An asymmetric trilinear skeleton with softening on the positive side
/// (the shape of the seed's connection tests).
const SKEL_PD: [f64; 3] = [0.5, 5.5, 10.5];
const SKEL_PF: [f64; 3] = [150.0, 651.0, 458.0];
const SKEL_ND: [f64; 2] = [-0.8, -9.0];
const SKEL_NF: [f64; 2] = [-200.0, -620.0];

/// Drives `m` to each target in steps of at most `step`, committing each.
fn drive_history<M: UniaxialMaterial>(m: &mut M, targets: &[f64], step: f64) {
    let mut d = 0.0;
    for &t in targets {
        let n = ((t - d).abs() / step).ceil().max(1.0) as usize;
        let start = d;
        for i in 1..=n {
            d = start + (t - start) * i as f64 / n as f64;
            m.set_trial(d).unwrap();
            m.commit();
        }
    }
}

/// The tangent matches the central difference of the force wherever the
/// two one-sided slopes agree (no event between d - h and d + h).
fn check_tangent<M: UniaxialMaterial>(m: &mut M, d: f64, h: f64, k_ref: f64, rel: f64) {
    m.set_trial(d - h).unwrap();
    let f_minus = m.force();
    m.set_trial(d + h).unwrap();
    let f_plus = m.force();
    m.set_trial(d).unwrap();
    let (f, k) = (m.force(), m.tangent());
    let left = (f - f_minus) / h;
    let right = (f_plus - f) / h;
    if (left - right).abs() > rel * k_ref {
        return; // an event (branch change) lies within the stencil
    }
    let central = (f_plus - f_minus) / (2.0 * h);
    assert!(
        (central - k).abs() <= rel * k_ref.max(k.abs()),
        "d {d}: tangent {k} vs finite difference {central} (left {left}, right {right})"
    );
}

/// Revert after a trial restores the committed material exactly, and a
/// second commit changes nothing.
fn check_revert_and_commit<M>(m: &mut M, trial: f64)
where
    M: UniaxialMaterial + Clone + PartialEq + Debug,
{
    let committed = m.clone();
    m.set_trial(trial).unwrap();
    m.set_trial(-trial).unwrap();
    m.revert();
    assert_eq!(*m, committed, "revert after trial {trial}");
    m.set_trial(trial).unwrap();
    m.commit();
    let once = m.clone();
    m.commit();
    assert_eq!(*m, once, "second commit of trial {trial}");
}

/// Runs the three properties on one material at history scale `scale` (mm).
fn properties<M>(mut m: M, targets: &[f64], offset: f64, scale: f64, rel: f64)
where
    M: UniaxialMaterial + Clone + PartialEq + Debug,
{
    let targets: Vec<f64> = targets.iter().map(|t| t * scale).collect();
    drive_history(&mut m, &targets, 0.02 * scale);
    let k_ref = m.initial_tangent().max(1.0);
    let d = targets.last().copied().unwrap_or(0.0) + offset * scale;
    let h = 1e-6 * scale;
    let committed = m.clone();
    if (offset * scale).abs() > 4.0 * h {
        check_tangent(&mut m, d, h, k_ref, rel);
    }
    m.revert();
    assert_eq!(m, committed, "revert after the tangent probes");
    check_revert_and_commit(&mut m, d);
}

fn targets() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(-1.0f64..1.0, 1..8)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn elastic(t in targets(), off in -0.3f64..0.3) {
        properties(Elastic::new(12.0).unwrap(), &t, off, 2.0, 1e-6);
    }

    #[test]
    fn gap(t in targets(), off in -0.3f64..0.3) {
        properties(Gap::new(588.0, 2.0).unwrap(), &t, off, 4.0, 1e-6);
    }

    #[test]
    fn steel01(t in targets(), off in -0.3f64..0.3) {
        let m = Steel01::new(Steel01Params { fy: 2.0, e0: 20.0, b: 0.05 }).unwrap();
        properties(m, &t, off, 1.0, 1e-6);
    }

    #[test]
    fn impact(t in targets(), off in -0.3f64..0.3) {
        let m = Impact::new(ImpactParams { k1: 300.0, k2: 100.0, dy: 0.1, gap: 1.0 }).unwrap();
        properties(m, &t, off, 2.0, 1e-6);
    }

    #[test]
    fn pinching4_cycle(t in targets(), off in -0.3f64..0.3, g in 0.0f64..0.5) {
        properties(pinching4("cycle", g), &t, off, 16.0, 1e-5);
    }

    #[test]
    fn pinching4_energy(t in targets(), off in -0.3f64..0.3, g in 0.0f64..0.5) {
        properties(pinching4("energy", g), &t, off, 16.0, 1e-5);
    }

    #[test]
    fn bouc_wen(t in targets(), off in -0.3f64..0.3, n in 1.0f64..20.0, r in 0.0f64..0.3) {
        let m = BoucWen::new(BoucWenParams { fy: 2.0, dy: 0.1, exponent: n, ratio: r }).unwrap();
        properties(m, &t, off, 1.0, 1e-4);
    }

    #[test]
    fn takeda(t in targets(), off in -0.3f64..0.3, alpha in 0.0f64..0.6) {
        let m = Takeda::new(&TakedaSpec {
            ePd: SKEL_PD.to_vec(), ePf: SKEL_PF.to_vec(),
            eNd: SKEL_ND.to_vec(), eNf: SKEL_NF.to_vec(), alpha,
        })
        .unwrap();
        properties(m, &t, off, 12.0, 1e-6);
    }

    #[test]
    fn pivot(t in targets(), off in -0.3f64..0.3, a1 in 0.5f64..30.0, a2 in 0.05f64..4.0,
             b1 in 0.0f64..0.95, b2 in 0.0f64..0.95) {
        let m = Pivot::new(&PivotSpec {
            ePd: SKEL_PD.to_vec(), ePf: SKEL_PF.to_vec(),
            eNd: SKEL_ND.to_vec(), eNf: SKEL_NF.to_vec(),
            alpha1: a1, alpha2: a2, beta1: b1, beta2: b2, eta: 0.0,
        })
        .unwrap();
        properties(m, &t, off, 12.0, 1e-6);
    }
}
