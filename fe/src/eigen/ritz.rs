//! Rayleigh–Ritz reanalysis: the lowest eigenpairs of K φ = ω² M φ within
//! the span of a given basis, typically the modes of a nearby model (the
//! same mesh with other stiffness or mass values). With B the basis
//! (n × m), the projected problem Bᵀ K B y = ω² Bᵀ M B y is dense and
//! m × m; its pairs give φ = B y, mass-normalised on the full problem.
//!
//! Ritz values bound the eigenvalues from above, and when the model moves
//! by h from the one whose modes span B they err by O(h²): the first-order
//! change of an eigenvalue is the Rayleigh quotient's, φᵀ(δK − ω² δM)φ,
//! which the projection holds exactly (Kirsch's reduced-basis reanalysis).
//! A shape's change within the basis is held exactly too; the part outside
//! it (coupling to modes beyond the basis) is not, so a basis with modes
//! beyond those wanted makes the lowest shapes better. The cost is m sparse
//! products and an m × m eigenproblem, against a factorization and a
//! Lanczos run for the full problem.

use nalgebra::{DMatrix, SymmetricEigen};

use super::lanczos::normalize_sign;
use super::Eigenpairs;
use crate::assembly::SparsePattern;

/// Why a basis cannot carry a Ritz reanalysis.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RitzError {
    /// A basis vector's length differs from the problem's size.
    #[error("basis vector {index} has {len} entries, the problem {n}")]
    Length {
        /// The vector's index.
        index: usize,
        /// Its length.
        len: usize,
        /// The problem's equations.
        n: usize,
    },
    /// Fewer basis vectors than modes asked for.
    #[error("{requested} modes asked of a basis of {available} vectors")]
    TooSmall {
        /// Modes asked for.
        requested: usize,
        /// Basis vectors.
        available: usize,
    },
    /// Bᵀ M B is not positive definite (the basis is dependent under M).
    #[error("the basis is not independent under the mass matrix")]
    Dependent,
}

/// The lowest `n_modes` Ritz pairs of K (values on `pattern`) and diagonal
/// M in the span of `basis` (ascending, mass-normalised, sign as
/// [`normalize_sign`] sets it).
pub fn ritz_pairs(
    pattern: &SparsePattern,
    k_values: &[f64],
    mass: &[f64],
    basis: &[Vec<f64>],
    n_modes: usize,
) -> Result<Eigenpairs, RitzError> {
    let (n, m) = (pattern.n, basis.len());
    if let Some((index, b)) = basis.iter().enumerate().find(|(_, b)| b.len() != n) {
        return Err(RitzError::Length { index, len: b.len(), n });
    }
    if n_modes > m {
        return Err(RitzError::TooSmall { requested: n_modes, available: m });
    }
    if n_modes == 0 {
        return Ok(Eigenpairs { omega2: vec![], vectors: vec![] });
    }
    let b = DMatrix::from_fn(n, m, |i, j| basis[j][i]);
    let (kr, mr) = projected(pattern, k_values, mass, &b);
    let l = mr.cholesky().ok_or(RitzError::Dependent)?.l();
    let l_inv = l.try_inverse().ok_or(RitzError::Dependent)?;
    let a = &l_inv * kr * l_inv.transpose();
    let eig = SymmetricEigen::new((&a + a.transpose()) * 0.5);
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|x, y| eig.eigenvalues[*x].total_cmp(&eig.eigenvalues[*y]));
    let lowest: Vec<usize> = order.into_iter().take(n_modes).collect();
    let y = l_inv.transpose() * eig.eigenvectors.select_columns(&lowest);
    let shapes = &b * y;
    let mut out = Eigenpairs { omega2: vec![], vectors: vec![] };
    for (c, &k) in lowest.iter().enumerate() {
        let mut x: Vec<f64> = shapes.column(c).iter().copied().collect();
        normalize_sign(&mut x);
        out.omega2.push(eig.eigenvalues[k]);
        out.vectors.push(x);
    }
    Ok(out)
}

/// Bᵀ K B and Bᵀ M B for the basis B (n × m), as dense products.
fn projected(
    pattern: &SparsePattern,
    k_values: &[f64],
    mass: &[f64],
    b: &DMatrix<f64>,
) -> (DMatrix<f64>, DMatrix<f64>) {
    let (n, m) = b.shape();
    let mut kb = DMatrix::zeros(n, m);
    for j in 0..m {
        let mut col = vec![0.0; n];
        pattern.mul_vec(k_values, b.column(j).as_slice(), &mut col);
        kb.column_mut(j).copy_from_slice(&col);
    }
    let scaled = DMatrix::from_fn(n, m, |i, j| b[(i, j)] * mass[i].max(0.0).sqrt());
    (b.transpose() * kb, scaled.transpose() * &scaled)
}

#[cfg(test)]
mod tests {
    use super::super::dense::dense_eigen;
    use super::*;
    use proptest::prelude::*;

    /// A chain of `n` equations, tridiag(−1, 2 + s, −1) scaled by `k`,
    /// every third one massless, the others of mass `m`.
    fn chain(n: usize, s: f64, k: f64, m: f64) -> (SparsePattern, Vec<f64>, Vec<f64>) {
        let (p, v) = SparsePattern::chain(n, s);
        let mass = (0..n).map(|i| if i % 3 == 2 { 0.0 } else { m }).collect();
        (p, v.iter().map(|x| x * k).collect(), mass)
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs().max(1e-300)
    }

    /// In the span of the exact modes the Ritz pairs are those modes.
    #[test]
    fn the_exact_modes_are_their_own_ritz_pairs() {
        let (p, k, m) = chain(12, 0.1, 1.0, 1.0);
        let exact = dense_eigen(&p, &k, &m).unwrap();
        let basis: Vec<Vec<f64>> = exact.vectors[..5].to_vec();
        let r = ritz_pairs(&p, &k, &m, &basis, 3).unwrap();
        for i in 0..3 {
            assert!(rel(r.omega2[i], exact.omega2[i]) < 1e-12, "{i}");
            for (a, b) in r.vectors[i].iter().zip(&exact.vectors[i]) {
                assert!((a - b).abs() < 1e-10);
            }
        }
    }

    /// A bad basis is refused with what is wrong.
    #[test]
    fn bad_bases_are_refused() {
        let (p, k, m) = chain(6, 0.1, 1.0, 1.0);
        let short = vec![vec![1.0; 5]];
        assert_eq!(
            ritz_pairs(&p, &k, &m, &short, 1).unwrap_err(),
            RitzError::Length { index: 0, len: 5, n: 6 }
        );
        let one = vec![vec![1.0; 6]];
        assert_eq!(
            ritz_pairs(&p, &k, &m, &one, 2).unwrap_err(),
            RitzError::TooSmall { requested: 2, available: 1 }
        );
        let none = ritz_pairs(&p, &k, &m, &[], 0).unwrap();
        assert!(none.omega2.is_empty() && none.vectors.is_empty());
        let twice = vec![vec![1.0; 6], vec![2.0; 6]];
        assert_eq!(ritz_pairs(&p, &k, &m, &twice, 1).unwrap_err(), RitzError::Dependent);
    }

    proptest! {
        /// On the modes of a nearby model the Ritz values bound the new
        /// eigenvalues from above and miss them by O(h²): the lowest three,
        /// from a basis of six, within 50 h² relative for a stiffness and
        /// mass change of relative size h (their first-order change held
        /// exactly, as a forward difference needs).
        #[test]
        fn ritz_values_err_by_the_square_of_the_change(
            h in 1e-4f64..2e-2, s in 0.05f64..0.5, sign in prop::bool::ANY,
        ) {
            let h = if sign { h } else { -h };
            let (p, k0, m0) = chain(15, s, 1.0, 1.0);
            let centre = dense_eigen(&p, &k0, &m0).unwrap();
            // Stiffness (symmetrically) and mass moved unevenly, so the
            // shapes move too.
            let mut k1 = k0.clone();
            for c in 0..p.n {
                let (from, to) = (p.col_ptr[c], p.col_ptr[c + 1]);
                for (v, r) in k1[from..to].iter_mut().zip(&p.row_idx[from..to]) {
                    *v *= 1.0 + h * (1.0 + (r.min(&c) % 4) as f64);
                }
            }
            let m1: Vec<f64> = m0.iter().enumerate().map(|(i, v)| v * (1.0 - h * (i % 5) as f64 / 2.0)).collect();
            let exact = dense_eigen(&p, &k1, &m1).unwrap();
            let r = ritz_pairs(&p, &k1, &m1, &centre.vectors[..6], 3).unwrap();
            for i in 0..3 {
                let e = (r.omega2[i] - exact.omega2[i]) / exact.omega2[i];
                prop_assert!(e > -1e-10, "mode {i}: Ritz value below the eigenvalue by {e}");
                prop_assert!(e < 50.0 * h * h + 1e-12, "mode {i}: relative error {e} at h {h}");
                let change = (exact.omega2[i] - centre.omega2[i]).abs() / exact.omega2[i];
                prop_assert!(change > 10.0 * e, "mode {i}: the change {change} is not resolved ({e})");
            }
        }
    }
}
