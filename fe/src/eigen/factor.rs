//! A sparse factorization of a symmetric matrix on a [`SparsePattern`]:
//! Cholesky (faer, AMD ordering) when positive definite, LU otherwise.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, Lu};
use faer::{MatMut, Side};

use crate::assembly::SparsePattern;

/// A factorized sparse matrix that solves A x = b in place.
pub enum SparseFactor {
    /// LLᵀ of a positive definite matrix.
    Cholesky(Llt<usize, f64>),
    /// LU with partial pivoting; boxed, being far larger than the other variant.
    Lu(Box<Lu<usize, f64>>),
}

impl SparseFactor {
    /// Factorizes the matrix with `values` on `pattern`; Cholesky first.
    pub fn new(pattern: &SparsePattern, values: &[f64]) -> Result<Self, String> {
        let a = pattern.to_faer(values);
        match a.sp_cholesky(Side::Lower) {
            Ok(llt) => Ok(SparseFactor::Cholesky(llt)),
            Err(_) => {
                a.sp_lu().map(|lu| SparseFactor::Lu(Box::new(lu))).map_err(|e| format!("{e:?}"))
            }
        }
    }

    /// Overwrites each column of `x` (n × k) with A⁻¹ x.
    pub fn solve_mat_in_place(&self, x: MatMut<'_, f64>) {
        match self {
            SparseFactor::Cholesky(f) => f.solve_in_place(x),
            SparseFactor::Lu(f) => f.solve_in_place(x),
        }
    }

    /// Overwrites `x` (length n) with A⁻¹ x.
    pub fn solve_in_place(&self, x: &mut [f64]) {
        let n = x.len();
        let m = MatMut::from_column_major_slice_mut(x, n, 1);
        match self {
            SparseFactor::Cholesky(f) => f.solve_in_place(m),
            SparseFactor::Lu(f) => f.solve_in_place(m),
        }
    }
}
