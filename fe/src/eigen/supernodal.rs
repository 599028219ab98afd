//! Supernodal sparse Cholesky A = Pᵀ L Lᵀ P (faer: symbolic analysis with a
//! given ordering, numeric factorization) and substitutions for a few
//! right-hand sides at once, stored interleaved (row-major n × K, position
//! order): every entry of L is loaded once for all K columns. Each
//! supernode is a dense column-major block, its columns' diagonal block on
//! top of the rows of its pattern (Ng & Peyton 1993). A generalisation of
//! the single-column substitution in `transient::factor_cache`.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Par, Side};

use super::ordering::Ordering;
use crate::assembly::SparsePattern;

/// Why a matrix has no supernodal Cholesky factor.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CholeskyError {
    /// The symbolic analysis failed (size overflow, out of memory).
    #[error("symbolic Cholesky analysis failed: {0}")]
    Symbolic(String),
    /// The matrix is not positive definite.
    #[error("matrix is not positive definite")]
    NotPositiveDefinite,
}

/// L of a symmetric positive definite matrix, supernodal.
pub struct SupernodalCholesky {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    /// 1 / L_ii per position (a product instead of a division in the
    /// substitutions' critical path).
    inv_diag: Vec<f64>,
    /// Position of each equation in the ordering.
    inv: Vec<usize>,
}

impl SupernodalCholesky {
    /// Factorizes `values` on `pattern` (full symmetric storage) in `ordering`.
    pub fn new(
        pattern: &SparsePattern,
        values: &[f64],
        ordering: &Ordering,
    ) -> Result<Self, CholeskyError> {
        let n = pattern.n;
        let a =
            SymbolicSparseColMatRef::new_checked(n, n, &pattern.col_ptr, None, &pattern.row_idx);
        let perm = PermRef::new_checked(&ordering.fwd, &ordering.inv, n);
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let symbolic =
            factorize_symbolic_cholesky(a, Side::Lower, SymmetricOrdering::Custom(perm), params)
                .map_err(|e| CholeskyError::Symbolic(format!("{e:?}")))?;
        let mut buf = MemBuffer::new(
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
        );
        let mut l_values = vec![0.0; symbolic.len_val()];
        symbolic
            .factorize_numeric_llt(
                &mut l_values,
                SparseColMatRef::new(a, values),
                Side::Lower,
                Default::default(),
                Par::Seq,
                MemStack::new(&mut buf),
                Default::default(),
            )
            .map_err(|_| CholeskyError::NotPositiveDefinite)?;
        let inv_diag = match symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(l) => (0..l.n_supernodes())
                .flat_map(|s| {
                    let (_, w, pattern, v) = supernode(l, &l_values, s);
                    let m = w + pattern.len();
                    (0..w).map(move |c| 1.0 / v[c * m + c])
                })
                .collect(),
            SymbolicCholeskyRaw::Simplicial(_) => {
                return Err(CholeskyError::Symbolic("simplicial analysis".into()))
            }
        };
        Ok(SupernodalCholesky { symbolic, values: l_values, inv_diag, inv: ordering.inv.clone() })
    }

    /// Position of equation `e` in the interleaved layout.
    pub fn position(&self, e: usize) -> usize {
        self.inv[e]
    }

    /// Number of equations.
    pub fn n(&self) -> usize {
        self.inv.len()
    }

    /// y ← A⁻¹ y for `K` right-hand sides interleaved in position order
    /// (entry (e, j) at `K * position(e) + j`).
    pub fn solve_interleaved<const K: usize>(&self, y: &mut [f64]) {
        let SymbolicCholeskyRaw::Supernodal(l) = self.symbolic.raw() else {
            unreachable!("the analysis is forced supernodal")
        };
        forward::<K>(l, &self.values, &self.inv_diag, y);
        backward::<K>(l, &self.values, &self.inv_diag, y);
    }
}

/// Columns [begin, begin + width) of supernode `s`, its pattern rows and
/// its block of values (column-major, (width + pattern) × width).
fn supernode<'a>(
    l: &'a SymbolicSupernodalCholesky<usize>,
    values: &'a [f64],
    s: usize,
) -> (usize, usize, &'a [usize], &'a [f64]) {
    let (b, e) = (l.supernode_begin()[s], l.supernode_end()[s]);
    let start = l.col_ptr_for_row_idx()[s];
    let pattern = &l.row_idx()[start..start + l.nnz_per_super()[s]];
    let vals = &values[l.col_ptr_for_val()[s]..l.col_ptr_for_val()[s + 1]];
    (b, e - b, pattern, vals)
}

/// L y = b supernode by supernode: the dense diagonal block first, then
/// its pattern rows gathered in `tmp` and scattered once.
fn forward<const K: usize>(
    l: &SymbolicSupernodalCholesky<usize>,
    values: &[f64],
    inv_diag: &[f64],
    y: &mut [f64],
) {
    let mut tmp: Vec<f64> = Vec::new();
    for s in 0..l.n_supernodes() {
        let (b, w, pattern, v) = supernode(l, values, s);
        let m = w + pattern.len();
        let ys = &mut y[b * K..(b + w) * K];
        if ys.iter().all(|x| *x == 0.0) {
            // A zero block of the right-hand side stays zero and updates nothing.
            continue;
        }
        for c in 0..w {
            let col = &v[c * m..c * m + w];
            let mut yc = [0.0; K];
            for j in 0..K {
                yc[j] = ys[c * K + j] * inv_diag[b + c];
                ys[c * K + j] = yc[j];
            }
            for (t, lv) in ys[(c + 1) * K..].chunks_exact_mut(K).zip(&col[c + 1..]) {
                for j in 0..K {
                    t[j] -= lv * yc[j];
                }
            }
        }
        tmp.clear();
        tmp.resize(pattern.len() * K, 0.0);
        for c in 0..w {
            let below = &v[c * m + w..(c + 1) * m];
            let mut yc = [0.0; K];
            yc.copy_from_slice(&ys[c * K..(c + 1) * K]);
            for (t, lv) in tmp.chunks_exact_mut(K).zip(below) {
                for j in 0..K {
                    t[j] += lv * yc[j];
                }
            }
        }
        for (row, t) in pattern.iter().zip(tmp.chunks_exact(K)) {
            for j in 0..K {
                y[row * K + j] -= t[j];
            }
        }
    }
}

/// Lᵀ x = y supernode by supernode from the last: the pattern rows
/// gathered once, dot products with each column, then the dense block.
fn backward<const K: usize>(
    l: &SymbolicSupernodalCholesky<usize>,
    values: &[f64],
    inv_diag: &[f64],
    y: &mut [f64],
) {
    let mut g: Vec<f64> = Vec::new();
    for s in (0..l.n_supernodes()).rev() {
        let (b, w, pattern, v) = supernode(l, values, s);
        let m = w + pattern.len();
        g.clear();
        for row in pattern {
            g.extend_from_slice(&y[row * K..(row + 1) * K]);
        }
        let ys = &mut y[b * K..(b + w) * K];
        for c in 0..w {
            let d = dot_interleaved::<K>(&v[c * m + w..(c + 1) * m], &g);
            for j in 0..K {
                ys[c * K + j] -= d[j];
            }
        }
        for c in (0..w).rev() {
            let col = &v[c * m..c * m + w];
            let d = dot_interleaved::<K>(&col[c + 1..], &ys[(c + 1) * K..]);
            for j in 0..K {
                ys[c * K + j] = (ys[c * K + j] - d[j]) * inv_diag[b + c];
            }
        }
    }
}

/// Σ_r a[r] g[r K + j] for each j, with four partial sums per column.
fn dot_interleaved<const K: usize>(a: &[f64], g: &[f64]) -> [f64; K] {
    let mut acc = [[0.0; K]; 4];
    let (a4, a_rest) = a.split_at(a.len() - a.len() % 4);
    for (av, gv) in a4.chunks_exact(4).zip(g.chunks_exact(4 * K)) {
        for u in 0..4 {
            for j in 0..K {
                acc[u][j] += av[u] * gv[u * K + j];
            }
        }
    }
    let mut out = [0.0; K];
    for j in 0..K {
        out[j] = (acc[0][j] + acc[1][j]) + (acc[2][j] + acc[3][j]);
    }
    for (av, gv) in a_rest.iter().zip(g[a4.len() * K..].chunks_exact(K)) {
        for j in 0..K {
            out[j] += av * gv[j];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::ordering::node_block_amd;
    use super::*;

    /// A 6 x 7 grid Laplacian plus `shift` on the diagonal: fill-in and
    /// supernodes wider than one column.
    fn grid(shift: f64) -> (SparsePattern, Vec<f64>) {
        let (nx, ny) = (6, 7);
        let id = |i: usize, j: usize| i * ny + j;
        let mut links = Vec::new();
        for i in 0..nx {
            for j in 0..ny {
                if i + 1 < nx {
                    links.push([Some(id(i, j)), Some(id(i + 1, j))]);
                }
                if j + 1 < ny {
                    links.push([Some(id(i, j)), Some(id(i, j + 1))]);
                }
            }
        }
        let p = SparsePattern::from_elements(nx * ny, links.iter().map(|e| &e[..]));
        let mut v = vec![0.0; p.nnz()];
        for (k, [a, b]) in links.iter().enumerate() {
            let (a, b) = (a.unwrap(), b.unwrap());
            let w = 1.0 + 0.1 * (k % 5) as f64;
            for (r, c, s) in [(a, a, w), (b, b, w), (a, b, -w), (b, a, -w)] {
                v[p.position(r, c).unwrap()] += s;
            }
        }
        for i in 0..p.n {
            v[p.position(i, i).unwrap()] += shift;
        }
        (p, v)
    }

    /// A x = b for three interleaved right-hand sides, one of them sparse.
    #[test]
    fn interleaved_solves_satisfy_the_system() {
        let (p, v) = grid(0.05);
        let n = p.n;
        let f = SupernodalCholesky::new(&p, &v, &node_block_amd(&p)).unwrap();
        let rhs: Vec<Vec<f64>> = (0..3)
            .map(|j| {
                (0..n)
                    .map(|i| {
                        if j == 2 {
                            f64::from(u8::from(i == 17))
                        } else {
                            (1.3 * (i + j) as f64).cos()
                        }
                    })
                    .collect()
            })
            .collect();
        let mut y = vec![0.0; 3 * n];
        for (j, b) in rhs.iter().enumerate() {
            for i in 0..n {
                y[3 * f.position(i) + j] = b[i];
            }
        }
        f.solve_interleaved::<3>(&mut y);
        for (j, b) in rhs.iter().enumerate() {
            let x: Vec<f64> = (0..n).map(|i| y[3 * f.position(i) + j]).collect();
            let mut ax = vec![0.0; n];
            p.mul_vec(&v, &x, &mut ax);
            for (a, bb) in ax.iter().zip(b) {
                assert!((a - bb).abs() < 1e-12, "rhs {j}: {a} vs {bb}");
            }
        }
    }

    #[test]
    fn indefinite_matrix_is_rejected() {
        let (p, v) = grid(-3.0);
        let r = SupernodalCholesky::new(&p, &v, &node_block_amd(&p));
        assert!(matches!(r, Err(CholeskyError::NotPositiveDefinite)));
    }

    /// A random symmetric, strictly diagonally dominant (so positive
    /// definite) matrix on the pattern of random element lists.
    fn random_spd(n: usize, elems: &[Vec<usize>], weights: &[f64]) -> (SparsePattern, Vec<f64>) {
        let lists: Vec<Vec<Option<usize>>> =
            elems.iter().map(|e| e.iter().map(|i| Some(i % n)).collect()).collect();
        let p = SparsePattern::from_elements(n, lists.iter().map(|e| &e[..]));
        let mut v = vec![0.0; p.nnz()];
        let mut k = 0;
        for c in 0..n {
            for q in p.col_ptr[c]..p.col_ptr[c + 1] {
                let r = p.row_idx[q];
                if r < c {
                    let w = weights[k % weights.len()];
                    k += 1;
                    v[q] = w;
                    v[p.position(c, r).unwrap()] = w;
                    v[p.position(r, r).unwrap()] += w.abs();
                    v[p.position(c, c).unwrap()] += w.abs();
                }
            }
        }
        for c in 0..n {
            v[p.position(c, c).unwrap()] += 0.1;
        }
        (p, v)
    }

    proptest::proptest! {
        /// A x = b to round-off for 1, 2 and 3 interleaved right-hand sides
        /// on random sparse SPD matrices (random fill-in and supernodes).
        #[test]
        fn random_spd_systems_are_solved(
            n in 1usize..40,
            elems in proptest::collection::vec(proptest::collection::vec(0usize..40, 1..7), 0..30),
            weights in proptest::collection::vec(-2.0..2.0f64, 1..20),
            b in proptest::collection::vec(-1.0..1.0f64, 120),
        ) {
            let (p, v) = random_spd(n, &elems, &weights);
            let f = SupernodalCholesky::new(&p, &v, &node_block_amd(&p)).unwrap();
            for k in 1..=3usize {
                let mut y = vec![0.0; k * n];
                for i in 0..n {
                    for j in 0..k {
                        y[k * f.position(i) + j] = b[j * 40 + i];
                    }
                }
                match k {
                    1 => f.solve_interleaved::<1>(&mut y),
                    2 => f.solve_interleaved::<2>(&mut y),
                    _ => f.solve_interleaved::<3>(&mut y),
                }
                for j in 0..k {
                    let x: Vec<f64> = (0..n).map(|i| y[k * f.position(i) + j]).collect();
                    let mut ax = vec![0.0; n];
                    p.mul_vec(&v, &x, &mut ax);
                    let scale = v.iter().fold(1.0f64, |m, a| m.max(a.abs()))
                        * x.iter().fold(1.0f64, |m, a| m.max(a.abs()));
                    for i in 0..n {
                        proptest::prop_assert!((ax[i] - b[j * 40 + i]).abs() <= 1e-12 * scale);
                    }
                }
            }
        }
    }
}
