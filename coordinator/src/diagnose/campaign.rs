//! A diagnosis's evaluation as a farm study of the worker kind
//! `ceiling-campaign`: the model spec (the variant's specimen, the runs with
//! their inputs and sensors, the spring groups), its hash, each point's task
//! parameters, and the workers' outputs back in the bundle's units. A task
//! simulates one run of one point (the study names `run_index`), so that a
//! point's runs spread over the workers and a lone point (a local search's
//! trial step) does not leave all but one idle. The
//! worker runs exactly what [`Evaluation::simulate`] (sensors) or
//! [`Evaluation::demand_at`] (spring peaks) runs, so the numbers match bit
//! for bit.

use super::cause::Demand;
use super::fit::{
    measured_sensors, Evaluation, Simulated, CONNECTION_GROUP, CONNECTION_TRANSVERSE_GROUP,
    DEMAND_GROUPS, PERIMETER_GROUP,
};
use crate::bundle::{self, Bundle};
use crate::specimen::{run_options, to_bundle_units};
use crate::study::hash_keys;
use fe::ceiling::SimOptions;
use protocol::Outcome;
use protocol::{ModelSpec, Outputs};
use std::collections::BTreeMap;
use worker::ceiling::sensors::{DirectionOption, SensorKindOption, SensorOptions};
use worker::ceiling_campaign::{CampaignOptions, CampaignRun, RUN_INDEX};

/// The registry name of the worker kind.
pub const KIND: &str = "ceiling-campaign";

/// What a study computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Purpose {
    /// The sensors' time histories ([`Evaluation::simulate`]).
    Histories,
    /// The spring-group peaks ([`Evaluation::demand_at`]).
    Demand,
}

/// One evaluation as a farm study.
#[derive(Debug, Clone)]
pub struct CampaignStudy {
    /// What the workers build.
    pub spec: ModelSpec,
    /// SHA-256 (hex) of the spec: the study hash.
    pub hash: String,
}

/// The farm study of `ev` for `purpose`.
pub fn campaign_study(ev: &Evaluation<'_>, purpose: Purpose) -> Result<CampaignStudy, String> {
    let spec = ev.fe_spec()?;
    let spec_toml = toml::to_string(&spec).map_err(|e| format!("specimen as TOML: {e}"))?;
    let (groups, with_sensors) = match purpose {
        Purpose::Histories => (vec![], true),
        Purpose::Demand => (DEMAND_GROUPS.map(String::from).to_vec(), false),
    };
    let runs = ev.runs.iter().map(|&k| campaign_run(ev.bundle, k, with_sensors)).collect();
    let sim = run_options(SimOptions::default().damping_ratio);
    let options = CampaignOptions {
        spec_toml,
        damping_ratio: sim.damping_ratio,
        rayleigh_groups: sim.rayleigh_groups,
        spring_groups: groups,
        max_step_s: sim.max_step_s,
        runs,
    };
    let options_json = serde_json::to_string(&options).map_err(|e| e.to_string())?;
    let mid: Vec<f64> = ev.priors.iter().map(|p| p.at(0.5)).collect();
    let mut param_names: Vec<String> =
        ev.assignments(&mid).iter().map(|(n, _)| n.to_string()).collect();
    param_names.push(RUN_INDEX.into());
    let spec = ModelSpec { kind: KIND.into(), options_json, param_names, outputs: vec![] };
    let keys = BTreeMap::from([
        ("kind".to_string(), spec.kind.clone()),
        ("options".to_string(), spec.options_json.clone()),
        ("parameters".to_string(), spec.param_names.join("\u{1f}")),
    ]);
    Ok(CampaignStudy { hash: hash_keys(&keys), spec })
}

/// A bundle run as a campaign run (its measured sensors or none).
fn campaign_run(b: &Bundle, k: usize, with_sensors: bool) -> CampaignRun {
    let run = &b.runs[k];
    let sensors = if with_sensors { measured_sensors(b, run) } else { vec![] };
    CampaignRun {
        id: run.id.clone(),
        dt_s: run.dt_s,
        input_x_m_s2: run.input_x_m_s2.clone(),
        input_y_m_s2: run.input_y_m_s2.clone(),
        sensors: sensors.iter().map(sensor_options).collect(),
    }
}

/// A bundle sensor as the worker reads it.
fn sensor_options(s: &bundle::Sensor) -> SensorOptions {
    SensorOptions {
        id: s.id.clone(),
        kind: match s.kind {
            bundle::SensorKind::Acceleration => SensorKindOption::Acceleration,
            bundle::SensorKind::Displacement => SensorKindOption::Displacement,
        },
        x_m: s.x_m,
        y_m: s.y_m,
        direction: match s.direction {
            bundle::Direction::X => DirectionOption::X,
            bundle::Direction::Y => DirectionOption::Y,
        },
    }
}

/// The parameters of `theta` (without the run index), or why the point
/// cannot be set up (the same message [`Evaluation::simulate`] gives).
pub fn task_params(
    ev: &Evaluation<'_>,
    study: &CampaignStudy,
    theta: &[f64],
) -> Result<Vec<f64>, String> {
    ev.setup(theta)?;
    let pairs = ev.assignments(theta);
    let names = &study.spec.param_names;
    let names_match = pairs.len() + 1 == names.len()
        && pairs.iter().zip(names).all(|((a, _), b)| a == b)
        && names.last().is_some_and(|n| n == RUN_INDEX);
    if !names_match {
        return Err(format!("parameter names at {theta:?} differ from the study's"));
    }
    Ok(pairs.into_iter().map(|(_, v)| v).collect())
}

/// The tasks of a point with parameters `params`: one per run, the run's
/// index last.
pub fn run_tasks(params: &[f64], n_runs: usize) -> Vec<Vec<f64>> {
    (0..n_runs)
        .map(|k| {
            let mut p = params.to_vec();
            p.push(k as f64);
            p
        })
        .collect()
}

/// The outcome of a point from those of its run tasks, in run order: the
/// first failure if any run failed, else the runs' histories in order and
/// each spring-group peak the largest over the runs.
pub fn merge_runs(runs: Vec<Outcome>) -> Outcome {
    let mut merged = Outputs::default();
    for (k, o) in runs.into_iter().enumerate() {
        let out = match o {
            Outcome::Ok(out) => out,
            failed @ Outcome::Failed { .. } => return failed,
        };
        if k == 0 {
            merged.scalars = out.scalars;
        } else {
            for ((_, a), (_, b)) in merged.scalars.iter_mut().zip(&out.scalars) {
                *a = a.max(*b);
            }
        }
        merged.histories.extend(out.histories);
    }
    Outcome::Ok(merged)
}

/// The simulated runs of `ev` from a worker's outputs (bundle units).
pub fn simulated(ev: &Evaluation<'_>, out: &Outputs) -> Result<Vec<Simulated>, String> {
    let mut histories = out.histories.iter();
    let mut sims = Vec::with_capacity(ev.runs.len());
    for &k in ev.runs {
        let run = &ev.bundle.runs[k];
        let mut series = Vec::new();
        for s in measured_sensors(ev.bundle, run) {
            let name = format!("{}/{}", run.id, s.id);
            let h = histories.next().filter(|h| h.name == name && h.channels.len() == 1);
            let h = h.ok_or_else(|| format!("expected history {name} with one channel"))?;
            let f = to_bundle_units(s.kind);
            series.push((s.id.clone(), h.data.iter().map(|v| v * f).collect()));
        }
        sims.push(series);
    }
    Ok(sims)
}

/// The demand of `ev` from a worker's spring-group peaks.
pub fn demand(ev: &Evaluation<'_>, out: &Outputs) -> Result<Demand, String> {
    let get = |name: String| out.scalar(&name).ok_or_else(|| format!("expected scalar {name}"));
    Ok(Demand {
        perimeter_mm: get(format!("{PERIMETER_GROUP}_deformation_mm"))?,
        perimeter_n: get(format!("{PERIMETER_GROUP}_force_n"))?,
        connection_n: get(format!("{CONNECTION_GROUP}_force_n"))?,
        connection_transverse_n: get(format!("{CONNECTION_TRANSVERSE_GROUP}_force_n"))?,
        nominal_gap_mm: ev.fe_spec()?.structure.nominal_gap_mm,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use protocol::History;

    fn run_out(id: &str, peak: f64) -> Outcome {
        Outcome::Ok(Outputs {
            scalars: vec![("g_force_n".into(), peak), ("h_force_n".into(), 2.0 * peak)],
            histories: vec![History {
                name: format!("{id}/A1"),
                dt_s: 0.01,
                channels: vec!["A1_accel_m_s2".into()],
                data: vec![peak],
            }],
        })
    }

    #[test]
    fn a_points_runs_merge_in_order_with_the_largest_peaks() {
        let Outcome::Ok(out) = merge_runs(vec![run_out("a", 3.0), run_out("b", 1.0)]) else {
            panic!("failed")
        };
        let names: Vec<&str> = out.histories.iter().map(|h| h.name.as_str()).collect();
        assert_eq!(names, ["a/A1", "b/A1"]);
        assert_eq!(out.scalars, vec![("g_force_n".into(), 3.0), ("h_force_n".into(), 6.0)]);
    }

    #[test]
    fn a_failed_run_fails_the_point() {
        let failed = Outcome::Failed { reason: "run b: no convergence".into() };
        let merged = merge_runs(vec![run_out("a", 1.0), failed.clone(), run_out("c", 2.0)]);
        assert_eq!(merged, failed);
    }

    #[test]
    fn each_run_gets_a_task_with_its_index_last() {
        assert_eq!(run_tasks(&[1.5, 0.1], 2), vec![vec![1.5, 0.1, 0.0], vec![1.5, 0.1, 1.0]]);
    }
}
