//! Input scaling to the unit cube from design bounds (or the data range)
//! and output standardisation after an optional mean trend.

use serde::{Deserialize, Serialize};

/// Affine map of each input from [lo, hi] to [0, 1].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InputScaling {
    /// Lower bounds, one per input (physical units).
    pub lo: Vec<f64>,
    /// Upper bounds, one per input (physical units).
    pub hi: Vec<f64>,
}

impl InputScaling {
    /// Bounds from the data range of the (n, d) row-major `x`.
    pub fn from_data(x: &[f64], d: usize) -> Self {
        let mut lo = vec![f64::INFINITY; d];
        let mut hi = vec![f64::NEG_INFINITY; d];
        for row in x.chunks(d) {
            for k in 0..d {
                lo[k] = lo[k].min(row[k]);
                hi[k] = hi[k].max(row[k]);
            }
        }
        for k in 0..d {
            if hi[k] <= lo[k] {
                hi[k] = lo[k] + 1.0;
            }
        }
        InputScaling { lo, hi }
    }

    /// Scale the (n, d) row-major points to the unit cube.
    pub fn apply(&self, x: &[f64]) -> Vec<f64> {
        let d = self.lo.len();
        x.iter()
            .enumerate()
            .map(|(i, v)| (v - self.lo[i % d]) / (self.hi[i % d] - self.lo[i % d]))
            .collect()
    }
}

/// Standardisation y_s = (y − m) / s of a single output.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OutputScaling {
    /// Offset m (output units).
    pub mean: f64,
    /// Scale s (output units), positive.
    pub sd: f64,
}

impl OutputScaling {
    /// Mean and sample sd of `y` (sd 1 if y is constant); zero offset
    /// when `centre` is false.
    pub fn from_data(y: &[f64], centre: bool) -> Self {
        let n = y.len() as f64;
        let m = y.iter().sum::<f64>() / n;
        let var = y.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / n;
        let mean = if centre { m } else { 0.0 };
        let sd =
            if centre { var.sqrt() } else { (y.iter().map(|v| v * v).sum::<f64>() / n).sqrt() };
        OutputScaling { mean, sd: if sd > 0.0 { sd } else { 1.0 } }
    }
}
