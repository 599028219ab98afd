//! Perimeter friction: the perimeter supports and seismic clips stick,
//! then slip (Steel01 on the perimeter springs).

use super::{Effect, FLOOR};
use crate::diagnose::cause::{Demand, Prior};
use fe::generator::{Boundary, ModelOptions, Perimeter};

/// Stick-slip at the perimeter supports and seismic clips.
pub struct PerimeterFriction;

/// Slip force over the baseline's peak perimeter force (≥ 1: never slips),
/// and the stiffness after slip over the stiffness before (Steel01 `b`, the
/// seed's 0.05: a scatter of slip forces along an edge, clips that bind, or
/// a rounded slip like a Wen link's harden the response after the first
/// slip).
const PRIORS: [Prior; 2] = [
    Prior { name: "slip_over_demand", unit: "-", low: 0.05, high: 1.5, log: true, reference: None },
    Prior {
        name: "friction_b",
        unit: "-",
        low: 0.005,
        high: 0.5,
        log: true,
        reference: Some(0.05),
    },
];

impl Effect for PerimeterFriction {
    fn name(&self) -> &'static str {
        "perimeter-friction"
    }

    fn explain(&self) -> &'static str {
        "the perimeter supports stick, then slip"
    }

    fn priors(&self) -> &'static [Prior] {
        &PRIORS
    }

    fn onset(&self) -> &'static str {
        "slip_over_demand"
    }

    fn add_to(&self, o: ModelOptions) -> ModelOptions {
        let perimeter = if o.perimeter.has_pounding() {
            Perimeter::FrictionPounding
        } else {
            Perimeter::Friction
        };
        ModelOptions { perimeter, ..o }
    }

    fn model_parameter_names(&self) -> &'static [&'static str] {
        &["friction_fy_N"]
    }

    fn model_parameters(
        &self,
        name: &str,
        value: f64,
        _other: &[(&str, f64)],
        demand: &Demand,
    ) -> Option<Vec<(&'static str, f64)>> {
        match name {
            "slip_over_demand" => {
                Some(vec![("friction_fy_N", (value * demand.perimeter_n).max(FLOOR))])
            }
            "friction_b" => Some(vec![("friction_b", value)]),
            _ => None,
        }
    }

    fn has_place(&self, boundary: Boundary) -> bool {
        boundary.has_sliding_ends()
    }

    fn damped_nonlinear_springs(&self) -> bool {
        true
    }
}
