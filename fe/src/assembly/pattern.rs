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
        // The free equations of each element, flat, with offsets.
        let (mut eqs, mut starts) = (Vec::new(), vec![0]);
        for e in elements {
            eqs.extend(e.iter().flatten().copied());
            starts.push(eqs.len());
        }
        // Room per column: the diagonal plus each element's list, duplicates
        // included; then filled, sorted and deduplicated in place.
        let mut room = vec![1usize; n + 1];
        for w in starts.windows(2) {
            for &c in &eqs[w[0]..w[1]] {
                room[c] += w[1] - w[0];
            }
        }
        let mut fill: Vec<usize> = Vec::with_capacity(n + 1);
        let mut total = 0;
        for r in &room[..n] {
            fill.push(total);
            total += r;
        }
        let mut buf = vec![0usize; total];
        let begin = fill.clone();
        for (c, f) in fill.iter_mut().enumerate() {
            buf[*f] = c;
            *f += 1;
        }
        for w in starts.windows(2) {
            let list = &eqs[w[0]..w[1]];
            for &c in list {
                buf[fill[c]..fill[c] + list.len()].copy_from_slice(list);
                fill[c] += list.len();
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(total);
        col_ptr.push(0);
        for c in 0..n {
            let col = &mut buf[begin[c]..fill[c]];
            col.sort_unstable();
            let mut last = usize::MAX;
            for &r in col.iter() {
                if r != last {
                    row_idx.push(r);
                    last = r;
                }
            }
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
    /// `None` where a row or column is a fixed DOF). Consecutive equations
    /// (the DOFs of one node) are consecutive in a column: one search per run.
    pub fn positions(&self, eqs: &[Option<usize>]) -> Vec<Option<usize>> {
        let m = eqs.len();
        let mut out = vec![None; m * m];
        for (ci, c) in eqs.iter().enumerate() {
            let Some(c) = c else { continue };
            let (a, b) = (self.col_ptr[*c], self.col_ptr[*c + 1]);
            let rows = &self.row_idx[a..b];
            let mut last: Option<(usize, usize)> = None;
            for (ri, r) in eqs.iter().enumerate() {
                let Some(r) = r else { continue };
                let p = match last {
                    Some((lr, lp)) if *r == lr + 1 && rows.get(lp + 1) == Some(r) => Some(lp + 1),
                    _ => rows.binary_search(r).ok(),
                };
                last = p.map(|p| (*r, p));
                out[ri * m + ci] = p.map(|p| a + p);
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
        for (c, &xc) in x[..self.n].iter().enumerate() {
            for k in self.col_ptr[c]..self.col_ptr[c + 1] {
                y[self.row_idx[k]] += values[k] * xc;
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
