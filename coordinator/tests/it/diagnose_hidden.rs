//! Tests that hide an effect: synthesise small campaigns (3.6 m x 3.6 m,
//! three short runs at 100 Hz) with each effect at moderate strength and a
//! null case with noise only, diagnose them without the answer, and require
//! the right cause, `none` on the null case, and the gain.

use coordinator::bundle::read_bundle;
use coordinator::diagnose::calibrate::Budget;
use coordinator::diagnose::pipeline::{diagnose, CandidateResult, DiagnoseOptions, Diagnosis};
use coordinator::synth::synth_to_dir;

/// The demo campaign with another seed and effect; with `channels` a
/// double-layer ceiling whose carrying channels weigh that (kg/m) and tie
/// the main tees by that fraction of the seed's section.
fn campaign(effect: &str, seed: u64, channels: Option<(f64, f64)>) -> String {
    let text = include_str!("../../../configs/synth/demo.toml");
    let mut out = String::new();
    for line in text.lines() {
        let line = if line.starts_with("seed =") {
            format!("seed = {seed}")
        } else if line.starts_with("effect =") {
            format!("effect = \"{effect}\"")
        } else if let (Some(_), true) = (channels, line.starts_with("layers =")) {
            "layers = 2".to_string()
        } else if let (Some((m, b)), true) = (channels, line.starts_with("parameters =")) {
            let channels = format!(", channel_mass_kg_per_m = {m}, channel_beam_factor = {b} }}");
            line.replacen(" }", &channels, 1)
        } else {
            line.to_string()
        };
        out.push_str(&line);
        out.push('\n');
    }
    out
}

fn run(effect: &str, seed: u64) -> (String, f64) {
    let d = diagnosis(&campaign(effect, seed, None), effect, seed);
    (d.cause.as_str().to_string(), d.gain)
}

/// The diagnosis of a campaign synthesised from `text`.
fn diagnosis(text: &str, label: &str, seed: u64) -> Diagnosis {
    let tmp = tempfile::tempdir().unwrap();
    let spec = tmp.path().join("campaign.toml");
    std::fs::write(&spec, text).unwrap();
    let bundle_dir = tmp.path().join("bundle");
    let answer = tmp.path().join("answer.json");
    synth_to_dir(&spec, &bundle_dir, &answer, &mut |_| {}).unwrap();
    std::fs::remove_file(&answer).unwrap();
    let b = read_bundle(&bundle_dir).unwrap();
    let opts =
        DiagnoseOptions { budget: Budget { seed, ..Budget::default() }, ..Default::default() };
    let d = diagnose(&b, &opts, &mut |_, _, _| {}).unwrap();
    for c in &d.candidates {
        eprintln!(
            "{label} seed {seed}: {} mdl {:?} val {:.4}{}",
            c.cause.as_str(),
            c.mdl.as_ref().map(|m| m.total),
            c.validation_error,
            if c.selected { " <- selected" } else { "" }
        );
    }
    baseline_fits_where_no_extension_engages(&d);
    assert!(d.unexplained.is_none(), "{label} seed {seed}: {:?}", d.unexplained);
    d
}

/// An extension whose onset lies beyond the calibration runs' demand (gap
/// or slip force above 1.1 times it) is the baseline there, so it fits the
/// calibration runs no better than the baseline does.
fn baseline_fits_where_no_extension_engages(d: &Diagnosis) {
    let fit = |c: &CandidateResult| c.mdl.as_ref().map(|m| m.fit);
    let Some(base) = fit(&d.candidates[0]) else { return };
    let onset = |c: &CandidateResult| {
        let names = ["gap_over_demand", "slip_over_demand"];
        c.estimates.iter().find(|e| names.contains(&e.name.as_str())).map(|e| e.value)
    };
    for c in &d.candidates[1..] {
        if let (Some(f), Some(x)) = (fit(c), onset(c)) {
            let what = c.cause.as_str();
            assert!(
                x < 1.1 || f > base - 1.0,
                "{what} (onset {x:.2}) fits by {f:.1}, baseline {base:.1}"
            );
        }
    }
}

#[test]
fn null_case_is_none() {
    let (cause, gain) = run("none", 101);
    assert_eq!(cause, "none");
    assert_eq!(gain, 0.0);
}

#[test]
fn hidden_pounding_is_found() {
    let (cause, gain) = run("perimeter-pounding", 102);
    assert_eq!(cause, "perimeter-pounding");
    assert!(gain > 0.5, "gain {gain}");
}

#[test]
fn hidden_friction_is_found() {
    let (cause, gain) = run("perimeter-friction", 103);
    assert_eq!(cause, "perimeter-friction");
    assert!(gain > 0.5, "gain {gain}");
}

/// The calibrated CJS-A model must reach the truth's basin: its
/// time-history likelihood is needle-sharp, so the extension first fits the
/// windowed RMS misfits (coarse) and then the time histories (fine).
#[test]
fn hidden_connection_hysteresis_is_found() {
    let (cause, gain) = run("connection-hysteresis", 104);
    assert_eq!(cause, "connection-hysteresis");
    assert!(gain > 0.5, "gain {gain}");
}

/// A double-layer ceiling with the seed's carrying channels, 2.24 kg/m (as
/// much again as half its panels) rigidly joined to the main tees: without
/// them the baseline is too light, and the hidden pounding must still be
/// found with them.
#[test]
fn carrying_channels_are_weighed_and_hidden_pounding_found() {
    let seed = 105;
    let d = diagnosis(&campaign("perimeter-pounding", seed, Some((2.24, 1.0))), "channels", seed);
    let form = d.channels.expect("a double-layer ceiling weighs its channels");
    eprintln!("channels: {form:?}; baseline: {:?}", d.candidates[0].estimates);
    assert!(form.calibrated, "{form:?}");
    let base = &d.candidates[0].estimates;
    let mass = base.iter().find(|e| e.name == "channel_mass_kg_per_m").unwrap();
    assert!((mass.value - 2.24).abs() < 0.25, "{mass:?}");
    let beams = base.iter().find(|e| e.name == "channel_beam_factor").unwrap();
    assert!(beams.value > 0.8, "{beams:?}");
    assert_eq!(d.cause.as_str(), "perimeter-pounding");
    assert!(d.gain > 0.5, "gain {}", d.gain);
}
