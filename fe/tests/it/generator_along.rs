//! Each grid line's support along its axis ([`fe::generator::along`]): a
//! factor on `K_friction` at both ends of one line, and nothing else.

use crate::common::type_c_structure;
use fe::eigen::{modal_analysis, LanczosSettings};
use fe::generator::along::{line_factor_name, row_factor_name};
use fe::generator::{
    generate, CeilingSpec, Connections, GenerateError, ModelOptions, Parameters, Perimeter,
    Structure,
};
use fe::materials::MaterialSpec;
use fe::model::{Model, Spring};

fn spec(perimeter: Perimeter) -> CeilingSpec {
    let structure = Structure { layers: 1, ..type_c_structure(3.6, 2.4) };
    CeilingSpec { structure, model: ModelOptions { perimeter, connections: Connections::Rigid } }
}

fn model(s: &CeilingSpec, set: &[(&str, f64)]) -> Result<Model, GenerateError> {
    let mut p = Parameters::prior_midpoints_for(s);
    for (name, value) in set {
        p.set(name, *value).unwrap();
    }
    generate(s, &p)
}

fn along(m: &Model) -> Vec<&Spring> {
    m.springs.iter().filter(|s| s.group.as_deref() == Some("perimeter_friction")).collect()
}

fn material(m: &Model, id: u64) -> &MaterialSpec {
    &m.materials.iter().find(|d| d.id == id).unwrap().spec
}

/// y of the grid node of a perimeter spring (its non-wall node).
fn y_mm(m: &Model, s: &Spring) -> f64 {
    let grid = if s.i >= 100000 { s.j } else { s.i };
    m.nodes.iter().find(|n| n.id == grid).unwrap().xyz_mm[1]
}

#[test]
fn unset_or_one_changes_nothing() {
    let s = spec(Perimeter::Linear);
    let plain = model(&s, &[]).unwrap();
    let one = model(&s, &[(row_factor_name(1200.0), 1.0), (line_factor_name(600.0), 1.0)]);
    let one = one.unwrap();
    assert_eq!(plain.materials, one.materials);
    assert_eq!(plain.springs, one.springs);
}

#[test]
fn a_rows_factor_scales_both_its_ends_and_nothing_else() {
    for perimeter in [Perimeter::Linear, Perimeter::Friction] {
        let s = spec(perimeter);
        let plain = model(&s, &[]).unwrap();
        let k_f = Parameters::prior_midpoints_for(&s).value_or_midpoint("K_friction");
        let scaled = model(&s, &[(row_factor_name(1200.0), 1.5)]).unwrap();
        let mut changed = 0;
        for (a, b) in along(&plain).into_iter().zip(along(&scaled)) {
            let in_row = a.dof == 1 && (y_mm(&plain, a) - 1200.0).abs() < 1e-9;
            match (material(&plain, a.mat), material(&scaled, b.mat)) {
                (MaterialSpec::Elastic { k: k0 }, MaterialSpec::Elastic { k }) if in_row => {
                    assert!((k / k0 - 1.5).abs() < 1e-12 && (k0 - k_f).abs() < 1e-12);
                    assert!(b.rayleigh, "an elastic along law is damped with the grid");
                    changed += 1;
                }
                (
                    MaterialSpec::Steel01 { fy: fy0, e0: e00, .. },
                    MaterialSpec::Steel01 { fy, e0, .. },
                ) if in_row => {
                    assert!((e0 / e00 - 1.5).abs() < 1e-12 && fy == fy0, "the slip force stays");
                    assert!(!b.rayleigh);
                    changed += 1;
                }
                (x, y) => assert_eq!(x, y, "{a:?}"),
            }
        }
        assert_eq!(changed, 2, "{perimeter:?}: the row's two ends");
    }
}

#[test]
fn every_line_at_one_factor_is_k_friction_times_it() {
    let s = spec(Perimeter::Linear);
    let k_f = Parameters::prior_midpoints_for(&s).value_or_midpoint("K_friction");
    // 3.6 m x 2.4 m, lines one module in: rows at y = 600 … 1800, y-lines at
    // x = 600 … 3000.
    let mut set: Vec<(&str, f64)> =
        (1..=3).map(|j| (row_factor_name(600.0 * j as f64), 1.7)).collect();
    set.extend((1..=5).map(|i| (line_factor_name(600.0 * i as f64), 1.7)));
    let by_lines = model(&s, &set).unwrap();
    let by_k = model(&s, &[("K_friction", 1.7 * k_f)]).unwrap();
    let hz = |m: &Model| modal_analysis(m, 8, &LanczosSettings::default()).unwrap().1.freq_hz;
    for (a, b) in hz(&by_lines).iter().zip(hz(&by_k)) {
        assert!((a / b - 1.0).abs() < 1e-9, "{a} vs {b}");
    }
}

#[test]
fn a_line_the_specimen_lacks_is_refused() {
    let s = spec(Perimeter::Linear);
    let err = model(&s, &[(row_factor_name(900.0), 1.2)]).unwrap_err();
    let text = err.to_string();
    assert!(text.contains("along_factor_row_y900"), "{text}");
    assert!(text.contains("along_factor_row_y600"), "names the lines it has: {text}");
    assert_eq!(text.matches("along_factor_row_y600,").count(), 1, "each once: {text}");
    let mut p = Parameters::prior_midpoints_for(&s);
    assert!(p.set("along_factor_row_y600", 0.0).is_err(), "a factor is positive");
    assert!(p.set("along_factor_row_y600.5", 1.0).is_err(), "whole millimetres");
}

#[test]
fn the_sliding_lines_are_listed_once_rows_first() {
    let s = spec(Perimeter::Linear);
    let names = fe::generator::along_factor_names(&s);
    let expected = [
        "along_factor_row_y600",
        "along_factor_row_y1200",
        "along_factor_row_y1800",
        "along_factor_line_x600",
        "along_factor_line_x1200",
        "along_factor_line_x1800",
        "along_factor_line_x2400",
        "along_factor_line_x3000",
    ];
    assert_eq!(names, expected);
    // Each takes a factor the generator accepts.
    let set: Vec<(&str, f64)> = names.iter().map(|n| (*n, 1.1)).collect();
    assert!(model(&s, &set).is_ok());
    // On a fixed wall nothing slides: its lines take no factor.
    let mut fixed = s.clone();
    fixed.structure.boundary = fe::generator::Boundary::Fixed;
    assert!(fe::generator::along_factor_names(&fixed).is_empty());
}
