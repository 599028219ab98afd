//! The hanger rods ([`fe::generator::rods`]): split into
//! [`ROD_ELEMENTS`] beams with their mass along them when the members
//! carry mass, so that their own bending modes appear at the continuous
//! rod's frequency; hinged at the tee through `K_rod_rot`.

use crate::common::type_c_structure;
use fe::eigen::{horizontal_share, modal_analysis, LanczosSettings};
use fe::generator::rods::ROD_ELEMENTS;
use fe::generator::{
    generate, CeilingSpec, Connections, ModelOptions, Parameters, Perimeter, Structure,
};
use fe::materials::MaterialSpec;
use fe::model::Model;

fn spec() -> CeilingSpec {
    let structure = Structure { layers: 1, ..type_c_structure(3.6, 2.4) };
    let model = ModelOptions { perimeter: Perimeter::Linear, connections: Connections::Rigid };
    CeilingSpec { structure, model }
}

fn model(set: &[(&str, f64)]) -> Model {
    let s = spec();
    let mut p = Parameters::prior_midpoints_for(&s);
    for (name, value) in set {
        p.set(name, *value).unwrap();
    }
    generate(&s, &p).unwrap()
}

fn rod_beams(m: &Model) -> usize {
    m.beams.iter().filter(|b| b.group.as_deref() == Some("rod")).count()
}

/// The horizontal modes' frequencies (Hz) among the lowest `n`.
fn sway_hz(m: &Model, n: usize) -> Vec<f64> {
    let (s, r) = modal_analysis(m, n, &LanczosSettings::default()).unwrap();
    let share = horizontal_share(&s, &r);
    r.freq_hz.iter().zip(share).filter(|(_, h)| *h >= 0.5).map(|(f, _)| *f).collect()
}

/// The first bending mode of a 1 m M8 rod (E at its prior mid-point,
/// I = A²/4π, 0.37 kg/m) fixed at the top, continuous: λ²/2π · √(EI/m)/L²
/// with λ² = 15.418 pinned at the tee, 22.373 fixed.
fn continuous_rod_hz(lambda2: f64) -> f64 {
    let e_mpa = Parameters::prior_midpoints().value_or_midpoint("E");
    let ei = e_mpa * 40.0 * 40.0 / (4.0 * std::f64::consts::PI);
    lambda2 / (2.0 * std::f64::consts::PI) * (ei / 0.37e-6).sqrt() / 1.0e6
}

#[test]
fn massless_rods_stay_one_beam_and_rods_with_mass_are_split() {
    // 3.6 m x 2.4 m, main tees at x = 0.6, 1.8, 3.0, rods at y = 0.6, 1.8.
    let plain = model(&[]);
    let heavy = model(&[("member_mass_factor", 1.0)]);
    assert_eq!(rod_beams(&plain), 6);
    assert_eq!(rod_beams(&heavy), 6 * ROD_ELEMENTS);
    assert_eq!(heavy.nodes.len(), plain.nodes.len() + 6 * (ROD_ELEMENTS - 1));
    let heights: Vec<f64> = (heavy.nodes.iter())
        .filter(|n| n.xyz_mm[2] > 0.0 && n.xyz_mm[2] < 1000.0)
        .map(|n| n.xyz_mm[2])
        .collect();
    for k in 1..ROD_ELEMENTS {
        let z = 1000.0 * k as f64 / ROD_ELEMENTS as f64;
        assert_eq!(heights.iter().filter(|h| (**h - z).abs() < 1e-9).count(), 6, "z = {z}");
    }
}

#[test]
fn a_pinned_rod_swings_near_the_continuous_rods_frequency() {
    let pinned = continuous_rod_hz(15.418);
    let fixed = continuous_rod_hz(22.373);
    let near = |m: &Model, f: f64, within: f64| {
        sway_hz(m, 40).iter().filter(|x| (*x / f - 1.0).abs() < within).count()
    };
    // Six rods, two directions each: twelve rod modes, the grid barely moving.
    let hinged = model(&[("member_mass_factor", 1.0), ("K_rod_rot", 10.0)]);
    assert!(near(&hinged, pinned, 0.02) >= 10, "{pinned:.2} Hz: {:?}", sway_hz(&hinged, 40));
    // Tied to the tee, a rod's lower end turns with the grid node, which the
    // grid holds less than a clamp does: a few percent below the fixed rod.
    let tied = model(&[("member_mass_factor", 1.0)]);
    assert!(near(&tied, fixed, 0.04) >= 10, "{fixed:.2} Hz: {:?}", sway_hz(&tied, 40));
    assert!(near(&tied, pinned, 0.02) < 6, "the grid's own modes only");
}

#[test]
fn a_stiff_hinge_gives_the_rigid_tie_and_only_the_rods_turn() {
    let rigid = model(&[("member_mass_factor", 1.0)]);
    let stiff = model(&[("member_mass_factor", 1.0), ("K_rod_rot", 1.0e8)]);
    for (a, b) in sway_hz(&rigid, 24).iter().zip(sway_hz(&stiff, 24)) {
        assert!((a / b - 1.0).abs() < 1e-3, "{a} vs {b}");
    }
    let soft = model(&[("K_rod_rot", 500.0)]);
    let hinge: Vec<_> =
        soft.springs.iter().filter(|s| s.group.as_deref() == Some("rod_hinge")).collect();
    assert_eq!(hinge.len(), 6 * 6);
    let k_of = |mat: u64| match soft.materials.iter().find(|d| d.id == mat).unwrap().spec {
        MaterialSpec::Elastic { k } => k,
        ref other => panic!("{other:?}"),
    };
    for s in &hinge {
        let turning = s.dof == 4 || s.dof == 5;
        assert_eq!(k_of(s.mat) == 500.0, turning, "{s:?}");
    }
    // A hinged rod sways more easily than a tied one: the first mode drops.
    assert!(sway_hz(&soft, 2)[0] < sway_hz(&model(&[]), 2)[0]);
}
