//! The damping's form for the named extension. Rayleigh's stiffness term
//! damps each flagged spring in proportion to its initial stiffness (the
//! seed's model, OpenSees `betaKinit`) or to its last committed tangent
//! (`betaKcomm`), which damps a slipping or yielding spring far less and a
//! stiffening one more. Only the extensions' nonlinear springs tell the
//! two apart: the baseline's are elastic. Fitted in the wrong form, slip or
//! yielding takes up the difference: on OpenSees campaigns damped on the
//! committed tangent, friction gained 0.61 to 0.70 and connection
//! hysteresis 0.10 to 0.80, against 0.97 to 1.00 and 0.64 to 0.89 when the
//! whole diagnosis ran in the committed form.
//!
//! So once the named extension is refined, its twin damped on the
//! committed tangent is searched ([`calibrate_committed_twin`], then
//! refined as the extension was); the twin replaces it only when it fits
//! the calibration runs better by more than [`FORM_NATS`]. Both forms have
//! the same parameters, so the fit decides.

use super::calibrate::{point_value, Budget, Calibration, Scale, Search};
use super::campaign_size::SizeTrims;
use super::cause::Cause;
use super::executor::{ExecutorError, FeExecutor};
use super::fit::Evaluation;
use crate::bundle::Bundle;

/// −log L by which the committed-tangent twin must beat the named
/// extension to replace it (nats): the verdict's misfit allowance.
pub const FORM_NATS: f64 = super::pipeline::MISFIT_NATS;

/// Whether the extension `cause` adds springs that are damped and
/// nonlinear (friction and connection springs carry Rayleigh damping;
/// pounding's contacts do not, and the baseline's springs are elastic).
pub fn has_damped_nonlinear_springs(cause: Cause) -> bool {
    cause.has_damped_nonlinear_springs()
}

/// Calibrates the twin of the extension calibrated in `ext`, damped on its
/// springs' committed tangent, on `runs` (weights `n_eff`): Levenberg–
/// Marquardt searches of `budget.local` FE runs each over every parameter,
/// from the extension's estimate and from there with its own parameters at
/// their prior mid-points (in the other form the estimate can sit at a
/// prior's edge far from the twin's optimum: a connection's first force at
/// the bottom where the twin's lay at 0.22 of 0.05..0.8); the Gauss–Newton
/// matrix is the better end's. In a large campaign ([`SizeTrims`]) both
/// starts are run and only the better is searched ([`twin_starts`]). None
/// when the extension has no damped nonlinear springs or no estimate.
/// `progress` hears the FE points the searches have spent.
pub fn calibrate_committed_twin(
    bundle: &Bundle,
    ext: &Calibration,
    runs: &[usize],
    n_eff: &[f64],
    budget: &Budget,
    exec: &mut dyn FeExecutor,
    progress: &mut dyn FnMut(usize),
) -> Result<Option<Calibration>, ExecutorError> {
    if !has_damped_nonlinear_springs(ext.cause) || ext.committed_share > 0.0 {
        return Ok(None);
    }
    let Some(best) = ext.best(n_eff) else { return Ok(None) };
    let all: Vec<usize> = (0..ext.priors.len()).collect();
    let own = ext.own_parameters();
    let mut twin = Calibration { committed_share: 1.0, ..ext.restarted(all.clone()) };
    let ev = Evaluation { committed_share: twin.committed_share, ..ext.evaluation(bundle, runs) };
    let mut search = Search { ev: &ev, n_eff, budget, exec, own: &own };
    let from_estimate = ext.points[best].u.clone();
    let mut from_mid = from_estimate.clone();
    own.iter().for_each(|&i| from_mid[i] = 0.5);
    let mut starts = vec![from_estimate, from_mid];
    if twin_starts(&budget.trims) < starts.len() {
        search.evaluate_into(&mut twin, &starts, progress)?;
        starts = vec![better_start(&twin, starts, n_eff)];
    }
    let mut ends = Vec::new();
    for start in starts {
        let (u, gn) = search.levenberg_marquardt(
            &mut twin,
            Scale::Fine,
            start,
            &all,
            budget.local,
            progress,
        )?;
        ends.push((point_value(&twin, &u, n_eff), gn));
    }
    twin.gauss_newton = ends.into_iter().min_by(|a, b| a.0.total_cmp(&b.0)).and_then(|e| e.1);
    Ok(Some(twin))
}

/// Starts the committed-tangent twin is searched from in a campaign
/// trimmed by `trims`: both in a small campaign, the better of the two in a
/// large one ([`SizeTrims::twin_starts`]). On the double-layer size check
/// with connection hysteresis hidden the twin's two searches had spent 350
/// of the diagnosis's 1290 worker seconds (4.2 s a run) and ended behind
/// the named form.
pub fn twin_starts(trims: &SizeTrims) -> usize {
    trims.twin_starts.map_or(TWIN_STARTS, |n| n.min(TWIN_STARTS))
}

/// Starts the twin may be searched from: the extension's estimate, and
/// there with the extension's own parameters at their prior mid-points.
pub const TWIN_STARTS: usize = 2;

/// The start of `starts` whose evaluation in `twin` fits best under
/// `n_eff` (the first when none was evaluated or all failed).
fn better_start(twin: &Calibration, starts: Vec<Vec<f64>>, n_eff: &[f64]) -> Vec<f64> {
    let value = |u: &Vec<f64>| point_value(twin, u, n_eff);
    let best = (0..starts.len()).min_by(|&a, &b| value(&starts[a]).total_cmp(&value(&starts[b])));
    starts.into_iter().nth(best.unwrap_or(0)).unwrap_or_default()
}

/// Whether `twin` fits better than `ext` under `n_eff` by more than
/// [`FORM_NATS`] (each at its best point).
pub fn twin_wins(ext: &Calibration, twin: &Calibration, n_eff: &[f64]) -> bool {
    let best = |c: &Calibration| c.best(n_eff).map(|k| c.points[k].neg_log_lik(n_eff));
    match (best(ext), best(twin)) {
        (Some(e), Some(t)) => t < e - FORM_NATS,
        (None, Some(_)) => true,
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::calibrate::Point;
    use crate::diagnose::fit::ChannelFit;

    /// A friction calibration with one point per −log L in `nlls` (one
    /// channel, n_eff 2: −log L = log SSR); NaN: a failed simulation.
    fn calibration(nlls: &[f64], committed_share: f64) -> Calibration {
        let cause = Cause::PERIMETER_FRICTION;
        let point = |nll: &f64| Point {
            u: vec![0.5; cause.priors().len()],
            fit: if nll.is_nan() {
                Err("failed".into())
            } else {
                Ok(vec![ChannelFit::with_neg_log_lik(*nll)])
            },
            coarse: 0.0,
            modal: None,
        };
        Calibration {
            cause,
            priors: cause.priors(),
            free: vec![],
            points: nlls.iter().map(point).collect(),
            demand: None,
            gauss_newton: None,
            committed_share,
        }
    }

    #[test]
    fn a_large_campaign_searches_the_twin_from_its_better_start() {
        let mut twin = calibration(&[3.0, 1.0, f64::NAN], 1.0);
        let starts: Vec<Vec<f64>> = [0.2, 0.4, 0.6].iter().map(|x| vec![*x; 4]).collect();
        for (p, u) in twin.points.iter_mut().zip(&starts) {
            p.u = u.clone();
        }
        let n_eff = [2.0];
        assert_eq!(better_start(&twin, starts.clone(), &n_eff), starts[1]);
        assert_eq!(
            better_start(&twin, vec![starts[2].clone(), starts[0].clone()], &n_eff),
            starts[0]
        );
        let large = crate::diagnose::campaign_size::LARGE_WORK;
        assert_eq!(twin_starts(&SizeTrims::for_work(large)), 2);
        assert_eq!(twin_starts(&SizeTrims::for_work(2.0 * large)), 1);
    }

    #[test]
    fn the_twin_must_win_by_more_than_the_allowance_at_each_best_point() {
        let n_eff = [2.0];
        let ext = calibration(&[-10.0, -20.0], 0.0);
        let by = |margin: f64| calibration(&[-20.0 - margin, 0.0], 1.0);
        assert!(twin_wins(&ext, &by(FORM_NATS + 1.0), &n_eff));
        assert!(!twin_wins(&ext, &by(FORM_NATS - 1.0), &n_eff));
        assert!(!twin_wins(&ext, &calibration(&[f64::NAN], 1.0), &n_eff));
        assert!(twin_wins(&calibration(&[f64::NAN], 0.0), &by(0.0), &n_eff));
    }

    #[test]
    fn only_friction_and_connections_have_damped_nonlinear_springs() {
        let with: Vec<Cause> =
            Cause::ALL.into_iter().filter(|c| has_damped_nonlinear_springs(*c)).collect();
        assert_eq!(with, [Cause::PERIMETER_FRICTION, Cause::CONNECTION_HYSTERESIS]);
    }
}
