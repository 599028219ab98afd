//! `ceiling`: a shaking-table run of the ceiling generated from a specimen
//! file, for each parameter set (`fe::ceiling::simulate`): its lowest modes
//! and the time histories of named sensors under a base excitation (the
//! seed's sine sweep or a record).
//!
//! Parameters are the names of `fe::generator::parameters_for` the specimen's
//! model variant (seed Table 6.1 and the variant's extensions; mm², MPa, mm⁴,
//! N/mm, N) plus `damping_ratio` (Rayleigh on the first x and y modes) and
//! `damping_mass_share` (its share on the mass term, 0.5 by default) and
//! `damping_committed_share` (its stiffness term's share on the flagged
//! springs' committed tangent, 0 by default);
//! those not in the study sit at their prior mid-points unless `fixed` sets
//! them.
//!
//! Outputs: scalars `f1_hz .. fk_hz`, `dir1 .. dirk` (direction of each
//! mode's largest effective mass: 1 = x, 2 = y, 3 = z) and `peak_<id>`
//! (peak |reading| of each sensor, m/s² or m); one history per sensor,
//! named by its id, sampled at the input's step, with one channel
//! `<id>_accel_m_s2` (absolute acceleration) or `<id>_disp_m`
//! (displacement relative to the base).

pub mod excitation;
pub mod sensors;

use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;

use crate::specimen::{base_parameters, read_spec};

use fe::ceiling::sensor::place;
use fe::ceiling::{check_damping_ratio, check_share};
use fe::ceiling::{simulate, BaseInput, CeilingError, SimOptions, Simulation};
use fe::generator::{generate, CeilingSpec, Parameters};
use protocol::{History, Outputs};
use serde::Deserialize;

use crate::model::{Model, ModelError, ParamSet, RunContext, RunError};
use excitation::Excitation;
use sensors::{id_ok, SensorOptions};

const KIND: &str = "ceiling";

/// The study parameter that sets the Rayleigh damping ratio.
pub const DAMPING_RATIO: &str = "damping_ratio";
/// The study parameter that sets the damping's share on the mass term
/// (`fe::ceiling::SimOptions::damping_mass_share`; 0.5 unless studied).
pub const DAMPING_MASS_SHARE: &str = "damping_mass_share";
/// The study parameter that sets the stiffness term's share on the flagged
/// springs' committed tangent
/// (`fe::ceiling::SimOptions::damping_committed_share`; 0 unless studied).
pub const DAMPING_COMMITTED_SHARE: &str = "damping_committed_share";
/// The hint that error messages about unknown parameter names end with.
pub(crate) const SOLVER_HINT: &str = " (or `damping_ratio`, the Rayleigh damping ratio, \
                                       `damping_mass_share`, its share on the mass term, or \
                                       `damping_committed_share`, its stiffness term's share \
                                       on the committed tangent)";

/// Sets `name` on `opts` when it is a solver parameter (`Some`, with the
/// check's verdict), `None` when it is a model parameter.
pub(crate) fn set_solver_parameter(
    opts: &mut SimOptions,
    name: &str,
    value: f64,
) -> Option<Result<(), String>> {
    match name {
        DAMPING_RATIO => Some(check_damping_ratio(value).map(|()| opts.damping_ratio = value)),
        DAMPING_MASS_SHARE => Some(check_share(value).map(|()| opts.damping_mass_share = value)),
        DAMPING_COMMITTED_SHARE => {
            Some(check_share(value).map(|()| opts.damping_committed_share = value))
        }
        _ => None,
    }
    .map(|r| r.map_err(|m| format!("{name} = {m}")))
}

/// Whether `name` is a solver parameter rather than a model's.
pub(crate) fn is_solver_parameter(name: &str) -> bool {
    [DAMPING_RATIO, DAMPING_MASS_SHARE, DAMPING_COMMITTED_SHARE].contains(&name)
}

/// `[model]` options of `ceiling`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CeilingOptions {
    /// The specimen TOML file (`[structure]`, `[model]`), read by this worker.
    #[serde(default)]
    pub spec: Option<PathBuf>,
    /// The specimen TOML text itself (the coordinator inlines `spec` files).
    #[serde(default)]
    pub spec_toml: Option<String>,
    /// Number of modes reported (default 6).
    #[serde(default = "six")]
    pub n_modes: usize,
    /// Rayleigh damping ratio on the first x and y modes (default 0.05)
    /// unless `damping_ratio` is a study parameter.
    #[serde(default = "five_percent")]
    pub damping_ratio: f64,
    /// Integration steps per input sample (default 1).
    #[serde(default = "one")]
    pub substeps: usize,
    /// Values for model parameters that are not study parameters.
    #[serde(default)]
    pub fixed: BTreeMap<String, f64>,
    /// The base input (`[model.excitation]`, see [`Excitation`]).
    pub excitation: serde_json::Value,
    /// The sensors read in every run (`[[model.sensors]]`, see [`SensorOptions`]).
    #[serde(default)]
    pub sensors: Vec<serde_json::Value>,
}

fn six() -> usize {
    6
}
fn five_percent() -> f64 {
    0.05
}
fn one() -> usize {
    1
}

/// The `ceiling` model kind.
pub struct Ceiling {
    spec: CeilingSpec,
    base: Parameters,
    input: BaseInput,
    sensors: Vec<SensorOptions>,
    opts: SimOptions,
}

fn invalid(message: String) -> ModelError {
    ModelError::Invalid { kind: KIND.into(), message }
}

impl Ceiling {
    /// Reads the specimen and the excitation, places the sensors and checks
    /// every parameter name against the specimen's model variant.
    pub fn new(opts: CeilingOptions, names: &[String]) -> Result<Self, ModelError> {
        let spec = read_spec(&opts.spec, &opts.spec_toml).map_err(invalid)?;
        let study_names = names.iter().filter(|n| !is_solver_parameter(n));
        let base =
            base_parameters(&spec, &opts.fixed, study_names, SOLVER_HINT).map_err(invalid)?;
        if opts.n_modes == 0 {
            return Err(invalid("n_modes = 0: expected at least 1".into()));
        }
        if opts.substeps == 0 {
            return Err(invalid("substeps = 0: expected at least 1".into()));
        }
        check_damping_ratio(opts.damping_ratio)
            .map_err(|m| invalid(format!("damping_ratio = {m}")))?;
        let input = Excitation::from_json(&opts.excitation)
            .and_then(|e| e.base_input())
            .map_err(|e| invalid(e.to_string()))?;
        let sensors: Vec<SensorOptions> = (opts.sensors.iter().enumerate())
            .map(|(k, v)| SensorOptions::from_json(v, k))
            .collect::<Result<_, _>>()
            .map_err(invalid)?;
        check_sensors(&spec, &base, &sensors, "model.sensors").map_err(invalid)?;
        let sim = SimOptions {
            damping_ratio: opts.damping_ratio,
            n_modes: opts.n_modes,
            substeps: opts.substeps,
            ..SimOptions::default()
        };
        Ok(Self { spec, base, input, sensors, opts: sim })
    }

    /// The base input every run uses (m/s²).
    pub fn input(&self) -> &BaseInput {
        &self.input
    }
}

/// Ids usable as history names and unique; every sensor on the ceiling;
/// errors name `key[k]`.
pub(crate) fn check_sensors(
    spec: &CeilingSpec,
    base: &Parameters,
    sensors: &[SensorOptions],
    key: &str,
) -> Result<(), String> {
    let model = generate(spec, base).map_err(|e| e.to_string())?;
    let s = &spec.structure;
    let nx = (s.length_x_m / s.module_m).round() as usize;
    let ny = (s.length_y_m / s.module_m).round() as usize;
    let mut seen = BTreeSet::new();
    for (k, opt) in sensors.iter().enumerate() {
        let key = format!("{key}[{k}]");
        if !id_ok(&opt.id) {
            return Err(format!(
                "{key}.id = {:?}: expected letters, digits, '_', '-' or '.'",
                opt.id
            ));
        }
        if !seen.insert(opt.id.as_str()) {
            return Err(format!("{key}.id = {:?}: used twice", opt.id));
        }
        let inside = |v: f64, l: f64| (0.0..=l * (1.0 + 1e-9)).contains(&v);
        if !(inside(opt.x_m, s.length_x_m) && inside(opt.y_m, s.length_y_m)) {
            return Err(format!(
                "{key} ({}): x_m = {}, y_m = {}: outside the ceiling (0..{} m, 0..{} m)",
                opt.id, opt.x_m, opt.y_m, s.length_x_m, s.length_y_m
            ));
        }
        place(&opt.sensor(), &model, s.module_m, nx, ny)
            .map_err(|e| format!("{key}.x_m/y_m: {e}"))?;
    }
    Ok(())
}

impl Model for Ceiling {
    fn output_names(&self) -> Vec<String> {
        let k = self.opts.n_modes;
        let f = (1..=k).map(|i| format!("f{i}_hz"));
        let dir = (1..=k).map(|i| format!("dir{i}"));
        let peaks = self.sensors.iter().map(|s| format!("peak_{}", s.id));
        f.chain(dir).chain(peaks).collect()
    }

    fn run(&self, params: &ParamSet<'_>, ctx: &RunContext) -> Result<Outputs, RunError> {
        let mut p = self.base.clone();
        let mut opts = self.opts.clone();
        for (name, value) in params.iter() {
            match set_solver_parameter(&mut opts, name, value) {
                Some(r) => r.map_err(RunError::Input)?,
                None => p.set(name, value).map_err(|e| RunError::Input(e.to_string()))?,
            }
        }
        if ctx.cancelled() {
            return Err(RunError::Cancelled);
        }
        let fe_sensors: Vec<_> = self.sensors.iter().map(SensorOptions::sensor).collect();
        let sim = simulate(&self.spec, &p, &self.input, &fe_sensors, &opts, &mut |_| {})
            .map_err(failure)?;
        outputs(&sim, &self.sensors, opts.n_modes)
    }
}

/// A simulation that could not finish, as a recorded failure with its reason.
pub fn failure(e: CeilingError) -> RunError {
    match e {
        CeilingError::Transient(t) => RunError::Failed(format!("transient: {t}")),
        other => RunError::Failed(other.to_string()),
    }
}

/// Scalars and one history per sensor from a simulation.
fn outputs(
    sim: &Simulation,
    sensors: &[SensorOptions],
    n_modes: usize,
) -> Result<Outputs, RunError> {
    if sim.freq_hz.len() < n_modes {
        return Err(RunError::Failed(format!(
            "modal analysis found {} modes: expected {n_modes}",
            sim.freq_hz.len()
        )));
    }
    let mut scalars = Vec::with_capacity(2 * n_modes + sensors.len());
    for (k, f) in sim.freq_hz.iter().take(n_modes).enumerate() {
        scalars.push((format!("f{}_hz", k + 1), *f));
    }
    for (k, d) in sim.mode_dir.iter().take(n_modes).enumerate() {
        let code = match d {
            'x' => 1.0,
            'y' => 2.0,
            _ => 3.0,
        };
        scalars.push((format!("dir{}", k + 1), code));
    }
    let mut histories = Vec::with_capacity(sensors.len());
    for (opt, h) in sensors.iter().zip(&sim.sensors) {
        let peak = h.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        scalars.push((format!("peak_{}", opt.id), peak));
        histories.push(History {
            name: opt.id.clone(),
            dt_s: sim.dt_s,
            channels: vec![opt.channel()],
            data: h.values.clone(),
        });
    }
    Ok(Outputs { scalars, histories })
}

#[cfg(test)]
mod tests;
