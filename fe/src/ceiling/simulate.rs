//! One simulated shaking-table run: prepare it ([`super::prepare`]: model,
//! modes, Rayleigh damping on the first x and y modes, sensors, base motion),
//! integrate the base input (Newmark average acceleration, Newton, step
//! halving) and read the sensors from the recorded history.

use super::damping::RayleighFit;
use super::input::BaseInput;
use super::prepare::{prepare, PreparedRun};
use super::sensor::{PlacementError, Sensor};
use crate::eigen::EigenError;
use crate::generator::{CeilingSpec, GenerateError, Parameters};
use crate::transient::{run_plan, History, StepReport, TransientError, TransientOptions};

/// Choices of a simulated run.
#[derive(Debug, Clone, PartialEq)]
pub struct SimOptions {
    /// Rayleigh damping ratio on the first x and y modes (seed: 0.05).
    pub damping_ratio: f64,
    /// Share of the damping carried by the mass term: α and β are 2·share
    /// and 2·(1 − share) times the Rayleigh pair on the first modes (0.5:
    /// that pair; 1: mass-proportional; 0: stiffness-proportional).
    pub damping_mass_share: f64,
    /// Share of the stiffness term on the flagged springs' last committed
    /// tangent rather than their initial stiffness (0: initial, the seed's;
    /// 1: committed, OpenSees `betaKcomm`).
    pub damping_committed_share: f64,
    /// Modes computed and reported.
    pub n_modes: usize,
    /// Integration steps per input sample (≥ 1).
    pub substeps: usize,
    /// Longest integration step (s): more steps per input sample where the
    /// sample step is longer ([`steps_per_sample`]); None: `substeps` alone.
    pub max_step_s: Option<f64>,
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
            damping_mass_share: 0.5,
            damping_committed_share: 0.0,
            n_modes: 6,
            substeps: 1,
            max_step_s: None,
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
    let run = prepare(spec, params, input, sensors, opts)?;
    let hist = run_prepared(&run, observer)?;
    Ok(read_history(&run, &hist))
}

/// Integrates a prepared run with ceilfarm's transient solver.
pub fn run_prepared(
    run: &PreparedRun,
    observer: &mut dyn FnMut(&StepReport),
) -> Result<History, CeilingError> {
    let opts = TransientOptions::new(std::path::Path::new("."));
    Ok(run_plan(&run.model, &run.plan(), &opts, observer)?)
}

/// The simulation a prepared run's history gives: its recorders are the last
/// columns of `hist`, one row per input sample; sensor readings are the
/// weighted sums of their node columns in m/s² or m.
pub fn read_history(run: &PreparedRun, hist: &History) -> Simulation {
    let first = hist.columns.len() - run.recorders.len();
    let (names, counts): (Vec<String>, Vec<usize>) = run.groups.iter().cloned().unzip();
    let spring_peaks = group_peaks(hist, first + run.n_sensor_recorders, &names, &counts);
    let mut out = Vec::with_capacity(run.sensors.len());
    let mut col = first;
    for (s, p) in run.sensors.iter().zip(&run.placements) {
        let mut values = vec![0.0; hist.rows.len()];
        for (_, w) in &p.nodes {
            values.iter_mut().zip(&hist.rows).for_each(|(v, r)| *v += w * r[col]);
            col += 1;
        }
        values.iter_mut().for_each(|v| *v *= 1e-3);
        out.push(SensorHistory { id: s.id.clone(), values });
    }
    Simulation {
        freq_hz: run.freq_hz.clone(),
        mode_dir: run.mode_dir.clone(),
        rayleigh: run.rayleigh,
        dt_s: run.input_dt_s,
        sensors: out,
        spring_peaks,
    }
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
