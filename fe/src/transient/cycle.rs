//! Detecting Newton iterations that cycle: on springs that are piecewise
//! linear in their deformation an iteration that returns to an earlier
//! iteration's tangents never converges ([`TangentHistory`]). Tangents in
//! N/mm.

use super::newton::NewtonFailure;

/// The springs' tangents (beyond the initial ones) at each Newton
/// iteration of a step. On springs that are piecewise linear in their
/// deformation (Pinching4, Steel01, contacts; the committed-tangent damping
/// is linear in it) a Newton iterate is fixed by the pieces its predecessor
/// lay on, so an iteration that leaves the last one's tangents for an
/// earlier one's (staying on the last one's pieces is convergence) starts
/// a cycle that never converges. Failing then, rather than after the
/// iteration limit, leaves the step to be subdivided as before: on a 6 m x
/// 4.8 m sweep with 126 Pinching4 connections damped on their committed
/// tangent, every one of its 60 steps that repeated tangents (at iteration
/// 4 to 8) ran to the 50-iteration limit.
#[derive(Default)]
pub struct TangentHistory {
    seen: Vec<Vec<f64>>,
}

impl TangentHistory {
    /// Records iteration `it`'s tangents `delta`; fails when they differ
    /// from the last iteration's and equal an earlier one's.
    pub fn record(&mut self, it: usize, delta: &[f64]) -> Result<(), NewtonFailure> {
        if self.seen.last().is_some_and(|d| d != delta) {
            if let Some(k) = self.seen.iter().position(|d| d == delta) {
                return Err(NewtonFailure::Cycling { iteration: it, earlier: k + 1 });
            }
        }
        self.seen.push(delta.to_vec());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Tangents that leave the last iteration's for an earlier one's
        /// fail with that iteration named; staying on the last one's, or
        /// new ones, do not.
        #[test]
        fn repeated_tangents_before_the_last_iteration_are_a_cycle(
            a in proptest::collection::vec(-1.0..1.0f64, 3),
            b in proptest::collection::vec(-1.0..1.0f64, 3),
        ) {
            prop_assume!(a != b);
            let mut h = TangentHistory::default();
            prop_assert!(h.record(1, &a).is_ok());
            prop_assert!(h.record(2, &a).is_ok());
            prop_assert!(h.record(3, &a).is_ok());
            prop_assert!(h.record(4, &b).is_ok());
            prop_assert!(h.record(5, &b).is_ok());
            prop_assert_eq!(
                h.record(6, &a),
                Err(NewtonFailure::Cycling { iteration: 6, earlier: 1 })
            );
        }
    }
}
