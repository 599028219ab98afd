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

use super::calibrate::{Budget, Calibration};
use super::cause::CHANNEL_BEAMS;
use super::executor::{ExecutorError, FeExecutor};
use super::resume::{search_from, Resumed};
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
/// and keeps its points ([`search_from`]). `progress` hears the FE points
/// the search has spent.
pub fn search_seed_section(
    cal: &mut Calibration,
    start: Vec<f64>,
    on: (&Bundle, &[usize]),
    n_eff: &[f64],
    budget: &Budget,
    exec: &mut dyn FeExecutor,
    progress: &mut dyn FnMut(usize),
) -> Result<(), ExecutorError> {
    let start_beams = beams_index(cal).map(|i| start[i]);
    let Resumed { before, after } =
        search_from(cal, start, on, n_eff, budget, budget.local, exec, progress)?;
    tracing::debug!(before, after, ?start_beams, "channels at the seed's section");
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
