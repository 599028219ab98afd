//! Where a class of several effects starts: its sub-classes' estimates
//! joined. A class such as pounding with friction nests each of its
//! effects alone; each single effect's calibration has found where its own
//! physics fits, and the class's exploration around the baseline's
//! estimate has to find both at once in twice the dimensions. On a
//! friction-and-pounding campaign it did not: its calibration ended
//! hundreds of nats below the mode its evidence's checks later rose to.
//! Each sub-class's best point, its missing effects' parameters taken from
//! the best sub-class that calibrated them, is one start; the class's own
//! search then begins from the best of its exploration and these.

use super::calibrate::{held_unit, Calibration};
use super::cause::{Cause, Prior};

/// The starts of class `c` (its priors `priors`, unit cube) joined from the
/// calibrations in `cals` of the classes it strictly contains (the baseline
/// excluded), best first under weights `n_eff`: one per such sub-class,
/// its own parameters from its best point, every other parameter from the
/// best sub-class that has it, else held as an extension's exploration
/// holds it (its reference, else the prior's middle). Empty for a single
/// effect or when no sub-class has a best point.
pub fn joined_starts(
    c: Cause,
    priors: &[Prior],
    cals: &[Calibration],
    n_eff: &[f64],
) -> Vec<Vec<f64>> {
    let inside = |s: Cause| s != Cause::NONE && s != c && s.indices().all(|k| c.has(k));
    let mut donors: Vec<(f64, &Calibration, usize)> = (cals.iter())
        .filter(|cal| inside(cal.cause))
        .filter_map(|cal| cal.best(n_eff).map(|k| (cal.objective(n_eff)[k], cal, k)))
        .collect();
    donors.sort_by(|a, b| a.0.total_cmp(&b.0));
    let value = |cal: &Calibration, k: usize, name: &str| {
        cal.priors.iter().position(|p| p.name == name).map(|i| cal.points[k].u[i])
    };
    let mut starts: Vec<Vec<f64>> = Vec::new();
    for (_, primary, k) in &donors {
        let u: Vec<f64> = (priors.iter())
            .map(|p| {
                let from_rest = || donors.iter().find_map(|(_, d, j)| value(d, *j, p.name));
                value(primary, *k, p.name).or_else(from_rest).unwrap_or_else(|| held_unit(p))
            })
            .collect();
        if !starts.contains(&u) {
            starts.push(u);
        }
    }
    starts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::calibrate::Point;
    use crate::diagnose::cause::BASELINE_PRIORS;
    use crate::diagnose::fit::ChannelFit;

    /// A calibration of `c` with one successful point at `u` of −log L
    /// `value` under weight 2 ([`N_EFF`]).
    fn one_point(c: Cause, u: Vec<f64>, value: f64) -> Calibration {
        let priors = c.priors_on(&BASELINE_PRIORS);
        assert_eq!(priors.len(), u.len());
        let fit = ChannelFit::with_neg_log_lik(value);
        Calibration {
            cause: c,
            priors,
            free: vec![],
            points: vec![Point { u, fit: Ok(vec![fit]), coarse: value, modal: None }],
            demand: None,
            gauss_newton: None,
            committed_share: 0.0,
        }
    }

    /// The channel weight of the tests' points.
    const N_EFF: [f64; 1] = [2.0];

    #[test]
    fn a_pair_starts_from_each_single_effect_with_the_others_parameters() {
        let (p, f) = (Cause::PERIMETER_POUNDING, Cause::PERIMETER_FRICTION);
        let pf = p.with(1);
        let nb = BASELINE_PRIORS.len();
        let (np, nf) = (p.extra_priors().len(), f.extra_priors().len());
        let base = |x: f64| vec![x; nb];
        let pu: Vec<f64> = base(0.1).into_iter().chain(vec![0.2; np]).collect();
        let fu: Vec<f64> = base(0.3).into_iter().chain(vec![0.4; nf]).collect();
        let cals = vec![
            one_point(Cause::NONE, base(0.9), -50.0),
            one_point(p, pu, -10.0),
            one_point(f, fu, -20.0),
        ];
        let n_eff = N_EFF;
        let starts = joined_starts(pf, &pf.priors_on(&BASELINE_PRIORS), &cals, &n_eff);
        // Friction fits better: its start first, the baseline's from it.
        let want_f: Vec<f64> =
            base(0.3).into_iter().chain(vec![0.2; np]).chain(vec![0.4; nf]).collect();
        let want_p: Vec<f64> =
            base(0.1).into_iter().chain(vec![0.2; np]).chain(vec![0.4; nf]).collect();
        assert_eq!(starts, vec![want_f, want_p]);
    }

    #[test]
    fn a_single_effect_or_a_class_without_calibrated_parts_has_none() {
        let p = Cause::PERIMETER_POUNDING;
        let nb = BASELINE_PRIORS.len();
        let cals = vec![one_point(Cause::NONE, vec![0.5; nb], -50.0)];
        let n_eff = N_EFF;
        assert!(joined_starts(p, &p.priors_on(&BASELINE_PRIORS), &cals, &n_eff).is_empty());
        let ph = p.with(2);
        assert!(joined_starts(ph, &ph.priors_on(&BASELINE_PRIORS), &cals, &n_eff).is_empty());
    }

    #[test]
    fn a_parameter_no_sub_class_calibrated_is_held_at_its_reference() {
        let p = Cause::PERIMETER_POUNDING;
        let all = p.with(1).with(2);
        let nb = BASELINE_PRIORS.len();
        let np = p.extra_priors().len();
        let pu: Vec<f64> = vec![0.1; nb].into_iter().chain(vec![0.2; np]).collect();
        let cals = vec![one_point(p, pu, -10.0)];
        let priors = all.priors_on(&BASELINE_PRIORS);
        let starts = joined_starts(all, &priors, &cals, &N_EFF);
        assert_eq!(starts.len(), 1);
        for (p, u) in priors.iter().zip(&starts[0]).skip(nb + np) {
            let want = p.reference.map_or(0.5, |r| p.unit(r).clamp(0.0, 1.0));
            assert_eq!(*u, want, "{}", p.name);
        }
    }
}
