//! First- and total-order Sobol' indices from Saltelli-design outputs,
//! with bootstrap confidence intervals. Total order by Jansen's estimator
//! V_Ti = ½ E[(f(A) − f(A_B^i))²]; first order by Saltelli et al. (2010)
//! V_i = E[f(B) (f(A_B^i) − f(A))] or Jansen's V − ½ E[(f(B) − f(A_B^i))²];
//! both divided by the variance of f over A and B (SALib's convention).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// First-order estimator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FirstOrder {
    /// Saltelli et al. (2010), table 2 (b).
    Saltelli2010,
    /// Jansen (1999), table 2 (f).
    Jansen,
}

/// Settings of the analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnalyzeSettings {
    /// First-order estimator.
    pub first_order: FirstOrder,
    /// Bootstrap resamples (0 = no intervals).
    pub resamples: usize,
    /// Confidence level of the intervals.
    pub level: f64,
    /// Seed of the bootstrap.
    pub seed: u64,
}

impl Default for AnalyzeSettings {
    fn default() -> Self {
        AnalyzeSettings {
            first_order: FirstOrder::Saltelli2010,
            resamples: 100,
            level: 0.95,
            seed: 0,
        }
    }
}

/// Sobol' indices with half-widths of their confidence intervals.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Indices {
    /// First-order indices, (d).
    pub s1: Vec<f64>,
    /// Total-order indices, (d).
    pub st: Vec<f64>,
    /// Half-width of the S1 interval, (d).
    pub s1_conf: Vec<f64>,
    /// Half-width of the ST interval, (d).
    pub st_conf: Vec<f64>,
}

/// Bad output array.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SobolError {
    /// Length is not a multiple of d + 2.
    #[error("{found} outputs: expected a multiple of d + 2 = {block}")]
    Length {
        /// Outputs given.
        found: usize,
        /// Block size d + 2.
        block: usize,
    },
    /// A non-finite output.
    #[error("output {index} is not finite")]
    NonFinite {
        /// Position in the output array.
        index: usize,
    },
    /// Zero variance of the outputs.
    #[error("outputs have zero variance")]
    ZeroVariance,
}

/// Indices from outputs `y` laid out as by `saltelli_sample` for d inputs.
pub fn analyze(d: usize, y: &[f64], set: &AnalyzeSettings) -> Result<Indices, SobolError> {
    let block = d + 2;
    if y.is_empty() || !y.len().is_multiple_of(block) {
        return Err(SobolError::Length { found: y.len(), block });
    }
    if let Some(index) = y.iter().position(|v| !v.is_finite()) {
        return Err(SobolError::NonFinite { index });
    }
    // Centre the outputs: the Saltelli-2010 first-order estimator's
    // variance grows with the squared mean of f (SALib standardises too).
    let centre = y.iter().sum::<f64>() / y.len() as f64;
    let y: Vec<f64> = y.iter().map(|v| v - centre).collect();
    let y = &y[..];
    let n = y.len() / block;
    let rows: Vec<usize> = (0..n).collect();
    let (s1, st) = estimate(d, y, &rows, set.first_order).ok_or(SobolError::ZeroVariance)?;
    let (s1_conf, st_conf) = bootstrap(d, y, set);
    Ok(Indices { s1, st, s1_conf, st_conf })
}

/// First-order and total indices of one estimate (point or bootstrap).
type Replicate = (Vec<f64>, Vec<f64>);

/// Point estimates over the base rows `rows`; None if the variance is 0.
fn estimate(d: usize, y: &[f64], rows: &[usize], fo: FirstOrder) -> Option<Replicate> {
    let block = d + 2;
    let m = rows.len() as f64;
    let (mut s, mut s2) = (0.0, 0.0);
    for &j in rows {
        let (a, b) = (y[j * block], y[j * block + d + 1]);
        s += a + b;
        s2 += a * a + b * b;
    }
    let mean = s / (2.0 * m);
    let var = s2 / (2.0 * m) - mean * mean;
    if var <= 0.0 {
        return None;
    }
    let mut s1 = vec![0.0; d];
    let mut st = vec![0.0; d];
    for &j in rows {
        let r = &y[j * block..(j + 1) * block];
        let (a, b) = (r[0], r[d + 1]);
        for i in 0..d {
            let ab = r[1 + i];
            s1[i] += match fo {
                FirstOrder::Saltelli2010 => b * (ab - a),
                FirstOrder::Jansen => (b - ab) * (b - ab),
            };
            st[i] += (a - ab) * (a - ab);
        }
    }
    for i in 0..d {
        s1[i] = match fo {
            FirstOrder::Saltelli2010 => s1[i] / m / var,
            FirstOrder::Jansen => 1.0 - 0.5 * s1[i] / m / var,
        };
        st[i] = 0.5 * st[i] / m / var;
    }
    Some((s1, st))
}

/// Half-widths z · sd of bootstrap replicates (SALib's convention).
fn bootstrap(d: usize, y: &[f64], set: &AnalyzeSettings) -> (Vec<f64>, Vec<f64>) {
    if set.resamples < 2 {
        return (vec![0.0; d], vec![0.0; d]);
    }
    let n = y.len() / (d + 2);
    let mut rng = ChaCha8Rng::seed_from_u64(set.seed);
    let mut reps = Vec::with_capacity(set.resamples);
    let mut rows = vec![0; n];
    for _ in 0..set.resamples {
        rows.iter_mut().for_each(|r| *r = rng.random_range(0..n));
        if let Some(e) = estimate(d, y, &rows, set.first_order) {
            reps.push(e);
        }
    }
    let z = normal_quantile(0.5 + set.level / 2.0);
    let sd = |f: &dyn Fn(&Replicate) -> f64| {
        let k = reps.len() as f64;
        let m = reps.iter().map(f).sum::<f64>() / k;
        (reps.iter().map(|r| (f(r) - m).powi(2)).sum::<f64>() / (k - 1.0)).sqrt()
    };
    let s1c = (0..d).map(|i| z * sd(&|r| r.0[i])).collect();
    let stc = (0..d).map(|i| z * sd(&|r| r.1[i])).collect();
    (s1c, stc)
}

/// Standard-normal quantile by bisection on erf-free Φ (Abramowitz and
/// Stegun 26.2.17, |error| < 7.5e-8).
fn normal_quantile(p: f64) -> f64 {
    let cdf = |x: f64| {
        let t = 1.0 / (1.0 + 0.2316419 * x.abs());
        let poly = t
            * (0.319381530
                + t * (-0.356563782 + t * (1.781477937 + t * (-1.821255978 + t * 1.330274429))));
        let tail = (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt() * poly;
        if x >= 0.0 {
            1.0 - tail
        } else {
            tail
        }
    };
    let (mut lo, mut hi) = (-10.0, 10.0);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if cdf(mid) < p {
            lo = mid
        } else {
            hi = mid
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantile_of_975_is_196() {
        assert!((normal_quantile(0.975) - 1.959964).abs() < 1e-5);
    }

    #[test]
    fn offset_does_not_widen_first_order_interval() {
        let p = super::super::Problem {
            names: vec!["a".into(), "b".into()],
            bounds: vec![(0.0, 1.0); 2],
        };
        let x = super::super::saltelli_sample(&p, 1024, 3);
        let y: Vec<f64> = x.chunks(2).map(|r| r[0] + 2.0 * r[1]).collect();
        let shifted: Vec<f64> = y.iter().map(|v| v + 1000.0).collect();
        let a = analyze(2, &y, &AnalyzeSettings::default()).unwrap();
        let b = analyze(2, &shifted, &AnalyzeSettings::default()).unwrap();
        for i in 0..2 {
            assert!(
                (a.s1_conf[i] - b.s1_conf[i]).abs() < 1e-6,
                "{} vs {}",
                a.s1_conf[i],
                b.s1_conf[i]
            );
        }
    }

    #[test]
    fn additive_model_has_equal_first_and_total() {
        // y = x1 + 2 x2 on U(0,1)^2: S = (1/5, 4/5) exactly.
        let p = super::super::Problem {
            names: vec!["a".into(), "b".into()],
            bounds: vec![(0.0, 1.0); 2],
        };
        let x = super::super::saltelli_sample(&p, 4096, 3);
        let y: Vec<f64> = x.chunks(2).map(|r| r[0] + 2.0 * r[1]).collect();
        let r = analyze(2, &y, &AnalyzeSettings::default()).unwrap();
        for (s, t) in [(r.s1[0], 0.2), (r.s1[1], 0.8), (r.st[0], 0.2), (r.st[1], 0.8)] {
            assert!((s - t).abs() < 5e-3, "{s} vs {t}");
        }
    }
}
