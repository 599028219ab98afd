//! The lower-damping path of an extension whose physics dissipates energy
//! (connection hysteresis). The baseline puts the dissipation it misses
//! into viscous damping (a strong-hysteresis OpenSees campaign: 0.078
//! against a true 0.04), and an extension explored at the baseline's
//! damping stops in a basin that keeps it. The second path explores the
//! damping below the baseline's estimate with the extension's own
//! parameters, and the better end of the two paths is kept.
//!
//! The path costs about 50 FE runs of the most expensive variant, so by
//! default it is taken only where the extension contends for the verdict
//! ([`DampingPathUse::WhenContending`]): its first path ended within
//! [`CONTENTION_NATS`] of the best variant calibrated before it, in a
//! campaign that is not large ([`super::campaign_size::LARGE_WORK`]).

use super::calibrate::{proposals, Budget, Calibration, Scale, Search, SearchEnd};
use super::campaign_size::SizeTrims;
use super::executor::ExecutorError;
use super::fit::DAMPING_RATIO;
use crate::design::draw;
use crate::study::DesignMethod;

/// When an extension with three or more parameters of its own takes the
/// lower-damping path (`--damping-path never|auto|always`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum DampingPathUse {
    /// Never.
    Never,
    /// When its first path ended within [`CONTENTION_NATS`] of the lowest
    /// −log L of the variants calibrated before it and the campaign is not
    /// large ([`SizeTrims::contending_damping_path`]).
    #[default]
    #[value(
        name = "auto",
        help = "When its first path ends within 1000 nats of the best variant before it, \
                in a campaign that is not large"
    )]
    WhenContending,
    /// Always.
    Always,
}

/// −log L within which an extension's first path contends with the best
/// variant calibrated before it: the path has improved a contending
/// hysteresis fit by up to 660 nats (OpenSees and ceilfarm campaigns), so
/// an extension 1000 nats behind the leader is not expected to overtake
/// it; in pounding campaigns hysteresis trails by 170 to 6800 nats.
pub const CONTENTION_NATS: f64 = 1000.0;

impl DampingPathUse {
    /// Whether an extension whose first path reached −log L `own` takes
    /// the path, the best variant before it having reached `rival`, in a
    /// campaign trimmed by `trims`.
    pub fn takes(self, own: f64, rival: f64, trims: &SizeTrims) -> bool {
        match self {
            DampingPathUse::Never => false,
            DampingPathUse::Always => true,
            DampingPathUse::WhenContending => {
                own <= rival + CONTENTION_NATS && trims.contending_damping_path
            }
        }
    }
}

/// What the lower-damping path of an extension needs from its calibration.
pub(super) struct DampingPath<'p> {
    /// Where the exploration holds the parameters it does not vary.
    pub(super) held: &'p [f64],
    /// The extension's explored dimensions.
    pub(super) explored: &'p [usize],
    /// Every dimension (the final search's).
    pub(super) all: &'p [usize],
}

impl DampingPath<'_> {
    /// FE runs the path plans: a design over the damping and the `d`
    /// explored dimensions, its emulator rounds and a local search.
    pub(super) fn runs(budget: &Budget, d: usize) -> usize {
        budget.per_dim * (d + 1) + budget.extra + budget.rounds * budget.per_round + budget.local
    }
}

impl Search<'_, '_> {
    /// A maximin design over the damping between its prior's low end and
    /// the baseline's estimate and the explored dimensions, emulator rounds
    /// (the emulator over every point so far), then the local search from
    /// the best point of this path. Returns its end and Gauss–Newton matrix
    /// (None when nothing on the path simulated).
    pub(super) fn damping_path(
        &mut self,
        cal: &mut Calibration,
        path: &DampingPath<'_>,
        progress: &mut dyn FnMut(usize),
    ) -> Result<Option<SearchEnd>, ExecutorError> {
        let Some(damping) = cal.priors.iter().position(|p| p.name == DAMPING_RATIO) else {
            return Ok(None);
        };
        let (budget, n_eff, own) = (self.budget, self.n_eff, cal.free.clone());
        let dims: Vec<usize> =
            std::iter::once(damping).chain(path.explored.iter().copied()).collect();
        let put = |x: &[f64], top: f64| {
            let mut v = path.held.to_vec();
            dims.iter().zip(x).for_each(|(j, x)| v[*j] = *x);
            v[damping] *= top;
            v
        };
        let n = budget.per_dim * dims.len() + budget.extra;
        let design = draw(DesignMethod::MaximinLhs, n, dims.len(), budget.seed + 7);
        let us: Vec<Vec<f64>> =
            (0..design.n()).map(|i| put(design.row(i), path.held[damping])).collect();
        let first = cal.points.len();
        self.evaluate_into(cal, &us, progress)?;
        let best = |cal: &Calibration| {
            let f = cal.objective(n_eff);
            (first..cal.points.len())
                .filter(|k| f[*k].is_finite())
                .min_by(|a, b| f[*a].total_cmp(&f[*b]))
        };
        cal.free = dims.clone();
        for round in 0..budget.rounds {
            let Some(gp) = cal.emulator(n_eff) else { break };
            let at =
                best(cal).map(|k| dims.iter().map(|i| cal.points[k].u[*i]).collect::<Vec<_>>());
            let seed = budget.seed + 100 + round as u64;
            let next = proposals(&gp, dims.len(), at.as_deref(), budget.per_round, seed);
            let next: Vec<Vec<f64>> = next.iter().map(|x| put(x, 1.0)).collect();
            self.evaluate_into(cal, &next, progress)?;
        }
        cal.free = own;
        let Some(k) = best(cal) else { return Ok(None) };
        let from = cal.points[k].u.clone();
        let end =
            self.levenberg_marquardt(cal, Scale::Fine, from, path.all, budget.local, progress)?;
        Ok(Some(end))
    }
}

#[cfg(test)]
mod tests {
    use super::super::campaign_size::LARGE_WORK;
    use super::*;

    #[test]
    fn the_path_is_taken_by_a_contending_extension_only() {
        let (rival, small) = (-10_000.0, &SizeTrims::for_work(72_000.0));
        let auto = DampingPathUse::WhenContending;
        assert!(auto.takes(rival - 50.0, rival, small));
        assert!(auto.takes(rival + 0.5 * CONTENTION_NATS, rival, small));
        assert!(!auto.takes(rival + 2.0 * CONTENTION_NATS, rival, small));
        assert!(DampingPathUse::Always.takes(rival + 1e6, rival, small));
        assert!(!DampingPathUse::Never.takes(rival - 1e6, rival, small));
        // Nothing before it (infinite rival): it contends.
        assert!(auto.takes(rival, f64::INFINITY, small));
    }

    #[test]
    fn a_large_campaign_takes_the_path_only_when_asked() {
        let rival = -10_000.0;
        let large = &SizeTrims::for_work(2.0 * LARGE_WORK);
        let small = &SizeTrims::for_work(LARGE_WORK);
        assert!(!DampingPathUse::WhenContending.takes(rival - 50.0, rival, large));
        assert!(DampingPathUse::WhenContending.takes(rival - 50.0, rival, small));
        assert!(DampingPathUse::Always.takes(rival - 50.0, rival, large));
    }
}
