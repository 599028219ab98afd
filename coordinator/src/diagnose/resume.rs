//! A calibration's local search resumed from a point found after it ended:
//! a second basin's start ([`super::channel_start`]) or an FE check of the
//! class evidence that rose above the calibration's best point
//! ([`super::class_evidence::settled_evidence`]).

use super::calibrate::{point_value, Budget, Calibration, Scale, Search};
use super::executor::{ExecutorError, FeExecutor};
use crate::bundle::Bundle;

/// −log L (the calibration's weights) at its best point before a resumed
/// search and where the search ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resumed {
    /// At the best point before the search.
    pub before: f64,
    /// Where the search ended.
    pub after: f64,
}

/// Runs a Levenberg–Marquardt search of `local` FE runs of `runs` of
/// `bundle` over every parameter of `cal` from `start` (weights `n_eff`) and
/// keeps its points in `cal`; its Gauss–Newton matrix replaces the
/// calibration's when it ended below the best point before it. `progress`
/// hears the FE points the search has spent.
#[allow(clippy::too_many_arguments)] // each a different input of one search
pub fn search_from(
    cal: &mut Calibration,
    start: Vec<f64>,
    (bundle, runs): (&Bundle, &[usize]),
    n_eff: &[f64],
    budget: &Budget,
    local: usize,
    exec: &mut dyn FeExecutor,
    progress: &mut dyn FnMut(usize),
) -> Result<Resumed, ExecutorError> {
    let before = cal.best(n_eff).map_or(f64::INFINITY, |k| cal.objective(n_eff)[k]);
    let all: Vec<usize> = (0..cal.priors.len()).collect();
    // The extension's own parameters take the extension's difference steps.
    let own = cal.own_parameters();
    let mut found = cal.restarted(all.clone());
    let ev = cal.evaluation(bundle, runs);
    let mut search = Search { ev: &ev, n_eff, budget, exec, own: &own };
    let (end, gn) =
        search.levenberg_marquardt(&mut found, Scale::Fine, start, &all, local, progress)?;
    let after = point_value(&found, &end, n_eff);
    cal.points.append(&mut found.points);
    if after < before && gn.is_some() {
        cal.gauss_newton = gn;
    }
    Ok(Resumed { before, after })
}
