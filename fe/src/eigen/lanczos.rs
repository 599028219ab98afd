//! Block shift-invert Lanczos with full reorthogonalisation (Ericsson &
//! Ruhe 1980; Grimes, Lewis & Simon 1994) for the lowest modes of
//! K φ = ω² M φ with M diagonal and possibly singular.
//!
//! The iteration runs on the mass-scaled operator Op = M½ (K − σM)⁻¹ M½
//! restricted to the DOFs with mass ([`ScaledShiftInvert`]): symmetric in
//! the plain inner product, eigenvalues θ = 1/(ω² − σ), largest for the
//! lowest modes. The basis Q grows by blocks Op(previous block), each block
//! orthogonalised twice against all earlier vectors (classical Gram-Schmidt,
//! twice is enough) as dense matrix products; the Rayleigh-Ritz matrix
//! H = Qᵀ Op Q is formed incrementally. Blocks of b vectors (default 2: the
//! double modes of symmetric grids) find eigenvalues of multiplicity up to
//! b; the six rigid-body modes of a free frame need b = 6.
//!
//! A Ritz pair (θ, s) has converged when ‖Op Q s − θ Q s‖ ≤ tol · θ (the
//! M-norm of the residual of the unscaled problem). Since Op Q = Q H + W
//! with W the next block's directions before normalisation, the residual
//! costs almost nothing to estimate after every block; once every estimate
//! passes, the residuals are computed explicitly and decide. Then
//! ω² = σ + 1/θ (free of the cancellation a Rayleigh quotient xᵀKx suffers
//! with stiff massless DOFs) and the shape is (K − σM)⁻¹ M Q s, exactly
//! condensed onto the massless DOFs.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};

use super::factor::SparseFactor;
use super::ordering::node_block_amd;
use super::shift_invert::{ScaledShiftInvert, ShiftedFactor};
use super::supernodal::SupernodalCholesky;
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
    let mut op = ScaledShiftInvert::new(&factor, mass);
    // Room for the usual basis (4 to 5 vectors per mode on the ceiling grids).
    let room = available.min(4 * n_modes + 6 * settings.block.max(1));
    let mut basis = Basis::new(op.dim(), op.n_equations(), room);
    let mut rng = settings.seed | 1;
    let block = settings.block.max(1);
    // Start from Op(random): one step of power iteration damps the high modes.
    let start = basis.random_block(block, &mut rng);
    let mut next = basis.start_images(start, &mut op);
    let mut skip: usize = 0;
    loop {
        basis.push(next, &mut op);
        let full = basis.len >= available;
        let images = basis.projected_last_images();
        if basis.len >= n_modes && (skip == 0 || full) {
            match look(&basis, &images, n_modes, settings, full)? {
                Look::Done(pairs) => return Ok(pairs),
                Look::Again(blocks) => skip = blocks,
            }
        } else {
            skip = skip.saturating_sub(1);
        }
        next = basis.orthonormalize(images.0, &images.1);
        if next.ncols() == 0 {
            next = basis.random_block(block, &mut rng);
        }
        if next.ncols() == 0 {
            let steps = basis.len;
            return Err(EigenError::NoConvergence { converged: 0, requested: n_modes, steps });
        }
    }
}

/// What one Rayleigh-Ritz look at the basis decides.
enum Look {
    /// Every requested pair has converged.
    Done(Eigenpairs),
    /// Grow the basis; look again after this many more blocks.
    Again(usize),
}

/// A Rayleigh-Ritz look: the cheap residual estimates first, the explicit
/// residuals once every estimate passes (or the basis can grow no more, when
/// anything short of convergence is an error).
fn look(
    basis: &Basis,
    images: &(Mat<f64>, Vec<f64>),
    n_modes: usize,
    settings: &LanczosSettings,
    full: bool,
) -> Result<Look, EigenError> {
    let stuck =
        |converged| EigenError::NoConvergence { converged, requested: n_modes, steps: basis.len };
    let ritz = basis.ritz(n_modes).ok_or_else(|| stuck(0))?;
    let estimated = ritz.estimates(images, basis.len);
    let worst = ritz.worst_ratio(&estimated, settings.tol);
    if full || worst <= 1.0 {
        let residuals = basis.residuals(&ritz);
        let converged = ritz.converged(&residuals, settings.tol);
        if converged == n_modes {
            return Ok(Look::Done(finish(settings.shift, basis, &ritz)));
        }
        if full {
            return Err(stuck(converged));
        }
    }
    Ok(Look::Again(blocks_to_skip(worst)))
}

/// Blocks to add before the next Rayleigh-Ritz look, from the worst ratio
/// of estimated residual to tolerance: none within 10⁶ of convergence, then
/// one more per factor 10³ (the ratio falls by 2–20x per block on the
/// ceiling grids, so the look after is still early). Only the cost of
/// looking changes, not the test.
fn blocks_to_skip(worst: f64) -> usize {
    if !worst.is_finite() || worst <= 1e6 {
        return 0;
    }
    ((worst.log10() / 3.0).floor() as usize).saturating_sub(1).min(4)
}

/// Factorizes K − σM.
fn shifted_factor(
    pattern: &SparsePattern,
    k_values: &[f64],
    mass: &[f64],
    shift: f64,
) -> Result<ShiftedFactor, EigenError> {
    let mut a = k_values.to_vec();
    for (c, m) in mass.iter().enumerate() {
        if let Some(p) = pattern.position(c, c) {
            a[p] -= shift * m;
        }
    }
    match SupernodalCholesky::new(pattern, &a, &node_block_amd(pattern)) {
        Ok(l) => Ok(ShiftedFactor::Cholesky(Box::new(l))),
        Err(_) => SparseFactor::new(pattern, &a)
            .map(ShiftedFactor::General)
            .map_err(|message| EigenError::Singular { shift, message }),
    }
}

/// Columns of one length, appended in place (amortised growth).
struct Columns {
    rows: usize,
    data: Vec<f64>,
}

impl Columns {
    fn new(rows: usize, cols: usize) -> Self {
        Columns { rows, data: Vec::with_capacity(rows * cols) }
    }

    fn ncols(&self) -> usize {
        self.data.len() / self.rows.max(1)
    }

    fn view(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.data, self.rows, self.ncols())
    }

    /// Appends `k` zero columns; returns them.
    fn append(&mut self, k: usize) -> MatMut<'_, f64> {
        let start = self.data.len();
        self.data.resize(start + k * self.rows, 0.0);
        MatMut::from_column_major_slice_mut(&mut self.data[start..], self.rows, k)
    }
}

/// The `n` Ritz pairs of largest θ: values and coefficient columns (m × n).
struct Ritz {
    theta: Vec<f64>,
    coeffs: Mat<f64>,
}

impl Ritz {
    /// Largest ratio of residual to tol · |θ| over the pairs.
    fn worst_ratio(&self, residuals: &[f64], tol: f64) -> f64 {
        residuals.iter().zip(&self.theta).map(|(r, t)| r / (tol * t.abs())).fold(0.0, f64::max)
    }

    /// Number of pairs with residual ≤ tol · |θ|.
    fn converged(&self, residuals: &[f64], tol: f64) -> usize {
        residuals.iter().zip(&self.theta).filter(|(r, t)| **r <= tol * t.abs()).count()
    }

    /// ‖W s_last‖ per pair: the residual norms from the relation
    /// Op Q = Q H + W, `images` = (W, the number of columns of Q whose
    /// images W holds, i.e. the last block).
    fn estimates(&self, images: &(Mat<f64>, Vec<f64>), m: usize) -> Vec<f64> {
        let w = &images.0;
        let last = w.ncols();
        let s_last = self.coeffs.as_ref().subrows(m - last, last);
        let mut r = Mat::zeros(w.nrows(), self.theta.len());
        matmul(r.as_mut(), Accum::Replace, w.as_ref(), s_last, 1.0, Par::Seq);
        (0..r.ncols()).map(|j| r.col(j).norm_l2()).collect()
    }
}

/// The orthonormal basis Q (scaled coordinates), its images Op Q, their
/// unscaled full-length versions, and H = Qᵀ Op Q.
struct Basis {
    q: Columns,
    z: Columns,
    z_full: Columns,
    h: Mat<f64>,
    len: usize,
    /// Columns added by the last block.
    last_block: usize,
    /// Qᵀ (images of the last block), H's last columns.
    last_coeffs: Mat<f64>,
}

impl Basis {
    /// An empty basis with room for `cols` vectors before any reallocation.
    fn new(dim: usize, n: usize, cols: usize) -> Self {
        Basis {
            q: Columns::new(dim, cols),
            z: Columns::new(dim, cols),
            z_full: Columns::new(n, cols),
            h: Mat::zeros(0, 0),
            len: 0,
            last_block: 0,
            last_coeffs: Mat::zeros(0, 0),
        }
    }

    /// `size` deterministic pseudo-random directions (xorshift64*),
    /// orthonormalised against the basis.
    fn random_block(&self, size: usize, rng: &mut u64) -> Mat<f64> {
        let w = Mat::from_fn(self.q.rows, size, |_, _| {
            *rng ^= *rng >> 12;
            *rng ^= *rng << 25;
            *rng ^= *rng >> 27;
            let r = rng.wrapping_mul(0x2545_f491_4f6c_dd1d);
            (r >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        });
        let before: Vec<f64> = (0..size).map(|j| w.col(j).norm_l2()).collect();
        let mut w = w;
        self.project(w.as_mut());
        self.orthonormalize(w, &before)
    }

    /// Op applied to an empty basis' start block, orthonormalised.
    fn start_images(&self, start: Mat<f64>, op: &mut ScaledShiftInvert) -> Mat<f64> {
        let k = start.ncols();
        let mut full = Mat::zeros(self.z_full.rows, k);
        let mut w = Mat::zeros(self.q.rows, k);
        op.apply(start.as_ref(), full.as_mut(), w.as_mut());
        let before: Vec<f64> = (0..k).map(|j| w.col(j).norm_l2()).collect();
        self.orthonormalize(w, &before)
    }

    /// w ← (I − Q Qᵀ)² w.
    fn project(&self, mut w: MatMut<'_, f64>) {
        if self.len == 0 {
            return;
        }
        let q = self.q.view();
        let mut c = Mat::zeros(self.len, w.ncols());
        for _ in 0..2 {
            matmul(c.as_mut(), Accum::Replace, q.transpose(), w.as_ref(), 1.0, Par::Seq);
            matmul(w.as_mut(), Accum::Add, q, c.as_ref(), -1.0, Par::Seq);
        }
    }

    /// Images of the last block, projected twice against the basis (the
    /// first coefficients are H's last columns), with their norms before
    /// the projection.
    fn projected_last_images(&self) -> (Mat<f64>, Vec<f64>) {
        let z = self.z.view();
        let last = z.ncols() - self.last_block;
        let mut w = z.subcols(last, self.last_block).to_owned();
        let before = (0..w.ncols()).map(|j| w.col(j).norm_l2()).collect();
        let q = self.q.view();
        matmul(w.as_mut(), Accum::Add, q, self.last_coeffs.as_ref(), -1.0, Par::Seq);
        let mut c = Mat::zeros(self.len, w.ncols());
        matmul(c.as_mut(), Accum::Replace, q.transpose(), w.as_ref(), 1.0, Par::Seq);
        matmul(w.as_mut(), Accum::Add, q, c.as_ref(), -1.0, Par::Seq);
        (w, before)
    }

    /// Orthonormalises the columns of `w` (already projected against the
    /// basis) among themselves, dropping those that lose all but 1e-10 of
    /// their norm `before`, and at most as many as the space has left.
    fn orthonormalize(&self, w: Mat<f64>, before: &[f64]) -> Mat<f64> {
        let room = self.q.rows - self.len;
        let mut kept: Vec<Vec<f64>> = Vec::with_capacity(w.ncols());
        for (j, &norm_before) in before[..w.ncols()].iter().enumerate() {
            if kept.len() >= room {
                break;
            }
            let mut v: Vec<f64> = w.col(j).iter().copied().collect();
            for _ in 0..2 {
                for k in &kept {
                    let c = dot(k, &v);
                    v.iter_mut().zip(k).for_each(|(a, b)| *a -= c * b);
                }
            }
            let after = dot(&v, &v).sqrt();
            if after > 1e-10 * norm_before {
                v.iter_mut().for_each(|a| *a /= after);
                kept.push(v);
            }
        }
        Mat::from_fn(self.q.rows, kept.len(), |i, j| kept[j][i])
    }

    /// Appends orthonormal directions and their images; grows H.
    fn push(&mut self, block: Mat<f64>, op: &mut ScaledShiftInvert) {
        let (m0, k) = (self.len, block.ncols());
        self.q.append(k).copy_from(block.as_ref());
        op.apply(block.as_ref(), self.z_full.append(k), self.z.append(k));
        self.len += k;
        self.last_block = k;
        let m = self.len;
        let (q, z) = (self.q.view(), self.z.view());
        // New columns of H, Qᵀ z_new; the rows mirror them (H is symmetric in
        // exact arithmetic). They are also the first Gram-Schmidt
        // coefficients of the next block, z_new.
        let mut cols = Mat::zeros(m, k);
        matmul(cols.as_mut(), Accum::Replace, q.transpose(), z.subcols(m0, k), 1.0, Par::Seq);
        self.h.resize_with(m, m, |_, _| 0.0);
        for j in 0..k {
            for r in 0..m {
                self.h[(r, m0 + j)] = cols[(r, j)];
                if r < m0 {
                    self.h[(m0 + j, r)] = cols[(r, j)];
                }
            }
        }
        self.last_coeffs = cols;
    }

    /// The `n` Ritz pairs of largest θ (`None` if H holds non-finite values).
    fn ritz(&self, n: usize) -> Option<Ritz> {
        let m = self.len;
        let h = Mat::from_fn(m, m, |r, c| 0.5 * (self.h[(r, c)] + self.h[(c, r)]));
        let eig = h.self_adjoint_eigen(Side::Lower).ok()?;
        let (s, u) = (eig.S(), eig.U());
        // Ascending order: the largest θ are the last columns.
        let theta = (0..n).map(|k| s[m - 1 - k]).collect();
        let coeffs = Mat::from_fn(m, n, |r, k| u[(r, m - 1 - k)]);
        Some(Ritz { theta, coeffs })
    }

    /// Explicit ‖Op Q s − θ Q s‖ per Ritz pair.
    fn residuals(&self, ritz: &Ritz) -> Vec<f64> {
        let mut r = Mat::zeros(self.q.rows, ritz.theta.len());
        matmul(r.as_mut(), Accum::Replace, self.z.view(), ritz.coeffs.as_ref(), 1.0, Par::Seq);
        let scaled =
            Mat::from_fn(self.len, ritz.theta.len(), |i, k| ritz.coeffs[(i, k)] * ritz.theta[k]);
        matmul(r.as_mut(), Accum::Add, self.q.view(), scaled.as_ref(), -1.0, Par::Seq);
        (0..r.ncols()).map(|j| r.col(j).norm_l2()).collect()
    }
}

/// Plain dot product.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Shapes (K − σM)⁻¹ M Q s, M-normalised; ω² = σ + 1/θ; ascending.
fn finish(shift: f64, basis: &Basis, ritz: &Ritz) -> Eigenpairs {
    let n_modes = ritz.theta.len();
    let mut x = Mat::zeros(basis.z_full.rows, n_modes);
    matmul(x.as_mut(), Accum::Replace, basis.z_full.view(), ritz.coeffs.as_ref(), 1.0, Par::Seq);
    // ‖x‖_M = ‖Op Q s‖ in scaled coordinates.
    let mut zs = Mat::zeros(basis.q.rows, n_modes);
    matmul(zs.as_mut(), Accum::Replace, basis.z.view(), ritz.coeffs.as_ref(), 1.0, Par::Seq);
    let mut pairs: Vec<(f64, Vec<f64>)> = (0..n_modes)
        .map(|k| {
            let norm = zs.col(k).norm_l2();
            let mut v: Vec<f64> = x.col(k).iter().map(|a| a / norm).collect();
            normalize_sign(&mut v);
            (shift + 1.0 / ritz.theta[k], v)
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

#[cfg(test)]
mod tests {
    use super::super::dense::dense_eigen;
    use super::*;

    /// A chain of 12 equations, every third one massless: all eight modes
    /// (the basis fills the massed space) equal the condensed dense answer,
    /// for blocks of 1, 2 and 3.
    #[test]
    fn all_modes_of_a_chain_match_the_dense_solver() {
        let (p, k) = SparsePattern::chain(12, 0.3);
        let mass: Vec<f64> =
            (0..12).map(|i| if i % 3 == 2 { 0.0 } else { 1.0 + 0.1 * i as f64 }).collect();
        let dense = dense_eigen(&p, &k, &mass).unwrap();
        for block in 1..=3 {
            let settings = LanczosSettings { block, ..Default::default() };
            let got = shift_invert_lanczos(&p, &k, &mass, 8, &settings).unwrap();
            for (mode, (a, b)) in got.omega2.iter().zip(&dense.omega2).enumerate() {
                assert!((a - b).abs() <= 1e-9 * b.abs(), "block {block} mode {mode}: {a} vs {b}");
                let dot: f64 = got.vectors[mode]
                    .iter()
                    .zip(&dense.vectors[mode])
                    .zip(&mass)
                    .map(|((x, y), m)| x * y * m)
                    .sum();
                assert!((dot.abs() - 1.0).abs() < 1e-8, "block {block} mode {mode}: {dot}");
            }
        }
    }
}
