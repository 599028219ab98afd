//! Log marginal likelihood of a zero-mean GP with white noise and its
//! analytic gradient in log space (Rasmussen and Williams 2006, eq. 2.30
//! and 5.9): ∂L/∂θ_j = ½ tr((α αᵀ − K⁻¹) ∂K/∂θ_j), with W = α αᵀ − K⁻¹
//! formed once per evaluation. Cost O(n³ + d n²). The full parameter
//! vector is θ = [kernel θ.., warp exponents λ.., ln σ²_noise] (no λ when
//! no input is warped); inputs x are (n, d) row-major.

use super::error::GpError;
use super::kernel::{Kernel, KernelKind};
use super::lml_workspace::LmlWorkspace;
use faer::linalg::solvers::Solve;
use faer::Mat;

/// Jitters tried in turn (relative to the signal variance) when the
/// Cholesky factorisation fails.
pub const JITTERS: [f64; 6] = [0.0, 1e-10, 1e-9, 1e-8, 1e-7, 1e-6];

/// Cholesky factor of K + σ²I (+ jitter) and the weights α = K⁻¹ y.
pub struct Factor {
    /// Lower Cholesky factor.
    pub llt: faer::linalg::solvers::Llt<f64>,
    /// α = K⁻¹ y, (n).
    pub alpha: Vec<f64>,
    /// Jitter that was needed (absolute, added to the diagonal).
    pub jitter: f64,
}

/// Covariance K(x, x) + σ² I of the (n, d) row-major points `x`.
pub fn covariance(kernel: &Kernel, noise_var: f64, x: &[f64], d: usize) -> Mat<f64> {
    let n = x.len() / d;
    let mut k = Mat::<f64>::zeros(n, n);
    for i in 0..n {
        let xi = &x[i * d..(i + 1) * d];
        k[(i, i)] = kernel.variance + noise_var;
        for j in 0..i {
            let v = kernel.eval(xi, &x[j * d..(j + 1) * d]);
            k[(i, j)] = v;
            k[(j, i)] = v;
        }
    }
    k
}

/// Factor K + σ² I, escalating the jitter on failure.
pub fn factor(
    kernel: &Kernel,
    noise_var: f64,
    x: &[f64],
    d: usize,
    y: &[f64],
) -> Result<Factor, GpError> {
    let k = covariance(kernel, noise_var, x, d);
    factor_matrix(k, kernel.variance, y)
}

/// Factor a given covariance, escalating the jitter (relative to `scale`).
pub fn factor_matrix(mut k: Mat<f64>, scale: f64, y: &[f64]) -> Result<Factor, GpError> {
    factor_lower(&mut k, scale, y)
}

fn factor_lower(k: &mut Mat<f64>, scale: f64, y: &[f64]) -> Result<Factor, GpError> {
    let n = k.nrows();
    let mut added = 0.0;
    for rel in JITTERS {
        let jitter = rel * scale;
        for i in 0..n {
            k[(i, i)] += jitter - added;
        }
        added = jitter;
        if let Ok(llt) = k.as_ref().llt(faer::Side::Lower) {
            let mut rhs = Mat::<f64>::from_fn(n, 1, |i, _| y[i]);
            llt.solve_in_place(rhs.as_mut());
            let alpha = (0..n).map(|i| rhs[(i, 0)]).collect();
            return Ok(Factor { llt, alpha, jitter });
        }
    }
    Err(GpError::NotPositiveDefinite { jitter: JITTERS[JITTERS.len() - 1] * scale, n })
}

/// Log-likelihood value from a factor: −½ yᵀα − Σ ln L_ii − n/2 ln 2π.
pub fn lml_from_factor(f: &Factor, y: &[f64]) -> f64 {
    let l = f.llt.L();
    let n = y.len();
    let fit: f64 = y.iter().zip(&f.alpha).map(|(a, b)| a * b).sum();
    let logdet: f64 = (0..n).map(|i| l[(i, i)].ln()).sum();
    -0.5 * fit - logdet - 0.5 * n as f64 * (2.0 * std::f64::consts::PI).ln()
}

/// Log marginal likelihood and its gradient with respect to θ.
pub fn lml_and_grad(
    kind: KernelKind,
    theta: &[f64],
    x: &[f64],
    d: usize,
    y: &[f64],
) -> Result<(f64, Vec<f64>), GpError> {
    lml_and_grad_shared(kind, theta, x, d, &[y])
}

/// Sum over outputs `ys` (each (n), sharing one kernel and noise) of the
/// log marginal likelihoods, and its gradient: W = Σ_c α_c α_cᵀ − m K⁻¹.
pub fn lml_and_grad_shared(
    kind: KernelKind,
    theta: &[f64],
    x: &[f64],
    d: usize,
    ys: &[&[f64]],
) -> Result<(f64, Vec<f64>), GpError> {
    lml_and_grad_warped(kind, &[], theta, x, d, ys)
}

/// As [`lml_and_grad_shared`] with inputs power-warped: `ratios` (one per
/// input, or empty) marks the warped inputs, whose exponents λ follow the
/// kernel parameters: θ = [kernel θ.., λ.., ln σ²] (see [`LmlWorkspace`]).
pub fn lml_and_grad_warped(
    kind: KernelKind,
    ratios: &[Option<f64>],
    theta: &[f64],
    x: &[f64],
    d: usize,
    ys: &[&[f64]],
) -> Result<(f64, Vec<f64>), GpError> {
    LmlWorkspace::default().lml_and_grad(kind, ratios, theta, x, d, ys)
}
