//! Every bad-input case of the model format is refused on load with a
//! message naming the item and what was expected; a valid model round-trips
//! through JSON unchanged.

use std::path::Path;

use fe::model::{parse_model, ReadError};
use serde_json::{json, Value};

/// A small valid model: a beam 1–2, a spring 2–3 (coincident), masses, an eigen block.
fn valid() -> Value {
    json!({
        "format": "ceiling-fe-model", "format_version": 1, "name": "t",
        "units": {"force": "N", "length": "mm", "time": "s", "mass": "t"},
        "ndm": 3, "ndf": 6,
        "nodes": [[1, 0.0, 0.0, 0.0], [2, 600.0, 0.0, 0.0], [3, 600.0, 0.0, 0.0]],
        "fixities": [[1, 1, 1, 1, 1, 1, 1], [3, 1, 1, 1, 1, 1, 1]],
        "materials": [{"id": 1, "type": "Elastic", "k": 20.0, "note": "x"},
                      {"id": 2, "type": "Steel01", "Fy": 2.0, "E0": 20.0, "b": 0.05}],
        "beams": [{"id": 1, "i": 1, "j": 2, "A": 38.0, "E": 210000.0, "G": 78000.0,
                   "J": 8200.0, "Iy": 7525.0, "Iz": 1000.0, "vecxz": [0.0, 0.0, 1.0], "group": "main_tee"}],
        "springs": [{"id": 2, "i": 3, "j": 2, "dof": 1, "mat": 1, "rayleigh": true}],
        "masses": [{"node": 2, "m": [0.0006, 0.0006, 0.0006, 0.0, 0.0, 0.0]}],
        "analysis": {"type": "eigen", "n_modes": 2}
    })
}

/// The error message of loading `v`.
fn error(v: &Value) -> String {
    match parse_model(&v.to_string(), Path::new("m.json")) {
        Ok(_) => panic!("accepted an invalid model"),
        Err(e) => e.to_string(),
    }
}

fn expect(edit: impl Fn(&mut Value), message: &str) {
    let mut v = valid();
    edit(&mut v);
    let e = error(&v);
    assert!(e.contains(message), "expected `{message}` in `{e}`");
}

#[test]
fn valid_model_loads_and_round_trips() {
    let m = parse_model(&valid().to_string(), Path::new("m.json")).unwrap();
    let text = serde_json::to_string(&m).unwrap();
    let again = parse_model(&text, Path::new("m.json")).unwrap();
    assert_eq!(m, again);
    assert_eq!(m.materials[1].spec.type_name(), "Steel01");
}

#[test]
fn duplicate_ids_are_refused() {
    expect(|v| v["nodes"][2][0] = json!(2), "node id 2: duplicate node id");
    expect(|v| v["springs"][0]["id"] = json!(1), "element id 1: duplicate element id");
    expect(|v| v["materials"][1]["id"] = json!(1), "material id 1: duplicate material id");
}

#[test]
fn dangling_references_are_refused() {
    expect(|v| v["beams"][0]["j"] = json!(9), "beam 1: node 9 does not exist");
    expect(|v| v["springs"][0]["i"] = json!(7), "spring 2: node 7 does not exist");
    expect(|v| v["springs"][0]["mat"] = json!(5), "spring 2: material 5 does not exist");
    expect(|v| v["masses"][0]["node"] = json!(8), "mass on node 8: node 8 does not exist");
    expect(|v| v["fixities"][0][0] = json!(6), "fixity of node 6: node 6 does not exist");
}

#[test]
fn spring_between_non_coincident_nodes_is_refused() {
    expect(
        |v| v["nodes"][2] = json!([3, 600.0, 0.0, 5.0]),
        "spring 2: nodes 3 and 2 are 5 mm apart: expected coincident nodes",
    );
    expect(|v| v["springs"][0]["dof"] = json!(7), "spring 2: dof = 7: expected 1..6");
}

#[test]
fn parallel_vecxz_is_refused() {
    expect(
        |v| v["beams"][0]["vecxz"] = json!([2.0, 0.0, 0.0]),
        "beam 1: vecxz [2.0, 0.0, 0.0] is parallel",
    );
    expect(
        |v| v["beams"][0]["vecxz"] = json!([0.0, 0.0, 0.0]),
        "beam 1: vecxz [0.0, 0.0, 0.0] is parallel",
    );
    expect(|v| v["beams"][0]["j"] = json!(1), "beam 1: nodes 1 and 1 coincide");
}

#[test]
fn negative_section_properties_are_refused() {
    for key in ["A", "E", "G", "J", "Iy", "Iz"] {
        expect(|v| v["beams"][0][key] = json!(-1.0), &format!("beam 1: {key} = -1: expected > 0"));
    }
    expect(|v| v["masses"][0]["m"][1] = json!(-0.1), "mass on node 2: m[1] = -0.1: expected >= 0");
}

#[test]
fn wrong_units_and_format_are_refused() {
    expect(|v| v["units"]["length"] = json!("m"), "units.length = `m`: expected `mm`");
    expect(|v| v["units"]["mass"] = json!("kg"), "units.mass = `kg`: expected `t`");
    expect(|v| v["format_version"] = json!(2), "expected `ceiling-fe-model` version 1");
    expect(|v| v["ndf"] = json!(3), "expected ndm = 3, ndf = 6");
}

#[test]
fn invalid_material_and_malformed_json_are_refused() {
    expect(
        |v| v["materials"][0] = json!({"id": 1, "type": "Gap", "k": 5.0, "gap": -1.0}),
        "material 1: Gap: gap = -1",
    );
    let e = parse_model("{\"format\": 3", Path::new("m.json")).unwrap_err();
    assert!(matches!(e, ReadError::Json { line: 1, .. }), "{e}");
    expect(|v| v["nodes"][0] = json!([1, 0.0, 0.0]), "m.json:");
}

#[test]
fn bad_damping_is_refused() {
    let with = |d: Value| move |v: &mut Value| v["damping"] = d.clone();
    let ok = json!({"type": "rayleigh", "alphaM": 0.5, "betaK": 1e-3, "stiffness": "committed"});
    let mut v = valid();
    with(ok)(&mut v);
    parse_model(&v.to_string(), Path::new("m.json")).unwrap();
    expect(
        with(json!({"type": "modal", "alphaM": 0.5, "betaK": 1e-3})),
        "damping.type = `modal`: expected `rayleigh`",
    );
    expect(
        with(json!({"type": "rayleigh", "alphaM": -0.5, "betaK": 1e-3})),
        "damping.alphaM = -0.5: expected a finite number >= 0",
    );
    expect(
        with(json!({"type": "rayleigh", "alphaM": 0.5, "betaK": 1e308, "stiffness": "current"})),
        "damping.stiffness = \"current\": expected \"initial\" or \"committed\"",
    );
    expect(
        with(json!({"type": "rayleigh", "alphaM": 0.5, "betaK": 1e-3, "stiffness": 1})),
        "damping.stiffness = 1: expected",
    );
}

#[test]
fn a_committed_share_needs_the_committed_form_and_0_to_1() {
    let with = |d: Value| move |v: &mut Value| v["damping"] = d.clone();
    let mut v = valid();
    with(json!({"type": "rayleigh", "alphaM": 0.5, "betaK": 1e-3, "stiffness": "committed",
                "committed_share": 0.25}))(&mut v);
    let m = parse_model(&v.to_string(), Path::new("m.json")).unwrap();
    assert_eq!(m.damping.unwrap().committed_share(), Ok(0.25));
    expect(
        with(json!({"type": "rayleigh", "alphaM": 0.5, "betaK": 1e-3, "stiffness": "committed",
                    "committed_share": 1.5})),
        "damping.committed_share = 1.5: expected a number 0..=1, with stiffness = \"committed\"",
    );
    expect(
        with(json!({"type": "rayleigh", "alphaM": 0.5, "betaK": 1e-3, "committed_share": 0.5})),
        "damping.committed_share = 0.5: expected",
    );
}
