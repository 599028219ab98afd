//! A sensitivity problem: named inputs with uniform bounds (SALib's
//! `problem` dictionary).

use serde::{Deserialize, Serialize};

/// Named inputs, each uniform on [lo, hi].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Problem {
    /// Input names.
    pub names: Vec<String>,
    /// (lo, hi) bounds per input (physical units).
    pub bounds: Vec<(f64, f64)>,
}

impl Problem {
    /// Number of inputs.
    pub fn dim(&self) -> usize {
        self.names.len()
    }

    /// Map a unit-cube coordinate of input `k` to physical units.
    pub fn to_physical(&self, k: usize, u: f64) -> f64 {
        let (lo, hi) = self.bounds[k];
        lo + u * (hi - lo)
    }
}
