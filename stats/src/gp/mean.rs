//! Prior mean functions of the GP: zero, constant, or linear in the scaled
//! inputs. The constant and linear trends are fitted by least squares and
//! subtracted before the GP models the residual (a plug-in estimate of the
//! generalised-least-squares trend).

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Which prior mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MeanKind {
    /// m(x) = 0 (the output is only scaled, not centred).
    Zero,
    /// m(x) = β₀, the sample mean.
    Constant,
    /// m(x) = β₀ + βᵀ x on the scaled inputs.
    Linear,
}

impl MeanKind {
    /// Parse `zero`, `constant` or `linear`.
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "zero" => Some(Self::Zero),
            "constant" => Some(Self::Constant),
            "linear" => Some(Self::Linear),
            _ => None,
        }
    }
}

/// Coefficients of a fitted linear trend [β₀, β₁..β_d] (scaled inputs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trend {
    /// Intercept then slopes.
    pub beta: Vec<f64>,
}

impl Trend {
    /// Least-squares linear trend of `y` on the (n, d) scaled inputs, with
    /// a small ridge for stability.
    pub fn fit_linear(x: &[f64], d: usize, y: &[f64]) -> Self {
        let n = y.len();
        let h = DMatrix::from_fn(n, d + 1, |i, j| if j == 0 { 1.0 } else { x[i * d + j - 1] });
        let mut a = h.transpose() * &h;
        for j in 0..=d {
            a[(j, j)] += 1e-10 * n as f64;
        }
        let b = h.transpose() * DVector::from_column_slice(y);
        let beta = a
            .cholesky()
            .map(|c| c.solve(&b).as_slice().to_vec())
            .unwrap_or_else(|| vec![0.0; d + 1]);
        Trend { beta }
    }

    /// Trend value at one scaled point.
    pub fn eval(&self, x: &[f64]) -> f64 {
        self.beta[0] + self.beta[1..].iter().zip(x).map(|(b, v)| b * v).sum::<f64>()
    }
}
