//! Exact low-rank correction of a factorized tangent (Sherman–Morrison–
//! Woodbury): when a few springs change tangent by δ_k, the new matrix is
//! A = K₀ + W D Wᵀ with w_k = e_j − e_i on the spring's two equations and
//! D = diag(δ_k), and
//!
//! A⁻¹ b = y − Z (I + D Wᵀ Z)⁻¹ D Wᵀ y,  y = K₀⁻¹ b,  Z = K₀⁻¹ W.
//!
//! The columns z_k are cached per spring for the life of the base factor.
//! Units: those of the matrix (N/mm) and of b.

use std::collections::HashMap;

use nalgebra::{DMatrix, DVector};

use super::factor_cache::TangentFactor;

/// Equations of a spring's two nodes in its DOF.
pub type SpringEqs = [Option<usize>; 2];

/// wᵀ x for w = e_j − e_i: a spring's deformation (or its rate, ...) from
/// the free-DOF vector `x` (a fixed node contributes 0).
#[inline]
pub(super) fn w_dot(eqs: &SpringEqs, x: &[f64]) -> f64 {
    eqs[1].map_or(0.0, |e| x[e]) - eqs[0].map_or(0.0, |e| x[e])
}

/// The active correction: springs, their δ, cached columns, capacitance LU.
#[derive(Default)]
pub struct LowRankUpdate {
    columns: HashMap<usize, Vec<f64>>,
    active: Vec<(usize, f64)>,
    capacitance: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    /// Columns z_k solved so far (one solve with the base factor each).
    pub column_solves: usize,
}

impl LowRankUpdate {
    /// Forgets everything (a new base factor).
    pub fn reset(&mut self) {
        self.columns.clear();
        self.active.clear();
        self.capacitance = None;
    }

    /// Rank of the active correction.
    pub fn rank(&self) -> usize {
        self.active.len()
    }

    /// Whether the active correction is exactly `changes` (spring, δ).
    pub fn is(&self, changes: &[(usize, f64)]) -> bool {
        self.active == changes
    }

    /// Sets the correction to `changes`; `false` if the capacitance is singular.
    pub fn set(
        &mut self,
        base: &TangentFactor,
        eqs: &[SpringEqs],
        n: usize,
        changes: &[(usize, f64)],
    ) -> bool {
        for (k, _) in changes {
            if self.columns.contains_key(k) {
                continue;
            }
            self.column_solves += 1;
            self.columns.entry(*k).or_insert_with(|| {
                let mut z = vec![0.0; n];
                if let Some(e) = eqs[*k][1] {
                    z[e] += 1.0;
                }
                if let Some(e) = eqs[*k][0] {
                    z[e] -= 1.0;
                }
                base.solve_in_place(&mut z);
                z
            });
        }
        let r = changes.len();
        let mut s = DMatrix::<f64>::identity(r, r);
        for (a, (ka, da)) in changes.iter().enumerate() {
            for (b, (kb, _)) in changes.iter().enumerate() {
                s[(a, b)] += da * w_dot(&eqs[*ka], &self.columns[kb]);
            }
        }
        let lu = s.lu();
        let ok = lu.determinant().is_normal();
        self.active.clear();
        self.capacitance = None;
        if ok {
            self.active.extend_from_slice(changes);
            self.capacitance = Some(lu);
        }
        ok
    }

    /// Overwrites `x` (already K₀⁻¹ b) with A⁻¹ b.
    pub fn correct(&self, eqs: &[SpringEqs], x: &mut [f64]) {
        let Some(lu) = &self.capacitance else { return };
        if self.active.is_empty() {
            return;
        }
        let t = DVector::from_iterator(
            self.active.len(),
            self.active.iter().map(|(k, d)| d * w_dot(&eqs[*k], x)),
        );
        let Some(s) = lu.solve(&t) else { return };
        for ((k, _), sk) in self.active.iter().zip(s.iter()) {
            let z = &self.columns[k];
            x.iter_mut().zip(z).for_each(|(xi, zi)| *xi -= sk * zi);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::SparsePattern;
    use proptest::prelude::*;

    proptest! {
        /// The corrected solve equals a direct solve of the updated matrix.
        #[test]
        fn woodbury_equals_direct_solve(deltas in proptest::collection::vec(-0.9..5.0f64, 3),
                                        b in proptest::collection::vec(-1.0..1.0f64, 8)) {
            let n = 8;
            let (p, v0) = SparsePattern::chain(n, 0.5);
            let springs: Vec<SpringEqs> = vec![[Some(0), Some(3)], [None, Some(5)], [Some(6), Some(7)]];
            let base = TangentFactor::General(crate::eigen::factor::SparseFactor::new(&p, &v0).unwrap());
            let changes: Vec<(usize, f64)> = deltas.iter().copied().enumerate().collect();
            let mut upd = LowRankUpdate::default();
            prop_assert!(upd.set(&base, &springs, n, &changes));
            let mut x = b.clone();
            base.solve_in_place(&mut x);
            upd.correct(&springs, &mut x);
            // Direct: A = K0 + sum delta w w^T, applied as A x and compared to b.
            let mut ax = vec![0.0; n];
            p.mul_vec(&v0, &x, &mut ax);
            for (k, d) in &changes {
                let w = w_dot(&springs[*k], &x);
                if let Some(e) = springs[*k][1] { ax[e] += d * w; }
                if let Some(e) = springs[*k][0] { ax[e] -= d * w; }
            }
            for (a, bb) in ax.iter().zip(&b) {
                prop_assert!((a - bb).abs() < 1e-10, "{a} vs {bb}");
            }
        }
    }
}
