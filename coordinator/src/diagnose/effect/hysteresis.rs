//! Connection hysteresis: the grid connections soften, yield and pinch (the
//! tee joints' axial spring a scaled CJS-A Pinching4, and their in-plane
//! transverse spring another, each with its own onset).

use super::{Effect, FLOOR};
use crate::diagnose::cause::{Demand, LinearPart, Prior};
use fe::generator::{Boundary, Connections, ModelOptions};

/// Nonlinear, softening and pinching grid connections.
pub struct ConnectionHysteresis;

/// First backbone force of the seed's CJS-A connection (N).
pub const CJS_A_FIRST_FORCE_N: f64 = 150.0;

/// Initial stiffness of the unscaled CJS-A backbone (N/mm): 150 N at 0.5 mm.
const CJS_A_INITIAL_N_PER_MM: f64 = 300.0;

/// The first compression slope over the first tension slope of the
/// class's connections: 1, so that below its first backbone point a joint
/// is the baseline's elastic K_cc1 spring in both directions and the class
/// nests the baseline (at `conn_stiffness_factor` 1 and an onset above the
/// demand). With CJS-A's own 4/3 the joint was a bimodular spring there,
/// and the class's linear part could not rebuild the baseline: on bench dev
/// campaign 700003 it fitted the calibration runs 86 nats worse (MDL) than
/// the baseline it should contain.
const SYMMETRIC_FIRST_SLOPE: f64 = 1.0;

/// CJS-A first backbone force over the baseline's peak connection force,
/// its initial stiffness over the baseline's elastic K_cc1 (1 and a first
/// force above the demand: the baseline again), and the pinching: Pinching4's
/// reloading force over the force at the largest past deformation (CJS-A:
/// 0.2; fuller loops above). The pinching is explored from the start, not
/// held at CJS-A's: a connection with fuller loops seen through CJS-A's
/// pinching is best fitted as one that never yields, where the pinching has
/// no gradient left to follow. The unloading force (Pinching4 uForce, as a
/// shift from CJS-A's −0.01; Table 5.5's connection kinds span −0.3 to
/// −0.01) is held at CJS-A's until the estimate has converged, then freed
/// in a last local search ([`Effect::late_parameters`]): connections whose unloading keeps a tenth of their
/// strength (uForce 0.1), seen through CJS-A's, were fitted with a first
/// force half the true one, and the stronger validation run drove them past
/// their backbone's peak (gain −8.9 on such an OpenSees campaign; 0.97 with
/// it freed, uForce found 0.096). Explored from the start, it left a six-dimensional
/// design too sparse to find the valley (gain −2.3).
///
/// The transverse onset is the joints' first backbone force across their
/// member over the baseline's peak transverse connection force, on the
/// axial onset's prior: a cross tee shaken across its axis works its tab in
/// the slot as one pulled along it does, and a joint's strength either way
/// is its own (the seed tested pull-out alone). At its prior's top the
/// transverse springs stay the baseline's up to the calibration runs'
/// demand, so the class holds axial hysteresis alone; at the axial onset's
/// top, transverse alone.
const PRIORS: [Prior; 5] = [
    Prior { name: "yield_over_demand", unit: "-", low: 0.1, high: 1.5, log: true, reference: None },
    Prior {
        name: "transverse_yield_over_demand",
        unit: "-",
        low: 0.1,
        high: 1.5,
        log: true,
        reference: None,
    },
    Prior {
        name: "conn_stiffness_factor",
        unit: "-",
        low: 0.2,
        high: 5.0,
        log: true,
        reference: None,
    },
    Prior {
        name: "conn_reload_force",
        unit: "-",
        low: 0.05,
        high: 0.8,
        log: false,
        reference: None,
    },
    Prior {
        name: "conn_unload_shift",
        unit: "-",
        low: -0.3,
        high: 0.3,
        log: false,
        reference: Some(0.0),
    },
];

impl Effect for ConnectionHysteresis {
    fn name(&self) -> &'static str {
        "connection-hysteresis"
    }

    fn explain(&self) -> &'static str {
        "the grid connections soften, yield and pinch"
    }

    fn priors(&self) -> &'static [Prior] {
        &PRIORS
    }

    fn onset(&self) -> &'static str {
        "yield_over_demand"
    }

    fn add_to(&self, o: ModelOptions) -> ModelOptions {
        ModelOptions { connections: Connections::Pinching4, ..o }
    }

    fn model_parameter_names(&self) -> &'static [&'static str] {
        &["conn_force_scale", "conn_disp_scale"]
    }

    fn model_parameters(
        &self,
        name: &str,
        value: f64,
        other: &[(&str, f64)],
        demand: &Demand,
    ) -> Option<Vec<(&'static str, f64)>> {
        let of = |n: &str| other.iter().find(|(m, _)| *m == n).map(|(_, v)| *v);
        // A joint's first backbone force at `value` times its peak force
        // `peak_n`, its first slope `conn_stiffness_factor` times the held
        // spring `spring` (N/mm): (force scale, deformation scale) of CJS-A.
        let scales = |peak_n: f64, spring: &str| {
            let force = (value * peak_n / CJS_A_FIRST_FORCE_N).max(FLOOR);
            let k = of("conn_stiffness_factor").unwrap_or(1.0);
            let held = of(spring).unwrap_or_else(|| {
                fe::generator::param_info(spring).map_or(f64::NAN, |p| p.midpoint())
            });
            (force, force * CJS_A_INITIAL_N_PER_MM / (k * held))
        };
        match name {
            "yield_over_demand" => {
                let (force, disp) = scales(demand.connection_n, "K_cc1");
                Some(vec![
                    ("conn_force_scale", force),
                    ("conn_disp_scale", disp),
                    ("conn_compression_ratio", SYMMETRIC_FIRST_SLOPE),
                ])
            }
            "transverse_yield_over_demand" => {
                if demand.connection_transverse_n.is_nan() || demand.connection_transverse_n <= 0.0
                {
                    // No joint is loaded across: the springs stay elastic.
                    return Some(vec![]);
                }
                let (force, disp) = scales(demand.connection_transverse_n, "K_cc2");
                Some(vec![
                    ("conn_transverse_force_scale", force),
                    ("conn_transverse_disp_scale", disp),
                ])
            }
            // Acts through the yield forces' displacement scales above.
            "conn_stiffness_factor" => Some(vec![]),
            "conn_reload_force" => Some(vec![("conn_reload_force", value)]),
            "conn_unload_shift" => Some(vec![("conn_unload_shift", value)]),
            _ => None,
        }
    }

    /// Freed in the main local search, the unloading force left its six
    /// dimensions too few steps: a weak hysteresis campaign fell back to
    /// `none`, a strong one gained −0.06.
    fn late_parameters(&self) -> &'static [&'static str] {
        &["conn_unload_shift"]
    }

    fn linear_part(&self) -> Option<LinearPart> {
        Some(LinearPart {
            onset: self.onset(),
            also_beyond: &["transverse_yield_over_demand"],
            linear: &["conn_stiffness_factor"],
            nesting: &[1.0],
        })
    }

    fn has_place(&self, _boundary: Boundary) -> bool {
        true
    }

    fn damped_nonlinear_springs(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fe::generator::connections::{cjs_a, set_compression_ratio};
    use fe::materials::{build, MaterialSpec};

    /// Below its first backbone point the class's joint is the baseline's
    /// elastic K_cc1 × `conn_stiffness_factor` in tension and compression
    /// alike, whatever the onset: the class nests the baseline.
    #[test]
    fn the_joint_starts_as_the_baselines_spring_both_ways() {
        let demand = Demand {
            perimeter_mm: 1.0,
            perimeter_n: 10.0,
            connection_n: 90.0,
            connection_transverse_n: 12.0,
            nominal_gap_mm: 19.0,
        };
        let onsets = [
            ("yield_over_demand", "conn_force_scale", "conn_disp_scale", 780.0, 90.0),
            (
                "transverse_yield_over_demand",
                "conn_transverse_force_scale",
                "conn_transverse_disp_scale",
                95.0,
                12.0,
            ),
        ];
        for (onset_name, force, disp, spring, peak_n) in onsets {
            for (onset, factor) in [(0.3, 1.0), (1.2, 1.0), (0.5, 2.5)] {
                let other = [("conn_stiffness_factor", factor), ("K_cc1", 780.0), ("K_cc2", 95.0)];
                let set = ConnectionHysteresis
                    .model_parameters(onset_name, onset, &other, &demand)
                    .unwrap();
                let value = |n: &str| set.iter().find(|(m, _)| *m == n).unwrap().1;
                let mut spec = cjs_a(value(force), value(disp));
                // The axial onset makes both joints symmetric below their first point.
                set_compression_ratio(&mut spec, SYMMETRIC_FIRST_SLOPE);
                assert!((spec.ePf[0] / (onset * peak_n) - 1.0).abs() < 1e-12, "{onset_name}");
                let mut joint = build(&MaterialSpec::Pinching4(Box::new(spec.clone()))).unwrap();
                let k = spring * factor;
                for d_mm in [0.2, -0.2].map(|s| s * spec.ePd[0]) {
                    let (force_n, tangent) = joint.trial(d_mm).unwrap();
                    assert!(
                        (tangent / k - 1.0).abs() < 1e-9,
                        "{onset} {factor}: {tangent} at {d_mm}"
                    );
                    assert!((force_n / (k * d_mm) - 1.0).abs() < 1e-9, "{force_n} at {d_mm}");
                }
            }
        }
        let axial =
            ConnectionHysteresis.model_parameters("yield_over_demand", 0.5, &[], &demand).unwrap();
        assert!(axial.contains(&("conn_compression_ratio", SYMMETRIC_FIRST_SLOPE)));
    }

    /// A campaign that loads no joint across leaves the transverse springs
    /// the baseline's, whatever the transverse onset.
    #[test]
    fn no_transverse_demand_no_transverse_joint() {
        let demand = Demand {
            perimeter_mm: 1.0,
            perimeter_n: 10.0,
            connection_n: 90.0,
            connection_transverse_n: 0.0,
            nominal_gap_mm: 19.0,
        };
        let set = ConnectionHysteresis.model_parameters(
            "transverse_yield_over_demand",
            0.2,
            &[],
            &demand,
        );
        assert_eq!(set, Some(vec![]));
    }
}
