//! Numeric refactorization on a fixed pattern: the symbolic Cholesky
//! analysis (ordering, elimination tree) of the effective tangent is done
//! once and reused; a matrix that is not positive definite falls back to a
//! full sparse LU.

use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::Side;

use crate::assembly::SparsePattern;
use crate::eigen::factor::SparseFactor;

/// The pattern in faer form and its symbolic Cholesky analysis.
pub struct FactorCache {
    symbolic_mat: SymbolicSparseColMat<usize>,
    symbolic_llt: Option<SymbolicLlt<usize>>,
}

impl FactorCache {
    /// Analyses the pattern once.
    pub fn new(pattern: &SparsePattern) -> Self {
        let symbolic_mat = SymbolicSparseColMat::new_checked(
            pattern.n,
            pattern.n,
            pattern.col_ptr.clone(),
            None,
            pattern.row_idx.clone(),
        );
        let symbolic_llt = SymbolicLlt::try_new(symbolic_mat.as_ref(), Side::Lower).ok();
        FactorCache { symbolic_mat, symbolic_llt }
    }

    /// Factorizes `values` on the pattern: Cholesky with the stored analysis,
    /// else LU.
    pub fn factor(&self, pattern: &SparsePattern, values: &[f64]) -> Result<SparseFactor, String> {
        if let Some(sym) = &self.symbolic_llt {
            let a = SparseColMatRef::new(self.symbolic_mat.as_ref(), values);
            if let Ok(llt) = Llt::try_new_with_symbolic(sym.clone(), a, Side::Lower) {
                return Ok(SparseFactor::Cholesky(llt));
            }
        }
        SparseFactor::new(pattern, values)
    }
}
