//! Synthetic test campaigns (`ceilfarm synth SPEC.toml --out DIR`): simulate
//! shaking-table runs of a specimen with ceilfarm's own FE model, optionally
//! with a hidden effect, degrade the readings like real sensors, and write a
//! `ceiling-measured/1` bundle. The truth goes to a separate answer file,
//! never into the bundle.
//!
//! A hidden effect's `strength` is set from the baseline model's own demand
//! in the campaign's strongest run (so it shows whatever the amplitudes):
//! pounding puts the gap at 85 / 60 / 40 % of the peak perimeter
//! displacement (weak / moderate / strong); friction puts the slip force at
//! 70 / 40 / 20 % of the peak perimeter spring force; connection hysteresis
//! scales the CJS-A backbone so that the peak connection force is 1.5 / 4 /
//! 8 times its first backbone force (150 N).

pub mod export;
pub mod histories;
pub mod input;
pub mod noise;
pub mod spec;

use crate::bundle::{self, Bundle, Manifest, ModalEntry, RunData, RunMeta, FORMAT};
use crate::diagnose::cause::Cause;
use crate::specimen::{
    bundle_series, fe_sensor, fe_spec, run_options, simulate_run, SpecimenError,
};
use fe::ceiling::{BaseInput, SimOptions};
use fe::generator::{CeilingSpec, Parameters};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use serde::Serialize;
use spec::{Shaking, Strength, SynthSpec};
use std::collections::BTreeMap;
use std::path::Path;
use worker::ceiling::excitation::split;

use crate::diagnose::cause::CJS_A_FIRST_FORCE_N;
pub use crate::diagnose::fit::{CONNECTION_GROUP, PERIMETER_GROUP};

/// The truth behind a synthetic bundle (`answer.json`).
#[derive(Debug, Clone, Serialize)]
pub struct Answer {
    /// `ceiling-synth-answer/1`.
    pub format: String,
    /// Bundle name.
    pub bundle: String,
    /// The hidden cause (`none` when nothing is hidden).
    pub cause: String,
    /// Strength preset used for parameters not given explicitly.
    pub strength: String,
    /// Every parameter value of the true model.
    pub parameters: BTreeMap<String, f64>,
    /// Rayleigh damping ratio.
    pub damping_ratio: f64,
    /// The damping's share on the mass term (written only when not 0.5).
    #[serde(skip_serializing_if = "is_even_share")]
    pub damping_mass_share: f64,
    /// Baseline demand the strength was set from: peak perimeter
    /// displacement (mm), perimeter force (N), connection force (N).
    pub baseline_demand: Option<[f64; 3]>,
    /// Random seed.
    pub seed: u64,
    /// The code that computed the time histories (`ceilfarm`, `opensees`).
    pub simulator: String,
}

/// Where a campaign's sensor histories come from.
#[derive(Debug, Clone, Copy)]
pub enum Simulator<'a> {
    /// ceilfarm's own FE solver; with a folder, every run's true model is
    /// exported there as well ([`export`]).
    Ceilfarm {
        /// `--export-models` folder.
        export: Option<&'a Path>,
    },
    /// Another simulator's histories of the exported runs ([`histories`]).
    Histories(&'a Path),
}

/// Why a campaign could not be synthesised.
#[derive(Debug, thiserror::Error)]
pub enum SynthError {
    /// `hidden.effect` is not a known cause.
    #[error("hidden.effect = {0:?}: expected none, or perimeter-pounding, perimeter-friction and connection-hysteresis, each at most once, joined by +")]
    Effect(String),
    /// The hidden effect cannot act on this perimeter.
    #[error("hidden.effect = {effect:?}: no grid end can slide on a {boundary:?} perimeter; expected none or connection-hysteresis")]
    NoPlace {
        /// The effect.
        effect: &'static str,
        /// `structure.boundary`.
        boundary: &'static str,
    },
    /// The specimen cannot be modelled.
    #[error(transparent)]
    Specimen(#[from] SpecimenError),
    /// A parameter value was refused.
    #[error("{key}: {message}")]
    Parameter {
        /// `truth.parameters.NAME` or `hidden.parameters.NAME`.
        key: String,
        /// The refusal.
        message: String,
    },
    /// An input could not be built.
    #[error(transparent)]
    Input(#[from] input::InputError),
    /// A simulation failed.
    #[error("run {run}: simulation failed: {message}")]
    Simulation {
        /// Run id.
        run: String,
        /// Why.
        message: String,
    },
    /// The bundle could not be assembled or written.
    #[error(transparent)]
    Bundle(#[from] bundle::BundleError),
    /// A run model could not be exported.
    #[error(transparent)]
    Export(#[from] export::ExportError),
    /// Another simulator's history cannot be used.
    #[error(transparent)]
    History(#[from] histories::HistoryError),
}

/// Simulates the campaign; returns the bundle and its answer.
pub fn synthesize(
    spec: &SynthSpec,
    base_dir: &Path,
    observer: &mut dyn FnMut(&str),
) -> Result<(Bundle, Answer), SynthError> {
    synthesize_with(spec, base_dir, Simulator::Ceilfarm { export: None }, observer)
}

/// Simulates the campaign with `simulator`; returns the bundle and its answer.
pub fn synthesize_with(
    spec: &SynthSpec,
    base_dir: &Path,
    simulator: Simulator<'_>,
    observer: &mut dyn FnMut(&str),
) -> Result<(Bundle, Answer), SynthError> {
    let cause = hidden_cause(spec)?;
    let (inputs, base_inputs) = run_inputs(spec, base_dir)?;
    let truth_spec = fe_spec(&spec.structure, cause.model_options())?;
    let mut params = truth_parameters(spec, &truth_spec, cause)?;
    let demand = effect_demand(spec, cause, &params, &base_inputs, observer)?;
    set_effect(&mut params, effect_values(spec, cause, demand))?;
    let (runs, freq_hz) =
        simulate_runs(spec, &truth_spec, &params, &inputs, &base_inputs, simulator, observer)?;
    let (simulator_name, freq_hz) = simulator_results(spec, simulator, freq_hz)?;
    let bundle = assemble(spec, runs, modal(spec, &freq_hz));
    let answer = Answer {
        format: "ceiling-synth-answer/1".into(),
        bundle: spec.name.clone(),
        cause: cause.as_str().into(),
        strength: format!("{:?}", spec.hidden.strength).to_lowercase(),
        parameters: params.iter().map(|(k, v)| (k.to_string(), v)).collect(),
        damping_ratio: spec.truth.damping_ratio,
        damping_mass_share: spec.truth.damping_mass_share,
        baseline_demand: demand,
        seed: spec.seed,
        simulator: simulator_name,
    };
    Ok((bundle, answer))
}

/// The hidden effect of `hidden.effect`, refused where it has no place on the perimeter.
fn hidden_cause(spec: &SynthSpec) -> Result<Cause, SynthError> {
    let cause = match spec.hidden.effect.as_deref() {
        None => Cause::NONE,
        Some(e) => Cause::parse(e).ok_or_else(|| SynthError::Effect(e.into()))?,
    };
    let boundary = spec.structure.boundary;
    if !cause.has_place(boundary) {
        return Err(SynthError::NoPlace { effect: cause.as_str(), boundary: boundary.as_str() });
    }
    Ok(cause)
}

/// Each run's input samples (m/s²) and their step (s).
type Inputs = Vec<(Vec<f64>, f64)>;

/// Every run's input samples (m/s²) and step (s), and the base input built from them.
fn run_inputs(spec: &SynthSpec, base_dir: &Path) -> Result<(Inputs, Vec<BaseInput>), SynthError> {
    let inputs = spec
        .runs
        .iter()
        .enumerate()
        .map(|(k, r)| input::build_input(r, spec.seed.wrapping_add(1000 + k as u64), base_dir))
        .collect::<Result<Vec<_>, _>>()?;
    let base_inputs: Vec<BaseInput> = spec
        .runs
        .iter()
        .zip(&inputs)
        .map(|(r, (a, dt))| split(r.direction, *dt, a.clone(), a.clone()))
        .collect();
    Ok((inputs, base_inputs))
}

/// The baseline demand sizing the hidden effect, if a parameter of it is not given.
fn effect_demand(
    spec: &SynthSpec,
    cause: Cause,
    params: &Parameters,
    base_inputs: &[BaseInput],
    observer: &mut dyn FnMut(&str),
) -> Result<Option<[f64; 3]>, SynthError> {
    let needs_demand =
        cause.model_parameter_names().iter().any(|p| !spec.hidden.parameters.contains_key(*p));
    if cause == Cause::NONE || !needs_demand {
        return Ok(None);
    }
    observer("baseline runs to size the hidden effect");
    let baseline = fe_spec(&spec.structure, Cause::NONE.model_options())?;
    let p = shared_parameters(&baseline, params)?;
    Ok(Some(baseline_demand(spec, &baseline, &p, base_inputs)?))
}

/// Sets the hidden effect's parameter values (`hidden.parameters.NAME`).
fn set_effect(params: &mut Parameters, effect: BTreeMap<String, f64>) -> Result<(), SynthError> {
    for (name, v) in &effect {
        params.set(name, *v).map_err(|e| SynthError::Parameter {
            key: format!("hidden.parameters.{name}"),
            message: e.to_string(),
        })?;
    }
    Ok(())
}

/// The simulator's name and the true frequencies (Hz): ceilfarm's, or its `modal.json`.
fn simulator_results(
    spec: &SynthSpec,
    simulator: Simulator<'_>,
    freq_hz: Vec<f64>,
) -> Result<(String, Vec<f64>), SynthError> {
    Ok(match simulator {
        Simulator::Ceilfarm { .. } => ("ceilfarm".to_string(), freq_hz),
        Simulator::Histories(dir) => {
            let name = histories::read_simulator(dir)?;
            match &spec.modal {
                Some(m) => (name, histories::read_modal(dir, m.modes)?),
                None => (name, freq_hz),
            }
        }
    })
}

/// The true model's solver options: `truth`'s damping ratio and mass share.
fn truth_options(spec: &SynthSpec) -> SimOptions {
    let opts = run_options(spec.truth.damping_ratio);
    SimOptions { damping_mass_share: spec.truth.damping_mass_share, ..opts }
}

/// Whether `share` is the seed's even split (left out of the answer).
fn is_even_share(share: &f64) -> bool {
    *share == crate::diagnose::damping_share::SEED_PAIR_SHARE
}

/// Mid-points of the variant's priors overridden by `truth.parameters`.
fn truth_parameters(
    spec: &SynthSpec,
    fe: &CeilingSpec,
    cause: Cause,
) -> Result<Parameters, SynthError> {
    let mut p = Parameters::prior_midpoints_for(fe);
    for (name, v) in &spec.truth.parameters {
        if cause.model_parameter_names().contains(&name.as_str()) {
            continue;
        }
        p.set(name, *v).map_err(|e| SynthError::Parameter {
            key: format!("truth.parameters.{name}"),
            message: e.to_string(),
        })?;
    }
    Ok(p)
}

/// The values of `truth` that the `baseline` variant uses, the rest at its
/// mid-points: the baseline that sizes a hidden effect shares the
/// specimen's properties, not the effect's own parameters (a contact
/// stiffness, a gap spread).
fn shared_parameters(baseline: &CeilingSpec, truth: &Parameters) -> Result<Parameters, SynthError> {
    let mut p = Parameters::prior_midpoints_for(baseline);
    let accepted: Vec<&str> = p.accepted().iter().map(|i| i.name).collect();
    for (name, v) in truth.iter().filter(|(n, _)| accepted.contains(n)) {
        p.set(name, v).map_err(|e| SynthError::Parameter {
            key: format!("truth.parameters.{name}"),
            message: e.to_string(),
        })?;
    }
    Ok(p)
}

/// Peak perimeter displacement (mm), perimeter force (N) and connection
/// force (N) of the baseline over all runs.
fn baseline_demand(
    spec: &SynthSpec,
    fe: &CeilingSpec,
    p: &Parameters,
    inputs: &[BaseInput],
) -> Result<[f64; 3], SynthError> {
    let opts = SimOptions {
        spring_groups: vec![PERIMETER_GROUP.into(), CONNECTION_GROUP.into()],
        ..truth_options(spec)
    };
    let mut d = [0.0f64; 3];
    for (r, input) in spec.runs.iter().zip(inputs) {
        let (_, sim) = simulate_run(fe, p, &[], input, &opts)
            .map_err(|e| SynthError::Simulation { run: r.id.clone(), message: e.to_string() })?;
        d[0] = d[0].max(sim.spring_peaks[0].deformation_mm);
        d[1] = d[1].max(sim.spring_peaks[0].force_n);
        d[2] = d[2].max(sim.spring_peaks[1].force_n);
    }
    Ok(d)
}

/// The effect's parameter values: explicit ones, else the strength preset.
fn effect_values(
    spec: &SynthSpec,
    cause: Cause,
    demand: Option<[f64; 3]>,
) -> BTreeMap<String, f64> {
    let s = spec.hidden.strength;
    let pick = |w: f64, m: f64, st: f64| match s {
        Strength::Weak => w,
        Strength::Moderate => m,
        Strength::Strong => st,
    };
    let d = demand.unwrap_or([0.0; 3]);
    let gap_mm = spec.structure.nominal_gap_mm.unwrap_or(0.0).max(1e-9);
    let mut out = BTreeMap::new();
    for name in cause.model_parameter_names() {
        let v = match spec.hidden.parameters.get(name) {
            Some(v) => *v,
            None => match name {
                "gap_ratio" => pick(0.85, 0.6, 0.4) * d[0] / gap_mm,
                "friction_fy_N" => pick(0.7, 0.4, 0.2) * d[1],
                _ => d[2] / (pick(1.5, 4.0, 8.0) * CJS_A_FIRST_FORCE_N),
            },
        };
        out.insert(name.to_string(), v);
    }
    out
}

type Runs = Vec<(RunMeta, RunData)>;

fn simulate_runs(
    spec: &SynthSpec,
    fe: &CeilingSpec,
    params: &Parameters,
    inputs: &[(Vec<f64>, f64)],
    base: &[BaseInput],
    simulator: Simulator<'_>,
    observer: &mut dyn FnMut(&str),
) -> Result<(Runs, Vec<f64>), SynthError> {
    let n_modes = spec.modal.as_ref().map_or(6, |m| m.modes.max(1));
    let opts = SimOptions { n_modes, ..truth_options(spec) };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(spec.seed);
    let mut runs = Vec::new();
    let mut freq_hz = Vec::new();
    for (k, ((r, (a, dt)), input)) in spec.runs.iter().zip(inputs).zip(base).enumerate() {
        observer(&format!("run {} of {}: {}", k + 1, spec.runs.len(), r.id));
        let sim = run_histories(spec, fe, params, input, &opts, &r.id, k == 0, simulator)?;
        let mut series = bundle_series(&spec.sensors, &sim);
        for ((_, v), s) in series.iter_mut().zip(&spec.sensors) {
            noise::degrade(v, s.kind, &spec.noise, &mut rng);
        }
        freq_hz = sim.freq_hz;
        let (input_x, input_y) = match r.direction {
            Shaking::X => (Some("base_ax".to_string()), None),
            Shaking::Y => (None, Some("base_ay".to_string())),
            Shaking::Xy => (Some("base_ax".to_string()), Some("base_ay".to_string())),
        };
        let meta = RunMeta {
            id: r.id.clone(),
            file: format!("runs/{}.csv", r.id),
            description: r.description.clone(),
            input_x,
            input_y,
            input_units: r.input_units,
            role: r.role,
        };
        let data = RunData {
            id: r.id.clone(),
            t0_s: 0.0,
            dt_s: *dt,
            input_x_m_s2: input.x_m_s2.as_ref().map(|_| a.clone()),
            input_y_m_s2: input.y_m_s2.as_ref().map(|_| a.clone()),
            sensors: series,
        };
        runs.push((meta, data));
    }
    Ok((runs, freq_hz))
}

/// One run's simulation: by ceilfarm (exporting it first when asked) or
/// read from another simulator's history of the exported run.
#[allow(clippy::too_many_arguments)]
fn run_histories(
    spec: &SynthSpec,
    fe: &CeilingSpec,
    params: &Parameters,
    input: &BaseInput,
    opts: &SimOptions,
    run_id: &str,
    first: bool,
    simulator: Simulator<'_>,
) -> Result<fe::ceiling::Simulation, SynthError> {
    let fail = |e: fe::ceiling::CeilingError| SynthError::Simulation {
        run: run_id.into(),
        message: e.to_string(),
    };
    let sensors: Vec<_> = spec.sensors.iter().map(fe_sensor).collect();
    let prep = fe::ceiling::prepare(fe, params, input, &sensors, opts).map_err(fail)?;
    let hist = match simulator {
        Simulator::Ceilfarm { export } => {
            if let Some(dir) = export {
                export::write_run(dir, spec, run_id, &prep)?;
            }
            let hist = fe::ceiling::run_prepared(&prep, &mut |_| {}).map_err(fail)?;
            if let Some(dir) = export {
                export::write_ceilfarm_history(dir, run_id, &prep, &hist)?;
                if let (Some(m), true) = (&spec.modal, first) {
                    export::write_modal(dir, run_id, m.modes, &prep)?;
                }
            }
            hist
        }
        Simulator::Histories(dir) => {
            histories::check_model(dir, spec, run_id, &prep)?;
            histories::read_run_history(dir, run_id, &prep)?
        }
    };
    Ok(fe::ceiling::read_history(&prep, &hist))
}

/// `modal.csv` entries: the true frequencies plus Gaussian noise.
fn modal(spec: &SynthSpec, freq_hz: &[f64]) -> Option<Vec<ModalEntry>> {
    let m = spec.modal.as_ref()?;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(spec.seed ^ 0x5eed);
    let noise = Normal::new(0.0, m.std_hz.max(0.0)).ok()?;
    Some(
        freq_hz
            .iter()
            .take(m.modes)
            .enumerate()
            .map(|(k, f)| ModalEntry {
                mode: k as u32 + 1,
                freq_hz: f + noise.sample(&mut rng),
                std_hz: (m.std_hz > 0.0).then_some(m.std_hz),
            })
            .collect(),
    )
}

fn assemble(spec: &SynthSpec, runs: Runs, modal: Option<Vec<ModalEntry>>) -> Bundle {
    let (metas, data): (Vec<_>, Vec<_>) = runs.into_iter().unzip();
    Bundle {
        dir: Default::default(),
        manifest: Manifest {
            format: FORMAT.into(),
            name: spec.name.clone(),
            description: spec.description.clone(),
            structure: spec.structure.clone(),
            sensors: spec.sensors.clone(),
            runs: metas,
        },
        runs: data,
        modal,
        linear_form: Vec::new(),
    }
}

/// Synthesises and writes the bundle to `out` and the answer to `answer`.
pub fn synth_to_dir(
    spec_path: &Path,
    out: &Path,
    answer: &Path,
    observer: &mut dyn FnMut(&str),
) -> anyhow::Result<Answer> {
    synth_to_dir_with(spec_path, out, answer, Simulator::Ceilfarm { export: None }, observer)
}

/// [`synth_to_dir`] with the histories from `simulator`.
pub fn synth_to_dir_with(
    spec_path: &Path,
    out: &Path,
    answer: &Path,
    simulator: Simulator<'_>,
    observer: &mut dyn FnMut(&str),
) -> anyhow::Result<Answer> {
    let spec = SynthSpec::from_file(spec_path)?;
    let base = spec_path.parent().unwrap_or(Path::new("."));
    let (bundle, ans) = synthesize_with(&spec, base, simulator, observer)?;
    if answer.starts_with(out) {
        anyhow::bail!(
            "--answer {}: must lie outside the bundle directory {}",
            answer.display(),
            out.display()
        );
    }
    bundle::write_bundle(&bundle, out)?;
    bundle::read_bundle(out)
        .map_err(|e| anyhow::anyhow!("the written bundle does not read back: {e}"))?;
    std::fs::write(answer, serde_json::to_string_pretty(&ans)?)?;
    Ok(ans)
}

#[cfg(test)]
mod export_tests;
#[cfg(test)]
mod tests;
