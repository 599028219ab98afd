//! A second start of the double-layer baseline's local search, at the
//! seed's channel section (beam factor 1, [`super::cause::CHANNEL_BEAMS`]),
//! when the first search ended in the lower half of the factor. Channels
//! that only hang from the rods and channels joined to every main tee they
//! cross are two basins of −log L, and a design of 22 points over four
//! parameters lands in one of them: a campaign with the seed's channels
//! hidden had its baseline stop at beam factor 0, 1270 nats above a point
//! with the beams at 0.67, and every extension then explored from the wrong
//! basin. A search that ended in the upper half is already in the seed's
//! basin and is not repeated: the second search costs 24 FE runs, and the
//! largest campaigns are near the time goal without them.

use super::calibrate::{point_value, Budget, Calibration, Scale, Search};
use super::cause::CHANNEL_BEAMS;
use super::executor::{ExecutorError, FeExecutor};
use crate::bundle::Bundle;

/// Index of the beam factor among the priors of `cal` (None: not calibrated).
fn beams_index(cal: &Calibration) -> Option<usize> {
    cal.priors.iter().position(|p| p.name == CHANNEL_BEAMS.name)
}

/// The start of the second search: the best point of `cal` under weights
/// `n_eff` with the beam factor at the seed's section (1). None when `cal`
/// does not calibrate the beams, has no best point, or has it in the upper
/// half of the factor.
pub fn seed_section_start(cal: &Calibration, n_eff: &[f64]) -> Option<Vec<f64>> {
    let i = beams_index(cal)?;
    let mut u = cal.points[cal.best(n_eff)?].u.clone();
    if u[i] >= 0.5 {
        return None;
    }
    u[i] = CHANNEL_BEAMS.unit(1.0);
    Some(u)
}

/// Runs a Levenberg–Marquardt search of `budget.local` FE runs of `runs` of
/// `bundle` over every parameter of `cal` from `start` ([`seed_section_start`])
/// and keeps its points; its Gauss–Newton matrix replaces the calibration's
/// when it ended below the best point before it. `progress` hears the FE
/// points the search has spent.
pub fn search_seed_section(
    cal: &mut Calibration,
    start: Vec<f64>,
    (bundle, runs): (&Bundle, &[usize]),
    n_eff: &[f64],
    budget: &Budget,
    exec: &mut dyn FeExecutor,
    progress: &mut dyn FnMut(usize),
) -> Result<(), ExecutorError> {
    let before = cal.best(n_eff).map_or(f64::INFINITY, |k| cal.objective(n_eff)[k]);
    let all: Vec<usize> = (0..cal.priors.len()).collect();
    let mut found = cal.restarted(all.clone());
    let ev = cal.evaluation(bundle, runs);
    let mut search = Search { ev: &ev, n_eff, budget, exec, own: &all };
    let (end, gn) =
        search.levenberg_marquardt(&mut found, Scale::Fine, start, &all, budget.local, progress)?;
    let after = point_value(&found, &end, n_eff);
    let end_beams = beams_index(cal).map(|i| end[i]);
    tracing::debug!(before, after, ?end_beams, "channels at the seed's section");
    cal.points.append(&mut found.points);
    if after < before && gn.is_some() {
        cal.gauss_newton = gn;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::calibrate::Point;
    use crate::diagnose::cause::{baseline_priors, Cause};
    use crate::diagnose::fit::ChannelFit;

    fn channel_cal(beams_u: f64) -> Calibration {
        let priors = baseline_priors(&[], true);
        let u = vec![0.3, 0.4, 0.5, beams_u];
        Calibration {
            cause: Cause::NONE,
            priors,
            free: vec![0, 1, 2, 3],
            points: vec![Point {
                u,
                fit: Ok(vec![ChannelFit::with_neg_log_lik(10.0)]),
                coarse: 0.0,
                modal: None,
            }],
            demand: None,
            gauss_newton: None,
            committed_share: 0.0,
        }
    }

    #[test]
    fn a_search_that_ended_low_starts_again_at_the_seed_section() {
        let n_eff = [2.0];
        let start = seed_section_start(&channel_cal(0.1), &n_eff);
        assert_eq!(start, Some(vec![0.3, 0.4, 0.5, 1.0]));
    }

    #[test]
    fn a_search_that_ended_high_is_not_repeated() {
        assert_eq!(seed_section_start(&channel_cal(0.5), &[2.0]), None);
        assert_eq!(seed_section_start(&channel_cal(0.8), &[2.0]), None);
    }

    #[test]
    fn a_baseline_without_beams_has_no_second_start() {
        let mut cal = channel_cal(0.1);
        cal.priors = baseline_priors(&[], false);
        cal.points[0].u.truncate(2);
        assert_eq!(seed_section_start(&cal, &[2.0]), None);
    }
}
