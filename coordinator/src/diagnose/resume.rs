//! A calibration's local search resumed from a point found after it ended:
//! a second basin's start ([`super::channel_start`]), or the search of the
//! likelihood a class's evidence integrates, from the calibration's best
//! point under it or from an FE check of the evidence that rose above it
//! ([`super::class_evidence::settled_evidence`]).

use super::calibrate::{point_value, Budget, Calibration, Scale, Search, SearchEnd};
use super::executor::{ExecutorError, FeExecutor};
use super::likelihood::{ChannelWeights, LikelihoodKind};
use crate::bundle::Bundle;
use nalgebra::DMatrix;

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
    data: (&Bundle, &[usize]),
    n_eff: &[f64],
    budget: &Budget,
    local: usize,
    exec: &mut dyn FeExecutor,
    progress: &mut dyn FnMut(usize),
) -> Result<Resumed, ExecutorError> {
    let before = cal.best(n_eff).map_or(f64::INFINITY, |k| cal.objective(n_eff)[k]);
    let climb = Climb { scale: Scale::Fine, weights: n_eff, budget, local };
    let (end, gn) = climb.run(cal, start, data, exec, progress)?;
    let after = point_value(cal, &end, n_eff);
    if after < before && gn.is_some() {
        cal.gauss_newton = gn;
    }
    Ok(Resumed { before, after })
}

/// The local search of the likelihood a class's evidence integrates
/// (`kind` under the diagnosis's weights `w`), `local` FE runs from
/// `start` over every parameter of `cal`, its points kept in `cal`: its
/// Gauss–Newton matrix of −ln L (unit cube) where it ended (None when no
/// centre could be linearised). The time likelihood climbs the time
/// histories; the band and Whittle likelihoods the band-passed ones under
/// the band's weights (Whittle's own curvature is not a Gauss–Newton form:
/// the band's stands for it). The calibration's own Gauss–Newton matrix
/// (the time likelihood's) is left as it was.
pub fn peak_search(
    cal: &mut Calibration,
    start: Vec<f64>,
    data: (&Bundle, &[usize]),
    (kind, w): (LikelihoodKind, ChannelWeights<'_>),
    budget: &Budget,
    local: usize,
    exec: &mut dyn FeExecutor,
) -> Result<Option<DMatrix<f64>>, ExecutorError> {
    let (scale, weights) = match kind {
        LikelihoodKind::Time => (Scale::Fine, w.n_eff),
        LikelihoodKind::Band | LikelihoodKind::Whittle => (Scale::Band, w.band_dof),
    };
    let climb = Climb { scale, weights, budget, local };
    Ok(climb.run(cal, start, data, exec, &mut |_| {})?.1)
}

/// One Levenberg–Marquardt search over every parameter of a calibration.
struct Climb<'c> {
    /// The residuals it fits.
    scale: Scale,
    /// Their channel weights.
    weights: &'c [f64],
    /// The calibration budget (difference steps).
    budget: &'c Budget,
    /// FE runs it may spend.
    local: usize,
}

impl Climb<'_> {
    /// Searches `cal` from `start`, keeping its points in `cal`; where it
    /// ended and its Gauss–Newton matrix there.
    fn run(
        &self,
        cal: &mut Calibration,
        start: Vec<f64>,
        (bundle, runs): (&Bundle, &[usize]),
        exec: &mut dyn FeExecutor,
        progress: &mut dyn FnMut(usize),
    ) -> Result<SearchEnd, ExecutorError> {
        let all: Vec<usize> = (0..cal.priors.len()).collect();
        // The extension's own parameters take the extension's difference steps.
        let own = cal.own_parameters();
        let mut found = cal.restarted(all.clone());
        let ev = cal.evaluation(bundle, runs);
        let (n_eff, budget) = (self.weights, self.budget);
        let mut search = Search { ev: &ev, n_eff, budget, exec, own: &own };
        let end = search
            .levenberg_marquardt(&mut found, self.scale, start, &all, self.local, progress)?;
        cal.points.append(&mut found.points);
        Ok(end)
    }
}
