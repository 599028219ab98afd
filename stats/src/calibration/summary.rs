//! Posterior summaries from draws in physical units: mean, sd, 5/50/95 %
//! quantiles and the correlation matrix.

use nalgebra::DMatrix;

/// One parameter's marginal summary.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Marginal {
    /// Posterior mean.
    pub mean: f64,
    /// Posterior sd.
    pub sd: f64,
    /// 5 % quantile.
    pub q05: f64,
    /// Median.
    pub q50: f64,
    /// 95 % quantile.
    pub q95: f64,
}

/// Summary of a set of draws (n_draws, n_params).
#[derive(Debug, Clone, PartialEq)]
pub struct PosteriorSummary {
    /// Parameter names.
    pub names: Vec<String>,
    /// Marginals, one per name.
    pub marginals: Vec<Marginal>,
    /// Correlation matrix (n_params, n_params).
    pub correlation: DMatrix<f64>,
}

/// Linear-interpolated quantile of sorted values, p in [0, 1].
pub fn quantile_sorted(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let h = p * (sorted.len() - 1) as f64;
    let (lo, frac) = (h.floor() as usize, h - h.floor());
    let hi = (lo + 1).min(sorted.len() - 1);
    sorted[lo] + frac * (sorted[hi] - sorted[lo])
}

impl PosteriorSummary {
    /// Summarises `draws`, each of length names.len().
    pub fn from_draws(names: &[String], draws: &[Vec<f64>]) -> Self {
        let (n, d) = (draws.len() as f64, names.len());
        let mean: Vec<f64> = (0..d).map(|j| draws.iter().map(|x| x[j]).sum::<f64>() / n).collect();
        let cov = DMatrix::from_fn(d, d, |a, b| {
            draws.iter().map(|x| (x[a] - mean[a]) * (x[b] - mean[b])).sum::<f64>() / (n - 1.0)
        });
        let correlation =
            DMatrix::from_fn(d, d, |a, b| cov[(a, b)] / (cov[(a, a)] * cov[(b, b)]).sqrt());
        let marginals = (0..d)
            .map(|j| {
                let mut v: Vec<f64> = draws.iter().map(|x| x[j]).collect();
                v.sort_by(f64::total_cmp);
                Marginal {
                    mean: mean[j],
                    sd: cov[(j, j)].sqrt(),
                    q05: quantile_sorted(&v, 0.05),
                    q50: quantile_sorted(&v, 0.5),
                    q95: quantile_sorted(&v, 0.95),
                }
            })
            .collect();
        Self { names: names.to_vec(), marginals, correlation }
    }

    /// Index of a parameter by name.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_of_a_ramp() {
        let v: Vec<f64> = (0..=100).map(f64::from).collect();
        assert_eq!(quantile_sorted(&v, 0.05), 5.0);
        assert_eq!(quantile_sorted(&v, 0.5), 50.0);
    }

    #[test]
    fn perfectly_correlated_draws() {
        let draws: Vec<Vec<f64>> = (0..10).map(|i| vec![i as f64, 2.0 * i as f64]).collect();
        let s = PosteriorSummary::from_draws(&["a".into(), "b".into()], &draws);
        assert!((s.correlation[(0, 1)] - 1.0).abs() < 1e-12);
        assert!((s.marginals[0].mean - 4.5).abs() < 1e-12);
    }
}
