//! How much FE work one parameter point of a campaign costs, and what a
//! large campaign trims ([`SizeTrims`]): the longer search of an extension
//! with three parameters of its own and its lower-damping path
//! ([`super::calibrate`]), the committed-tangent twin's second start and
//! its refinement ([`super::damping_form`], [`super::refine`]), the named
//! extension's valley walks, the posterior's FE-check rounds
//! ([`super::posterior_check`]) and, in the largest, the damping's mass
//! share ([`super::damping_share`]), so that a diagnosis of a 6 m x 4.8 m
//! ceiling with three 30 s runs stays near 10 minutes on two cores. The
//! trims are decided here once, from the campaign's work, and carried in
//! the budget ([`super::calibrate::Budget::trims`]): no stage branches on
//! the campaign's size itself.

use crate::bundle::Bundle;

/// Largest [`campaign_work`] that is not large. A 6 m x 4.8 m campaign
/// calibrated on two 30 s runs at 200 Hz (960 000) spent 430 s of its
/// diagnosis's 780 s wall time on 2 cores in connection hysteresis's first
/// path, which the lower-damping path lengthened by 300 s; the 3.6 m x
/// 3.6 m campaigns of 4 and 6 s runs the full stages were measured on are
/// 72 000.
pub const LARGE_WORK: f64 = 250_000.0;

/// FE work of simulating one parameter point of a campaign, in grid
/// module-samples: modules of the ceiling's plan (every layer) times the
/// samples of calibration runs `runs` of `bundle`.
pub fn campaign_work(bundle: &Bundle, runs: &[usize]) -> f64 {
    let s = &bundle.manifest.structure;
    let per_side = |l: f64| (l / s.module_m).round().max(1.0);
    let modules = per_side(s.length_x_m) * per_side(s.length_y_m) * f64::from(s.layers.max(1));
    let samples: usize =
        runs.iter().filter_map(|r| bundle.runs.get(*r)).map(|r| r.n_samples()).sum();
    modules * samples as f64
}

/// Largest [`campaign_work`] whose diagnosis searches the damping's mass
/// share: twice [`LARGE_WORK`], so that a 4.8 m x 4.8 m double-layer
/// ceiling calibrated on 8 and 12 s at 100 Hz (256 000) and a
/// single-layer 3.6 m x 3.6 m one on two 30 s runs at 200 Hz (432 000) get
/// it, and the 6 m x 4.8 m double-layer size check (1 920 000, about 3.3 s
/// of a worker a point), near its 10 minutes, does not.
pub const SHARE_MAX_WORK: f64 = 2.0 * LARGE_WORK;

/// Rounds of the posterior's FE checks in a large campaign, whose FE runs
/// are the slowest: on a 6 m x 4.8 m double-layer campaign with three 30 s
/// runs at 200 Hz, three rounds took 54 of its 610 s and each ended 98 to
/// 168 nats off.
pub const LARGE_ROUNDS: usize = 1;

/// Most own parameters a named extension of a large campaign may have to
/// be refined at all (each valley walk costs ~20 of its slowest FE runs):
/// as many as get two coarse starts
/// ([`COARSE_MAX_DIMS`](super::calibrate::COARSE_MAX_DIMS)).
pub const LARGE_REFINED_OWN: usize = 2;

/// What a campaign's size trims, decided once from its FE work
/// ([`SizeTrims::for_work`]); [`SizeTrims::NONE`] (every stage in full) by
/// default.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SizeTrims {
    /// An extension with more own parameters than get two coarse starts
    /// searches longer (more emulator rounds, a local search half as long
    /// again); else it keeps the plain stages.
    pub long_search: bool,
    /// A contending extension may take the lower-damping path
    /// (`--damping-path auto`).
    pub contending_damping_path: bool,
    /// Most starts the committed-tangent twin is searched from (None: all
    /// of them).
    pub twin_starts: Option<usize>,
    /// Whether the committed-tangent twin is refined as the named extension
    /// was.
    pub twin_refined: bool,
    /// Most valley walks the named extension is refined with and the most
    /// own parameters it may have to be refined at all (None: the budget's
    /// walks, any number of parameters).
    pub refine: Option<(usize, usize)>,
    /// Most rounds of the posterior's FE checks (None: all of them).
    pub check_rounds: Option<usize>,
    /// Whether the damping's mass share is searched.
    pub mass_share: bool,
}

impl SizeTrims {
    /// Every stage in full.
    pub const NONE: SizeTrims = SizeTrims {
        long_search: true,
        contending_damping_path: true,
        twin_starts: None,
        twin_refined: true,
        refine: None,
        check_rounds: None,
        mass_share: true,
    };

    /// The trims of calibration runs `runs` of `bundle`.
    pub fn of(bundle: &Bundle, runs: &[usize]) -> SizeTrims {
        SizeTrims::for_work(campaign_work(bundle, runs))
    }

    /// The trims of a campaign of [`campaign_work`] `work`: none up to
    /// [`LARGE_WORK`]; above it, no longer search or contending
    /// lower-damping path, one twin start and no twin refinement, one
    /// valley walk for at most [`LARGE_REFINED_OWN`] own parameters,
    /// [`LARGE_ROUNDS`] of checks; above [`SHARE_MAX_WORK`], no mass share.
    pub fn for_work(work: f64) -> SizeTrims {
        let mass_share = work <= SHARE_MAX_WORK;
        if work <= LARGE_WORK {
            return SizeTrims { mass_share, ..SizeTrims::NONE };
        }
        SizeTrims {
            long_search: false,
            contending_damping_path: false,
            twin_starts: Some(1),
            twin_refined: false,
            refine: Some((1, LARGE_REFINED_OWN)),
            check_rounds: Some(LARGE_ROUNDS),
            mass_share,
        }
    }
}

impl Default for SizeTrims {
    fn default() -> Self {
        SizeTrims::NONE
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn campaign_work_counts_modules_times_calibration_samples() {
        let dir = tempfile::tempdir().unwrap();
        let b = super::super::farm_executor_tests::tiny_bundle(dir.path());
        // 2.4 m x 2.4 m at 0.6 m: 16 modules; 2 s at 50 Hz: 101 samples.
        assert_eq!(b.runs.iter().map(|r| r.n_samples()).collect::<Vec<_>>(), [101; 3]);
        assert_eq!(campaign_work(&b, &[0, 1]), 16.0 * 202.0);
        assert_eq!(campaign_work(&b, &[2]), 16.0 * 101.0);
        // An index past the runs adds nothing.
        assert_eq!(campaign_work(&b, &[2, 9]), 16.0 * 101.0);
    }

    #[test]
    fn the_size_check_campaign_is_trimmed_and_the_test_campaigns_are_not() {
        // 6 m x 4.8 m at 0.6 m, two 30 s runs at 200 Hz.
        let large = SizeTrims::for_work(80.0 * 2.0 * 6001.0);
        assert_eq!(large.check_rounds, Some(LARGE_ROUNDS));
        assert!(!large.long_search && !large.twin_refined && !large.mass_share);
        // 3.6 m x 3.6 m, a 4 s and a 6 s run at 200 Hz.
        assert_eq!(SizeTrims::for_work(36.0 * (801.0 + 1201.0)), SizeTrims::NONE);
        assert_eq!(SizeTrims::for_work(LARGE_WORK), SizeTrims::NONE);
        assert_eq!(SizeTrims::default(), SizeTrims::NONE);
    }

    #[test]
    fn the_size_check_does_not_search_the_share() {
        assert!(SizeTrims::for_work(LARGE_WORK * 1.024).mass_share);
        assert!(SizeTrims::for_work(432_000.0).mass_share);
        assert!(!SizeTrims::for_work(1_920_000.0).mass_share);
    }

    #[test]
    fn a_large_campaign_refines_what_gets_two_coarse_starts() {
        assert_eq!(LARGE_REFINED_OWN, crate::diagnose::calibrate::COARSE_MAX_DIMS);
    }
}
