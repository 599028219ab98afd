use super::*;
use crate::ceiling::sensors::{DirectionOption, SensorKindOption};
use protocol::ModelSpec;

/// The small 3.6 m specimen with the baseline variant (elastic perimeter
/// springs, elastic grid connections).
fn spec_toml() -> String {
    let p = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../configs/specimens/small-3p6.toml");
    std::fs::read_to_string(p)
        .unwrap()
        .replace("variant = \"nonlinear\"", "perimeter = \"linear\"\nconnections = \"elastic\"")
}

fn sensor(id: &str, kind: SensorKindOption, x_m: f64, dir: DirectionOption) -> SensorOptions {
    SensorOptions { id: id.into(), kind, x_m, y_m: 1.8, direction: dir }
}

/// A 1 s pulse train at 0.01 s (101 samples), with a 17-digit step and
/// sample values that a decimal JSON parser could round.
fn pulse(amp: f64) -> Vec<f64> {
    (0..101).map(|k| amp * (k as f64 * 0.37).sin() / 3.0).collect()
}

/// Two runs: x only (two sensors), then y only (one sensor).
fn options() -> CampaignOptions {
    use DirectionOption::{X, Y};
    use SensorKindOption::{Acceleration, Displacement};
    CampaignOptions {
        spec_toml: spec_toml(),
        damping_ratio: 0.05,
        rayleigh_groups: vec!["perimeter_friction".into()],
        spring_groups: vec!["perimeter_friction".into(), "connection_axial".into()],
        max_step_s: None,
        runs: vec![
            CampaignRun {
                id: "r1".into(),
                dt_s: 0.1 / 9.999999999999998,
                input_x_m_s2: Some(pulse(2.0)),
                input_y_m_s2: None,
                sensors: vec![
                    sensor("A1", Acceleration, 1.8, X),
                    sensor("D1", Displacement, 1.0 / 3.0 * 4.5, X),
                ],
            },
            CampaignRun {
                id: "r2".into(),
                dt_s: 0.01,
                input_x_m_s2: None,
                input_y_m_s2: Some(pulse(1.5)),
                sensors: vec![sensor("A2", Acceleration, 0.9, Y)],
            },
        ],
    }
}

fn names() -> Vec<String> {
    ["K_friction", "damping_ratio"].iter().map(|s| s.to_string()).collect()
}

/// The model as a worker builds it: options through JSON text and the registry.
fn built(o: &CampaignOptions) -> Result<Box<dyn Model>, ModelError> {
    built_with(o, names())
}

/// [`built`] for a study with the parameters `param_names`.
fn built_with(o: &CampaignOptions, param_names: Vec<String>) -> Result<Box<dyn Model>, ModelError> {
    crate::registry::build(&ModelSpec {
        kind: KIND.into(),
        options_json: serde_json::to_string(o).unwrap(),
        param_names,
        outputs: vec![],
    })
}

fn build_error(edit: impl Fn(&mut CampaignOptions)) -> String {
    let mut o = options();
    edit(&mut o);
    built(&o).err().expect("refused").to_string()
}

/// What `fe::ceiling::simulate` needs to replay the campaign directly: the
/// specimen, its prior mid-points with `K_friction` at `k_friction_n_mm`,
/// and `opts` with the campaign's spring and Rayleigh groups.
fn direct(
    o: &CampaignOptions,
    k_friction_n_mm: f64,
    opts: SimOptions,
) -> (CeilingSpec, Parameters, SimOptions) {
    let spec = CeilingSpec::from_toml_str(&o.spec_toml, Path::new("t")).unwrap();
    let mut p = Parameters::prior_midpoints_for(&spec);
    p.set("K_friction", k_friction_n_mm).unwrap();
    let opts = SimOptions {
        spring_groups: o.spring_groups.clone(),
        rayleigh_groups: o.rayleigh_groups.clone(),
        ..opts
    };
    (spec, p, opts)
}

/// Every run simulated directly with `fe::ceiling::simulate` gives the same
/// histories and spring peaks, bit for bit, as the model built from JSON.
#[test]
fn runs_match_direct_simulation_bit_for_bit() {
    let o = options();
    let m = built(&o).unwrap();
    let out = m.run(&ParamSet::new(&names(), &[17.5, 0.03]).unwrap(), &RunContext::default());
    let out = out.unwrap();
    let (spec, p, opts) =
        direct(&o, 17.5, SimOptions { damping_ratio: 0.03, ..SimOptions::default() });
    let (mut hist, mut peaks) = (vec![], [0.0f64; 4]);
    for run in &o.runs {
        let fe: Vec<_> = run.sensors.iter().map(SensorOptions::sensor).collect();
        let sim = simulate(&spec, &p, &run.base_input(), &fe, &opts, &mut |_| {}).unwrap();
        for (s, h) in run.sensors.iter().zip(&sim.sensors) {
            hist.push((format!("{}/{}", run.id, s.id), s.channel(), sim.dt_s, h.values.clone()));
        }
        for (k, g) in sim.spring_peaks.iter().enumerate() {
            peaks[2 * k] = peaks[2 * k].max(g.deformation_mm);
            peaks[2 * k + 1] = peaks[2 * k + 1].max(g.force_n);
        }
    }
    let got: Vec<_> = out
        .histories
        .iter()
        .map(|h| (h.name.clone(), h.channels[0].clone(), h.dt_s, h.data.clone()))
        .collect();
    assert_eq!(got, hist);
    assert_eq!(got[1].1, "D1_disp_m");
    let names: Vec<&str> = out.scalars.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "perimeter_friction_deformation_mm",
            "perimeter_friction_force_n",
            "connection_axial_deformation_mm",
            "connection_axial_force_n"
        ]
    );
    let values: Vec<f64> = out.scalars.iter().map(|(_, v)| *v).collect();
    assert_eq!(values, peaks);
    assert!(peaks.iter().all(|v| *v > 0.0), "{peaks:?}");
}

/// An edit of the options and the refusal it must bring.
type Case = (Box<dyn Fn(&mut CampaignOptions)>, &'static str);

#[test]
fn refusals_name_the_key_the_value_and_what_was_expected() {
    let cases: Vec<Case> = vec![
        (Box::new(|o| o.runs.clear()), "runs = []: expected at least one run"),
        (Box::new(|o| o.runs[1].id = "r1".into()), "runs[1].id = \"r1\": expected a unique id"),
        (Box::new(|o| o.runs[0].dt_s = 0.0), "runs[0] (r1).dt_s = 0: expected a step > 0 s"),
        (
            Box::new(|o| o.runs[1].input_y_m_s2 = None),
            "runs[1] (r2): no input_x_m_s2 or input_y_m_s2: expected at least one",
        ),
        (
            Box::new(|o| o.runs[0].input_x_m_s2 = Some(vec![1.0])),
            "runs[0] (r1).input_x_m_s2: 1 samples: expected at least 2",
        ),
        (
            Box::new(|o| o.runs[0].input_x_m_s2.as_mut().unwrap()[3] = f64::NAN),
            "runs[0] (r1).input_x_m_s2[3] = NaN: expected a finite acceleration",
        ),
        (Box::new(|o| o.runs[1].sensors[0].x_m = 9.0), "runs[1].sensors[0] (A2): x_m = 9"),
        (Box::new(|o| o.damping_ratio = 1.5), "damping_ratio = 1.5: expected 0 <= ratio < 1"),
        (
            Box::new(|o| o.spring_groups.push("connection_axial".into())),
            "spring_groups[2] = \"connection_axial\": expected a non-empty group name",
        ),
        (Box::new(|o| o.spec_toml = "[structure]".into()), "[model] spec_toml"),
    ];
    for (edit, want) in cases {
        let e = build_error(edit);
        assert!(e.contains(want) && e.contains("ceiling-campaign"), "{e}\nwanted: {want}");
    }
}

#[test]
fn unknown_parameters_and_options_are_refused() {
    let e = crate::registry::build(&ModelSpec {
        kind: KIND.into(),
        options_json: serde_json::to_string(&options()).unwrap(),
        param_names: vec!["K_nope".into()],
        outputs: vec![],
    })
    .err()
    .unwrap()
    .to_string();
    assert!(e.contains("K_nope"), "{e}");
    let mut v = serde_json::to_value(options()).unwrap();
    v["n_modes"] = 3.into();
    let e = crate::registry::build(&ModelSpec {
        kind: KIND.into(),
        options_json: v.to_string(),
        param_names: names(),
        outputs: vec![],
    })
    .err()
    .unwrap()
    .to_string();
    assert!(e.contains("unknown field `n_modes`"), "{e}");
}

/// A task naming `run_index` simulates that run alone: its histories are the
/// all-runs task's for that run, bit for bit, and the peaks over the runs
/// are the largest of the one-run peaks.
#[test]
fn a_run_index_task_simulates_that_run_alone() {
    let o = options();
    let all = built(&o).unwrap();
    let whole = all.run(&ParamSet::new(&names(), &[17.5, 0.03]).unwrap(), &RunContext::default());
    let whole = whole.unwrap();
    let mut with_index = names();
    with_index.push(RUN_INDEX.into());
    let one = built_with(&o, with_index.clone()).unwrap();
    let mut histories = vec![];
    let mut peaks = vec![0.0f64; whole.scalars.len()];
    for (k, run) in o.runs.iter().enumerate() {
        let values = [17.5, 0.03, k as f64];
        let p = ParamSet::new(&with_index, &values).unwrap();
        let out = one.run(&p, &RunContext::default()).unwrap();
        assert!(out.histories.iter().all(|h| h.name.starts_with(&format!("{}/", run.id))));
        histories.extend(out.histories);
        peaks.iter_mut().zip(&out.scalars).for_each(|(a, (_, v))| *a = a.max(*v));
    }
    assert_eq!(histories, whole.histories);
    let expected: Vec<f64> = whole.scalars.iter().map(|(_, v)| *v).collect();
    assert_eq!(peaks, expected);
    for bad in [2.0, -1.0, 0.5, f64::NAN] {
        let values = [17.5, 0.03, bad];
        let p = ParamSet::new(&with_index, &values).unwrap();
        let e = one.run(&p, &RunContext::default()).unwrap_err().to_string();
        assert!(
            e.contains(&format!("run_index = {bad}: expected a whole number from 0 to 1")),
            "{e}"
        );
    }
}

/// A share parameter of the damping reaches the simulation: at `value` the
/// histories are those of `at_value` (the same share set on `SimOptions`),
/// bit for bit, and differ from those at `default`; a share outside
/// [0, 1] fails the task.
fn share_is_a_study_parameter(
    o: &CampaignOptions,
    name: &str,
    (value, default): (f64, f64),
    at_value: SimOptions,
) {
    let names: Vec<String> =
        ["K_friction", "damping_ratio", name].iter().map(|s| s.to_string()).collect();
    let m = built_with(o, names.clone()).unwrap();
    let run = |share: f64| {
        let values = [17.5, 0.05, share];
        m.run(&ParamSet::new(&names, &values).unwrap(), &RunContext::default())
    };
    let (spec, p, opts) = direct(o, 17.5, at_value);
    let first = &o.runs[0];
    let fe: Vec<_> = first.sensors.iter().map(SensorOptions::sensor).collect();
    let sim = simulate(&spec, &p, &first.base_input(), &fe, &opts, &mut |_| {}).unwrap();
    let (at, at_default) = (run(value).unwrap(), run(default).unwrap());
    assert_eq!(at.histories[0].data, sim.sensors[0].values);
    assert_ne!(at.histories[0].data, at_default.histories[0].data);
    for bad in [-0.1, 1.5, f64::NAN] {
        let r = run(bad);
        let ok = matches!(&r, Err(RunError::Input(s)) if s.contains(&format!("{name} = "))
            && s.contains("expected 0 <= share <= 1"));
        assert!(ok, "{bad}: {r:?}");
    }
}

/// `damping_mass_share` is a study parameter.
#[test]
fn the_damping_share_is_a_study_parameter() {
    let at = SimOptions { damping_mass_share: 0.9, ..SimOptions::default() };
    share_is_a_study_parameter(&options(), "damping_mass_share", (0.9, 0.5), at);
}

/// `damping_committed_share` is a study parameter: on a specimen whose
/// perimeter slips, damping on the committed tangent changes the histories.
#[test]
fn the_committed_share_is_a_study_parameter() {
    let mut o = options();
    o.spec_toml = std::fs::read_to_string(
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../configs/specimens/small-3p6.toml"),
    )
    .unwrap();
    let at = SimOptions { damping_committed_share: 1.0, ..SimOptions::default() };
    share_is_a_study_parameter(&o, "damping_committed_share", (1.0, 0.0), at);
}
