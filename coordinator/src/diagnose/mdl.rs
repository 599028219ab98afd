//! Minimum description length of a calibrated variant (seed eq. 3.63):
//! MDL = −log f(x|θ̂) + k/2 · log(N/2π) + log ∫ √det I(θ) dθ, over the
//! variant's prior box in unit-cube coordinates (volume 1). N is the total
//! effective sample size; the per-sample Fisher information I(θ) is taken
//! as |H(θ)|/N, H the Hessian of the emulated −log L (finite differences on
//! the GP mean, eigenvalues made non-negative by their absolute value and
//! floored at 2π so that a parameter the data cannot see adds no negative
//! complexity: k/2·log(N/2π) + ½·log(λ/N) ≥ 0 per direction), and the
//! integral is a quasi-Monte-Carlo mean over scrambled Sobol' points, with
//! its standard error. An extension calibrated with the baseline's
//! parameters held ([`super::calibrate::calibrate`] with `base`) takes the
//! baseline's geometric term for those (Fisher information taken
//! block-diagonal). When the calibration ends with Gauss–Newton steps, the
//! Fisher information is taken constant over the box at its value at θ̂
//! ([`laplace_geometric`]; then MDL is the Laplace approximation of the
//! negative log evidence under the uniform prior), and the Gauss–Newton
//! matrix gives the posterior spread.

use super::calibrate::Calibration;
use crate::design::draw;
use crate::study::DesignMethod;
use nalgebra::{DMatrix, SymmetricEigen};
use stats::gp::Gp;

/// The terms of one variant's MDL.
#[derive(Debug, Clone, PartialEq)]
pub struct Mdl {
    /// −log f(x|θ̂).
    pub fit: f64,
    /// k/2 · log(N/2π).
    pub parametric: f64,
    /// log ∫ √det I(θ) dθ.
    pub geometric: f64,
    /// Standard error of the geometric term (delta method).
    pub geometric_se: f64,
    /// Sum of the three.
    pub total: f64,
    /// Parameters k.
    pub k: usize,
    /// Effective samples N.
    pub n_eff: f64,
}

/// Hessian of the GP mean at `u` (unit cube), central differences of step
/// `h` (the centre moved inside the cube by `h` so that no point leaves it).
pub fn gp_hessian(gp: &Gp, u: &[f64], h: f64) -> Option<DMatrix<f64>> {
    let d = u.len();
    let u: Vec<f64> = u.iter().map(|x| x.clamp(h, 1.0 - h)).collect();
    let u = u.as_slice();
    let at = |du: &[(usize, f64)]| {
        let mut x = u.to_vec();
        for (i, s) in du {
            x[*i] = (x[*i] + s).clamp(0.0, 1.0);
        }
        x
    };
    let mut pts = vec![u.to_vec()];
    for i in 0..d {
        for j in i..d {
            for (si, sj) in [(h, h), (h, -h), (-h, h), (-h, -h)] {
                pts.push(if i == j { at(&[(i, si)]) } else { at(&[(i, si), (j, sj)]) });
            }
        }
    }
    let flat: Vec<f64> = pts.iter().flatten().copied().collect();
    let m = gp.predict(&flat, false).ok()?.mean;
    let mut hm = DMatrix::zeros(d, d);
    let mut k = 1;
    for i in 0..d {
        for j in i..d {
            let (pp, pm, mp, mm) = (m[k], m[k + 1], m[k + 2], m[k + 3]);
            // i == j: the four points are +h, +h, −h, −h along i.
            k += 4;
            let _ = (pm, mp);
            let v = if i == j {
                (pp - 2.0 * m[0] + mm) / (h * h)
            } else {
                (pp - pm - mp + mm) / (4.0 * h * h)
            };
            hm[(i, j)] = v;
            hm[(j, i)] = v;
        }
    }
    Some(hm)
}

/// Eigenvalues of a symmetric matrix made non-negative, floored at `floor`.
fn abs_eigen(h: &DMatrix<f64>, floor: f64) -> (Vec<f64>, DMatrix<f64>) {
    let e = SymmetricEigen::new(h.clone());
    (e.eigenvalues.iter().map(|l| l.abs().max(floor)).collect(), e.eigenvectors)
}

/// The MDL of a calibrated variant under weights `n_eff`; `held` is the
/// geometric term (and its se) of the dimensions the calibration held.
pub fn mdl(cal: &Calibration, gp: Option<&Gp>, n_eff: &[f64], held: (f64, f64)) -> Option<Mdl> {
    let best = cal.best(n_eff)?;
    let fit = cal.objective(n_eff)[best];
    let k = cal.priors.len();
    let n: f64 = n_eff.iter().sum();
    let parametric = 0.5 * k as f64 * (n / (2.0 * std::f64::consts::PI)).ln();
    let (geometric, geometric_se) = if let Some(h) = &cal.gauss_newton {
        (laplace_geometric(h, n), 0.0)
    } else {
        let (g, se) = match (cal.free.len(), gp) {
            (0, _) => (0.0, 0.0),
            (d, Some(gp)) => geometric_term(gp, d, n)?,
            (_, None) => return None,
        };
        (g + held.0, (se * se + held.1 * held.1).sqrt())
    };
    Some(Mdl {
        fit,
        parametric,
        geometric,
        geometric_se,
        total: fit + parametric + geometric,
        k,
        n_eff: n,
    })
}

/// log ∫ √det(|H|/N) over the unit cube of the emulator's `k` inputs, and its se.
pub fn geometric_term(gp: &Gp, k: usize, n: f64) -> Option<(f64, f64)> {
    let pts = draw(DesignMethod::Sobol, 64, k, 17);
    let mut vals = Vec::with_capacity(pts.n());
    for i in 0..pts.n() {
        let h = gp_hessian(gp, pts.row(i), 0.02)?;
        let (l, _) = abs_eigen(&h, 2.0 * std::f64::consts::PI);
        vals.push(l.iter().map(|x| (x / n).sqrt()).product::<f64>());
    }
    let m = vals.iter().sum::<f64>() / vals.len() as f64;
    let var = vals.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (vals.len() as f64 - 1.0);
    let se = (var / vals.len() as f64).sqrt();
    Some((m.max(1e-300).ln(), se / m.max(1e-300)))
}

/// The geometric term with the Fisher information constant over the box at
/// its value at θ̂, H/N (H the Gauss–Newton matrix of −log L at θ̂): then
/// k/2·log(N/2π) + this = ½·Σ log(max(λᵢ, 2π)/2π), the Laplace Occam factor.
pub fn laplace_geometric(h: &DMatrix<f64>, n: f64) -> f64 {
    let (l, _) = abs_eigen(h, 2.0 * std::f64::consts::PI);
    l.iter().map(|x| 0.5 * (x / n).ln()).sum()
}

/// Standard deviations (unit cube) from a Gauss–Newton matrix, at most 1.
pub fn gn_sd(h: &DMatrix<f64>) -> Vec<f64> {
    let (l, v) = abs_eigen(h, 1e-9);
    let d = h.nrows();
    (0..d).map(|i| (0..d).map(|j| v[(i, j)].powi(2) / l[j]).sum::<f64>().sqrt().min(1.0)).collect()
}

/// Laplace posterior standard deviations (unit cube) at `u`.
pub fn laplace_sd(gp: &Gp, u: &[f64]) -> Option<Vec<f64>> {
    let h = gp_hessian(gp, u, 0.02)?;
    let (l, v) = abs_eigen(&h, 1e-9);
    let d = u.len();
    Some(
        (0..d)
            .map(|i| (0..d).map(|j| v[(i, j)].powi(2) / l[j]).sum::<f64>().sqrt().min(1.0))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use stats::gp::{fit, GpSettings, InputScaling};

    /// A GP through a quadratic returns its Hessian; the geometric term of a
    /// constant Hessian H over the unit square is ½ log det(H/N).
    #[test]
    fn hessian_and_geometric_term_of_a_quadratic() {
        let f = |u: &[f64]| {
            50.0 * (u[0] - 0.5).powi(2) + 20.0 * (u[1] - 0.3).powi(2) + 10.0 * u[0] * u[1]
        };
        let pts = draw(DesignMethod::MaximinLhs, 30, 2, 5);
        let y: Vec<f64> = (0..pts.n()).map(|i| f(pts.row(i))).collect();
        let scaling = InputScaling { lo: vec![0.0; 2], hi: vec![1.0; 2] };
        let gp =
            fit(&pts.x, 2, &y, Some(scaling), &GpSettings { restarts: 2, ..Default::default() })
                .unwrap();
        let h = gp_hessian(&gp, &[0.5, 0.5], 0.02).unwrap();
        for (got, want) in [(h[(0, 0)], 100.0), (h[(1, 1)], 40.0), (h[(0, 1)], 10.0)] {
            assert!((got - want).abs() < 0.05 * 100.0, "{got} vs {want}");
        }
        let n = 1000.0;
        let (g, _) = geometric_term(&gp, 2, n).unwrap();
        let exact = 0.5 * ((100.0 * 40.0 - 100.0) / (n * n)).ln();
        assert!((g - exact).abs() < 0.05, "{g} vs {exact}");
    }
}
