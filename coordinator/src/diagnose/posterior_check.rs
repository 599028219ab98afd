//! The variational posterior checked against the FE model. Its emulator
//! (a Gauss–Newton quadratic plus a GP through the calibration's FE runs)
//! is trained where the calibration searched; between those points the GP
//! can dip below the best FE point and give a mode the FE model does not
//! have. So the FE model runs at q's mean and a few of its draws; where the
//! emulated excess −log L misses the FE's by more than [`TOL_NATS`], those
//! runs join the calibration's points (and so the GP's training set) and
//! BBVI runs again, at most [`ROUNDS`] times (fewer in a large campaign:
//! [`super::campaign_size::LARGE_ROUNDS`]). The posterior reported is the
//! last one checked, with the gap measured at its own probes.

use super::calibrate::{evaluate_points, Calibration};
use super::executor::{ExecutorError, FeExecutor};
use super::posterior::{variational_posterior, EmulatorCheck, VariationalPosterior, CAP_NATS};
use crate::bundle::Bundle;

/// Rounds of FE checks (each [`super::posterior::PROBES`] FE points).
pub const ROUNDS: usize = 3;
/// Largest |FE − emulated| excess −log L at a probe for the emulator to
/// stand (nats): e⁵ ≈ 150 in density.
pub const TOL_NATS: f64 = 5.0;

/// Rounds of FE checks of a campaign trimmed by `trims`
/// ([`super::campaign_size::SizeTrims::check_rounds`]).
pub fn rounds(trims: &super::campaign_size::SizeTrims) -> usize {
    trims.check_rounds.map_or(ROUNDS, |n| n.min(ROUNDS))
}

/// The posterior of `cal` under weights `n_eff`, its emulator checked by
/// FE runs of `runs` of `bundle` through `exec` (which join `cal`'s points)
/// in up to `rounds` rounds.
pub fn checked_posterior(
    cal: &mut Calibration,
    (bundle, runs): (&Bundle, &[usize]),
    n_eff: &[f64],
    (seed, rounds): (u64, usize),
    exec: &mut dyn FeExecutor,
) -> Result<Result<VariationalPosterior, String>, ExecutorError> {
    let mut spent = 0;
    let mut last = None;
    for round in 0..rounds {
        let mut post = match variational_posterior(cal, n_eff, seed + round as u64) {
            Ok(p) => p,
            Err(why) => return Ok(last.ok_or(why)),
        };
        let points = evaluate_points(&cal.evaluation(bundle, runs), &post.probes, exec)?;
        spent += points.len();
        let f0 = post.best_neg_log_lik;
        let fe: Vec<f64> = points.iter().map(|p| p.neg_log_lik(n_eff) - f0).collect();
        let gap = probe_gap(&fe, &post.probe_excess);
        cal.points.extend(points);
        let confirmed = gap <= TOL_NATS;
        post.check = Some(EmulatorCheck { fe_points: spent, gap_nats: gap, confirmed });
        let emulated = &post.probe_excess;
        tracing::debug!(cause = cal.cause.as_str(), round, gap, ?fe, ?emulated, "emulator check");
        if confirmed {
            return Ok(Ok(post));
        }
        last = Some(post);
    }
    Ok(last.ok_or_else(|| "no posterior".to_string()))
}

/// Largest |FE − emulated| excess over the probes, both capped at
/// [`CAP_NATS`] (a failed FE run counts as the cap).
pub fn probe_gap(fe_excess: &[f64], emulated: &[f64]) -> f64 {
    let cap = |v: f64| if v.is_nan() { CAP_NATS } else { v.min(CAP_NATS) };
    fe_excess.iter().zip(emulated).map(|(f, e)| (cap(*f) - cap(*e)).abs()).fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_large_campaign_checks_once() {
        use crate::diagnose::campaign_size::{SizeTrims, LARGE_ROUNDS};
        assert_eq!(rounds(&SizeTrims::for_work(1e5)), ROUNDS);
        assert_eq!(rounds(&SizeTrims::for_work(1e7)), LARGE_ROUNDS);
    }

    #[test]
    fn gap_is_the_largest_capped_difference() {
        assert_eq!(probe_gap(&[1.0, 7.0], &[2.0, 3.0]), 4.0);
        assert_eq!(probe_gap(&[f64::INFINITY], &[90.0]), CAP_NATS - 90.0);
        assert_eq!(probe_gap(&[500.0], &[CAP_NATS]), 0.0);
        assert_eq!(probe_gap(&[f64::NAN], &[0.0]), CAP_NATS);
        assert_eq!(probe_gap(&[], &[]), 0.0);
    }

    #[test]
    fn a_probe_better_than_the_best_counts_too() {
        assert_eq!(probe_gap(&[-3.0], &[2.0]), 5.0);
    }
}
