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
use super::effect::EFFECTS;
use super::executor::{ExecutorError, FeExecutor};
use super::likelihood::ChannelWeights;
use crate::bundle::Bundle;

/// A class's evidence and its posterior probability.
#[derive(Debug, Clone, PartialEq)]
pub struct ClassOdds {
    /// The evidence, its error and its rounds.
    pub evidence: ClassEvidence,
    /// Posterior probability among the classes whose evidence settled
    /// (NaN for one that did not).
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
/// (`effect_prior`, [`ln_prior`]) over those whose evidence settled
/// ([`settled_ln_posterior`]); NaN for the others.
pub fn renormalise<'o>(
    classes: impl Iterator<Item = (Cause, Option<&'o mut ClassOdds>)>,
    effect_prior: f64,
) {
    let mut classes: Vec<(Cause, Option<&mut ClassOdds>)> = classes.collect();
    let ln_post: Vec<f64> = (classes.iter())
        .map(|(c, o)| o.as_ref().and_then(|o| settled_ln_posterior(o, *c, effect_prior)))
        .map(|z| z.unwrap_or(f64::NAN))
        .collect();
    for ((_, o), p) in classes.iter_mut().zip(probabilities(&ln_post)) {
        if let Some(o) = o {
            o.probability = p;
        }
    }
}

/// The unnormalised log-posterior of class `cause` (its log-evidence plus
/// [`ln_prior`] under `effect_prior`) when its evidence settled; None when
/// its rounds ran out first: such an evidence is reported, never compared,
/// and takes no share of the probability.
pub fn settled_ln_posterior(o: &ClassOdds, cause: Cause, effect_prior: f64) -> Option<f64> {
    o.evidence.converged.then(|| o.evidence.ln_evidence + ln_prior(cause, effect_prior))
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
}
