//! A shaking-table run made ready to integrate: the generated model with
//! its Rayleigh damping (fitted on the first x and y modes), the modes, the
//! sensor placements, the recorders (one per sensor node, then the
//! requested spring groups) and the base motion. [`super::simulate`] runs
//! it; an exporter can write it as a `ceiling-fe-model` file for another
//! code to run.
//!
//! Units: the model's N, mm, s, t; base motion mm/s².

use super::damping::{check_damping_ratio, check_share, rayleigh_on_first_modes, RayleighFit};
use super::input::BaseInput;
use super::sensor::{place, Placement, Sensor, SensorKind};
use super::simulate::{CeilingError, SimOptions};
use crate::assembly::Structure;
use crate::eigen::{modal_analysis_on, LanczosSettings, ModalResult};
use crate::generator::{generate, CeilingSpec, Parameters};
use crate::model::{Damping, Model};
use crate::transient::spec::RecorderSpec;
use crate::transient::{BaseMotion, GroundMotion, Plan};

/// Everything a run integrates and reads, before integration.
#[derive(Debug, Clone, PartialEq)]
pub struct PreparedRun {
    /// The model with its Rayleigh damping and flagged springs (no analysis block).
    pub model: Model,
    /// Lowest frequencies (Hz) of the initial-stiffness model (`n_modes` of them).
    pub freq_hz: Vec<f64>,
    /// Direction of each mode's largest effective mass ('x', 'y', 'z').
    pub mode_dir: Vec<char>,
    /// The Rayleigh damping used.
    pub rayleigh: RayleighFit,
    /// Sensors, as given.
    pub sensors: Vec<Sensor>,
    /// Grid nodes and weights of each sensor.
    pub placements: Vec<Placement>,
    /// Sensor recorders (one per sensor node, placement order), then spring-group recorders.
    pub recorders: Vec<RecorderSpec>,
    /// How many of `recorders` belong to the sensors.
    pub n_sensor_recorders: usize,
    /// Spring groups whose peaks are reported, and their spring counts.
    pub groups: Vec<(String, usize)>,
    /// Base motion in mm/s², one component per shaken direction (x = DOF 1, y = DOF 2).
    pub base: BaseMotion,
    /// Integration step (s).
    pub dt_s: f64,
    /// Integration steps.
    pub n_steps: usize,
    /// One output row per input sample: every this many steps.
    pub output_every_n_steps: usize,
    /// Input sample interval (s).
    pub input_dt_s: f64,
}

impl PreparedRun {
    /// Rows of the recorded history: one per input sample, t = 0 included.
    pub fn output_rows(&self) -> usize {
        self.n_steps / self.output_every_n_steps.max(1) + 1
    }

    /// The integration plan (Newmark average acceleration).
    pub fn plan(&self) -> Plan<'_> {
        Plan {
            base: &self.base,
            dt_s: self.dt_s,
            n_steps: self.n_steps,
            gamma: 0.5,
            beta: 0.25,
            output_every_n_steps: self.output_every_n_steps,
            recorders: &self.recorders,
        }
    }
}

/// Generates, damps and instruments one run of `spec` with values `params`.
pub fn prepare(
    spec: &CeilingSpec,
    params: &Parameters,
    input: &BaseInput,
    sensors: &[Sensor],
    opts: &SimOptions,
) -> Result<PreparedRun, CeilingError> {
    check(input, opts)?;
    instrument(&damped_model(spec, params, opts, 0)?, spec, input, sensors, opts)
}

/// A generated model with its Rayleigh damping, its structure and modes,
/// before any run is instrumented on it.
#[derive(Debug, Clone)]
pub struct DampedModel {
    /// The model with its damping block and flagged springs.
    pub model: Model,
    /// Its assembled structure.
    pub structure: Structure,
    /// Its lowest modes: `max(n_modes, opts.n_modes)` asked of
    /// [`damped_model`], at most one per DOF with mass.
    pub modal: ModalResult,
    /// The Rayleigh damping, fitted on the first `opts.n_modes` modes.
    pub rayleigh: RayleighFit,
    /// How many of the modes a run reports (`opts.n_modes`).
    pub reported: usize,
}

/// Generates `spec` with `params`, flags the springs of `opts`'
/// Rayleigh groups and fits the Rayleigh pair on the first `opts.n_modes`
/// modes of the lowest `max(n_modes, opts.n_modes)` computed (as many as
/// carry mass when fewer).
pub fn damped_model(
    spec: &CeilingSpec,
    params: &Parameters,
    opts: &SimOptions,
    n_modes: usize,
) -> Result<DampedModel, CeilingError> {
    damped_model_on(spec, params, opts, n_modes, None)
}

/// [`damped_model`] with its modes found by Rayleigh–Ritz on `basis` when
/// one is given and can carry the model
/// ([`crate::eigen::modal_analysis_on`]), by Lanczos otherwise: for a model
/// near the one whose modes the basis holds, as a search's forward
/// differences are.
pub fn damped_model_on(
    spec: &CeilingSpec,
    params: &Parameters,
    opts: &SimOptions,
    n_modes: usize,
    basis: Option<&[Vec<f64>]>,
) -> Result<DampedModel, CeilingError> {
    check_options(opts)?;
    let mut model = generate(spec, params)?;
    for sp in model.springs.iter_mut() {
        if sp.group.as_ref().is_some_and(|g| opts.rayleigh_groups.contains(g)) {
            sp.rayleigh = true;
        }
    }
    let first = opts.n_modes.max(2);
    let wanted = n_modes.max(first).min(model.mass_dofs()).max(first);
    let (structure, modal) = modal_analysis_on(&model, basis, wanted, &LanczosSettings::default())?;
    let rayleigh = rayleigh_on_first_modes(&first_modes(&modal, first), opts.damping_ratio)
        .ok_or_else(|| CeilingError::Input("no mode moves mass in x or y".into()))?
        .with_mass_share(opts.damping_mass_share);
    model.damping = Some(Damping {
        kind: "rayleigh".into(),
        alpha_m_per_s: rayleigh.alpha_m_per_s,
        beta_k_s: rayleigh.beta_k_s,
        extra: damping_form(opts.damping_committed_share),
    });
    Ok(DampedModel { model, structure, modal, rayleigh, reported: opts.n_modes })
}

/// One run of input `input` read by `sensors` on a damped model of `spec`.
pub fn instrument(
    dm: &DampedModel,
    spec: &CeilingSpec,
    input: &BaseInput,
    sensors: &[Sensor],
    opts: &SimOptions,
) -> Result<PreparedRun, CeilingError> {
    check(input, opts)?;
    let model = dm.model.clone();
    let (nx, ny) = grid_size(spec);
    let placements: Vec<Placement> = sensors
        .iter()
        .map(|s| place(s, &model, spec.structure.module_m, nx, ny))
        .collect::<Result<_, _>>()?;
    let mut recorders = recorder_specs(sensors, &placements);
    let n_sensor_recorders = recorders.len();
    let counts = spring_recorders(&model, &opts.spring_groups, &mut recorders);
    let n = dm.reported.min(dm.modal.freq_hz.len());
    let steps = steps_per_sample(input.dt_s, opts.substeps, opts.max_step_s);
    Ok(PreparedRun {
        freq_hz: dm.modal.freq_hz[..n].to_vec(),
        mode_dir: (0..n).map(|k| dm.modal.dominant(k)).collect(),
        model,
        rayleigh: dm.rayleigh,
        sensors: sensors.to_vec(),
        placements,
        recorders,
        n_sensor_recorders,
        groups: opts.spring_groups.iter().cloned().zip(counts).collect(),
        base: base_motion(input),
        dt_s: input.dt_s / steps as f64,
        n_steps: (input.len() - 1) * steps,
        output_every_n_steps: steps,
        input_dt_s: input.dt_s,
    })
}

/// The first `n` of `modal`'s modes.
fn first_modes(modal: &ModalResult, n: usize) -> ModalResult {
    let n = n.min(modal.freq_hz.len());
    ModalResult {
        freq_hz: modal.freq_hz[..n].to_vec(),
        omega2: modal.omega2[..n].to_vec(),
        shapes: modal.shapes[..n].to_vec(),
        participation: modal.participation[..n].to_vec(),
        effective_mass_t: modal.effective_mass_t[..n].to_vec(),
        total_mass_t: modal.total_mass_t,
    }
}

fn check(input: &BaseInput, opts: &SimOptions) -> Result<(), CeilingError> {
    let bad = |m: String| Err(CeilingError::Input(m));
    if !(input.dt_s > 0.0 && input.dt_s.is_finite()) {
        return bad(format!("input dt_s = {}: expected > 0", input.dt_s));
    }
    if input.len() < 2 {
        return bad(format!("input has {} samples: expected at least 2", input.len()));
    }
    for (name, c) in [("x", &input.x_m_s2), ("y", &input.y_m_s2)] {
        if let Some(k) = c.as_ref().and_then(|v| v.iter().position(|a| !a.is_finite())) {
            return bad(format!("input {name}: sample {k} is not a finite number"));
        }
    }
    check_options(opts)
}

fn check_options(opts: &SimOptions) -> Result<(), CeilingError> {
    let bad = |m: String| Err(CeilingError::Input(m));
    check_damping_ratio(opts.damping_ratio).or_else(|m| bad(format!("damping_ratio = {m}")))?;
    check_share(opts.damping_mass_share).or_else(|m| bad(format!("damping_mass_share = {m}")))?;
    check_share(opts.damping_committed_share)
        .or_else(|m| bad(format!("damping_committed_share = {m}")))?;
    if opts.substeps == 0 {
        return bad("substeps = 0: expected >= 1".into());
    }
    if let Some(h) = opts.max_step_s.filter(|h| !(*h > 0.0 && h.is_finite())) {
        return bad(format!("max_step_s = {h}: expected a finite step > 0"));
    }
    Ok(())
}

fn grid_size(spec: &CeilingSpec) -> (usize, usize) {
    let s = &spec.structure;
    ((s.length_x_m / s.module_m).round() as usize, (s.length_y_m / s.module_m).round() as usize)
}

/// The recorder name of node `k` of a sensor's placement.
pub fn sensor_recorder_name(sensor_id: &str, k: usize) -> String {
    format!("{sensor_id}#{k}")
}

/// One node recorder per (sensor, node) in placement order.
fn recorder_specs(sensors: &[Sensor], placements: &[Placement]) -> Vec<RecorderSpec> {
    let mut out = Vec::new();
    for (s, p) in sensors.iter().zip(placements) {
        let response = match s.kind {
            SensorKind::Acceleration => "accel_abs",
            SensorKind::Displacement => "disp",
        };
        for (k, (node, _)) in p.nodes.iter().enumerate() {
            out.push(RecorderSpec {
                name: Some(sensor_recorder_name(&s.id, k)),
                node: Some(*node),
                dof: Some(s.direction.dof()),
                element: None,
                response: response.into(),
            });
        }
    }
    out
}

/// The input in mm/s², one component per given direction.
fn base_motion(input: &BaseInput) -> BaseMotion {
    let comp = |dof: u8, v: &Vec<f64>| GroundMotion {
        dof,
        dt_s: input.dt_s,
        accel_mm_s2: v.iter().map(|a| a * 1e3).collect(),
    };
    let mut components = Vec::new();
    if let Some(x) = &input.x_m_s2 {
        components.push(comp(1, x));
    }
    if let Some(y) = &input.y_m_s2 {
        components.push(comp(2, y));
    }
    BaseMotion { components }
}

/// Deformation and force recorders for every spring of each group; returns
/// the spring count per group.
fn spring_recorders(model: &Model, groups: &[String], out: &mut Vec<RecorderSpec>) -> Vec<usize> {
    groups
        .iter()
        .map(|g| {
            let ids: Vec<u64> = model
                .springs
                .iter()
                .filter(|s| s.group.as_deref() == Some(g.as_str()))
                .map(|s| s.id)
                .collect();
            for id in &ids {
                for response in ["deformation", "force"] {
                    out.push(RecorderSpec {
                        name: Some(format!("{g}#{id}_{response}")),
                        node: None,
                        dof: None,
                        element: Some(*id),
                        response: response.into(),
                    });
                }
            }
            ids.len()
        })
        .collect()
}

/// Integration steps per input sample: `substeps`, or more where that
/// leaves a step longer than `max_step_s` (the fewest that do not).
pub fn steps_per_sample(dt_s: f64, substeps: usize, max_step_s: Option<f64>) -> usize {
    let needed = max_step_s.map_or(1, |h| (dt_s / h * (1.0 - 1e-9)).ceil().max(1.0) as usize);
    substeps.max(needed)
}

/// The damping block's `stiffness` (and `committed_share`) keys for a share
/// on the committed tangent: none at 0 (the initial stiffness).
fn damping_form(committed_share: f64) -> serde_json::Map<String, serde_json::Value> {
    let mut extra = serde_json::Map::new();
    if committed_share > 0.0 {
        extra.insert("stiffness".into(), "committed".into());
        extra.insert("committed_share".into(), committed_share.into());
    }
    extra
}

#[cfg(test)]
mod tests {
    use super::steps_per_sample;
    use proptest::prelude::*;

    #[test]
    fn a_step_limit_splits_long_samples_only() {
        assert_eq!(steps_per_sample(0.01, 1, None), 1);
        assert_eq!(steps_per_sample(0.01, 3, None), 3);
        assert_eq!(steps_per_sample(0.01, 1, Some(0.005)), 2);
        assert_eq!(steps_per_sample(1.0 / 200.0, 1, Some(0.005)), 1);
        assert_eq!(steps_per_sample(0.0051, 1, Some(0.005)), 2);
        assert_eq!(steps_per_sample(0.01, 4, Some(0.005)), 4);
    }

    proptest! {
        /// The fewest steps that keep each within the limit (to rounding).
        #[test]
        fn steps_are_the_fewest_within_the_limit(dt in 1e-4..0.1f64, h in 1e-4..0.1f64) {
            let n = steps_per_sample(dt, 1, Some(h));
            prop_assert!(dt / n as f64 <= h * (1.0 + 1e-9));
            prop_assert!(n == 1 || dt / (n - 1) as f64 > h * (1.0 - 1e-9));
        }
    }
}
