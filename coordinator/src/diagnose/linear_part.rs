//! The linear part of a calibrated extension ([`super::cause::Cause::linear_part`]): the
//! extension with its onset held beyond the calibration runs' reach,
//! recalibrated over the baseline's parameters and the extension's own that
//! act before the onset (the connections' initial stiffness). An extension
//! names its physics only where it beats its linear part: a gain that a
//! linear change of the model (a softer connection making up for a grid that
//! is stiffer than assumed) gives as well is no evidence of the
//! nonlinearity.

use super::calibrate::{Budget, Calibration, Scale, Search};
use super::executor::{ExecutorError, FeExecutor};
use crate::bundle::Bundle;

/// Calibrates the linear part of the extension calibrated in `ext` on runs
/// `runs` (weights `n_eff`): a Levenberg–Marquardt search of `local / 2` FE
/// runs from the extension's estimate with its onset at the top of its
/// prior. None when the extension has no linear part or no estimate.
/// `progress` hears the FE points the search has spent.
pub fn calibrate_linear_part(
    bundle: &Bundle,
    ext: &Calibration,
    runs: &[usize],
    n_eff: &[f64],
    budget: &Budget,
    exec: &mut dyn FeExecutor,
    progress: &mut dyn FnMut(usize),
) -> Result<Option<Calibration>, ExecutorError> {
    let Some(part) = ext.cause.linear_part() else { return Ok(None) };
    let Some(best) = ext.best(n_eff) else { return Ok(None) };
    let index = |name: &str| ext.priors.iter().position(|p| p.name == name);
    let Some(onset) = index(part.onset) else { return Ok(None) };
    let n_base = ext.n_base();
    let linear: Vec<usize> =
        (0..n_base).chain(part.linear.iter().filter_map(|n| index(n))).collect();
    let own = ext.own_parameters();
    let mut start = ext.points[best].u.clone();
    start[onset] = 1.0;
    let mut twin = ext.restarted(linear.clone());
    let ev = ext.evaluation(bundle, runs);
    let mut search = Search { ev: &ev, n_eff, budget, exec, own: &own };
    let local = budget.local / 2;
    let (_, gn) =
        search.levenberg_marquardt(&mut twin, Scale::Fine, start, &linear, local, progress)?;
    twin.gauss_newton = gn;
    Ok(Some(twin))
}
