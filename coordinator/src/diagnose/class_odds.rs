//! The posterior probability of each calibrated model class: its evidence
//! ([`super::class_evidence`]) times its prior odds, normalised over the
//! classes tried. Equal prior odds by default: no class is favoured before
//! the data; the evidence's own Occam factor (each parameter's prior
//! volume) is the only penalty on complexity.
//!
//! Reported beside the verdict, which the MDL rules decide by default;
//! under `--verdict evidence` the most probable class names the cause and
//! classes of several effects are searched ([`super::class_search`]).

use super::calibrate::Calibration;
use super::class_evidence::{class_evidence, ClassEvidence, ClassEvidenceError, EvidencePolicy};
use super::executor::{ExecutorError, FeExecutor};
use super::likelihood::ChannelWeights;
use crate::bundle::Bundle;

/// A class's evidence and its posterior probability.
#[derive(Debug, Clone, PartialEq)]
pub struct ClassOdds {
    /// The evidence, its error and its rounds.
    pub evidence: ClassEvidence,
    /// Posterior probability among the classes whose evidence was had
    /// (equal prior odds).
    pub probability: f64,
}

/// The evidence of each calibration in `cals` on `runs` of `bundle`
/// (channel weights `w`), each with its posterior probability among
/// those that have one; a class whose evidence failed carries why.
/// `progress` hears (done, planned).
pub fn class_odds(
    cals: &[Calibration],
    (bundle, runs): (&Bundle, &[usize]),
    w: ChannelWeights<'_>,
    exec: &mut dyn FeExecutor,
    policy: &EvidencePolicy,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Vec<Result<ClassOdds, String>>, ExecutorError> {
    let mut out = Vec::with_capacity(cals.len());
    for (k, cal) in cals.iter().enumerate() {
        progress(k, cals.len());
        out.push(match class_evidence(cal, (bundle, runs), w, exec, policy) {
            Ok(evidence) => Ok(ClassOdds { evidence, probability: f64::NAN }),
            Err(ClassEvidenceError::Executor(e)) => return Err(e),
            Err(e) => Err(e.to_string()),
        });
    }
    progress(cals.len(), cals.len());
    let ln_z: Vec<f64> =
        out.iter().map(|o| o.as_ref().map_or(f64::NAN, |o| o.evidence.ln_evidence)).collect();
    for (o, p) in out.iter_mut().zip(probabilities(&ln_z)) {
        if let Ok(o) = o {
            o.probability = p;
        }
    }
    Ok(out)
}

/// Posterior probabilities under equal prior odds from log-evidences
/// (NaN entries have none and take no share).
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
    use super::probabilities;

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
