//! The posterior probability of each calibrated model class: its evidence
//! ([`super::class_evidence`]) times its prior ([`ln_prior`]), normalised
//! over the classes tried. Each registered effect acts with prior
//! probability [`EvidencePolicy::effect_prior`], independently of the
//! others; at its default 0.5 every class is equally probable before the
//! data, and the evidence's own Occam factor (each parameter's prior volume)
//! is the only penalty on complexity.
//!
//! Reported beside the verdict, which the MDL rules decide by default;
//! under `--verdict evidence` the most probable class names the cause and
//! classes of several effects are searched ([`super::class_search`]).

use super::calibrate::Calibration;
use super::cause::Cause;
use super::class_evidence::{
    settled_evidence, ClassEvidence, ClassEvidenceError, EvidencePolicy, PeakSearch,
};
use super::class_search::Weighed;
use super::effect::EFFECTS;
use super::executor::{ExecutorError, FeExecutor};
use super::likelihood::ChannelWeights;
use crate::bundle::Bundle;

/// A class's evidence and its posterior probability.
#[derive(Debug, Clone, PartialEq)]
pub struct ClassOdds {
    /// The evidence, its error and its rounds.
    pub evidence: ClassEvidence,
    /// Posterior probability among the classes whose evidence is counted
    /// (NaN for one that is not: [`counted_ln_posterior`]).
    pub probability: f64,
    /// The prior probability of each effect it was weighed under
    /// ([`EvidencePolicy::effect_prior`]).
    pub effect_prior: f64,
}

/// ln p(class): each of the n registered effects acts with probability
/// `effect_prior`, independently, so a class of k of them has
/// k ln p + (n − k) ln(1 − p).
pub fn ln_prior(cause: Cause, effect_prior: f64) -> f64 {
    let (k, n) = (cause.size() as f64, EFFECTS.len() as f64);
    k * effect_prior.ln() + (n - k) * (1.0 - effect_prior).ln()
}

/// The evidence of each calibration in `cals` on `runs` of `bundle`
/// (channel weights `w`), each with its posterior probability among
/// those that have one; a class whose evidence failed carries why. Each
/// evidence starts from `search` (the local search of the likelihood it
/// integrates) and may resume it from higher ground it found
/// ([`settled_evidence`]). `progress` hears (done, planned).
pub fn class_odds(
    cals: &mut [Calibration],
    (bundle, runs): (&Bundle, &[usize]),
    w: ChannelWeights<'_>,
    exec: &mut dyn FeExecutor,
    (policy, search): (&EvidencePolicy, &mut PeakSearch<'_>),
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Vec<Result<ClassOdds, String>>, ExecutorError> {
    let mut out = Vec::with_capacity(cals.len());
    let planned = cals.len();
    for (k, cal) in cals.iter_mut().enumerate() {
        progress(k, planned);
        out.push(match settled_evidence(cal, (bundle, runs), w, exec, policy, search) {
            Ok(evidence) => {
                Ok(ClassOdds { evidence, probability: f64::NAN, effect_prior: policy.effect_prior })
            }
            Err(ClassEvidenceError::Executor(e)) => return Err(e),
            Err(e) => Err(e.to_string()),
        });
    }
    progress(cals.len(), cals.len());
    let classes = cals.iter().map(|c| c.cause).zip(out.iter_mut().map(|o| o.as_mut().ok()));
    renormalise(classes, policy.effect_prior);
    Ok(out)
}

/// Sets each class's posterior probability among `classes` (its cause and
/// its odds, None for one without an evidence): evidence times prior
/// (`effect_prior`, [`ln_prior`]) over those whose evidence is counted
/// ([`counted_ln_posterior`]); NaN for the others.
pub fn renormalise<'o>(
    classes: impl Iterator<Item = (Cause, Option<&'o mut ClassOdds>)>,
    effect_prior: f64,
) {
    let mut classes: Vec<(Cause, Option<&mut ClassOdds>)> = classes.collect();
    let ln_post: Vec<f64> = (classes.iter())
        .map(|(c, o)| o.as_ref().and_then(|o| counted_ln_posterior(o, *c, effect_prior)))
        .map(|z| z.unwrap_or(f64::NAN))
        .collect();
    for ((_, o), p) in classes.iter_mut().zip(probabilities(&ln_post)) {
        if let Some(o) = o {
            o.probability = p;
        }
    }
}

/// The unnormalised log-posterior of class `cause` (its counted
/// log-evidence plus [`ln_prior`] under `effect_prior`): the estimate when
/// it settled, a lower bound when an annealing ran out of FE runs before
/// the FE posterior or reached it with too large an error
/// ([`ClassEvidence::counted_ln_evidence`]); None for an
/// evidence that neither settled nor is bounded: it is reported, never
/// compared, and takes no share of the probability. A bounded class's
/// probability so computed is a lower bound on its probability against
/// settled classes; two bounded classes are not ordered by their bounds
/// (the higher bound is not known to be the higher evidence).
pub fn counted_ln_posterior(o: &ClassOdds, cause: Cause, effect_prior: f64) -> Option<f64> {
    (o.evidence.counted_ln_evidence()).map(|z| z + ln_prior(cause, effect_prior))
}

/// What the evidence knows of a class's log-posterior (ln Z plus
/// [`ln_prior`]): at least `counted` ([`counted_ln_posterior`]), at most
/// `at_most` ([`ClassEvidence::ln_evidence_at_most`](super::class_evidence::ClassEvidence::ln_evidence_at_most);
/// None: no limit known). A settled class has both at its estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// What it is counted at.
    pub counted: f64,
    /// The most it may be (None: unbounded).
    pub at_most: Option<f64>,
}

/// The range of class `cause`'s log-posterior under `effect_prior` (None:
/// not counted).
pub fn range(o: &ClassOdds, cause: Cause, effect_prior: f64) -> Option<Range> {
    let prior = ln_prior(cause, effect_prior);
    let counted = o.evidence.counted_ln_evidence()? + prior;
    Some(Range { counted, at_most: o.evidence.ln_evidence_at_most().map(|z| z + prior) })
}

/// What the evidence decides among classes: the one of highest counted
/// log-posterior and its rivals, the others that may lie above it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Order {
    /// The class of highest counted log-posterior (an index).
    pub top: usize,
    /// Every other class whose most (unbounded: +∞) lies above the top's
    /// counted value; empty when the evidence orders the top first.
    pub rivals: Vec<usize>,
}

/// The order of classes with `ranges` (None: not counted; None when no
/// class is). A settled class is never a rival (its most is its counted
/// value, at most the top's); a class bounded by an annealing is one when
/// its upper bound lies above the top's counted value: the evidence then
/// does not say which is higher, and no class is named by it.
pub fn order(ranges: &[Option<Range>]) -> Option<Order> {
    let top = (0..ranges.len())
        .filter_map(|k| ranges[k].map(|r| (k, r.counted)))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    let above = |r: &Range| r.at_most.is_none_or(|m| m > top.1);
    let rivals = (0..ranges.len())
        .filter(|k| *k != top.0 && ranges[*k].as_ref().is_some_and(above))
        .collect();
    Some(Order { top: top.0, rivals })
}

/// What class `cause` weighs in the class search ([`Weighed`]): its
/// counted log-posterior ([`counted_ln_posterior`]) and its guide. The
/// guide is the settled value when the evidence settled; else the Laplace
/// approximation's log-posterior, never below the counted bound: a bound
/// says what the evidence is at least, conservative for naming, while the
/// search looks where the evidence may be highest.
pub fn weighed(o: &ClassOdds, cause: Cause, effect_prior: f64) -> Weighed {
    let counted = counted_ln_posterior(o, cause, effect_prior);
    if o.evidence.converged {
        return Weighed::counted(counted);
    }
    let laplace = Some(o.evidence.laplace_ln_evidence + ln_prior(cause, effect_prior))
        .filter(|z| z.is_finite());
    let guide = match (counted, laplace) {
        (Some(c), Some(l)) => Some(c.max(l)),
        (c, l) => c.or(l),
    };
    Weighed { counted, guide }
}

/// Posterior probabilities from unnormalised log-posteriors (ln Z plus ln
/// prior; NaN entries have none and take no share).
pub fn probabilities(ln_z: &[f64]) -> Vec<f64> {
    let top = ln_z.iter().copied().filter(|v| v.is_finite()).fold(f64::NEG_INFINITY, f64::max);
    if !top.is_finite() {
        return vec![f64::NAN; ln_z.len()];
    }
    let w: Vec<f64> = ln_z.iter().map(|v| if v.is_nan() { 0.0 } else { (v - top).exp() }).collect();
    let sum: f64 = w.iter().sum();
    ln_z.iter().zip(&w).map(|(v, w)| if v.is_nan() { f64::NAN } else { w / sum }).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_prior_of_a_class_is_its_effects_acting_independently() {
        let pf = Cause::PERIMETER_FRICTION.with(0);
        // At 1/2 every class has 2^-n.
        for c in [Cause::NONE, Cause::PERIMETER_FRICTION, pf] {
            assert!((ln_prior(c, 0.5) - (0.125f64).ln()).abs() < 1e-12);
        }
        // At 0.1 each effect costs ln 9 against its absence.
        let step = ln_prior(Cause::PERIMETER_FRICTION, 0.1) - ln_prior(pf, 0.1);
        assert!((step - 9f64.ln()).abs() < 1e-12);
        let total: f64 = (0..8u8)
            .map(|bits| {
                let c = (0..3).filter(|k| bits & (1 << k) != 0).fold(Cause::NONE, |c, k| c.with(k));
                ln_prior(c, 0.1).exp()
            })
            .sum();
        assert!((total - 1.0).abs() < 1e-12);
    }

    #[test]
    fn probabilities_follow_the_evidence_ratios_and_skip_missing_classes() {
        let p = probabilities(&[0.0, 2f64.ln(), f64::NAN]);
        assert!((p[0] - 1.0 / 3.0).abs() < 1e-12 && (p[1] - 2.0 / 3.0).abs() < 1e-12);
        assert!(p[2].is_nan());
        // Evidences of thousands of nats do not overflow.
        let p = probabilities(&[-5000.0, -5001.0]);
        assert!((p[0] - 1.0 / (1.0 + (-1f64).exp())).abs() < 1e-12);
        assert!(probabilities(&[f64::NAN]).iter().all(|v| v.is_nan()));
    }

    fn evidence(z: f64, converged: bool, lower: Option<(f64, f64)>) -> ClassOdds {
        with_laplace(z, converged, lower, z)
    }

    fn with_laplace(z: f64, converged: bool, lower: Option<(f64, f64)>, laplace: f64) -> ClassOdds {
        use super::super::class_evidence::Annealed;
        let mut o = super::super::testkit::class_odds(z, converged);
        o.evidence.laplace_ln_evidence = laplace;
        o.evidence.annealed = lower.map(|lower| Annealed {
            estimate: None,
            stages: 8,
            fe_points: 640,
            beta: 0.9,
            lower: Some(lower),
            upper: None,
        });
        o
    }

    /// A class bounded to [lower, upper] (each ± 0, so counted as given).
    fn bounded(lower: f64, upper: Option<f64>) -> ClassOdds {
        super::super::testkit::bounded(lower, upper, 640)
    }

    #[test]
    fn bounded_classes_are_ordered_only_where_their_bounds_do_not_overlap() {
        let (none, f, pf) =
            (Cause::NONE, Cause::PERIMETER_FRICTION, Cause::PERIMETER_FRICTION.with(0));
        let prior = ln_prior(none, 0.5);
        let settled = evidence(100.0, true, None);
        let ranges = |odds: &[(Cause, &ClassOdds)]| -> Vec<Option<Range>> {
            odds.iter().map(|(c, o)| range(o, *c, 0.5)).collect()
        };
        // A settled class has a point range.
        let r = range(&settled, none, 0.5).unwrap();
        assert_eq!(r, Range { counted: 100.0 + prior, at_most: Some(100.0 + prior) });
        // Settled 100 against a class bounded to [60, 90]: decided.
        let low = bounded(60.0, Some(90.0));
        let o = order(&ranges(&[(none, &settled), (f, &low)])).unwrap();
        assert_eq!(o, Order { top: 0, rivals: vec![] });
        // ... to [60, 130]: it may lie above, undecided.
        let may = bounded(60.0, Some(130.0));
        let o = order(&ranges(&[(none, &settled), (f, &may)])).unwrap();
        assert_eq!(o, Order { top: 0, rivals: vec![1] });
        // Two bounded classes: the higher bound leads, the other may lie
        // above it, whichever bound is higher; none with no upper bound.
        let (a, b) = (bounded(3099.0, Some(5000.0)), bounded(4384.0, Some(6000.0)));
        let o = order(&ranges(&[(none, &settled), (f, &a), (pf, &b)])).unwrap();
        assert_eq!(o, Order { top: 2, rivals: vec![1] });
        let o = order(&ranges(&[(f, &bounded(3099.0, None)), (pf, &b)])).unwrap();
        assert_eq!(o, Order { top: 1, rivals: vec![0] });
        // Bounded above the settled one, wholly: decided for it.
        let o = order(&ranges(&[(none, &settled), (f, &bounded(200.0, Some(300.0)))])).unwrap();
        assert_eq!(o, Order { top: 1, rivals: vec![] });
        // A class neither settled nor bounded is not counted, nor a rival.
        let loose = evidence(900.0, false, None);
        let o = order(&ranges(&[(none, &settled), (f, &loose)])).unwrap();
        assert_eq!(o, Order { top: 0, rivals: vec![] });
        assert_eq!(order(&ranges(&[(f, &loose)])), None);
    }

    #[test]
    fn a_class_bounded_below_is_counted_at_its_bound_and_an_unsettled_one_not_at_all() {
        let (a, b) = (Cause::PERIMETER_FRICTION, Cause::PERIMETER_POUNDING);
        // Friction settled at 100; pounding not settled, its annealing's
        // bound 104 ± 1.5: counted at 101, so e^1 : 1 for pounding.
        let mut odds = [evidence(100.0, true, None), evidence(900.0, false, Some((104.0, 1.5)))];
        assert_eq!(odds[1].evidence.counted_ln_evidence(), Some(101.0));
        let [fa, pb] = &mut odds;
        renormalise([(a, Some(fa)), (b, Some(pb))].into_iter(), 0.5);
        let e = std::f64::consts::E;
        assert!((odds[1].probability - e / (1.0 + e)).abs() < 1e-12, "{}", odds[1].probability);
        // The same class unsettled without a bound (its estimate 900 nat
        // above, never compared) takes no share.
        let mut odds = [evidence(100.0, true, None), evidence(900.0, false, None)];
        assert_eq!(odds[1].evidence.counted_ln_evidence(), None);
        let [fa, pb] = &mut odds;
        renormalise([(a, Some(fa)), (b, Some(pb))].into_iter(), 0.5);
        assert_eq!(odds[0].probability, 1.0);
        assert!(odds[1].probability.is_nan());
        // A settled class is counted at its estimate, bound or not.
        assert_eq!(evidence(7.0, true, Some((1.0, 1.0))).evidence.counted_ln_evidence(), Some(7.0));
    }

    #[test]
    fn an_annealing_that_reached_the_fe_posterior_counts_within_its_error() {
        use super::super::class_evidence::Annealed;
        // The annealing reached β = 1 at 109.5 ± 1.01, just above the
        // 1-nat error that settles it: counted at 109.5 − 2.02, at most
        // 109.5 + 2.02, so a settled class at 36.7 is ordered below it,
        // and one at 108, counted above it, is not known to be above it.
        let mut o = evidence(900.0, false, None);
        o.evidence.annealed = Some(Annealed {
            estimate: Some((109.5, 1.01)),
            stages: 6,
            fe_points: 600,
            beta: 1.0,
            lower: None,
            upper: None,
        });
        let e = &o.evidence;
        assert!((e.counted_ln_evidence().unwrap() - 107.48).abs() < 1e-12);
        assert!((e.ln_evidence_at_most().unwrap() - 111.52).abs() < 1e-12);
        let (pf, pfh) =
            (Cause::PERIMETER_FRICTION.with(0), Cause::PERIMETER_FRICTION.with(0).with(2));
        let low = evidence(36.7, true, None);
        let r = |o: &ClassOdds, c| range(o, c, 0.5);
        let top = order(&[r(&low, pf), r(&o, pfh)]).unwrap();
        assert_eq!(top, Order { top: 1, rivals: vec![] });
        let near = evidence(108.0, true, None);
        let doubt = order(&[r(&near, pf), r(&o, pfh)]).unwrap();
        assert_eq!(doubt, Order { top: 0, rivals: vec![1] });
        // The search counts it too (it was not weighed at all before).
        assert!(weighed(&o, pfh, 0.5).counted.is_some());
    }

    #[test]
    fn a_bounded_class_guides_the_search_by_its_laplace_value_when_higher() {
        let c = Cause::PERIMETER_FRICTION;
        let prior = ln_prior(c, 0.5);
        // Bounded: counted at 101, its Laplace approximation at 140 leads.
        let w = weighed(&with_laplace(900.0, false, Some((104.0, 1.5)), 140.0), c, 0.5);
        assert_eq!(w, Weighed { counted: Some(101.0 + prior), guide: Some(140.0 + prior) });
        // A Laplace value below the bound never lowers the guide.
        let w = weighed(&with_laplace(900.0, false, Some((104.0, 1.5)), 60.0), c, 0.5);
        assert_eq!(w.guide, Some(101.0 + prior));
        // Neither settled nor bounded: the Laplace value guides, nothing is counted.
        let w = weighed(&with_laplace(900.0, false, None, 60.0), c, 0.5);
        assert_eq!(w, Weighed { counted: None, guide: Some(60.0 + prior) });
        // Settled: the estimate is both.
        let w = weighed(&with_laplace(70.0, true, None, 500.0), c, 0.5);
        assert_eq!(w, Weighed::counted(Some(70.0 + prior)));
    }
}
