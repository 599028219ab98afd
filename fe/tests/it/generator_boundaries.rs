//! The four perimeter conditions of the bundle format (seed 4.2.2): which
//! springs each wall gets, the spelling in `[structure] boundary`, the
//! stiffening order of the first in-plane mode (free < semi-free < fixed)
//! and a short transient of each with friction and pounding.

use std::collections::BTreeMap;
use std::path::Path;

use crate::common::{type_c_structure, verification_dir};
use fe::eigen::{modal_analysis, LanczosSettings};
use fe::generator::{
    generate, Boundary, CeilingSpec, Connections, EndCondition, ModelOptions, Parameters,
    Perimeter, Structure,
};
use fe::model::{Analysis, Damping, Model};
use fe::transient::{run_model, TransientOptions};
use serde_json::json;

const BOUNDARIES: [Boundary; 4] =
    [Boundary::SemiFree, Boundary::Free, Boundary::Fixed, Boundary::FixedSemiFree];

fn specimen(boundary: Boundary, perimeter: Perimeter) -> CeilingSpec {
    let structure = Structure { layers: 1, boundary, ..type_c_structure(2.4, 3.6) };
    CeilingSpec::new(structure, ModelOptions::new(perimeter, Connections::Elastic)).unwrap()
}

fn model(boundary: Boundary, perimeter: Perimeter) -> Model {
    let spec = specimen(boundary, perimeter);
    generate(&spec, &Parameters::prior_midpoints_for(&spec)).unwrap()
}

/// Perimeter springs counted by (wall, group).
fn groups(m: &Model) -> BTreeMap<(String, String), usize> {
    let mut out = BTreeMap::new();
    for s in m.springs.iter().filter(|s| s.side.is_some()) {
        let key = (s.side.clone().unwrap_or_default(), s.group.clone().unwrap_or_default());
        *out.entry(key).or_insert(0) += 1;
    }
    out
}

#[test]
fn each_wall_gets_the_springs_of_its_condition() {
    // 2.4 m x 3.6 m at 0.6 m: 3 grid ends on each x-normal... y0/y1 walls
    // (4 modules along x), 5 on each x0/x1 wall (6 modules along y).
    let ends = |side: &str| if side.starts_with('y') { 3 } else { 5 };
    for boundary in BOUNDARIES {
        let m = model(boundary, Perimeter::FrictionPounding);
        let got = groups(&m);
        for side in ["x0", "x1", "y0", "y1"] {
            let count = |group: &str| got.get(&(side.into(), group.into())).copied().unwrap_or(0);
            let n = ends(side);
            let (friction, gap, across, perpendicular, fixed) = match boundary.on_side(side) {
                EndCondition::SemiFree => (n, n, 0, n, 0),
                EndCondition::Free => (n, n, n, 0, 0),
                EndCondition::Fixed => (0, 0, 0, n, n),
            };
            let what = format!("{boundary:?} {side}");
            assert_eq!(count("perimeter_friction"), friction, "{what}");
            assert_eq!(count("perimeter_gap"), gap, "{what}");
            assert_eq!(count("perimeter_friction_across"), across, "{what}");
            assert_eq!(count("perimeter_perpendicular"), perpendicular, "{what}");
            assert_eq!(count("perimeter_fixed"), fixed, "{what}");
            assert_eq!(count("perimeter_vertical"), n, "{what}");
        }
    }
    // Fixed-semi-free: fixed on the walls through the origin only.
    let b = Boundary::FixedSemiFree;
    assert_eq!(b.on_side("x0"), EndCondition::Fixed);
    assert_eq!(b.on_side("y0"), EndCondition::Fixed);
    assert_eq!(b.on_side("x1"), EndCondition::SemiFree);
    assert_eq!(b.on_side("y1"), EndCondition::SemiFree);
    assert!(!Boundary::Fixed.has_sliding_ends());
    assert!(BOUNDARIES.iter().filter(|b| **b != Boundary::Fixed).all(|b| b.has_sliding_ends()));
}

#[test]
fn a_free_end_slides_both_ways_on_its_along_axis_law() {
    let m = model(Boundary::Free, Perimeter::Friction);
    let along: Vec<_> =
        m.springs.iter().filter(|s| s.group.as_deref() == Some("perimeter_friction")).collect();
    let across: Vec<_> = m
        .springs
        .iter()
        .filter(|s| s.group.as_deref() == Some("perimeter_friction_across"))
        .collect();
    assert_eq!(along.len(), across.len());
    for (a, c) in along.iter().zip(&across) {
        assert_eq!((a.i, a.j, a.mat), (c.i, c.j, c.mat));
        assert_ne!(a.dof, c.dof);
        assert!(c.dof == 1 || c.dof == 2);
    }
}

#[test]
fn boundaries_are_spelled_as_in_the_bundle_format() {
    for (text, boundary) in [
        ("semi-free", Boundary::SemiFree),
        ("free", Boundary::Free),
        ("fixed", Boundary::Fixed),
        ("fixed-semi-free", Boundary::FixedSemiFree),
    ] {
        let toml = format!(
            "[structure]\nlength_x_m = 2.4\nlength_y_m = 2.4\nmodule_m = 0.6\n\
             main_tee_spacing_m = 1.2\nhanger_spacing_m = 1.2\nhanger_length_m = 1.0\n\
             panel_mass_kg = 1.2\nboundary = \"{text}\"\nnominal_gap_mm = 19.0\n"
        );
        let spec = CeilingSpec::from_toml_str(&toml, Path::new("t.toml")).unwrap();
        assert_eq!(spec.structure.boundary, boundary);
        assert_eq!(boundary.as_str(), text);
    }
}

/// The lowest mode with most of its motion in the plane (Hz).
fn first_in_plane_hz(m: &Model) -> f64 {
    let (_, modes) = modal_analysis(m, 12, &LanczosSettings::default()).unwrap();
    modes.freq_hz[0]
}

/// More restraint at the walls, a stiffer ceiling: free < semi-free <
/// fixed-semi-free <= fixed in the first mode (linear perimeter).
#[test]
fn more_restraint_raises_the_first_frequency() {
    let f = |b| first_in_plane_hz(&model(b, Perimeter::Linear));
    let (free, semi, mixed, fixed) =
        (f(Boundary::Free), f(Boundary::SemiFree), f(Boundary::FixedSemiFree), f(Boundary::Fixed));
    assert!(free < semi && semi < mixed && mixed <= fixed, "{free} {semi} {mixed} {fixed}");
}

/// Half a second of the verification sweep at 0.5 g through every
/// boundary with friction and pounding: Newton converges throughout.
#[test]
fn every_boundary_runs_a_nonlinear_transient() {
    for boundary in BOUNDARIES {
        let mut m = model(boundary, Perimeter::FrictionPounding);
        m.damping = Some(Damping {
            kind: "rayleigh".into(),
            alpha_m_per_s: 4.76,
            beta_k_s: 5.2e-4,
            extra: Default::default(),
        });
        let node = m.masses[m.masses.len() / 2].node;
        let block = json!({
            "excitation": {"type": "uniform_base_acceleration", "dof": 1,
                           "record_csv": "sweep_x_unit_1g.csv", "dt": 0.002, "npts": 10001,
                           "scale": 0.5},
            "integrator": {"type": "Newmark", "gamma": 0.5, "beta": 0.25},
            "dt": 0.005, "n_steps": 100,
            "recorders": [{"name": "u", "node": node, "dof": 1, "response": "disp"}],
        });
        let serde_json::Value::Object(map) = block else { unreachable!() };
        m.analysis = Some(Analysis::Transient(map));
        let dir = verification_dir().join("models");
        let h = run_model(&m, &TransientOptions::new(&dir), &mut |_| {})
            .unwrap_or_else(|e| panic!("{boundary:?}: {e}"));
        assert_eq!(h.rows.len(), 101, "{boundary:?}");
        assert!(h.rows.iter().all(|r| r.iter().all(|v| v.is_finite())), "{boundary:?}");
    }
}
