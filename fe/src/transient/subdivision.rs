//! Step subdivision: when a Newton step fails, the materials are reverted
//! and the step is done as two halves, recursively, down to a depth limit;
//! below it the failure is returned with the time it was reached.
//!
//! Units: s.

use super::excitation::BaseMotion;
use super::newmark::NewmarkConstants;
use super::newton::{Dynamics, Kinematics, NewtonFailure, NewtonSettings, Step};
use super::springs::SpringStates;

/// The mutable state a step advances.
pub struct StepState {
    /// Committed kinematics.
    pub committed: Kinematics,
    /// Work space for the trial kinematics.
    pub trial: Kinematics,
    /// Spring materials.
    pub springs: SpringStates,
}

/// What one (possibly subdivided) step cost.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepCost {
    /// Newton iterations over all sub-steps.
    pub iterations: usize,
    /// Sub-steps done (1 if no subdivision).
    pub substeps: usize,
}

/// A step that failed at the deepest subdivision.
#[derive(Debug, Clone, PartialEq)]
pub struct StepFailure {
    /// Start of the smallest sub-step that failed (s).
    pub t_s: f64,
    /// Its size (s).
    pub dt_s: f64,
    /// Why Newton failed there.
    pub reason: NewtonFailure,
}

/// Subdivision and Newton settings together.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepControl {
    /// Newmark γ.
    pub gamma: f64,
    /// Newmark β.
    pub beta: f64,
    /// Newton settings.
    pub newton: NewtonSettings,
    /// Halvings allowed (0 = no subdivision).
    pub max_halvings: u32,
}

/// Advances the state from `t0_s` by `dt_s`, halving on failure; commits
/// every converged sub-step.
#[allow(clippy::too_many_arguments)]
pub fn advance(
    sys: &mut Dynamics<'_>,
    st: &mut StepState,
    ground: &BaseMotion,
    loads: &[Vec<f64>],
    ctl: &StepControl,
    t0_s: f64,
    dt_s: f64,
    depth: u32,
) -> Result<StepCost, StepFailure> {
    let nm = NewmarkConstants::new(ctl.gamma, ctl.beta, dt_s);
    let ext = external_load(ground, loads, t0_s + dt_s);
    let step = Step { nm: &nm, committed: &st.committed, ext: &ext, settings: &ctl.newton };
    let res = sys.solve_step(&step, &mut st.trial, &mut st.springs);
    match res {
        Ok(iterations) => {
            st.springs.commit();
            std::mem::swap(&mut st.committed, &mut st.trial);
            Ok(StepCost { iterations, substeps: 1 })
        }
        Err(reason) => {
            st.springs.revert();
            if depth >= ctl.max_halvings {
                return Err(StepFailure { t_s: t0_s, dt_s, reason });
            }
            let h = 0.5 * dt_s;
            let a = advance(sys, st, ground, loads, ctl, t0_s, h, depth + 1)?;
            let b = advance(sys, st, ground, loads, ctl, t0_s + h, h, depth + 1)?;
            Ok(StepCost {
                iterations: a.iterations + b.iterations,
                substeps: a.substeps + b.substeps,
            })
        }
    }
}

/// Σ over components of M r_c a_c(t) (N), `loads[c]` being M r_c.
fn external_load(ground: &BaseMotion, loads: &[Vec<f64>], t_s: f64) -> Vec<f64> {
    let n = loads.first().map_or(0, Vec::len);
    let mut ext = vec![0.0; n];
    for (g, load) in ground.components.iter().zip(loads) {
        let ag = g.accel_at(t_s);
        ext.iter_mut().zip(load).for_each(|(e, m)| *e += m * ag);
    }
    ext
}
