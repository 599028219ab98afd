//! The round-off floor of the Newton residual: each equation's residual is
//! a sum of forces (inertia, damping, beams, springs, load), so it cannot be
//! computed more accurately than a small multiple of the unit round-off ε
//! times the sum of the magnitudes of its terms (componentwise backward
//! error, Oettli & Prager 1964; Higham, *Accuracy and Stability of
//! Numerical Algorithms*, 2nd ed., 7.2). A stiff spring k contributes
//! k (|u_i| + |u_j|): its force is k times a difference of displacements
//! each rounded to ε |u|. Once every component of the residual is below
//! that floor, further iterations only move round-off around, and the
//! displacement-increment test can stall above its tolerance (1e10 N/mm
//! springs: ‖Δu‖ wanders at 1e-10–1e-9 mm).
//!
//! Units: N (residual and its scale), mm, N/mm.

use super::newton::Kinematics;
use super::springs::SpringStates;
use crate::assembly::Structure;

/// Σ|terms| of every equation's residual (N) into `out`: |load| + m|a| +
/// Σ|K_beam,q u| + Σ|C_q v| + Σ over springs (|f| + |k_t| (|u_i| + |u_j|)).
pub fn residual_scale(
    s: &Structure,
    c_values: &[f64],
    trial: &Kinematics,
    springs: &SpringStates,
    ext: &[f64],
    out: &mut [f64],
) {
    let p = &s.pattern;
    for k in 0..out.len() {
        out[k] = ext[k].abs() + (s.mass[k] * trial.a[k]).abs();
    }
    for c in 0..p.n {
        let (uc, vc) = (trial.u[c], trial.v[c]);
        for q in p.col_ptr[c]..p.col_ptr[c + 1] {
            out[p.row_idx[q]] += (s.beam_values[q] * uc).abs() + (c_values[q] * vc).abs();
        }
    }
    for (k, sp) in s.springs.iter().enumerate() {
        let ui = sp.eqs[0].map_or(0.0, |e| trial.u[e].abs());
        let uj = sp.eqs[1].map_or(0.0, |e| trial.u[e].abs());
        let term = springs.force_n[k].abs() + springs.tangent_n_mm[k].abs() * (ui + uj);
        for e in sp.eqs.iter().flatten() {
            out[*e] += term;
        }
    }
}

/// Whether every |residual| is at most `factor` ε times its scale.
pub fn at_round_off(residual: &[f64], scale: &[f64], factor: f64) -> bool {
    let floor = factor * f64::EPSILON;
    residual.iter().zip(scale).all(|(r, s)| r.abs() <= floor * s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// A sum of terms that cancels exactly in real numbers, evaluated in
        /// floating point, stays within the floor (factor = number of terms).
        #[test]
        fn cancelling_sums_are_at_round_off(terms in proptest::collection::vec(-1e10..1e10f64, 2..40)) {
            let mut all = terms.clone();
            all.extend(terms.iter().rev().map(|t| -t * (1.0 + f64::EPSILON)));
            let r: f64 = all.iter().sum();
            let scale: f64 = all.iter().map(|t| t.abs()).sum();
            prop_assert!(at_round_off(&[r], &[scale], all.len() as f64));
        }
    }

    #[test]
    fn a_residual_above_the_floor_is_not_at_round_off() {
        assert!(!at_round_off(&[1e-3, 0.0], &[1e4, 1.0], 1e3));
        assert!(at_round_off(&[1e-13, 0.0], &[1e4, 1.0], 1e3));
    }
}
