//! Exported run models replayed without OpenSees: each exported model is
//! integrated by ceilfarm's transient solver straight from its file (its
//! records, recorders, damping), the histories are written as another
//! simulator would, and `--histories` must rebuild the normal bundle.

use super::tests::SPEC;
use super::{synth_to_dir, synth_to_dir_with, Simulator};
use crate::bundle::{read_bundle, Bundle};
use fe::transient::spec::{ExcitationSpec, RecorderSpec};
use fe::transient::TransientOptions;
use fe::transient::{run_plan, write_history_csv, BaseMotion, GroundMotion, History, Plan};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn campaign(dir: &Path, seed: u64) -> PathBuf {
    // A third sensor between grid nodes, read by interpolation weights.
    let between = "\n[[sensors]]\nid = \"B\"\nkind = \"acceleration\"\nx_m = 0.9\ny_m = 1.5\n\
                   direction = \"y\"\nunits = \"m/s2\"\n";
    let text = SPEC.replace("seed = 3", &format!("seed = {seed}"))
        + "\n[hidden]\neffect = \"perimeter-friction\"\n"
        + between;
    let p = dir.join("campaign.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// Integrates `mdir/<run>.json` as written and writes `<run>.history.csv`.
fn replay(mdir: &Path, run: &str) {
    let model = fe::model::read_model(&mdir.join(format!("{run}.json"))).unwrap();
    let Some(fe::model::Analysis::Transient(an)) = &model.analysis else {
        panic!("{run}.json has no transient stanza")
    };
    let get = |k: &str| an.get(k).cloned().unwrap_or(Value::Null);
    let exc: Vec<ExcitationSpec> = serde_json::from_value(get("excitations")).unwrap();
    let base = BaseMotion {
        components: exc.iter().map(|e| GroundMotion::from_spec(e, mdir).unwrap()).collect(),
    };
    let recorders: Vec<RecorderSpec> = serde_json::from_value(get("recorders")).unwrap();
    let plan = Plan {
        base: &base,
        dt_s: get("dt").as_f64().unwrap(),
        n_steps: get("n_steps").as_u64().unwrap() as usize,
        gamma: get("integrator")["gamma"].as_f64().unwrap(),
        beta: get("integrator")["beta"].as_f64().unwrap(),
        output_every_n_steps: get("output_every_n_steps").as_u64().unwrap() as usize,
        recorders: &recorders,
    };
    let h = run_plan(&model, &plan, &TransientOptions::new(mdir), &mut |_| {}).unwrap();
    let first = h.columns.len() - recorders.len();
    let mut columns = vec!["t_s".to_string()];
    columns.extend(h.columns[first..].iter().cloned());
    let rows = h.rows.iter().map(|r| [&r[..1], &r[first..]].concat()).collect();
    write_history_csv(&History { columns, rows }, &mdir.join(format!("{run}.history.csv")))
        .unwrap();
}

/// Exports the campaign, replays every run and fills modal.json / simulator.json.
fn export_and_replay(spec: &Path, tmp: &Path) -> PathBuf {
    let mdir = tmp.join("models");
    let sim = Simulator::Ceilfarm { export: Some(&mdir) };
    synth_to_dir_with(spec, &tmp.join("exported"), &tmp.join("e.json"), sim, &mut |_| {}).unwrap();
    for run in ["wn", "sw"] {
        replay(&mdir, run);
    }
    let path = mdir.join("modal.json");
    let mut modal: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    modal["freq_hz"] = modal["ceilfarm_freq_hz"].clone();
    std::fs::write(&path, modal.to_string()).unwrap();
    std::fs::write(mdir.join("simulator.json"), r#"{"simulator": "ceilfarm-replay"}"#).unwrap();
    mdir
}

/// Sensor readings within `rel` of each channel's peak (NaN where NaN), modal
/// frequencies within `rel`.
fn assert_close(a: &Bundle, b: &Bundle, rel: f64) {
    for (ra, rb) in a.runs.iter().zip(&b.runs) {
        assert_eq!(ra.sensors.len(), rb.sensors.len());
        for ((id, va), (_, vb)) in ra.sensors.iter().zip(&rb.sensors) {
            let peak = va.iter().filter(|v| v.is_finite()).fold(0.0f64, |m, v| m.max(v.abs()));
            assert_eq!(va.len(), vb.len(), "{} {id}", ra.id);
            for (k, (x, y)) in va.iter().zip(vb).enumerate() {
                let same = (x.is_nan() && y.is_nan()) || (x - y).abs() <= rel * peak;
                assert!(same, "run {} sensor {id} sample {k}: {x} vs {y}", ra.id);
            }
        }
    }
    let (ma, mb) = (a.modal.as_ref().unwrap(), b.modal.as_ref().unwrap());
    for (x, y) in ma.iter().zip(mb) {
        assert!((x.freq_hz - y.freq_hz).abs() <= rel * x.freq_hz, "{x:?} vs {y:?}");
    }
}

#[test]
fn exported_models_replayed_rebuild_the_bundle() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = campaign(tmp.path(), 3);
    let normal = tmp.path().join("normal");
    let ans = synth_to_dir(&spec, &normal, &tmp.path().join("n.json"), &mut |_| {}).unwrap();
    assert_eq!(ans.simulator, "ceilfarm");
    let mdir = export_and_replay(&spec, tmp.path());
    // Exporting does not change the bundle.
    let exported = read_bundle(&tmp.path().join("exported")).unwrap();
    let want = read_bundle(&normal).unwrap();
    assert_close(&exported, &want, 0.0);
    // Two directions in the xy run, one record file each; the sidecar names the columns.
    assert!(mdir.join("sw.base_x.csv").is_file() && mdir.join("sw.base_y.csv").is_file());
    let side: Value =
        serde_json::from_str(&std::fs::read_to_string(mdir.join("wn.sensors.json")).unwrap())
            .unwrap();
    assert_eq!(side["sensors"][0]["columns"][0], "A#0");
    assert_eq!(side["sensors"][1]["to_bundle"], 1.0);
    let w: Vec<f64> = serde_json::from_value(side["sensors"][2]["weights"].clone()).unwrap();
    assert!(w.len() > 1 && (w.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{w:?}");
    let out = tmp.path().join("replayed");
    let sim = Simulator::Histories(&mdir);
    let ans2 =
        synth_to_dir_with(&spec, &out, &tmp.path().join("r.json"), sim, &mut |_| {}).unwrap();
    assert_eq!(ans2.simulator, "ceilfarm-replay");
    assert_eq!(ans2.parameters, ans.parameters);
    assert_close(&read_bundle(&out).unwrap(), &want, 1e-9);
}

#[test]
fn a_mismatched_history_is_refused_with_file_and_column() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = campaign(tmp.path(), 3);
    let mdir = export_and_replay(&spec, tmp.path());
    let hist = mdir.join("sw.history.csv");
    let good = std::fs::read_to_string(&hist).unwrap();
    let out = tmp.path().join("b");
    let answer = tmp.path().join("a.json");
    let err = |spec: &Path| {
        synth_to_dir_with(spec, &out, &answer, Simulator::Histories(&mdir), &mut |_| {})
            .unwrap_err()
            .to_string()
    };
    // A recorder column renamed away.
    std::fs::write(&hist, good.replacen("D#0", "D#9", 1)).unwrap();
    let e = err(&spec);
    assert!(e.contains("sw.history.csv") && e.contains("no column \"D#0\""), "{e}");
    // A run that stopped early.
    let short: Vec<&str> = good.lines().take(100).collect();
    std::fs::write(&hist, short.join("\n")).unwrap();
    let e = err(&spec);
    assert!(e.contains("sw.history.csv") && e.contains("99 rows, expected 401"), "{e}");
    // A value that is not a number.
    let mut bad: Vec<String> = good.lines().map(str::to_string).collect();
    let mut cells: Vec<&str> = bad[5].split(',').collect();
    cells[1] = "x";
    bad[5] = cells.join(",");
    std::fs::write(&hist, bad.join("\n")).unwrap();
    let e = err(&spec);
    assert!(e.contains("sw.history.csv:6") && e.contains("\"x\" is not a number"), "{e}");
    // Histories of another campaign (here: another seed, so other inputs).
    std::fs::write(&hist, &good).unwrap();
    std::fs::create_dir_all(tmp.path().join("other")).unwrap();
    let other = campaign(&tmp.path().join("other"), 4);
    let e = err(&other);
    assert!(e.contains("wn.json") && e.contains("differs from the model"), "{e}");
    // No history at all.
    std::fs::remove_file(&hist).unwrap();
    let e = err(&spec);
    assert!(e.contains("sw.history.csv"), "{e}");
}
