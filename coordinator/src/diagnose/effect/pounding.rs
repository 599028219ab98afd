//! Perimeter pounding: grid ends strike the wall angle once the gap closes
//! (the seed's eq. 5.4 contact).

use super::{Effect, FLOOR};
use crate::diagnose::cause::{Demand, Prior};
use fe::generator::{Boundary, ModelOptions, Perimeter};

/// Grid ends strike the wall angle once the gap closes.
pub struct PerimeterPounding;

/// Gap over the baseline's peak perimeter displacement (≥ 1: never closes),
/// and the contact stiffness over the seed's 0.4 EA/L (the seed's simplified
/// model used 300 then 100 N/mm, 0.2–1.4 of it; a wall angle that bends or a
/// scatter of gaps along an edge acts softer, a grid end bearing on a stiff
/// wall stiffer).
const PRIORS: [Prior; 2] = [
    Prior { name: "gap_over_demand", unit: "-", low: 0.1, high: 1.5, log: true, reference: None },
    Prior {
        name: "impact_factor",
        unit: "-",
        low: 0.05,
        high: 2.0,
        log: true,
        reference: Some(1.0),
    },
];

impl Effect for PerimeterPounding {
    fn name(&self) -> &'static str {
        "perimeter-pounding"
    }

    fn explain(&self) -> &'static str {
        "grid ends strike the wall angle once the gap closes"
    }

    fn priors(&self) -> &'static [Prior] {
        &PRIORS
    }

    fn onset(&self) -> &'static str {
        "gap_over_demand"
    }

    fn add_to(&self, o: ModelOptions) -> ModelOptions {
        let perimeter = if o.perimeter.has_friction() {
            Perimeter::FrictionPounding
        } else {
            Perimeter::Pounding
        };
        ModelOptions { perimeter, ..o }
    }

    fn model_parameter_names(&self) -> &'static [&'static str] {
        &["gap_ratio"]
    }

    fn model_parameters(
        &self,
        name: &str,
        value: f64,
        _other: &[(&str, f64)],
        demand: &Demand,
    ) -> Option<Vec<(&'static str, f64)>> {
        match name {
            "gap_over_demand" => {
                let gap_mm = (value * demand.perimeter_mm).max(FLOOR);
                Some(vec![("gap_ratio", gap_mm / demand.nominal_gap_mm.max(FLOOR))])
            }
            "impact_factor" => Some(vec![("impact_factor", value)]),
            _ => None,
        }
    }

    fn has_place(&self, boundary: Boundary) -> bool {
        boundary.has_sliding_ends()
    }

    fn damped_nonlinear_springs(&self) -> bool {
        false // contacts carry no Rayleigh damping
    }
}
