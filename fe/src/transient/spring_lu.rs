//! The dense LU of the condensed Newton matrix J = I + G δ on the springs
//! whose tangent left its initial value (the active springs; the others'
//! columns of J are the identity's). It is factorized in place in one kept
//! buffer with faer's partial-pivoting kernel: no copy of J into a new
//! matrix, nor of the factors into separate L and U. Its values are
//! dimensionless; G is in mm/N and δ in N/mm.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Conj, MatMut, MatRef, Par};

/// An LU of J restricted to the active springs, P J_AA = L U.
#[derive(Default)]
pub struct SpringLu {
    /// Indices of the active springs (δ ≠ 0).
    active: Vec<usize>,
    /// L (unit lower, below the diagonal) and U in place, r × r
    /// column-major with r = `active.len()`.
    lu: Vec<f64>,
    /// The row permutation P: forward and inverse.
    forward: Vec<usize>,
    inverse: Vec<usize>,
    /// Scratch for the factorization and the solves.
    scratch: Option<MemBuffer>,
}

impl SpringLu {
    /// Factorizes J = I + G δ (G m × m column-major, δ of length m) on the
    /// springs with δ ≠ 0, reusing this LU's buffers.
    pub fn factor(&mut self, g: &[f64], delta: &[f64]) {
        let m = delta.len();
        self.active.clear();
        self.active.extend((0..m).filter(|&k| delta[k] != 0.0));
        let r = self.active.len();
        self.lu.clear();
        self.lu.resize(r * r, 0.0);
        for (c, &b) in self.active.iter().enumerate() {
            let (col, gb, db) =
                (&mut self.lu[c * r..(c + 1) * r], &g[b * m..(b + 1) * m], delta[b]);
            col.iter_mut().zip(&self.active).for_each(|(x, &a)| *x = gb[a] * db);
            col[c] += 1.0;
        }
        self.forward.resize(r, 0);
        self.inverse.resize(r, 0);
        if r == 0 {
            return;
        }
        let need = factor::lu_in_place_scratch::<usize, f64>(r, r, Par::Seq, Default::default())
            .or(solve::solve_in_place_scratch::<usize, f64>(r, 1, Par::Seq));
        let scratch = self.scratch.get_or_insert_with(|| MemBuffer::new(need));
        if scratch.len() < need.unaligned_bytes_required() {
            *scratch = MemBuffer::new(need);
        }
        factor::lu_in_place(
            MatMut::from_column_major_slice_mut(&mut self.lu, r, r),
            &mut self.forward,
            &mut self.inverse,
            Par::Seq,
            MemStack::new(scratch),
            Default::default(),
        );
    }

    /// The active springs' indices.
    pub fn active(&self) -> &[usize] {
        &self.active
    }

    /// Overwrites `x` (one value per active spring) with J_AA⁻¹ x.
    pub fn solve_in_place(&mut self, x: &mut [f64]) {
        let r = self.active.len();
        let Some(scratch) = self.scratch.as_mut().filter(|_| r > 0) else { return };
        let lu = MatRef::from_column_major_slice(&self.lu, r, r);
        let perm = PermRef::new_checked(&self.forward, &self.inverse, r);
        solve::solve_in_place_with_conj(
            lu,
            lu,
            perm,
            Conj::No,
            MatMut::from_column_major_slice_mut(x, r, 1),
            Par::Seq,
            MemStack::new(scratch),
        );
    }
}

/// AᵀA + I for A m × m column-major: symmetric positive definite, as
/// G = Wᵀ K₀⁻¹ W is positive semi-definite (a test matrix).
#[cfg(test)]
pub(super) fn spd(m: usize, a: &[f64]) -> Vec<f64> {
    let mut g = vec![0.0; m * m];
    for i in 0..m {
        for j in 0..m {
            let dot: f64 = (0..m).map(|k| a[k + i * m] * a[k + j * m]).sum();
            g[i + j * m] = dot + f64::from(u8::from(i == j));
        }
    }
    g
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The factors solve J_AA x = b on the active springs, for δ ≥ 0
        /// with zeros (J then invertible), also after refactoring at
        /// another δ in the same buffers.
        #[test]
        fn solves_the_active_block(
            a in proptest::collection::vec(-1.0..1.0f64, 49),
            deltas in proptest::collection::vec(
                proptest::collection::vec(prop_oneof![Just(0.0), 0.0..3.0f64], 7), 2),
            b in proptest::collection::vec(-1.0..1.0f64, 7),
        ) {
            let m = 7;
            let g = spd(m, &a);
            let mut lu = SpringLu::default();
            for delta in &deltas {
                lu.factor(&g, delta);
                let active = lu.active().to_vec();
                let r = active.len();
                let mut x = b[..r].to_vec();
                lu.solve_in_place(&mut x);
                for (i, &a) in active.iter().enumerate() {
                    let row: f64 = x[i]
                        + active.iter().zip(&x).map(|(&c, xc)| g[a + c * m] * delta[c] * xc).sum::<f64>();
                    prop_assert!((row - b[i]).abs() < 1e-9, "row {i}: {row} vs {}", b[i]);
                }
            }
        }
    }
}
