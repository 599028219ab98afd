//! Krylov subspace acceleration of modified Newton iterations (Carlson &
//! Miller 1998, "Design and analysis of a generalized Newton-Krylov method",
//! the algorithm of OpenSees `KrylovNewton`): with a fixed approximate
//! tangent P, each iteration gives the preconditioned residual r_k = P⁻¹ R_k.
//! The earlier increments v_j and the residual changes a_j = r_j − r_{j+1}
//! (≈ P⁻¹K v_j) span a subspace in which the true tangent is known; the
//! increment is
//!
//! v_k = r_k + Σ c_j (v_j − a_j),  c = argmin ‖r_k − Σ c_j a_j‖₂,
//!
//! which is the Newton increment whenever K − P acts inside that subspace
//! (a few springs whose tangent changed). Units: those of the increments.

use nalgebra::{DMatrix, DVector};

/// Relative singular-value cut-off of the least-squares matrix.
const RANK_TOL: f64 = 1e-7;

/// The subspace of one fixed approximate tangent.
#[derive(Debug, Clone, Default)]
pub struct KrylovAccelerator {
    /// Earlier increments v_j.
    increments: Vec<Vec<f64>>,
    /// Residual changes a_j = r_j − r_{j+1}.
    changes: Vec<Vec<f64>>,
    /// The last preconditioned residual r_{k−1}.
    last_residual: Option<Vec<f64>>,
}

impl KrylovAccelerator {
    /// Forgets the subspace (a new approximate tangent or a new step).
    pub fn reset(&mut self) {
        self.increments.clear();
        self.changes.clear();
        self.last_residual = None;
    }

    /// Dimension of the subspace used by the next call.
    pub fn dimension(&self) -> usize {
        self.changes.len() + usize::from(self.last_residual.is_some())
    }

    /// Overwrites `r` (the preconditioned residual r_k) with the increment
    /// v_k and remembers both; at most `max_dim` directions are kept.
    pub fn accelerate(&mut self, r: &mut [f64], max_dim: usize) {
        if let Some(prev) = self.last_residual.take() {
            let a: Vec<f64> = prev.iter().zip(r.iter()).map(|(p, x)| p - x).collect();
            self.changes.push(a);
        }
        while self.changes.len() > max_dim {
            self.changes.remove(0);
            self.increments.remove(0);
        }
        let rk = r.to_vec();
        if let Some(c) = self.coefficients(r) {
            for ((v, a), cj) in self.increments.iter().zip(&self.changes).zip(c.iter()) {
                r.iter_mut().zip(v.iter().zip(a)).for_each(|(x, (vj, aj))| *x += cj * (vj - aj));
            }
        }
        self.increments.push(r.to_vec());
        self.last_residual = Some(rk);
    }

    /// c minimising ‖r − A c‖₂ over the stored changes (None when empty),
    /// by the SVD of A itself (not of the normal equations, which square
    /// its condition number) with a relative singular-value cut-off.
    fn coefficients(&self, r: &[f64]) -> Option<DVector<f64>> {
        let m = self.changes.len();
        if m == 0 {
            return None;
        }
        let n = r.len();
        let a = DMatrix::from_fn(n, m, |i, j| self.changes[j][i]);
        let svd = a.svd(true, true);
        let cut = RANK_TOL * svd.singular_values.max();
        svd.solve(&DVector::from_column_slice(r), cut)
            .ok()
            .filter(|c| c.iter().all(|x| x.is_finite()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// y = A x for a dense row-major n x n matrix.
    fn mul(a: &[f64], x: &[f64]) -> Vec<f64> {
        let n = x.len();
        (0..n).map(|i| (0..n).map(|j| a[i * n + j] * x[j]).sum()).collect()
    }

    proptest! {
        /// On a linear system K x = b with P = I and K = I + (rank-2
        /// perturbation), the accelerated iteration is exact after four
        /// iterations (rank + 2: the first is a plain step), so the fifth
        /// increment vanishes.
        #[test]
        fn low_rank_perturbation_is_solved_in_rank_plus_two(
            // 1 + 2d >= 0.2: K well conditioned (the normal equations
            // square its condition number).
            d in proptest::collection::vec(-0.4..2.0f64, 2),
            b in proptest::collection::vec(-1.0..1.0f64, 6),
        ) {
            let (k, x, last) = five_accelerated_steps(&d, &b);
            prop_assert!(last < 1e-9, "last increment {last}");
            let kx = mul(&k, &x);
            for (a, bb) in kx.iter().zip(&b) {
                prop_assert!((a - bb).abs() < 1e-9);
            }
        }
    }

    /// K = I plus springs `d` between equations (0, 2) and (3, 5) (row-major
    /// 6 x 6), and five accelerated iterations on K x = b with P = I:
    /// (K, x, norm of the last increment).
    fn five_accelerated_steps(d: &[f64], b: &[f64]) -> (Vec<f64>, Vec<f64>, f64) {
        let n = 6;
        let mut k = vec![0.0; n * n];
        for i in 0..n {
            k[i * n + i] = 1.0;
        }
        for (s, (i, j)) in [(0usize, 2usize), (3, 5)].iter().enumerate() {
            k[i * n + i] += d[s];
            k[j * n + j] += d[s];
            k[i * n + j] -= d[s];
            k[j * n + i] -= d[s];
        }
        let mut x = vec![0.0; n];
        let mut acc = KrylovAccelerator::default();
        let mut last = f64::NAN;
        for _ in 0..5 {
            let kx = mul(&k, &x);
            let mut r: Vec<f64> = b.iter().zip(&kx).map(|(bi, ki)| bi - ki).collect();
            acc.accelerate(&mut r, 8);
            x.iter_mut().zip(&r).for_each(|(xi, ri)| *xi += ri);
            last = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        }
        (k, x, last)
    }

    /// A case the normal equations got wrong (last increment 5.3e-8):
    /// springs -0.271 and 0.411, one right-hand side entry zero.
    #[test]
    fn low_rank_case_with_a_weak_direction() {
        let d = [-0.27145341568316905, 0.41085233303784985];
        let b = [
            0.5557115946395841,
            -0.1928935951455313,
            0.7092140587910948,
            -0.851183656600406,
            0.0,
            -0.8807908179729057,
        ];
        let (_, _, last) = five_accelerated_steps(&d, &b);
        assert!(last < 1e-9, "last increment {last}");
    }

    #[test]
    fn reset_forgets_the_subspace() {
        let mut acc = KrylovAccelerator::default();
        let mut r = vec![1.0, 2.0];
        acc.accelerate(&mut r, 4);
        assert_eq!(acc.dimension(), 1);
        acc.reset();
        assert_eq!(acc.dimension(), 0);
        let mut r2 = vec![3.0, 4.0];
        acc.accelerate(&mut r2, 4);
        assert_eq!(r2, vec![3.0, 4.0]);
    }
}
