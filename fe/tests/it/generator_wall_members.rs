//! Members on the wall lines (`wall_members`): a main tee on each wall
//! that falls on the main-tee lines, hung on rods, and cross tees along the
//! y walls, their nodes held by the walls' perimeter springs. Counts of a
//! 2.4 m x 2.4 m specimen, the panels' whole mass, the joints at the walls
//! (very stiff connections rebuild the continuous grid), and the stiffer
//! plan they make.

use crate::common::type_c_structure;
use fe::eigen::{modal_analysis, LanczosSettings};
use fe::generator::{
    generate, CeilingSpec, Connections, ModelOptions, Parameters, Perimeter, Structure,
};
use fe::model::Model;

/// A semi-free 2.4 m x 2.4 m specimen in the bundle frame (main tees at
/// x = 0, 1.2, 2.4 m), members on the walls or not.
fn spec(wall_members: bool, connections: Connections, perimeter: Perimeter) -> CeilingSpec {
    let structure = Structure {
        layers: 1,
        lines_from_origin: true,
        wall_members,
        ..type_c_structure(2.4, 2.4)
    };
    CeilingSpec { structure, model: ModelOptions { perimeter, connections } }
}

fn model(s: &CeilingSpec, set: &[(&str, f64)]) -> Model {
    let mut p = Parameters::prior_midpoints_for(s);
    for (name, value) in set {
        p.set(name, *value).unwrap();
    }
    generate(s, &p).unwrap()
}

fn count(m: &Model, group: &str) -> usize {
    let beams = m.beams.iter().filter(|b| b.group.as_deref() == Some(group)).count();
    beams + m.springs.iter().filter(|s| s.group.as_deref() == Some(group)).count()
}

fn frequencies(m: &Model, n: usize) -> Vec<f64> {
    modal_analysis(m, n, &LanczosSettings::default()).unwrap().1.freq_hz
}

#[test]
fn wall_lines_carry_members_rods_and_the_corners() {
    let rigid = |walls| model(&spec(walls, Connections::Rigid, Perimeter::Linear), &[]);
    let (inside, walls) = (rigid(false), rigid(true));
    // 4 x 4 modules: main tees on y-lines 0, 2, 4, sub cross tees on 1, 3.
    assert_eq!((count(&inside, "main_tee"), count(&walls, "main_tee")), (4, 12));
    assert_eq!((count(&inside, "sub_cross_tee"), count(&walls, "sub_cross_tee")), (8, 8));
    assert_eq!((count(&inside, "cross_tee"), count(&walls, "cross_tee")), (12, 20));
    // Rods on the main tees at y = 1.2 m: x = 1.2 m only, or x = 0, 1.2, 2.4 m.
    assert_eq!((count(&inside, "rod"), count(&walls, "rod")), (1, 3));
    // Every grid end on a wall: 3 (or 5) ends along each of the four walls;
    // a corner takes the ends of both walls on one wall node.
    let ends = |m: &Model| count(m, "perimeter_vertical");
    assert_eq!((ends(&inside), ends(&walls)), (12, 20));
    let wall_nodes =
        |m: &Model| m.nodes.iter().filter(|n| (100000..200000).contains(&n.id)).count();
    assert_eq!((wall_nodes(&inside), wall_nodes(&walls)), (12, 16));
    // The corners are grid nodes: the panels' whole mass, 16 x 1.2 kg.
    let mass_t = |m: &Model| m.masses.iter().map(|x| x.m_t[0]).sum::<f64>();
    assert!((mass_t(&walls) - 16.0 * 1.2e-3).abs() < 1e-15, "{}", mass_t(&walls));
    assert!((mass_t(&inside) - 15.0 * 1.2e-3).abs() < 1e-15, "{}", mass_t(&inside));
    assert_eq!(walls.meta.as_ref().unwrap()["wall_members"], true);
    assert!(inside.meta.as_ref().unwrap().get("wall_members").is_none());
}

/// The joints the wall lines add (cross tees ending at a wall's main tee,
/// sub cross tees ending at a wall's cross tee, a wall's cross tee ending
/// at the main tees) rebuild the continuous grid when very stiff.
#[test]
fn stiff_joints_on_the_walls_give_the_continuous_grid() {
    let perimeter = Perimeter::Linear;
    let m_rigid = model(&spec(true, Connections::Rigid, perimeter), &[]);
    let stiff: Vec<(&str, f64)> =
        ["K_cc1", "K_cc2", "K_cc3", "K_mc"].into_iter().map(|n| (n, 1e10)).collect();
    let m_el = model(&spec(true, Connections::Elastic, perimeter), &stiff);
    let axial = count(&m_el, "connection_axial");
    // Cross tees end at the main tees (rows 0..4 x main lines 0, 2, 4,
    // a piece on each side the row goes on: 5 x (1 + 2 + 1) = 20) and sub
    // cross tees at the cross tees (lines 1, 3 x rows 0..4, a piece on each
    // side the line goes on: 2 x (1 + 2 + 2 + 2 + 1) = 16).
    assert_eq!(axial, 36);
    let (f_rigid, f_el) = (frequencies(&m_rigid, 12), frequencies(&m_el, 12));
    for (k, (a, b)) in f_rigid.iter().zip(&f_el).enumerate() {
        assert!((a - b).abs() / a < 1e-6, "mode {}: rigid {a} Hz, stiff joints {b} Hz", k + 1);
    }
}

/// On a semi-free specimen the wall lines' members and rods stiffen the
/// plan: every one of the first six modes rises.
#[test]
fn members_on_the_walls_stiffen_the_plan() {
    let elastic = |walls| model(&spec(walls, Connections::Elastic, Perimeter::Linear), &[]);
    let (f_inside, f_walls) = (frequencies(&elastic(false), 6), frequencies(&elastic(true), 6));
    eprintln!("inside {f_inside:.3?} Hz, members on the walls {f_walls:.3?} Hz");
    for (a, b) in f_inside.iter().zip(&f_walls) {
        assert!(b > a, "{b} Hz with members on the walls, {a} Hz without");
    }
}

/// Every perimeter law and the hysteretic joints build with members on
/// the walls (gap spreads over the longer walls included).
#[test]
fn every_variant_builds_with_members_on_the_walls() {
    for perimeter in
        [Perimeter::Linear, Perimeter::Friction, Perimeter::Pounding, Perimeter::FrictionPounding]
    {
        for connections in [Connections::Rigid, Connections::Elastic, Connections::Pinching4] {
            let s = spec(true, connections, perimeter);
            let spread: &[(&str, f64)] =
                if perimeter.has_pounding() { &[("gap_spread", 0.3)] } else { &[] };
            let m = model(&s, spread);
            assert!(frequencies(&m, 3)[0] > 0.0, "{perimeter:?} {connections:?}");
        }
    }
}

/// `hanger_offset_m` moves the rows of rods: at 0.6 m on the 1.2 m grid
/// they hang at y = 0.6 and 1.8 m instead of 1.2 m; an offset off the
/// module, negative or not below the spacing is refused with its key.
#[test]
fn hanger_offset_moves_the_rows_of_rods() {
    let rods_y_mm = |walls: bool, offset_m: f64| -> Vec<(f64, f64)> {
        let mut s = spec(walls, Connections::Elastic, Perimeter::Linear);
        s.structure.hanger_offset_m = offset_m;
        s.check().unwrap();
        let m = model(&s, &[]);
        let mut at: Vec<(f64, f64)> = m
            .nodes
            .iter()
            .filter(|n| (200000..300000).contains(&n.id))
            .map(|n| (n.xyz_mm[0], n.xyz_mm[1]))
            .collect();
        at.sort_by(|a, b| a.partial_cmp(b).unwrap());
        at
    };
    assert_eq!(rods_y_mm(false, 0.0), [(1200.0, 1200.0)]);
    assert_eq!(rods_y_mm(false, 0.6), [(1200.0, 600.0), (1200.0, 1800.0)]);
    let walls = rods_y_mm(true, 0.6);
    assert_eq!(walls.len(), 6, "{walls:?}");
    assert!(walls.iter().all(|(_, y)| *y == 600.0 || *y == 1800.0), "{walls:?}");
    for bad in [1.2, 0.3, -0.6, f64::NAN] {
        let mut s = spec(false, Connections::Elastic, Perimeter::Linear);
        s.structure.hanger_offset_m = bad;
        let e = s.check().unwrap_err().to_string();
        assert!(e.contains("structure.hanger_offset_m"), "{bad}: {e}");
    }
}
