//! A second look at the extension a diagnosis names. Every variant's
//! calibration ends where a local search stopped, and the time-history
//! likelihood of a slipping, striking or yielding ceiling has narrow,
//! bumpy valleys that finite-difference steps stall in: a perimeter-friction
//! calibration of an OpenSees-simulated campaign stopped at −log L = −4716
//! with the true slip force and hardening 350 nats lower. Searching every
//! variant longer would let extensions fit noise the baseline cannot, so
//! only the one the MDL names gets a ridge walk along each of its shape
//! parameters ([`super::ridge`]) and valley walks
//! ([`Search::valley_walks`]); it is then assessed again.

use super::calibrate::{Budget, Calibration, Scale, Search, SLOPPY_STEPS};
use super::campaign_size::SizeTrims;
use super::executor::{ExecutorError, FeExecutor};
use super::fit::Evaluation;
use crate::bundle::Bundle;

/// Valley walks for a named extension with `own` parameters of its own
/// under `budget` (its walks and its campaign's [`SizeTrims::refine`]):
/// the budget's in a small campaign, at most one in a large one, none for
/// a large one with more than [`LARGE_REFINED_OWN`] own parameters (each
/// walk costs ~20 of its slowest FE runs) or for one parameter (its local
/// search already spans it).
///
/// [`LARGE_REFINED_OWN`]: super::campaign_size::LARGE_REFINED_OWN
pub fn refine_walks(budget: &Budget, own: usize) -> usize {
    match (own, budget.trims.refine) {
        (0..=1, _) => 0,
        (_, None) => budget.refine_walks,
        (o, Some((walks, max_own))) if o <= max_own => budget.refine_walks.min(walks),
        _ => 0,
    }
}

/// Valley walks for the committed-tangent twin ([`super::damping_form`])
/// of a named extension refined with `walks` ([`refine_walks`]): as many
/// in a small campaign; none in a large one ([`SizeTrims::twin_refined`]),
/// where the twin ends with its two local searches and is not refined. The
/// double-layer size check's friction twin spent at least 78 of its 126 FE
/// points on its ridge and valley walks and still ended 300 nats behind
/// the named form, which it must beat by 50; without them the diagnosis
/// took 551 s instead of 590 s.
pub fn twin_walks(walks: usize, trims: &SizeTrims) -> usize {
    if trims.twin_refined {
        walks
    } else {
        0
    }
}

/// FE runs planned for refining an extension with `own` parameters of its
/// own with `walks` valley walks (a walk's probes and a local search of
/// half the budget's), after a ridge walk along each shape parameter at
/// most and its local search.
pub fn planned_runs(budget: &Budget, walks: usize, own: usize) -> usize {
    let ridge = own.saturating_sub(1) * super::ridge::max_runs() + budget.local / 2;
    ridge + walks * (2 * SLOPPY_STEPS.len() + budget.local / 2)
}

/// Continues the calibration `cal` of an extension on `runs` from its best
/// point under `n_eff`: a ridge walk along each of its own parameters but
/// the onset ([`Search::ridge_walks`]) and a local search of
/// `budget.local / 2` FE runs from where it gained, then `walks` valley
/// walks, each followed by a local search as long; `progress` hears the FE
/// points evaluated so far. Returns whether it evaluated any.
#[allow(clippy::too_many_arguments)]
pub fn refine(
    bundle: &Bundle,
    cal: &mut Calibration,
    runs: &[usize],
    n_eff: &[f64],
    budget: &Budget,
    walks: usize,
    exec: &mut dyn FeExecutor,
    progress: &mut dyn FnMut(usize),
) -> Result<bool, ExecutorError> {
    let (Some(best), Some(gn)) = (cal.best(n_eff), cal.gauss_newton.clone()) else {
        return Ok(false);
    };
    let priors = cal.priors.clone();
    let own = cal.own_parameters();
    let ev = Evaluation {
        bundle,
        cause: cal.cause,
        priors: &priors,
        runs,
        demand: cal.demand,
        committed_share: cal.committed_share,
    };
    let before = cal.points.len();
    let mut start = (cal.points[best].u.clone(), Some(gn));
    let mut search = Search { ev: &ev, n_eff, budget, exec, own: &own };
    let mut report = |done: usize| progress(done - before);
    let onset = cal.cause.onset().and_then(|n| priors.iter().position(|p| p.name == n));
    if let Some(onset) = onset {
        let walked = search.ridge_walks(cal, &start.0, onset, &mut report)?;
        trace(cal, n_eff, walked.as_deref().unwrap_or(&start.0), "ridge walks");
        if let Some(from) = walked {
            let all: Vec<usize> = (0..priors.len()).collect();
            let local = budget.local / 2;
            let (u, gn) =
                search.levenberg_marquardt(cal, Scale::Fine, from, &all, local, &mut report)?;
            start = (u, gn.or(start.1));
            trace(cal, n_eff, &start.0, "local search after the ridge walks");
        }
    }
    let (end, gn) = search.valley_walks(cal, start, walks, budget.local / 2, &mut report)?;
    trace(cal, n_eff, &end, "valley walks");
    cal.gauss_newton = gn;
    Ok(cal.points.len() > before)
}

/// Logs (debug) where a refinement stage left the search.
fn trace(cal: &Calibration, n_eff: &[f64], u: &[f64], stage: &str) {
    let f = super::calibrate::point_value(cal, u, n_eff);
    let fe_points = cal.points.len();
    tracing::debug!(cause = cal.cause.as_str(), stage, fe_points, neg_log_lik = f, ?u);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::campaign_size::LARGE_WORK;

    #[test]
    fn walks_by_campaign_size_and_own_parameters() {
        let at = |work: f64| Budget {
            refine_walks: 2,
            trims: SizeTrims::for_work(work),
            ..Budget::default()
        };
        let (small, large) = (at(LARGE_WORK), at(2.0 * LARGE_WORK));
        // Friction and pounding (two own parameters), hysteresis (three).
        assert_eq!(refine_walks(&small, 2), 2);
        assert_eq!(refine_walks(&small, 3), 2);
        assert_eq!(refine_walks(&large, 2), 1);
        assert_eq!(refine_walks(&large, 3), 0);
        // One parameter: its local search already spans it.
        assert_eq!(refine_walks(&small, 1), 0);
        // The budget's zero turns refining off everywhere.
        let off = |b: Budget| Budget { refine_walks: 0, ..b };
        assert_eq!(refine_walks(&off(small), 2) + refine_walks(&off(large), 2), 0);
    }

    #[test]
    fn the_twin_is_refined_as_the_named_extension_only_in_a_small_campaign() {
        let (small, large) =
            (SizeTrims::for_work(LARGE_WORK), SizeTrims::for_work(2.0 * LARGE_WORK));
        assert_eq!(twin_walks(2, &small), 2);
        assert_eq!(twin_walks(0, &small), 0);
        assert_eq!(twin_walks(1, &large), 0);
    }

    #[test]
    fn planned_runs_count_the_ridge_walks_and_probes_and_a_half_local_search_per_walk() {
        let b = Budget { local: 24, ..Budget::default() };
        let ridge = crate::diagnose::ridge::max_runs();
        assert_eq!(planned_runs(&b, 2, 2), ridge + 12 + 2 * (8 + 12));
        assert_eq!(planned_runs(&b, 0, 3), 2 * ridge + 12);
    }
}
