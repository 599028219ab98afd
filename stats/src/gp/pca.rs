//! Emulating time histories: principal components of the centred (n, T)
//! output matrix by SVD, keeping the fewest components that explain a chosen
//! fraction of the variance, one independent GP per component score (fitted
//! in parallel threads), and reconstruction with propagated variance
//! var y(t) = Σ_k φ_k(t)² σ²_k (Higdon et al. 2008, *JASA* 103:570).

use super::error::GpError;
use super::fit::{fit, GpSettings};
use super::model::Gp;
use super::scaling::InputScaling;
use nalgebra::DMatrix;

/// A PCA-reduced multi-output GP.
pub struct PcaGp {
    /// Mean history, (T).
    pub mean: Vec<f64>,
    /// Basis vectors φ_k scaled by their singular value / √n, (K) of (T).
    pub basis: Vec<Vec<f64>>,
    /// Fraction of variance explained by the kept components.
    pub explained: f64,
    /// One GP per component score (unit-variance scores).
    pub gps: Vec<Gp>,
}

/// Mean and sd of predicted histories, each (m) of (T).
pub struct HistoryPrediction {
    /// Predicted mean histories.
    pub mean: Vec<Vec<f64>>,
    /// Predicted pointwise sds.
    pub sd: Vec<Vec<f64>>,
}

impl PcaGp {
    /// Fit to inputs `x` ((n, d) row-major) and histories `y` (n rows of T),
    /// keeping components up to `fraction` (0, 1] of the variance.
    pub fn fit(
        x: &[f64],
        d: usize,
        y: &[Vec<f64>],
        fraction: f64,
        scaling: Option<InputScaling>,
        set: &GpSettings,
    ) -> Result<Self, GpError> {
        let n = y.len();
        let t = y.first().map_or(0, |r| r.len());
        if n < 2 || t == 0 || y.iter().any(|r| r.len() != t) {
            return Err(GpError::Shape { what: "histories (n rows of T)", expected: t, found: n });
        }
        if !(fraction > 0.0 && fraction <= 1.0) {
            return Err(GpError::Setting {
                key: "fraction",
                value: fraction.to_string(),
                expected: "in (0, 1]",
            });
        }
        let mean: Vec<f64> =
            (0..t).map(|j| y.iter().map(|r| r[j]).sum::<f64>() / n as f64).collect();
        let c = DMatrix::from_fn(n, t, |i, j| y[i][j] - mean[j]);
        let svd = c.svd(true, true);
        let (u, vt) = (svd.u.expect("u requested"), svd.v_t.expect("v_t requested"));
        let mut order: Vec<usize> = (0..svd.singular_values.len()).collect();
        order.sort_by(|a, b| svd.singular_values[*b].total_cmp(&svd.singular_values[*a]));
        let total: f64 = svd.singular_values.iter().map(|s| s * s).sum();
        let (mut kept, mut acc) = (Vec::new(), 0.0);
        for &k in &order {
            if total > 0.0 && acc / total >= fraction {
                break;
            }
            acc += svd.singular_values[k].powi(2);
            kept.push(k);
        }
        let root_n = (n as f64).sqrt();
        let basis: Vec<Vec<f64>> = kept
            .iter()
            .map(|&k| (0..t).map(|j| vt[(k, j)] * svd.singular_values[k] / root_n).collect())
            .collect();
        let scores: Vec<Vec<f64>> =
            kept.iter().map(|&k| (0..n).map(|i| u[(i, k)] * root_n).collect()).collect();
        let inner = GpSettings { threads: 1, ..set.clone() };
        let gps = std::thread::scope(|s| {
            let hs: Vec<_> = scores
                .iter()
                .map(|z| {
                    let (inner, scaling) = (&inner, scaling.clone());
                    s.spawn(move || fit(x, d, z, scaling, inner))
                })
                .collect();
            hs.into_iter().map(|h| h.join().expect("component fit")).collect::<Result<Vec<_>, _>>()
        })?;
        let explained = if total > 0.0 { acc / total } else { 1.0 };
        Ok(PcaGp { mean, basis, explained, gps })
    }

    /// Predicted histories with pointwise sds at the (m, d) points.
    pub fn predict(&self, x: &[f64]) -> Result<HistoryPrediction, GpError> {
        let preds = self.gps.iter().map(|g| g.predict(x, false)).collect::<Result<Vec<_>, _>>()?;
        let m = preds.first().map_or(0, |p| p.mean.len());
        let t = self.mean.len();
        let mut mean = vec![self.mean.clone(); m];
        let mut var = vec![vec![0.0; t]; m];
        for (p, phi) in preds.iter().zip(&self.basis) {
            for i in 0..m {
                for j in 0..t {
                    mean[i][j] += phi[j] * p.mean[i];
                    var[i][j] += (phi[j] * p.sd[i]).powi(2);
                }
            }
        }
        let sd = var.into_iter().map(|r| r.into_iter().map(f64::sqrt).collect()).collect();
        Ok(HistoryPrediction { mean, sd })
    }
}
