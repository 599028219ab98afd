//! The linear part of a calibrated extension ([`super::cause::Cause::linear_part`]): the
//! extension with its onset held beyond the calibration runs' reach,
//! recalibrated over the baseline's parameters and the extension's own that
//! act before the onset (the connections' initial stiffness). An extension
//! names its physics only where it beats its linear part: a gain that a
//! linear change of the model (a softer connection making up for a grid that
//! is stiffer than assumed) gives as well is no evidence of the
//! nonlinearity.

use super::calibrate::{evaluate_points, Budget, Calibration, Scale, Search};
use super::cause::LinearPart;
use super::executor::{ExecutorError, FeExecutor};
use crate::bundle::Bundle;

/// Calibrates the linear part of the extension calibrated in `ext` on runs
/// `runs` (weights `n_eff`): a Levenberg–Marquardt search of `local / 2` FE
/// runs from the better of two starts, both with the onset at the top of its
/// prior: the extension's estimate, and the baseline's estimate `base`
/// (unit cube) with the linear parameters where they make the baseline
/// ([`nested_start`]), so that the linear part is a true rival of the
/// baseline too (from the extension's estimate alone it ended 6 and 93 nats
/// above the baseline on two null campaigns). None when the extension has
/// no linear part or no estimate. `progress` hears the FE points spent.
#[allow(clippy::too_many_arguments)] // each a different input of one calibration
pub fn calibrate_linear_part(
    bundle: &Bundle,
    ext: &Calibration,
    base: &[f64],
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
    let beyond: Vec<usize> =
        std::iter::once(onset).chain(part.also_beyond.iter().filter_map(|n| index(n))).collect();
    let n_base = ext.n_base();
    let linear: Vec<usize> =
        (0..n_base).chain(part.linear.iter().filter_map(|n| index(n))).collect();
    let own = ext.own_parameters();
    let mut from_ext = ext.points[best].u.clone();
    for &i in &beyond {
        from_ext[i] = 1.0;
    }
    let nested = nested_start(ext, &part, base, &from_ext);
    let mut twin = ext.restarted(linear.clone());
    let ev = ext.evaluation(bundle, runs);
    let starts: [Vec<f64>; STARTS] = [from_ext.clone(), nested];
    twin.points = evaluate_points(&ev, &starts, exec)?;
    progress(twin.points.len());
    let start = twin.best(n_eff).map_or(from_ext, |k| twin.points[k].u.clone());
    let mut search = Search { ev: &ev, n_eff, budget, exec, own: &own };
    let spent = twin.points.len();
    let local = budget.local / 2;
    let (_, gn) =
        search.levenberg_marquardt(&mut twin, Scale::Fine, start, &linear, local, &mut |d| {
            progress(d + spent)
        })?;
    twin.gauss_newton = gn;
    Ok(Some(twin))
}

/// Starts the linear part's search is chosen from (one FE run each).
const STARTS: usize = 2;

/// FE runs the linear part plans under `budget`: its starts and its search.
pub fn planned_runs(budget: &Budget) -> usize {
    STARTS + budget.local / 2
}

/// `from` (an extension's point with its onset beyond reach) with the
/// baseline's parameters at the baseline's estimate `base` and the linear
/// part's own at their [`LinearPart::nesting`] values: the baseline, seen
/// through the extension.
pub fn nested_start(ext: &Calibration, part: &LinearPart, base: &[f64], from: &[f64]) -> Vec<f64> {
    let mut u = from.to_vec();
    u[..base.len()].copy_from_slice(base);
    for (name, value) in part.linear.iter().zip(part.nesting) {
        if let Some(i) = ext.priors.iter().position(|p| p.name == *name) {
            u[i] = ext.priors[i].unit(*value).clamp(0.0, 1.0);
        }
    }
    u
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::cause::{baseline_priors, Cause};

    #[test]
    fn the_nested_start_is_the_baseline_seen_through_the_extension() {
        let c = Cause::CONNECTION_HYSTERESIS;
        let priors = c.priors_on(&baseline_priors(&[], false));
        let ext = Calibration {
            cause: c,
            priors: priors.clone(),
            free: vec![],
            points: vec![],
            demand: None,
            gauss_newton: None,
            committed_share: 0.0,
        };
        let part = c.linear_part().unwrap();
        let from = vec![0.9; priors.len()];
        let u = nested_start(&ext, &part, &[0.2, 0.3], &from);
        let k = priors.iter().position(|p| p.name == "conn_stiffness_factor").unwrap();
        assert_eq!(&u[..2], &[0.2, 0.3]);
        assert!((priors[k].at(u[k]) - 1.0).abs() < 1e-12);
        let others = (2..priors.len()).filter(|i| *i != k);
        assert!(others.map(|i| u[i]).all(|v| v == 0.9));
    }
}
