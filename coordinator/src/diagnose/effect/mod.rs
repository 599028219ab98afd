//! The effects a model class may add to the baseline, one file each, and
//! their registry. A model class ([`super::cause::Cause`]) is the baseline
//! plus any subset of [`EFFECTS`]; adding an effect is one file here and
//! one line in the registry.

mod friction;
mod hysteresis;
mod pounding;

use super::cause::{Demand, LinearPart, Prior};
use fe::generator::{Boundary, ModelOptions};

pub use friction::PerimeterFriction;
pub use hysteresis::{ConnectionHysteresis, CJS_A_FIRST_FORCE_N};
pub use pounding::PerimeterPounding;

/// One missing physics: its parameters with their priors, how it changes
/// the generated model, and where it switches on relative to the demand.
pub trait Effect: Sync {
    /// The spelling in `diagnosis.json`.
    fn name(&self) -> &'static str;
    /// What the physics is, in a sentence for the report.
    fn explain(&self) -> &'static str;
    /// Priors of its calibrated parameters.
    fn priors(&self) -> &'static [Prior];
    /// The parameter whose value sets where its physics switches on (a
    /// gap, a slip force, a yield force), explored from the start.
    fn onset(&self) -> &'static str;
    /// The model options `o` with this effect's physics added.
    fn add_to(&self, o: ModelOptions) -> ModelOptions;
    /// The FE model parameters that set the strength of the effect (a
    /// synthetic campaign sizes them from its `strength`).
    fn model_parameter_names(&self) -> &'static [&'static str];
    /// The FE model parameters set by its calibrated parameter `name` at
    /// `value` (`other`: every calibrated parameter's value), on the scale of
    /// the baseline's `demand`; None when `name` is not one it maps.
    fn model_parameters(
        &self,
        name: &str,
        value: f64,
        other: &[(&str, f64)],
        demand: &Demand,
    ) -> Option<Vec<(&'static str, f64)>>;
    /// Shape parameters searched only after everything else has converged.
    fn late_parameters(&self) -> &'static [&'static str] {
        &[]
    }
    /// Its linear part, when it has one that differs from the baseline.
    fn linear_part(&self) -> Option<LinearPart> {
        None
    }
    /// Whether the physics can act on a ceiling with this boundary.
    fn has_place(&self, boundary: Boundary) -> bool;
    /// Whether it adds springs that are damped and nonlinear (Rayleigh
    /// damping on their tangent).
    fn damped_nonlinear_springs(&self) -> bool;
}

/// Every registered effect, in the order class names list them. At most
/// eight (a class is a bit set in one byte).
pub static EFFECTS: [&dyn Effect; 3] =
    [&PerimeterPounding, &PerimeterFriction, &ConnectionHysteresis];

/// The floor on a mapped FE parameter (a gap or force of 0 is no model).
pub(crate) const FLOOR: f64 = 1e-6;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_parameters_are_unique_across_the_registry() {
        assert!(EFFECTS.len() <= 8);
        let mut names: Vec<&str> = EFFECTS.iter().map(|e| e.name()).collect();
        let mut params: Vec<&str> =
            EFFECTS.iter().flat_map(|e| e.priors().iter().map(|p| p.name)).collect();
        let (n, k) = (names.len(), params.len());
        names.sort_unstable();
        names.dedup();
        params.sort_unstable();
        params.dedup();
        assert_eq!((names.len(), params.len()), (n, k));
        assert!(names.iter().all(|n| !n.contains('+') && *n != "none"));
    }

    #[test]
    fn every_onset_and_late_parameter_is_an_own_parameter() {
        for e in EFFECTS {
            let own: Vec<&str> = e.priors().iter().map(|p| p.name).collect();
            assert!(own.contains(&e.onset()), "{}", e.name());
            assert!(e.late_parameters().iter().all(|n| own.contains(n)), "{}", e.name());
        }
    }
}
