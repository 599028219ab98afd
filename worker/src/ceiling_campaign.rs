//! `ceiling-campaign`: several shaking-table runs of one specimen per task
//! (`fe::ceiling::simulate` once per run), as a diagnosis calibrates a
//! model variant against a measured campaign.
//!
//! Options: the FE specimen as TOML text (`spec_toml`: `[structure]` and
//! the variant's `[model]`), the default Rayleigh damping ratio, the spring
//! groups whose springs take Rayleigh damping (`rayleigh_groups`) and whose
//! peaks are reported (`spring_groups`), and the runs: each with its id, its
//! step `dt_s` (s), its base input in x and/or y (m/s², hexadecimal
//! little-endian f64 text, see [`crate::exact_json`]) and the sensors read
//! in it (as `[[model.sensors]]` of `ceiling`). Floats travel as exact
//! text so that a worker reproduces the coordinator's numbers bit for bit.
//!
//! Parameters: the names of `fe::generator::parameters_for` the variant
//! (mm², MPa, mm⁴, N/mm, N, -) plus `damping_ratio` and `damping_mass_share`;
//! a name may repeat (the last value wins), the others sit at their prior
//! mid-points. A study may also name `run_index` ([`RUN_INDEX`]): each task
//! then simulates the one run of that (0-based) index, so that the runs of
//! one parameter point spread over the workers instead of queueing on one.
//!
//! Outputs: one history per (run, sensor) simulated, named `<run>/<sensor>`,
//! one channel `<sensor>_accel_m_s2` (absolute acceleration) or
//! `<sensor>_disp_m` (relative displacement), at the run's step; scalars
//! `<group>_deformation_mm` and `<group>_force_n`: the peak |deformation|
//! and |force| of each spring group over the runs simulated (0 when the
//! variant has no spring in the group).

use crate::ceiling::sensors::{id_ok, SensorOptions};
use crate::ceiling::{check_sensors, is_solver_parameter, set_solver_parameter, SOLVER_HINT};
use crate::exact_json::{f64_text, samples_hex};
use crate::model::{Model, ModelError, ParamSet, RunContext, RunError};
use crate::specimen::base_parameters;
use fe::ceiling::{simulate, BaseInput, SimOptions};
use fe::generator::{CeilingSpec, Parameters};
use protocol::{History, Outputs};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

const KIND: &str = "ceiling-campaign";

/// The parameter that picks the one run a task simulates (0-based index
/// into the options' runs).
pub const RUN_INDEX: &str = "run_index";

/// `[model]` options of `ceiling-campaign`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignOptions {
    /// The specimen: `[structure]` and `[model]` as TOML text.
    pub spec_toml: String,
    /// Rayleigh damping ratio unless `damping_ratio` is a parameter.
    #[serde(with = "f64_text", default = "five_percent")]
    pub damping_ratio: f64,
    /// Spring groups that take Rayleigh damping.
    #[serde(default)]
    pub rayleigh_groups: Vec<String>,
    /// Spring groups whose peaks are reported.
    #[serde(default)]
    pub spring_groups: Vec<String>,
    /// Longest integration step (s); a run sampled more coarsely is
    /// integrated in substeps (none: at its sample step).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_step_s: Option<f64>,
    /// The runs simulated by every task, in order.
    pub runs: Vec<CampaignRun>,
}

fn five_percent() -> f64 {
    0.05
}

/// One run of a campaign.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignRun {
    /// Run id (names its histories).
    pub id: String,
    /// Sample step of the input and of the histories (s).
    #[serde(with = "f64_text")]
    pub dt_s: f64,
    /// Base acceleration along x (m/s²).
    #[serde(with = "samples_hex", default, skip_serializing_if = "Option::is_none")]
    pub input_x_m_s2: Option<Vec<f64>>,
    /// Base acceleration along y (m/s²).
    #[serde(with = "samples_hex", default, skip_serializing_if = "Option::is_none")]
    pub input_y_m_s2: Option<Vec<f64>>,
    /// Sensors read in this run.
    #[serde(default)]
    pub sensors: Vec<SensorOptions>,
}

impl CampaignRun {
    /// The FE base input.
    fn base_input(&self) -> BaseInput {
        BaseInput {
            dt_s: self.dt_s,
            x_m_s2: self.input_x_m_s2.clone(),
            y_m_s2: self.input_y_m_s2.clone(),
        }
    }
}

/// A run ready to simulate.
struct Prepared {
    id: String,
    input: BaseInput,
    sensors: Vec<SensorOptions>,
    fe_sensors: Vec<fe::ceiling::Sensor>,
}

/// The `ceiling-campaign` model kind.
pub struct CeilingCampaign {
    spec: CeilingSpec,
    base: Parameters,
    runs: Vec<Prepared>,
    opts: SimOptions,
}

fn invalid(message: String) -> ModelError {
    ModelError::Invalid { kind: KIND.into(), message }
}

impl CeilingCampaign {
    /// Parses the specimen, checks every run, sensor and parameter name.
    pub fn new(o: CampaignOptions, names: &[String]) -> Result<Self, ModelError> {
        let spec = CeilingSpec::from_toml_str(&o.spec_toml, Path::new("[model] spec_toml"))
            .map_err(|e| invalid(e.to_string()))?;
        let study_names = names.iter().filter(|n| !is_solver_parameter(n) && *n != RUN_INDEX);
        let base =
            base_parameters(&spec, &BTreeMap::new(), study_names, SOLVER_HINT).map_err(invalid)?;
        fe::ceiling::check_damping_ratio(o.damping_ratio)
            .map_err(|m| invalid(format!("damping_ratio = {m}")))?;
        check_groups("rayleigh_groups", &o.rayleigh_groups)?;
        check_groups("spring_groups", &o.spring_groups)?;
        if o.runs.is_empty() {
            return Err(invalid("runs = []: expected at least one run".into()));
        }
        let mut ids = BTreeSet::new();
        let mut runs = Vec::with_capacity(o.runs.len());
        for (k, run) in o.runs.iter().enumerate() {
            check_run(k, run, &mut ids)?;
            check_sensors(&spec, &base, &run.sensors, &format!("runs[{k}].sensors"))
                .map_err(invalid)?;
            runs.push(Prepared {
                id: run.id.clone(),
                input: run.base_input(),
                fe_sensors: run.sensors.iter().map(SensorOptions::sensor).collect(),
                sensors: run.sensors.clone(),
            });
        }
        let opts = SimOptions {
            damping_ratio: o.damping_ratio,
            spring_groups: o.spring_groups,
            rayleigh_groups: o.rayleigh_groups,
            max_step_s: o.max_step_s,
            ..SimOptions::default()
        };
        Ok(Self { spec, base, runs, opts })
    }

    /// The run a `run_index` value names.
    fn run_at(&self, value: f64) -> Result<&Prepared, RunError> {
        let n = self.runs.len();
        let ok = value.fract() == 0.0 && value >= 0.0 && value < n as f64;
        ok.then(|| &self.runs[value as usize]).ok_or_else(|| {
            RunError::Input(format!(
                "{RUN_INDEX} = {value}: expected a whole number from 0 to {}",
                n - 1
            ))
        })
    }
}

/// Group names are non-empty and listed once.
fn check_groups(key: &str, groups: &[String]) -> Result<(), ModelError> {
    let mut seen = BTreeSet::new();
    for (k, g) in groups.iter().enumerate() {
        if g.is_empty() || !seen.insert(g.as_str()) {
            return Err(invalid(format!(
                "{key}[{k}] = {g:?}: expected a non-empty group name, listed once"
            )));
        }
    }
    Ok(())
}

/// A run's id, step and input.
fn check_run(k: usize, run: &CampaignRun, ids: &mut BTreeSet<String>) -> Result<(), ModelError> {
    let key = format!("runs[{k}]");
    if !id_ok(&run.id) || !ids.insert(run.id.clone()) {
        return Err(invalid(format!(
            "{key}.id = {:?}: expected a unique id of letters, digits, '_', '-' or '.'",
            run.id
        )));
    }
    if !(run.dt_s > 0.0 && run.dt_s.is_finite()) {
        return Err(invalid(format!(
            "{key} ({}).dt_s = {}: expected a step > 0 s",
            run.id, run.dt_s
        )));
    }
    let components = [("input_x_m_s2", &run.input_x_m_s2), ("input_y_m_s2", &run.input_y_m_s2)];
    if components.iter().all(|(_, c)| c.is_none()) {
        return Err(invalid(format!(
            "{key} ({}): no input_x_m_s2 or input_y_m_s2: expected at least one",
            run.id
        )));
    }
    for (name, c) in components {
        let Some(v) = c else { continue };
        if v.len() < 2 {
            return Err(invalid(format!(
                "{key} ({}).{name}: {} samples: expected at least 2",
                run.id,
                v.len()
            )));
        }
        if let Some(i) = v.iter().position(|a| !a.is_finite()) {
            return Err(invalid(format!(
                "{key} ({}).{name}[{i}] = {}: expected a finite acceleration",
                run.id, v[i]
            )));
        }
    }
    Ok(())
}

impl Model for CeilingCampaign {
    fn output_names(&self) -> Vec<String> {
        let peaks = self.opts.spring_groups.iter();
        peaks.flat_map(|g| [format!("{g}_deformation_mm"), format!("{g}_force_n")]).collect()
    }

    fn run(&self, params: &ParamSet<'_>, ctx: &RunContext) -> Result<Outputs, RunError> {
        let mut p = self.base.clone();
        let mut opts = self.opts.clone();
        let mut runs: &[Prepared] = &self.runs;
        for (name, value) in params.iter() {
            if name == RUN_INDEX {
                runs = std::slice::from_ref(self.run_at(value)?);
            } else if let Some(r) = set_solver_parameter(&mut opts, name, value) {
                r.map_err(RunError::Input)?;
            } else {
                p.set(name, value).map_err(|e| RunError::Input(e.to_string()))?;
            }
        }
        let mut peaks = vec![(0.0f64, 0.0f64); opts.spring_groups.len()];
        let mut histories = Vec::new();
        for run in runs {
            if ctx.cancelled() {
                return Err(RunError::Cancelled);
            }
            let sim = simulate(&self.spec, &p, &run.input, &run.fe_sensors, &opts, &mut |_| {})
                .map_err(|e| RunError::Failed(format!("run {}: {e}", run.id)))?;
            for (peak, g) in peaks.iter_mut().zip(&sim.spring_peaks) {
                *peak = (peak.0.max(g.deformation_mm), peak.1.max(g.force_n));
            }
            for (s, h) in run.sensors.iter().zip(&sim.sensors) {
                histories.push(History {
                    name: format!("{}/{}", run.id, s.id),
                    dt_s: sim.dt_s,
                    channels: vec![s.channel()],
                    data: h.values.clone(),
                });
            }
        }
        let scalars = self.output_names().into_iter().zip(peaks.iter().flat_map(|(d, f)| [*d, *f]));
        Ok(Outputs { scalars: scalars.collect(), histories })
    }
}

#[cfg(test)]
mod tests;
