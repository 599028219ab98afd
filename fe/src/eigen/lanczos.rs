//! Block shift-invert Lanczos with full M-reorthogonalisation (Ericsson &
//! Ruhe 1980; Grimes, Lewis & Simon 1994) for the lowest modes of
//! K φ = ω² M φ with M diagonal and possibly singular.
//!
//! Operator Op = (K − σM)⁻¹ M, symmetric in the M inner product; its
//! eigenvalues θ = 1/(ω² − σ) are largest for the lowest modes. The basis
//! grows by blocks Op(previous block), each vector M-orthogonalised twice
//! against all earlier ones; the Rayleigh-Ritz matrix H = Qᵀ M Op Q is formed
//! incrementally. Blocks of b vectors (default 2: the double modes of
//! symmetric grids) find eigenvalues of multiplicity up to b; the six
//! rigid-body modes of a free frame need b = 6. A Ritz pair (θ, y) has
//! converged when ‖Op y − θ y‖_M ≤ tol · θ (checked once the Ritz values
//! settle); then ω² = σ + 1/θ (free of the cancellation a Rayleigh quotient
//! xᵀKx suffers with stiff massless DOFs) and the shape is Z s = Op Q s,
//! exactly condensed onto the massless DOFs.

use nalgebra::{DMatrix, SymmetricEigen};

use super::factor::SparseFactor;
use super::{EigenError, Eigenpairs};
use crate::assembly::SparsePattern;

/// Settings of the Lanczos solver.
#[derive(Debug, Clone, Copy)]
pub struct LanczosSettings {
    /// Shift σ (rad²/s²); below the lowest eigenvalue keeps K − σM positive definite.
    pub shift: f64,
    /// Relative M-residual ‖Op y − θ y‖ / θ that counts as converged.
    pub tol: f64,
    /// Vectors per block (the largest multiplicity found reliably).
    pub block: usize,
    /// Seed of the deterministic start vectors.
    pub seed: u64,
}

impl Default for LanczosSettings {
    fn default() -> Self {
        LanczosSettings { shift: -1.0, tol: 1e-10, block: 2, seed: 0x5eed_ce11 }
    }
}

/// The lowest `n_modes` eigenpairs of K (values on `pattern`) and diagonal M.
pub fn shift_invert_lanczos(
    pattern: &SparsePattern,
    k_values: &[f64],
    mass: &[f64],
    n_modes: usize,
    settings: &LanczosSettings,
) -> Result<Eigenpairs, EigenError> {
    let available = mass.iter().filter(|m| **m > 0.0).count();
    if n_modes > available {
        return Err(EigenError::TooManyModes { requested: n_modes, available });
    }
    if n_modes == 0 {
        return Ok(Eigenpairs { omega2: vec![], vectors: vec![] });
    }
    let factor = shifted_factor(pattern, k_values, mass, settings.shift)?;
    let op = |x: &[f64]| -> Vec<f64> {
        let mut y: Vec<f64> = x.iter().zip(mass).map(|(a, m)| a * m).collect();
        factor.solve_in_place(&mut y);
        y
    };
    let mut basis = Basis::new(mass, settings.seed);
    let mut block = basis.random_block(settings.block, &op);
    let mut previous: Vec<f64> = vec![];
    let mut checked_at = 0;
    loop {
        block = basis.extend(block, &op);
        let full = basis.q.len() >= available;
        // Rayleigh-Ritz costs O(m³): look every 4 new vectors.
        if basis.q.len() >= n_modes && (basis.q.len() >= checked_at + 4 || full) {
            checked_at = basis.q.len();
            let mut ritz = basis.ritz(n_modes);
            // Residuals cost O(n m N); compute them once the Ritz values settle.
            let settled = previous.len() == n_modes
                && ritz
                    .iter()
                    .zip(&previous)
                    .all(|(r, p)| (r.theta - p).abs() <= 1e-9 * r.theta.abs());
            previous = ritz.iter().map(|r| r.theta).collect();
            if settled || full {
                basis.residuals(&mut ritz);
                let converged =
                    ritz.iter().filter(|r| r.residual <= settings.tol * r.theta.abs()).count();
                if converged == n_modes {
                    return Ok(finish(settings.shift, &basis, &ritz));
                }
                if full {
                    let steps = basis.q.len();
                    return Err(EigenError::NoConvergence { converged, requested: n_modes, steps });
                }
            }
        }
        if block.is_empty() && !full {
            block = basis.random_block(settings.block, &op);
        }
    }
}

/// Factorizes K − σM.
fn shifted_factor(
    pattern: &SparsePattern,
    k_values: &[f64],
    mass: &[f64],
    shift: f64,
) -> Result<SparseFactor, EigenError> {
    let mut a = k_values.to_vec();
    for (c, m) in mass.iter().enumerate() {
        if let Some(p) = pattern.position(c, c) {
            a[p] -= shift * m;
        }
    }
    SparseFactor::new(pattern, &a).map_err(|message| EigenError::Singular { shift, message })
}

/// One Ritz pair: θ, its coefficients in the basis, its M-residual.
struct Ritz {
    theta: f64,
    coeffs: Vec<f64>,
    residual: f64,
}

/// The M-orthonormal basis Q and the images Z = Op Q.
struct Basis<'a> {
    mass: &'a [f64],
    q: Vec<Vec<f64>>,
    z: Vec<Vec<f64>>,
    /// M q for each basis vector.
    mq: Vec<Vec<f64>>,
    /// H[r][c] = q_r' M z_c, grown as vectors are added.
    h: Vec<Vec<f64>>,
    rng: u64,
}

impl<'a> Basis<'a> {
    fn new(mass: &'a [f64], seed: u64) -> Self {
        Basis { mass, q: vec![], z: vec![], mq: vec![], h: vec![], rng: seed | 1 }
    }

    /// Op applied to `size` deterministic pseudo-random vectors (xorshift64*).
    fn random_block(&mut self, size: usize, op: &dyn Fn(&[f64]) -> Vec<f64>) -> Vec<Vec<f64>> {
        (0..size.max(1))
            .map(|_| {
                let r: Vec<f64> = (0..self.mass.len())
                    .map(|_| {
                        self.rng ^= self.rng >> 12;
                        self.rng ^= self.rng << 25;
                        self.rng ^= self.rng >> 27;
                        let r = self.rng.wrapping_mul(0x2545_f491_4f6c_dd1d);
                        (r >> 11) as f64 / (1u64 << 52) as f64 - 1.0
                    })
                    .collect();
                op(&r)
            })
            .collect()
    }

    fn dot_m(&self, a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).zip(self.mass).map(|((x, y), m)| x * y * m).sum()
    }

    /// Removes the basis' components from `w` (twice is enough).
    fn orthogonalize(&self, w: &mut [f64]) {
        for _ in 0..2 {
            for (q, mq) in self.q.iter().zip(&self.mq) {
                let c = dot(mq, w);
                w.iter_mut().zip(q).for_each(|(a, b)| *a -= c * b);
            }
        }
    }

    /// Adds the block's independent directions to Q; returns their images.
    fn extend(&mut self, block: Vec<Vec<f64>>, op: &dyn Fn(&[f64]) -> Vec<f64>) -> Vec<Vec<f64>> {
        let mut next = Vec::with_capacity(block.len());
        for mut w in block {
            let before = self.dot_m(&w, &w).sqrt();
            self.orthogonalize(&mut w);
            let after = self.dot_m(&w, &w).sqrt();
            if !(after > 1e-10 * before) || self.q.len() >= self.mass.len() {
                continue;
            }
            w.iter_mut().for_each(|v| *v /= after);
            let z = op(&w);
            self.mq.push(w.iter().zip(self.mass).map(|(a, m)| a * m).collect());
            self.q.push(w);
            self.z.push(z.clone());
            self.grow_h();
            next.push(z);
        }
        next
    }

    /// Adds the last vector's row and column to H.
    fn grow_h(&mut self) {
        let last = self.q.len() - 1;
        let row: Vec<f64> = (0..=last).map(|c| dot(&self.mq[last], &self.z[c])).collect();
        for r in 0..last {
            let v = dot(&self.mq[r], &self.z[last]);
            self.h[r].push(v);
        }
        self.h.push(row);
    }

    /// The `n` Ritz pairs of largest θ (residuals not yet computed).
    fn ritz(&self, n: usize) -> Vec<Ritz> {
        let m = self.q.len();
        let mut h = DMatrix::from_fn(m, m, |r, c| self.h[r][c]);
        h = (&h + h.transpose()) * 0.5;
        let eig = SymmetricEigen::new(h);
        let mut order: Vec<usize> = (0..m).collect();
        order.sort_by(|a, b| eig.eigenvalues[*b].total_cmp(&eig.eigenvalues[*a]));
        order
            .into_iter()
            .take(n)
            .map(|k| Ritz {
                theta: eig.eigenvalues[k],
                coeffs: eig.eigenvectors.column(k).iter().copied().collect(),
                residual: f64::INFINITY,
            })
            .collect()
    }

    /// Fills in ‖Z s − θ Q s‖_M of each Ritz pair.
    fn residuals(&self, ritz: &mut [Ritz]) {
        for r in ritz.iter_mut() {
            let mut v = vec![0.0; self.mass.len()];
            for ((q, z), c) in self.q.iter().zip(&self.z).zip(&r.coeffs) {
                v.iter_mut()
                    .zip(q.iter().zip(z))
                    .for_each(|(a, (qv, zv))| *a += c * (zv - r.theta * qv));
            }
            r.residual = self.dot_m(&v, &v).sqrt();
        }
    }
}

/// Plain dot product.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Ritz vectors Z s = Op Q s, M-normalisation, ω² = σ + 1/θ.
fn finish(shift: f64, basis: &Basis, ritz: &[Ritz]) -> Eigenpairs {
    let n = basis.mass.len();
    let mut pairs: Vec<(f64, Vec<f64>)> = ritz
        .iter()
        .map(|r| {
            let mut y = vec![0.0; n];
            for (z, c) in basis.z.iter().zip(&r.coeffs) {
                y.iter_mut().zip(z).for_each(|(a, b)| *a += c * b);
            }
            // y = Op (Q s): already in the range of Op, i.e. condensed.
            let mut x = y;
            let xm = basis.dot_m(&x, &x).sqrt();
            x.iter_mut().for_each(|v| *v /= xm);
            normalize_sign(&mut x);
            let omega2 = shift + 1.0 / r.theta;
            (omega2, x)
        })
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (omega2, vectors) = pairs.into_iter().unzip();
    Eigenpairs { omega2, vectors }
}

/// Makes the largest-magnitude component positive.
pub fn normalize_sign(x: &mut [f64]) {
    let big = x.iter().copied().fold(0.0_f64, |m, v| if v.abs() > m.abs() { v } else { m });
    if big < 0.0 {
        x.iter_mut().for_each(|v| *v = -*v);
    }
}
