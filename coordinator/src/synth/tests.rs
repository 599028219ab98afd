//! Synthetic campaigns: the bundle reads back, the truth stays outside it,
//! effects are sized from the baseline, bad files are refused clearly.

use super::spec::SynthSpec;
use super::synth_to_dir;
use crate::bundle::read_bundle;

pub(super) const SPEC: &str = r#"
name = "tiny"
seed = 3
[structure]
length_x_m = 2.4
length_y_m = 2.4
module_m = 0.6
main_tee_spacing_m = 1.2
hanger_spacing_m = 1.2
hanger_length_m = 1.0
panel_mass_kg = 1.2
boundary = "semi-free"
nominal_gap_mm = 19.0
[[sensors]]
id = "A"
kind = "acceleration"
x_m = 1.2
y_m = 1.2
direction = "x"
units = "g"
[[sensors]]
id = "D"
kind = "displacement"
x_m = 1.2
y_m = 1.2
direction = "x"
units = "m"
[[runs]]
id = "wn"
excitation = "white-noise"
direction = "x"
pga_g = 0.05
duration_s = 4.0
[[runs]]
id = "sw"
excitation = "sine-sweep"
direction = "xy"
pga_g = 0.2
duration_s = 4.0
sample_rate_hz = 100.0
input_units = "m/s2"
[noise]
accel_rms_m_s2 = 0.01
missing_fraction = 0.01
[modal]
modes = 3
std_hz = 0.01
"#;

fn write(dir: &std::path::Path, text: &str) -> std::path::PathBuf {
    let p = dir.join("campaign.toml");
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn an_effects_own_truth_values_do_not_reach_the_baseline_that_sizes_it() {
    let tmp = tempfile::tempdir().unwrap();
    let own = "[truth]\nparameters = { impact_factor = 0.8, gap_spread = 0.3 }\n";
    let hidden = "[hidden]\neffect = \"perimeter-pounding\"\n";
    let spec = write(tmp.path(), &format!("{SPEC}\n{own}{hidden}"));
    let ans = synth_to_dir(&spec, &tmp.path().join("b"), &tmp.path().join("a.json"), &mut |_| {})
        .unwrap();
    assert_eq!((ans.parameters["impact_factor"], ans.parameters["gap_spread"]), (0.8, 0.3));
    let plain = write(tmp.path(), &format!("{SPEC}\n{hidden}"));
    let base = synth_to_dir(&plain, &tmp.path().join("c"), &tmp.path().join("c.json"), &mut |_| {})
        .unwrap();
    assert_eq!(ans.baseline_demand, base.baseline_demand);
    // Without the effect the baseline refuses them, by key.
    let none = write(tmp.path(), &format!("{SPEC}\n{own}"));
    let e = synth_to_dir(&none, &tmp.path().join("d"), &tmp.path().join("d.json"), &mut |_| {})
        .unwrap_err();
    assert!(e.to_string().contains("truth.parameters.gap_spread"), "{e}");
}

#[test]
fn a_campaign_reads_back_and_keeps_its_answer_outside() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = write(tmp.path(), &format!("{SPEC}\n[hidden]\neffect = \"perimeter-pounding\"\n"));
    let out = tmp.path().join("bundle");
    let answer = tmp.path().join("answer.json");
    let ans = synth_to_dir(&spec, &out, &answer, &mut |_| {}).unwrap();
    let b = read_bundle(&out).unwrap();
    assert_eq!(b.runs.len(), 2);
    assert_eq!(b.runs[1].dt_s, 0.01);
    assert_eq!(b.modal.as_ref().unwrap().len(), 3);
    // Pounding sized at 60 % of the baseline's peak perimeter displacement.
    let demand = ans.baseline_demand.unwrap();
    let gap = ans.parameters["gap_ratio"] * 19.0;
    assert!((gap - 0.6 * demand[0]).abs() < 1e-9 * gap, "{gap} {demand:?}");
    // Missing readings stay missing; the input has none.
    let a = b.runs[0].sensor("A").unwrap();
    let missing = a.iter().filter(|v| v.is_nan()).count() as f64 / a.len() as f64;
    assert!(missing > 0.0 && missing < 0.03, "{missing}");
    assert!(b.runs[0].input_x_m_s2.as_ref().unwrap().iter().all(|v| v.is_finite()));
    // Nothing in the bundle names the effect.
    for entry in walk(&out) {
        let text = std::fs::read_to_string(&entry).unwrap();
        assert!(!text.contains("pounding") && !text.contains("gap_ratio"), "{}", entry.display());
    }
    let inside = out.join("answer.json");
    let e = synth_to_dir(&spec, &out, &inside, &mut |_| {}).unwrap_err();
    assert!(e.to_string().contains("outside the bundle"), "{e}");
}

fn walk(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut out = vec![];
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

#[test]
fn bad_campaigns_are_refused_with_the_key() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        (format!("{SPEC}\n[hidden]\neffect = \"ghosts\"\n"), "hidden.effect"),
        (
            SPEC.replace("duration_s = 4.0\nsample_rate_hz", "duration_s = -1.0\nsample_rate_hz"),
            "runs.sw.duration_s",
        ),
        (
            SPEC.replace("missing_fraction = 0.01", "missing_fraction = 0.9"),
            "noise.missing_fraction",
        ),
        (SPEC.replace("seed = 3", "seed = 3\ncolour = 1"), "unknown field"),
        (
            format!("{SPEC}\n[truth]\ndamping_mass_share = 1.5\n"),
            "campaign.toml: truth.damping_mass_share = 1.5: 0 <= share <= 1",
        ),
        (
            format!("{SPEC}\n[hidden]\neffect = \"perimeter-pounding\"\n")
                .replace("boundary = \"semi-free\"", "boundary = \"fixed\""),
            "hidden.effect = \"perimeter-pounding\": no grid end can slide on a \"fixed\" perimeter",
        ),
    ];
    for (text, key) in cases {
        let spec = write(tmp.path(), &text);
        let e = match SynthSpec::from_file(&spec) {
            Err(e) => e.to_string(),
            Ok(_) => {
                synth_to_dir(&spec, &tmp.path().join("b"), &tmp.path().join("a.json"), &mut |_| {})
                    .unwrap_err()
                    .to_string()
            }
        };
        assert!(e.contains(key), "{key}: {e}");
    }
}

#[test]
fn a_record_run_reads_its_file_in_its_units() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("rec.csv"), "t,a\n0,0\n0.01,0.1\n0.02,-0.2\n0.03,0\n").unwrap();
    let text = SPEC.replace(
        "[[runs]]\nid = \"wn\"",
        "[[runs]]\nid = \"rec\"\nexcitation = \"record\"\ndirection = \"y\"\nrecord = \"rec.csv\"\n\n[[runs]]\nid = \"wn\"",
    );
    let spec = write(tmp.path(), &text);
    let out = tmp.path().join("bundle");
    synth_to_dir(&spec, &out, &tmp.path().join("a.json"), &mut |_| {}).unwrap();
    let b = read_bundle(&out).unwrap();
    let rec = &b.runs[0];
    assert_eq!(rec.dt_s, 0.01);
    assert!(rec.input_x_m_s2.is_none());
    let y = rec.input_y_m_s2.as_ref().unwrap();
    let g = 9.80665;
    for (got, want) in y.iter().zip([0.0, 0.1 * g, -0.2 * g, 0.0]) {
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
}
