//! A fixed compressed-column sparsity pattern (full symmetric storage,
//! diagonal always present) built once from the elements' equation lists.

use faer::sparse::{SparseColMat, SymbolicSparseColMat};

/// Column pointers and sorted row indices of an n×n sparse matrix.
#[derive(Debug, Clone)]
pub struct SparsePattern {
    /// Dimension.
    pub n: usize,
    /// Column start offsets (n + 1).
    pub col_ptr: Vec<usize>,
    /// Row index of each stored entry, sorted within a column.
    pub row_idx: Vec<usize>,
}

impl SparsePattern {
    /// The pattern coupling every pair of equations within each element list.
    pub fn from_elements<'a>(
        n: usize,
        elements: impl Iterator<Item = &'a [Option<usize>]>,
    ) -> Self {
        let mut cols: Vec<Vec<usize>> = (0..n).map(|c| vec![c]).collect();
        for eqs in elements {
            for c in eqs.iter().flatten() {
                cols[*c].extend(eqs.iter().flatten());
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for mut c in cols {
            c.sort_unstable();
            c.dedup();
            row_idx.extend(c);
            col_ptr.push(row_idx.len());
        }
        SparsePattern { n, col_ptr, row_idx }
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Storage position of entry (row, col), if in the pattern.
    pub fn position(&self, row: usize, col: usize) -> Option<usize> {
        let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
        self.row_idx[a..b].binary_search(&row).ok().map(|k| a + k)
    }

    /// Storage positions of an element's dense matrix (row-major, m×m;
    /// `None` where a row or column is a fixed DOF).
    pub fn positions(&self, eqs: &[Option<usize>]) -> Vec<Option<usize>> {
        let mut out = Vec::with_capacity(eqs.len() * eqs.len());
        for r in eqs {
            for c in eqs {
                out.push(match (r, c) {
                    (Some(r), Some(c)) => self.position(*r, *c),
                    _ => None,
                });
            }
        }
        out
    }

    /// The faer matrix with this pattern and the given values.
    pub fn to_faer(&self, values: &[f64]) -> SparseColMat<usize, f64> {
        // SAFETY-free construction: the pattern is sorted and in bounds by construction.
        let symbolic = SymbolicSparseColMat::new_checked(
            self.n,
            self.n,
            self.col_ptr.clone(),
            None,
            self.row_idx.clone(),
        );
        SparseColMat::new(symbolic, values.to_vec())
    }

    /// y = A x for values on this pattern.
    pub fn mul_vec(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for c in 0..self.n {
            for k in self.col_ptr[c]..self.col_ptr[c + 1] {
                y[self.row_idx[k]] += values[k] * x[c];
            }
        }
    }
}

#[cfg(test)]
impl SparsePattern {
    /// Test matrix: tridiag(−1, 2 + s, −1) on n equations, with its pattern.
    pub(crate) fn chain(n: usize, s: f64) -> (SparsePattern, Vec<f64>) {
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
}
