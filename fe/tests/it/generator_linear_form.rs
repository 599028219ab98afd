//! The linear form beyond Table 6.1 (`K_across`, the mass factors, the
//! rods' and members' stiffness factors, the joints' turn in the plane)
//! and the layout of the measured-bundle frame: each default rebuilds the
//! model without it, and each value changes what it names and nothing else.

use crate::common::type_c_structure;
use fe::eigen::{modal_analysis, LanczosSettings};
use fe::generator::rods::ROD_ELEMENTS;
use fe::generator::{
    generate, CeilingSpec, Connections, ModelOptions, Parameters, Perimeter, Structure,
    MEMBER_KG_PER_M,
};
use fe::materials::MaterialSpec;
use fe::model::Model;

fn spec(connections: Connections, lines_from_origin: bool) -> CeilingSpec {
    let structure = Structure { layers: 1, lines_from_origin, ..type_c_structure(3.6, 2.4) };
    CeilingSpec { structure, model: ModelOptions { perimeter: Perimeter::Linear, connections } }
}

fn model(s: &CeilingSpec, set: &[(&str, f64)]) -> Model {
    let mut p = Parameters::prior_midpoints_for(s);
    for (name, value) in set {
        p.set(name, *value).unwrap();
    }
    generate(s, &p).unwrap()
}

fn mass_x_t(m: &Model) -> f64 {
    m.masses.iter().map(|x| x.m_t[0]).sum()
}

fn first_hz(m: &Model) -> f64 {
    modal_analysis(m, 2, &LanczosSettings::default()).unwrap().1.freq_hz[0]
}

#[test]
fn defaults_rebuild_the_model_without_them() {
    let s = spec(Connections::Elastic, false);
    let plain = model(&s, &[]);
    let named = model(
        &s,
        &[
            ("K_across", 1.0e4),
            ("panel_mass_factor", 1.0),
            ("member_mass_factor", 0.0),
            ("rod_bending_factor", 1.0),
            ("grid_axial_factor", 1.0),
            ("grid_bending_factor", 1.0),
            ("K_joint_rot", 1.0e13),
            ("K_rod_rot", 1.0e13),
        ],
    );
    assert_eq!(plain.materials, named.materials);
    assert_eq!(plain.beams, named.beams);
    assert_eq!(plain.springs, named.springs);
    assert_eq!(plain.masses, named.masses);
}

#[test]
fn member_mass_adds_the_seed_facts_masses() {
    let s = spec(Connections::Rigid, false);
    let base = mass_x_t(&model(&s, &[]));
    let with = mass_x_t(&model(&s, &[("member_mass_factor", 1.0)]));
    // 3.6 m x 2.4 m: y-lines at x = 0.6 … 3.0 (main at 0.6, 1.8, 3.0; sub at
    // 1.2, 2.4), each 2.4 m; cross tees on 3 rows of 3.6 m; rods on the main
    // tees at y = 0.6 and 1.8, in ROD_ELEMENTS beams of 1 m / n each, all
    // but the top node's half-beam (1 − 1/2n of each 1 m rod).
    let [main, cross, sub, rod] = MEMBER_KG_PER_M;
    let rod_m = 1.0 - 0.5 / ROD_ELEMENTS as f64;
    let kg = 3.0 * 2.4 * main + 2.0 * 2.4 * sub + 3.0 * 3.6 * cross + 6.0 * rod_m * rod;
    assert!((with - base - kg * 1e-3).abs() < 1e-12, "{} t added, {} kg expected", with - base, kg);
    let panels = mass_x_t(&model(&s, &[("panel_mass_factor", 0.8)]));
    assert!((panels - 0.8 * base).abs() < 1e-12);
}

#[test]
fn a_soft_perimeter_across_lowers_the_first_mode_and_touches_no_other_spring() {
    let s = spec(Connections::Rigid, false);
    let (stiff, soft) = (model(&s, &[]), model(&s, &[("K_across", 50.0)]));
    assert!(first_hz(&soft) < first_hz(&stiff));
    let across = soft.materials.last().unwrap();
    assert_eq!(across.spec, MaterialSpec::Elastic { k: 50.0 });
    for (a, b) in stiff.springs.iter().zip(&soft.springs) {
        let changed = a.mat != b.mat;
        let perpendicular = a.group.as_deref() == Some("perimeter_perpendicular");
        assert_eq!(changed, perpendicular, "{a:?} -> {b:?}");
        if changed {
            assert!(b.mat == across.id && b.rayleigh);
        }
    }
}

#[test]
fn joints_that_turn_soften_the_grid_only_where_there_are_joints() {
    let s = spec(Connections::Elastic, false);
    let stiff = first_hz(&model(&s, &[]));
    let soft = model(&s, &[("K_joint_rot", 1.0e3)]);
    assert!(first_hz(&soft) < stiff);
    let turned =
        soft.springs.iter().filter(|sp| sp.dof == 6 && sp.mat == soft.materials.last().unwrap().id);
    let joints = soft.springs.iter().filter(|sp| sp.group.as_deref() == Some("connection_axial"));
    assert_eq!(turned.count(), joints.count());
    let mut rigid = Parameters::prior_midpoints_for(&spec(Connections::Rigid, false));
    assert!(rigid.set("K_joint_rot", 1.0e3).is_err());
}

#[test]
fn the_bundle_frame_puts_main_tees_and_rods_on_lines_from_the_origin() {
    let main_lines = |m: &Model| {
        let mut x: Vec<i64> = (m.beams.iter())
            .filter(|b| b.group.as_deref() == Some("main_tee"))
            .map(|b| m.nodes.iter().find(|n| n.id == b.i).unwrap().xyz_mm[0].round() as i64)
            .collect();
        x.dedup();
        x.sort_unstable();
        x.dedup();
        x
    };
    let rod_rows = |m: &Model| {
        let mut y: Vec<i64> = (m.beams.iter())
            .filter(|b| b.group.as_deref() == Some("rod"))
            .map(|b| m.nodes.iter().find(|n| n.id == b.i).unwrap().xyz_mm[1].round() as i64)
            .collect();
        y.sort_unstable();
        y.dedup();
        y
    };
    let verification = model(&spec(Connections::Rigid, false), &[]);
    let bundle = model(&spec(Connections::Rigid, true), &[]);
    assert_eq!(main_lines(&verification), vec![600, 1800, 3000]);
    assert_eq!(main_lines(&bundle), vec![1200, 2400]);
    assert_eq!(rod_rows(&verification), vec![600, 1800]);
    assert_eq!(rod_rows(&bundle), vec![1200]);
}
