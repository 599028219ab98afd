//! One simulated shaking-table run: generate the model, find its modes,
//! damp it (Rayleigh on the first x and y modes), integrate the base input
//! (Newmark average acceleration, Newton, step halving) and read the sensors.

use super::damping::{rayleigh_on_first_modes, RayleighFit};
use super::input::BaseInput;
use super::sensor::{place, Placement, PlacementError, Sensor, SensorKind};
use crate::eigen::{modal_analysis, EigenError, LanczosSettings};
use crate::generator::{generate, CeilingSpec, GenerateError, Parameters};
use crate::model::{Damping, Model};
use crate::transient::spec::RecorderSpec;
use crate::transient::{
    run_plan, BaseMotion, GroundMotion, History, Plan, StepReport, TransientError, TransientOptions,
};

/// Choices of a simulated run.
#[derive(Debug, Clone, PartialEq)]
pub struct SimOptions {
    /// Rayleigh damping ratio on the first x and y modes (seed: 0.05).
    pub damping_ratio: f64,
    /// Modes computed and reported.
    pub n_modes: usize,
    /// Integration steps per input sample (≥ 1).
    pub substeps: usize,
    /// Spring groups whose peak deformation and force are reported
    /// (e.g. `perimeter_friction`).
    pub spring_groups: Vec<String>,
    /// Spring groups that carry Rayleigh damping whatever the generator
    /// chose (e.g. `perimeter_friction`, so that a friction variant that
    /// never slips is damped exactly as the elastic perimeter).
    pub rayleigh_groups: Vec<String>,
}

impl Default for SimOptions {
    fn default() -> Self {
        SimOptions {
            damping_ratio: 0.05,
            n_modes: 6,
            substeps: 1,
            spring_groups: vec![],
            rayleigh_groups: vec![],
        }
    }
}

/// The reading of one sensor, one value per input sample.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorHistory {
    /// Sensor id.
    pub id: String,
    /// Values (m/s² for acceleration, m for displacement).
    pub values: Vec<f64>,
}

/// Result of a simulated run.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    /// Lowest frequencies (Hz) of the initial-stiffness model.
    pub freq_hz: Vec<f64>,
    /// Direction of each mode's largest effective mass ('x', 'y', 'z').
    pub mode_dir: Vec<char>,
    /// The Rayleigh damping used.
    pub rayleigh: RayleighFit,
    /// Sample interval of the histories (s), the input's.
    pub dt_s: f64,
    /// Sensor histories, in the order the sensors were given.
    pub sensors: Vec<SensorHistory>,
    /// Peaks of the requested spring groups, in request order.
    pub spring_peaks: Vec<SpringPeak>,
}

/// Largest |deformation| and |force| over a spring group and the run.
#[derive(Debug, Clone, PartialEq)]
pub struct SpringPeak {
    /// Group name.
    pub group: String,
    /// Springs in the group.
    pub count: usize,
    /// Peak |deformation| (mm).
    pub deformation_mm: f64,
    /// Peak |force| (N).
    pub force_n: f64,
}

/// Why a run could not be simulated.
#[derive(Debug, thiserror::Error)]
pub enum CeilingError {
    /// The model could not be generated.
    #[error(transparent)]
    Generate(#[from] GenerateError),
    /// The modal analysis failed.
    #[error("modal analysis: {0}")]
    Eigen(#[from] EigenError),
    /// A sensor is not on the ceiling.
    #[error(transparent)]
    Sensor(#[from] PlacementError),
    /// Bad input or options.
    #[error("{0}")]
    Input(String),
    /// The transient failed (see its reason; a partial history is inside).
    #[error(transparent)]
    Transient(#[from] TransientError),
}

/// Simulates one run of `spec` with parameter values `params`.
pub fn simulate(
    spec: &CeilingSpec,
    params: &Parameters,
    input: &BaseInput,
    sensors: &[Sensor],
    opts: &SimOptions,
    observer: &mut dyn FnMut(&StepReport),
) -> Result<Simulation, CeilingError> {
    check(input, opts)?;
    let mut model = generate(spec, params)?;
    for sp in model.springs.iter_mut() {
        if sp.group.as_ref().is_some_and(|g| opts.rayleigh_groups.contains(g)) {
            sp.rayleigh = true;
        }
    }
    let (_, modal) = modal_analysis(&model, opts.n_modes.max(2), &LanczosSettings::default())?;
    let rayleigh = rayleigh_on_first_modes(&modal, opts.damping_ratio)
        .ok_or_else(|| CeilingError::Input("no mode moves mass in x or y".into()))?;
    model.damping = Some(Damping {
        kind: "rayleigh".into(),
        alpha_m_per_s: rayleigh.alpha_m_per_s,
        beta_k_s: rayleigh.beta_k_s,
        extra: Default::default(),
    });
    let (nx, ny) = grid_size(spec);
    let placements: Vec<Placement> = sensors
        .iter()
        .map(|s| place(s, &model, spec.structure.module_m, nx, ny))
        .collect::<Result<_, _>>()?;
    let mut recorders = recorder_specs(sensors, &placements);
    let n_sensor_cols = recorders.len();
    let groups = spring_recorders(&model, &opts.spring_groups, &mut recorders);
    let base = base_motion(input);
    let plan = Plan {
        base: &base,
        dt_s: input.dt_s / opts.substeps as f64,
        n_steps: (input.len() - 1) * opts.substeps,
        gamma: 0.5,
        beta: 0.25,
        output_every_n_steps: opts.substeps,
        recorders: &recorders,
    };
    let hist =
        run_plan(&model, &plan, &TransientOptions::new(std::path::Path::new(".")), observer)?;
    let first = hist.columns.len() - recorders.len();
    let spring_peaks = group_peaks(&hist, first + n_sensor_cols, &opts.spring_groups, &groups);
    let mut out = Vec::with_capacity(sensors.len());
    let mut col = first;
    for (s, p) in sensors.iter().zip(&placements) {
        let mut values = vec![0.0; hist.rows.len()];
        for (_, w) in &p.nodes {
            values.iter_mut().zip(&hist.rows).for_each(|(v, r)| *v += w * r[col]);
            col += 1;
        }
        values.iter_mut().for_each(|v| *v *= 1e-3);
        out.push(SensorHistory { id: s.id.clone(), values });
    }
    let n = opts.n_modes.min(modal.freq_hz.len());
    Ok(Simulation {
        freq_hz: modal.freq_hz[..n].to_vec(),
        mode_dir: (0..n).map(|k| modal.dominant(k)).collect(),
        rayleigh,
        dt_s: input.dt_s,
        sensors: out,
        spring_peaks,
    })
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
    if !(opts.damping_ratio >= 0.0 && opts.damping_ratio < 1.0) {
        return bad(format!("damping_ratio = {}: expected 0 <= ratio < 1", opts.damping_ratio));
    }
    if opts.substeps == 0 {
        return bad("substeps = 0: expected >= 1".into());
    }
    Ok(())
}

fn grid_size(spec: &CeilingSpec) -> (usize, usize) {
    let s = &spec.structure;
    ((s.length_x_m / s.module_m).round() as usize, (s.length_y_m / s.module_m).round() as usize)
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
                name: Some(format!("{}#{k}", s.id)),
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

/// Peak |deformation| and |force| per group from the recorded columns.
fn group_peaks(
    hist: &History,
    first: usize,
    groups: &[String],
    counts: &[usize],
) -> Vec<SpringPeak> {
    let mut col = first;
    let mut out = Vec::new();
    for (g, n) in groups.iter().zip(counts) {
        let (mut d, mut f) = (0.0f64, 0.0f64);
        for _ in 0..*n {
            for r in &hist.rows {
                d = d.max(r[col].abs());
                f = f.max(r[col + 1].abs());
            }
            col += 2;
        }
        out.push(SpringPeak { group: g.clone(), count: *n, deformation_mm: d, force_n: f });
    }
    out
}
