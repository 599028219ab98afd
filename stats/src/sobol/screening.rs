//! Screening: inputs whose total-order index falls below a threshold
//! (seed: 1 %) are declared inert and may be fixed.

use serde::{Deserialize, Serialize};

/// The screening decision.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Screening {
    /// Threshold on the total index.
    pub threshold: f64,
    /// Inputs kept (ST ≥ threshold).
    pub keep: Vec<String>,
    /// Inputs dropped (ST < threshold).
    pub drop: Vec<String>,
}

/// Split `names` by total index `st` against `threshold`.
pub fn screen(names: &[String], st: &[f64], threshold: f64) -> Screening {
    let (mut keep, mut drop) = (Vec::new(), Vec::new());
    for (n, s) in names.iter().zip(st) {
        if *s < threshold {
            drop.push(n.clone())
        } else {
            keep.push(n.clone())
        }
    }
    Screening { threshold, keep, drop }
}
