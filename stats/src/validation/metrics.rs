//! Held-out accuracy of a probabilistic prediction (means and sds against
//! observed values): RMSE, R², mean negative log predictive density (NLPD,
//! Gaussian), coverage of the central 95 % interval, standardised residuals.

use serde::{Deserialize, Serialize};

/// Summary of a held-out comparison.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Validation {
    /// Root mean squared error (output units).
    pub rmse: f64,
    /// Coefficient of determination 1 − SSE / SST.
    pub r2: f64,
    /// Mean negative log predictive density (nats per point).
    pub nlpd: f64,
    /// Fraction of observations inside mean ± 1.96 sd.
    pub coverage95: f64,
    /// Standardised residuals (y − mean) / sd.
    pub std_residuals: Vec<f64>,
}

/// Compare predictions (`mean`, `sd`) with observations `y` (same length,
/// sds positive). None if empty or lengths differ.
pub fn validate(mean: &[f64], sd: &[f64], y: &[f64]) -> Option<Validation> {
    let n = y.len();
    if n == 0 || mean.len() != n || sd.len() != n {
        return None;
    }
    let nf = n as f64;
    let ybar = y.iter().sum::<f64>() / nf;
    let sse: f64 = mean.iter().zip(y).map(|(m, t)| (t - m).powi(2)).sum();
    let sst: f64 = y.iter().map(|t| (t - ybar).powi(2)).sum();
    let std_residuals: Vec<f64> = (0..n).map(|i| (y[i] - mean[i]) / sd[i]).collect();
    let ln2pi = (2.0 * std::f64::consts::PI).ln();
    let nlpd =
        (0..n).map(|i| 0.5 * ln2pi + sd[i].ln() + 0.5 * std_residuals[i].powi(2)).sum::<f64>() / nf;
    let inside = std_residuals.iter().filter(|z| z.abs() <= 1.959964).count();
    Some(Validation {
        rmse: (sse / nf).sqrt(),
        r2: if sst > 0.0 { 1.0 - sse / sst } else { f64::NAN },
        nlpd,
        coverage95: inside as f64 / nf,
        std_residuals,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perfect_mean_with_unit_sd() {
        let y = [1.0, 2.0, 3.0];
        let v = validate(&y, &[1.0; 3], &y).unwrap();
        assert_eq!(v.rmse, 0.0);
        assert_eq!(v.r2, 1.0);
        assert_eq!(v.coverage95, 1.0);
        // NLPD of a standard normal at its mean: ½ ln 2π.
        assert!((v.nlpd - 0.5 * (2.0 * std::f64::consts::PI).ln()).abs() < 1e-15);
    }

    #[test]
    fn residual_of_three_sds_is_outside_interval() {
        let v = validate(&[0.0, 0.0], &[1.0, 1.0], &[3.0, 0.5]).unwrap();
        assert_eq!(v.coverage95, 0.5);
        assert_eq!(v.std_residuals, vec![3.0, 0.5]);
    }
}
