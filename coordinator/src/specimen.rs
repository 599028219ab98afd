//! The one bridge from a bundle's specimen and sensors to the FE model's
//! types: `bundle::Structure` → `fe::generator::CeilingSpec`, bundle sensors
//! → `fe::ceiling::Sensor`, run data → `fe::ceiling::BaseInput`.

use crate::bundle::{self, Bundle, RunData};
use fe::ceiling::{BaseInput, Direction, Sensor, SensorKind};
use fe::generator::{CeilingSpec, ModelOptions, Structure};

/// Why a bundle's specimen cannot be modelled.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpecimenError {
    /// A perimeter with sliding ends needs its gap.
    #[error("structure.nominal_gap_mm: required for a {0} perimeter")]
    MissingGap(&'static str),
    /// The FE generator refused the structure.
    #[error("structure: {0}")]
    Spec(String),
}

/// The FE specimen of a bundle's structure with the given model options
/// (a fixed perimeter has no gap: 0 mm).
pub fn fe_spec(s: &bundle::Structure, model: ModelOptions) -> Result<CeilingSpec, SpecimenError> {
    let gap = match (s.nominal_gap_mm, s.boundary.has_sliding_ends()) {
        (Some(g), _) => g,
        (None, false) => 0.0,
        (None, true) => return Err(SpecimenError::MissingGap(s.boundary.as_str())),
    };
    let spec = CeilingSpec {
        structure: Structure {
            length_x_m: s.length_x_m,
            length_y_m: s.length_y_m,
            module_m: s.module_m,
            main_tee_spacing_m: s.main_tee_spacing_m,
            hanger_spacing_m: s.hanger_spacing_m,
            hanger_length_m: s.hanger_length_m,
            panel_mass_kg: s.panel_mass_kg,
            layers: s.layers,
            boundary: s.boundary,
            nominal_gap_mm: gap,
            lines_from_origin: true,
            wall_members: s.wall_members,
            hanger_offset_m: s.hanger_offset_m,
        },
        model,
    };
    spec.check().map_err(|e| SpecimenError::Spec(e.to_string()))?;
    Ok(spec)
}

/// The FE sensor of a bundle sensor.
pub fn fe_sensor(s: &bundle::Sensor) -> Sensor {
    Sensor {
        id: s.id.clone(),
        kind: match s.kind {
            bundle::SensorKind::Acceleration => SensorKind::Acceleration,
            bundle::SensorKind::Displacement => SensorKind::Displacement,
        },
        x_m: s.x_m,
        y_m: s.y_m,
        direction: match s.direction {
            bundle::Direction::X => Direction::X,
            bundle::Direction::Y => Direction::Y,
        },
    }
}

/// Longest integration step (s) of every simulation of a bundle's runs: a
/// run sampled at 100 Hz is integrated in two steps a sample. Newmark's
/// average acceleration lengthens a period by about (ω Δt)²/12: 5.6 % for a
/// 13 Hz ceiling mode at a 10 ms step, 1.4 % at 5 ms, and a grid end's
/// contact rings at a period under 10 ms. On OpenSees campaigns integrated
/// at a tenth of the sample step, the diagnosis at the sample step gained
/// 0.399 with connection hysteresis hidden and −2.10 with pounding; at
/// 5 ms, 0.687 and 0.980 (at 2.5 ms the hysteresis gained 0.760, for
/// twice the FE time again).
pub const MAX_STEP_S: f64 = 0.005;

/// The longest integration step (s) of the runs `runs` of `b` under
/// [`run_options`]: a sample step split to at most [`MAX_STEP_S`]; 0
/// without runs.
pub fn fe_step_s(b: &Bundle, runs: &[usize]) -> f64 {
    // The step does not depend on the damping.
    let o = run_options(fe::ceiling::SimOptions::default().damping_ratio);
    runs.iter()
        .filter_map(|k| b.runs.get(*k))
        .map(|r| r.dt_s / fe::ceiling::steps_per_sample(r.dt_s, o.substeps, o.max_step_s) as f64)
        .fold(0.0, f64::max)
}

/// The simulation options of every run of a bundle, in `diagnose` and in
/// `synth`: Rayleigh damping `damping_ratio` on the first x and y modes,
/// the perimeter springs damped with the grid, steps of at most
/// [`MAX_STEP_S`].
pub fn run_options(damping_ratio: f64) -> fe::ceiling::SimOptions {
    fe::ceiling::SimOptions {
        damping_ratio,
        rayleigh_groups: vec![
            crate::diagnose::fit::PERIMETER_GROUP.into(),
            crate::diagnose::fit::PERIMETER_ACROSS_GROUP.into(),
        ],
        max_step_s: Some(MAX_STEP_S),
        ..fe::ceiling::SimOptions::default()
    }
}

/// The base input of a run (m/s²).
pub fn base_input(run: &RunData) -> BaseInput {
    BaseInput { dt_s: run.dt_s, x_m_s2: run.input_x_m_s2.clone(), y_m_s2: run.input_y_m_s2.clone() }
}

/// Factor from an FE sensor value (m/s² or m) to the bundle's internal unit
/// (m/s² or mm).
pub fn to_bundle_units(kind: bundle::SensorKind) -> f64 {
    match kind {
        bundle::SensorKind::Acceleration => 1.0,
        bundle::SensorKind::Displacement => 1000.0,
    }
}

/// (sensor id, samples) for every sensor, in the bundle's internal units.
pub type SensorSeries = Vec<(String, Vec<f64>)>;

/// One simulated run in the bundle's internal units: (sensor id, samples)
/// for every sensor, plus the simulation's frequencies and spring peaks.
pub fn simulate_run(
    spec: &CeilingSpec,
    params: &fe::generator::Parameters,
    sensors: &[bundle::Sensor],
    input: &BaseInput,
    opts: &fe::ceiling::SimOptions,
) -> Result<(SensorSeries, fe::ceiling::Simulation), fe::ceiling::CeilingError> {
    let fe_sensors: Vec<Sensor> = sensors.iter().map(fe_sensor).collect();
    let sim = fe::ceiling::simulate(spec, params, input, &fe_sensors, opts, &mut |_| {})?;
    Ok((bundle_series(sensors, &sim), sim))
}

/// A simulation's sensor histories in the bundle's internal units:
/// (sensor id, samples) for every sensor.
pub fn bundle_series(sensors: &[bundle::Sensor], sim: &fe::ceiling::Simulation) -> SensorSeries {
    sensors
        .iter()
        .zip(&sim.sensors)
        .map(|(s, h)| {
            let k = to_bundle_units(s.kind);
            (s.id.clone(), h.values.iter().map(|v| v * k).collect())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bundle::Boundary;

    fn structure(boundary: Boundary, gap: Option<f64>) -> bundle::Structure {
        let square = crate::diagnose::testkit::square_structure(2.4, 0.0);
        bundle::Structure { boundary, nominal_gap_mm: gap, ..square }
    }

    #[test]
    fn every_bundle_boundary_is_modelled_and_only_sliding_ends_need_a_gap() {
        let all = [Boundary::Free, Boundary::Fixed, Boundary::FixedSemiFree, Boundary::SemiFree];
        for b in all {
            let spec = fe_spec(&structure(b, Some(12.0)), ModelOptions::default()).unwrap();
            assert_eq!(spec.structure.boundary, b);
            assert_eq!(spec.structure.nominal_gap_mm, 12.0);
        }
        let fixed = fe_spec(&structure(Boundary::Fixed, None), ModelOptions::default()).unwrap();
        assert_eq!(fixed.structure.nominal_gap_mm, 0.0);
        let e = fe_spec(&structure(Boundary::Free, None), ModelOptions::default()).unwrap_err();
        assert_eq!(e.to_string(), "structure.nominal_gap_mm: required for a free perimeter");
    }
}
