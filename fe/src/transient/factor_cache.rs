//! Numeric refactorization on a fixed pattern: the symbolic Cholesky
//! analysis (AMD ordering, elimination tree, supernodes) of the effective
//! tangent is done once and reused; a matrix that is not positive definite
//! falls back to a full sparse LU.
//!
//! The Cholesky factor is simplicial (column by column) or supernodal
//! (dense blocks of columns with the same structure). A simplicial factor
//! is solved by plain substitutions here, about twice as fast as faer's
//! generic ones in the dev profile. With faer's solves on the generated
//! type-C grids (`examples/transient_variants.rs`, 800 steps, CPU s) the
//! supernodal layout was faster for rigid connections (release 1.62 ->
//! 1.37 s), slower for elastic ones (2.81 -> 3.34 s), even for Pinching4
//! (9.52 / 9.74 s; dev profile 15.0 -> 13.6 s); faer's own choice
//! (simplicial here) stays the default.

use std::sync::Arc;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};

use crate::assembly::SparsePattern;
use crate::eigen::factor::SparseFactor;

/// Layout of the Cholesky factor of the effective tangent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CholeskyLayout {
    /// faer's choice from the estimated flop counts (simplicial on the
    /// generated ceiling grids).
    #[default]
    Auto,
    /// Column by column.
    Simplicial,
    /// Dense supernodes: faster numeric factorizations, slower solves in
    /// the dev profile.
    Supernodal,
}

/// A factorized effective tangent that solves A x = b in place.
pub enum TangentFactor {
    /// LLᵀ on the cached symbolic analysis.
    Cholesky {
        /// The shared symbolic analysis.
        symbolic: Arc<SymbolicCholesky<usize>>,
        /// Numeric values of L.
        values: Vec<f64>,
    },
    /// Any other factorization (LU of an indefinite tangent).
    General(SparseFactor),
}

impl TangentFactor {
    /// Overwrites `x` (length n) with A⁻¹ x.
    pub fn solve_in_place(&self, x: &mut [f64]) {
        match self {
            TangentFactor::Cholesky { symbolic, values } => {
                if let SymbolicCholeskyRaw::Simplicial(l) = symbolic.raw() {
                    let fwd = symbolic.perm().map(|p| p.arrays().0);
                    solve_simplicial(l.col_ptr(), l.row_idx(), values, fwd, x);
                    return;
                }
                let n = x.len();
                let mut buf = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
                LltRef::new(symbolic, values).solve_in_place_with_conj(
                    Conj::No,
                    MatMut::from_column_major_slice_mut(x, n, 1),
                    Par::Seq,
                    MemStack::new(&mut buf),
                );
            }
            TangentFactor::General(f) => f.solve_in_place(x),
        }
    }
}

/// x ← A⁻¹ x for A = Pᵀ L Lᵀ P, L in CSC with the diagonal first in each
/// column, `fwd[i]` the original index of permuted row i: a column-oriented
/// forward substitution (skipping zeros, so a sparse right-hand side costs
/// only its elimination-tree reach) and a row-oriented backward one.
fn solve_simplicial(
    col_ptr: &[usize],
    row_idx: &[usize],
    l: &[f64],
    fwd: Option<&[usize]>,
    x: &mut [f64],
) {
    let n = x.len();
    let mut y: Vec<f64> = match fwd {
        Some(f) => f.iter().map(|&i| x[i]).collect(),
        None => x.to_vec(),
    };
    for j in 0..n {
        let (a, b) = (col_ptr[j], col_ptr[j + 1]);
        if y[j] == 0.0 {
            // Sparse right-hand sides (low-rank columns e_j - e_i): a zero
            // stays zero and updates nothing.
            continue;
        }
        let yj = y[j] / l[a];
        y[j] = yj;
        for (r, v) in row_idx[a + 1..b].iter().zip(&l[a + 1..b]) {
            y[*r] -= v * yj;
        }
    }
    for j in (0..n).rev() {
        let (a, b) = (col_ptr[j], col_ptr[j + 1]);
        let mut s = y[j];
        for (r, v) in row_idx[a + 1..b].iter().zip(&l[a + 1..b]) {
            s -= v * y[*r];
        }
        y[j] = s / l[a];
    }
    match fwd {
        Some(f) => f.iter().zip(&y).for_each(|(&i, v)| x[i] = *v),
        None => x.copy_from_slice(&y),
    }
}

/// The pattern in faer form and its symbolic Cholesky analysis.
pub struct FactorCache {
    symbolic_mat: SymbolicSparseColMat<usize>,
    symbolic: Option<Arc<SymbolicCholesky<usize>>>,
    scratch: Option<MemBuffer>,
}

impl FactorCache {
    /// Analyses the pattern once for a factor of the given layout.
    pub fn new(pattern: &SparsePattern, layout: CholeskyLayout) -> Self {
        let symbolic_mat = SymbolicSparseColMat::new_checked(
            pattern.n,
            pattern.n,
            pattern.col_ptr.clone(),
            None,
            pattern.row_idx.clone(),
        );
        let threshold = match layout {
            CholeskyLayout::Auto => SupernodalThreshold::AUTO,
            CholeskyLayout::Simplicial => SupernodalThreshold::FORCE_SIMPLICIAL,
            CholeskyLayout::Supernodal => SupernodalThreshold::FORCE_SUPERNODAL,
        };
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: threshold,
            ..Default::default()
        };
        let symbolic = factorize_symbolic_cholesky(
            symbolic_mat.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            params,
        )
        .ok()
        .map(Arc::new);
        FactorCache { symbolic_mat, symbolic, scratch: None }
    }

    /// Factorizes `values` on the pattern: Cholesky with the stored analysis,
    /// else LU.
    pub fn factor(
        &mut self,
        pattern: &SparsePattern,
        values: &[f64],
    ) -> Result<TangentFactor, String> {
        if let Some(sym) = &self.symbolic {
            let a = SparseColMatRef::new(self.symbolic_mat.as_ref(), values);
            let scratch = self.scratch.get_or_insert_with(|| {
                MemBuffer::new(
                    sym.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
                )
            });
            let mut l_values = vec![0.0; sym.len_val()];
            let ok = sym
                .factorize_numeric_llt(
                    &mut l_values,
                    a,
                    Side::Lower,
                    Default::default(),
                    Par::Seq,
                    MemStack::new(scratch),
                    Default::default(),
                )
                .is_ok();
            if ok {
                return Ok(TangentFactor::Cholesky { symbolic: Arc::clone(sym), values: l_values });
            }
        }
        SparseFactor::new(pattern, values).map(TangentFactor::General)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// tridiag(-1, 2 + s, -1) on n equations.
    fn chain(n: usize, s: f64) -> (SparsePattern, Vec<f64>) {
        let eqs: Vec<[Option<usize>; 2]> = (0..n - 1).map(|i| [Some(i), Some(i + 1)]).collect();
        let p = SparsePattern::from_elements(n, eqs.iter().map(|e| &e[..]));
        let mut v = vec![0.0; p.nnz()];
        for i in 0..n {
            v[p.position(i, i).unwrap()] = 2.0 + s;
            if i + 1 < n {
                v[p.position(i, i + 1).unwrap()] = -1.0;
                v[p.position(i + 1, i).unwrap()] = -1.0;
            }
        }
        (p, v)
    }

    /// The simplicial substitution equals faer's own solve.
    #[test]
    fn simplicial_substitution_matches_faer() {
        let n = 12;
        let (p, v) = chain(n, 0.3);
        let mut cache = FactorCache::new(&p, CholeskyLayout::Simplicial);
        let TangentFactor::Cholesky { symbolic, values } = cache.factor(&p, &v).unwrap() else {
            panic!("positive definite");
        };
        let b: Vec<f64> = (0..n).map(|i| (1.3 * i as f64).cos()).collect();
        let mut ours = b.clone();
        TangentFactor::Cholesky { symbolic: Arc::clone(&symbolic), values: values.clone() }
            .solve_in_place(&mut ours);
        let mut theirs = b;
        let mut buf = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        LltRef::new(&symbolic, &values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut theirs, n, 1),
            Par::Seq,
            MemStack::new(&mut buf),
        );
        for (a, b) in ours.iter().zip(&theirs) {
            assert!((a - b).abs() <= 1e-14 * b.abs().max(1.0), "{a} vs {b}");
        }
    }

    /// Both layouts solve A x = b; an indefinite matrix falls back to LU.
    #[test]
    fn both_layouts_solve_and_indefinite_falls_back() {
        let n = 9;
        for layout in [CholeskyLayout::Auto, CholeskyLayout::Simplicial, CholeskyLayout::Supernodal]
        {
            for s in [0.5, -3.0] {
                let (p, v) = chain(n, s);
                let mut cache = FactorCache::new(&p, layout);
                let f = cache.factor(&p, &v).unwrap();
                assert_eq!(matches!(f, TangentFactor::Cholesky { .. }), s > 0.0);
                let b: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
                let mut x = b.clone();
                f.solve_in_place(&mut x);
                let mut ax = vec![0.0; n];
                p.mul_vec(&v, &x, &mut ax);
                for (a, bb) in ax.iter().zip(&b) {
                    assert!((a - bb).abs() < 1e-12, "{layout:?} s {s}: {a} vs {bb}");
                }
            }
        }
    }
}
