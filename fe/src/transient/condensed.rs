//! Newton on the nonlinear springs' deformations alone (static
//! condensation of the linear structure). With K₀ the effective tangent at
//! every spring's initial stiffness, w_k = e_j − e_i on the k-th nonlinear
//! spring's equations and g_k(d) = f_k(d) − k₀_k d its force beyond the
//! initial stiffness, a step's equilibrium R(u) = 0 from the committed uₙ is
//!
//!   u = uₙ + r₀ − Z (g(Wᵀu) − gₙ),  r₀ = K₀⁻¹ R(uₙ),  Z = K₀⁻¹ W,
//!
//! so the m spring deformations d = Wᵀu solve
//!
//!   φ(d) = d − d₀ + G g(d) = 0,  d₀ = dₙ + Wᵀr₀ + G gₙ,  G = Wᵀ Z.
//!
//! Newton on φ, (I + G δ) Δd = −φ with δ = k_t − k₀, gives in exact
//! arithmetic the deformations of the full Newton iterates (the same
//! linearisation, eliminated), and each iterate's u is uₙ + r₀ − Z(ĝ − gₙ)
//! with ĝ the linearised spring forces. An iteration is then a dense solve
//! on the springs whose tangent left its initial value instead of a sparse
//! refactorization, and ‖Δu‖₂ comes from ZᵀZ. Z, G and ZᵀZ are computed
//! once per step size. Units: N, mm, s.

use super::cycle::TangentHistory;
use super::factor_cache::{FactorCache, TangentFactor};
use super::low_rank::w_dot;
use super::newmark::NewmarkConstants;
use super::newton::{Dynamics, Kinematics, NewtonFailure, NewtonSettings, Step};
use super::round_off::at_round_off;
use super::spring_lu::SpringLu;
use super::springs::SpringStates;
use crate::assembly::Structure;
use crate::materials::MaterialSpec;

/// Most nonlinear springs a structure may have for condensed steps. A dense
/// LU of order 126 (a 6 m x 4.8 m grid's Pinching4 connections) costs about
/// half a sparse refactorization of its 1356 equations (150 vs 290 µs),
/// and the cost grows as the cube of the springs whose tangent left its
/// initial value. Friction-pounding perimeter with Pinching4 connections,
/// 2000 steps of the 0.5 g sweep (`examples/transient_variants.rs`, CPU s,
/// condensed vs whole): 3.6 m x 3.6 m, 90 springs, 0.22 vs 0.45; 6 m x
/// 4.8 m, 190 springs, 0.94 vs 1.13, near the break-even.
pub const CONDENSE_MAX_SPRINGS: usize = 192;

/// The condensed operators at one step size.
struct Basis {
    dt_s: f64,
    /// K₀ factorized.
    factor: TangentFactor,
    /// Z = K₀⁻¹ W, n × m column-major.
    z: Vec<f64>,
    /// G = Wᵀ Z, m × m column-major (symmetric).
    g: Vec<f64>,
    /// ZᵀZ, m × m column-major.
    ztz: Vec<f64>,
}

/// The dense Newton system on the springs and its kept LU of I + G δ,
/// valid while the basis and δ are unchanged.
#[derive(Default)]
struct DenseSystem {
    lu: SpringLu,
    /// Basis and δ of the kept LU (None before the first).
    kept: Option<(usize, Vec<f64>)>,
    /// Dense LU factorizations of I + G δ done so far.
    factorizations: usize,
}

/// The nonlinear springs of a structure and their condensed operators.
pub struct Condensed {
    /// Indices (in the structure's spring list) of the nonlinear springs.
    springs: Vec<usize>,
    /// Their initial tangents (N/mm).
    k0: Vec<f64>,
    bases: Vec<Basis>,
    dense: DenseSystem,
    /// An upper bound on ‖W‖₂: √(2 × most nonlinear springs on one equation).
    w_norm: f64,
}

/// out += A c for A column-major with `rows` rows, skipping zeros of `c`
/// (as fast as faer's product on a 1356 x 126 Z, and sparse c is common).
fn add_columns(a: &[f64], rows: usize, c: &[f64], out: &mut [f64]) {
    for (k, ck) in c.iter().enumerate() {
        if *ck != 0.0 {
            let col = &a[k * rows..(k + 1) * rows];
            out.iter_mut().zip(col).for_each(|(o, v)| *o += ck * v);
        }
    }
}

impl Condensed {
    /// The condensation of `s`, when it has between 1 and
    /// [`CONDENSE_MAX_SPRINGS`] nonlinear (non-`Elastic`) springs on free DOFs.
    pub fn of(s: &Structure) -> Option<Self> {
        let springs: Vec<usize> = s
            .springs
            .iter()
            .enumerate()
            .filter(|(_, sp)| !matches!(sp.material, MaterialSpec::Elastic { .. }))
            .filter(|(_, sp)| sp.eqs.iter().any(Option::is_some))
            .map(|(k, _)| k)
            .collect();
        if springs.is_empty() || springs.len() > CONDENSE_MAX_SPRINGS {
            return None;
        }
        let k0 = springs.iter().map(|&k| s.springs[k].material.initial_tangent()).collect();
        let mut per_eq = vec![0usize; s.pattern.n];
        for &k in &springs {
            s.springs[k].eqs.iter().flatten().for_each(|e| per_eq[*e] += 1);
        }
        let most = per_eq.iter().copied().max().unwrap_or(1);
        let w_norm = (2.0 * most as f64).sqrt();
        Some(Condensed { springs, k0, bases: Vec::new(), dense: DenseSystem::default(), w_norm })
    }

    /// Dense LU factorizations of the springs' Newton matrix so far.
    pub fn dense_factorizations(&self) -> usize {
        self.dense.factorizations
    }

    /// The kept basis at step `dt_s`.
    fn basis_at(&self, dt_s: f64) -> Option<usize> {
        self.bases.iter().position(|b| b.dt_s == dt_s)
    }

    /// Computes the basis at step `dt_s` from `base_eff`, the beam, mass and
    /// damping part of the effective tangent; returns its index.
    fn add_basis(
        &mut self,
        s: &Structure,
        dt_s: f64,
        base_eff: &[f64],
        cache: &mut FactorCache,
    ) -> Result<usize, NewtonFailure> {
        let mut values = base_eff.to_vec();
        s.add_spring_tangents(&mut values, &s.initial_spring_tangents());
        let factor = cache
            .factor(&s.pattern, &values)
            .map_err(|message| NewtonFailure::Singular { message })?;
        let (n, m) = (s.pattern.n, self.springs.len());
        let mut z = vec![0.0; n * m];
        for (k, col) in z.chunks_mut(n).enumerate() {
            let eqs = s.springs[self.springs[k]].eqs;
            eqs[1].iter().for_each(|e| col[*e] += 1.0);
            eqs[0].iter().for_each(|e| col[*e] -= 1.0);
            factor.solve_in_place(col);
        }
        let mut g = vec![0.0; m * m];
        let mut ztz = vec![0.0; m * m];
        for b in 0..m {
            let zb = &z[b * n..(b + 1) * n];
            for a in 0..m {
                g[a + b * m] = w_dot(&s.springs[self.springs[a]].eqs, zb);
            }
            for a in 0..=b {
                let za = &z[a * n..(a + 1) * n];
                let dot: f64 = za.iter().zip(zb).map(|(x, y)| x * y).sum();
                (ztz[a + b * m], ztz[b + a * m]) = (dot, dot);
            }
        }
        self.bases.push(Basis { dt_s, factor, z, g, ztz });
        Ok(self.bases.len() - 1)
    }
}

impl DenseSystem {
    /// Δd solving (I + G δ) Δd = −φ with G of basis `basis`: a dense LU on
    /// the springs with δ ≠ 0 (kept while the basis and δ are unchanged),
    /// the others substituted.
    fn increment(&mut self, basis: usize, g: &[f64], delta: &[f64], phi: &[f64], dd: &mut [f64]) {
        let m = delta.len();
        if self.kept.as_ref().is_none_or(|(b, d)| *b != basis || d != delta) {
            self.lu.factor(g, delta);
            self.factorizations += 1;
            self.kept = Some((basis, delta.to_vec()));
        }
        let mut x: Vec<f64> = self.lu.active().iter().map(|&a| -phi[a]).collect();
        self.lu.solve_in_place(&mut x);
        dd.iter_mut().zip(phi).for_each(|(d, p)| *d = -p);
        for (&b, xb) in self.lu.active().iter().zip(&x) {
            let c = delta[b] * xb;
            let col = &g[b * m..(b + 1) * m];
            dd.iter_mut().zip(col).for_each(|(d, gv)| *d -= gv * c);
        }
        for (&a, xa) in self.lu.active().iter().zip(&x) {
            dd[a] = *xa;
        }
    }
}

/// Euclidean norm.
fn l2(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// ‖Z e‖₂ from ZᵀZ (m × m), over the nonzero entries of `e`.
fn z_norm(ztz: &[f64], e: &[f64]) -> f64 {
    let m = e.len();
    let nz: Vec<usize> = (0..m).filter(|&k| e[k] != 0.0).collect();
    let mut sq = 0.0;
    for &b in &nz {
        let col = &ztz[b * m..(b + 1) * m];
        sq += e[b] * nz.iter().map(|&a| col[a] * e[a]).sum::<f64>();
    }
    sq.max(0.0).sqrt()
}

/// The springs' values the condensed iteration works on.
#[derive(Clone)]
struct SpringVectors {
    /// Deformations (mm).
    d: Vec<f64>,
    /// Forces beyond the initial stiffness, f − k₀ d (N).
    g: Vec<f64>,
    /// Tangents minus initial tangents (N/mm).
    delta: Vec<f64>,
}

impl Condensed {
    /// The nonlinear springs' committed (current) values.
    fn current(&self, springs: &SpringStates) -> SpringVectors {
        let pick = |v: &[f64]| -> Vec<f64> { self.springs.iter().map(|&i| v[i]).collect() };
        let (d, f, kt) =
            (pick(&springs.deformation_mm), pick(&springs.force_n), pick(&springs.tangent_n_mm));
        let g = d.iter().zip(&f).zip(&self.k0).map(|((d, f), k)| f - k * d).collect();
        let delta = kt.iter().zip(&self.k0).map(|(t, k)| t - k).collect();
        SpringVectors { d, g, delta }
    }

    /// Trial deformations `d` for the nonlinear springs.
    fn trial(
        &self,
        s: &Structure,
        springs: &mut SpringStates,
        v: &mut SpringVectors,
    ) -> Result<(), NewtonFailure> {
        for (k, &i) in self.springs.iter().enumerate() {
            let (f, kt) = springs.set_trial_one(s, i, v.d[k]).map_err(NewtonFailure::Material)?;
            v.g[k] = f - self.k0[k] * v.d[k];
            v.delta[k] = kt - self.k0[k];
        }
        Ok(())
    }
}

impl Condensed {
    /// ‖Δu‖₂ of an iteration whose linearised spring forces are `ghat`:
    /// from ZᵀZ after an earlier iteration (`prev` its ĝ), else explicit
    /// (Δu = r₀ − Z(ĝ − gₙ)) unless the bound ‖Δu‖ ≥ ‖Δd‖ / ‖W‖ is already
    /// above both tolerances (the common case), when the bound decides alike.
    #[allow(clippy::too_many_arguments)]
    fn increment_norm(
        &self,
        bi: usize,
        settings: &NewtonSettings,
        prev: Option<&[f64]>,
        ghat: &[f64],
        dd: &[f64],
        r0: &[f64],
        g_start: &[f64],
    ) -> f64 {
        if let Some(prev) = prev {
            let e: Vec<f64> = ghat.iter().zip(prev).map(|(a, b)| a - b).collect();
            return z_norm(&self.bases[bi].ztz, &e);
        }
        let bound = l2(dd) / self.w_norm;
        if bound >= settings.tol_mm.max(settings.floor_tol_mm) {
            return bound;
        }
        let mut du = r0.to_vec();
        let e: Vec<f64> = g_start.iter().zip(ghat).map(|(a, b)| a - b).collect();
        add_columns(&self.bases[bi].z, r0.len(), &e, &mut du);
        l2(&du)
    }
}

/// What a condensed step starts from and keeps fixed.
struct StepStart {
    /// Index of the basis at the step size.
    bi: usize,
    /// r₀ = K₀⁻¹ R(uₙ) (mm); (n_dof).
    r0: Vec<f64>,
    /// The nonlinear springs' committed values.
    at_start: SpringVectors,
    /// d₀ = dₙ + Wᵀr₀ + G gₙ (mm); (m).
    d0: Vec<f64>,
}

impl Condensed {
    /// d₀ = dₙ + Wᵀr₀ + G gₙ (mm) with G of basis `bi`, from the committed
    /// values `start` and r₀ (n_dof).
    fn start_deformations(
        &self,
        s: &Structure,
        bi: usize,
        start: &SpringVectors,
        r0: &[f64],
    ) -> Vec<f64> {
        let m = self.springs.len();
        let mut d0: Vec<f64> =
            (0..m).map(|k| start.d[k] + w_dot(&s.springs[self.springs[k]].eqs, r0)).collect();
        add_columns(&self.bases[bi].g, m, &start.g, &mut d0);
        d0
    }

    /// φ = d − d₀ + G g (mm) at the springs' values `v` into `phi` (m).
    fn phi(&self, st: &StepStart, v: &SpringVectors, phi: &mut [f64]) {
        let m = self.springs.len();
        phi.iter_mut().zip(&v.d).zip(&st.d0).for_each(|((p, d), d0)| *p = d - d0);
        add_columns(&self.bases[st.bi].g, m, &v.g, phi);
    }

    /// Whether `phi` is at its round-off floor (fills `scale` with its scale).
    fn phi_at_round_off(
        &self,
        st: &StepStart,
        v: &SpringVectors,
        phi: &[f64],
        settings: &NewtonSettings,
        scale: &mut [f64],
    ) -> bool {
        phi_scale(&self.bases[st.bi].g, v, &st.at_start, &st.d0, scale);
        at_round_off(phi, scale, settings.floor_factor)
    }
}

/// The linearised spring forces ĝ = g + δ Δd (N) after the increment `dd`.
fn linearised_forces(v: &SpringVectors, dd: &[f64]) -> Vec<f64> {
    v.g.iter().zip(&v.delta).zip(dd).map(|((g, dl), x)| g + dl * x).collect()
}

impl Dynamics<'_> {
    /// [`Dynamics::solve_step`] on the nonlinear springs' deformations
    /// (see the module comment); returns the number of iterations.
    pub(super) fn solve_step_condensed(
        &mut self,
        c: &mut Condensed,
        step: &Step<'_>,
        trial: &mut Kinematics,
        springs: &mut SpringStates,
    ) -> Result<usize, NewtonFailure> {
        let settings = step.settings;
        let s = self.structure();
        let st = self.condensed_start(c, step, trial, springs)?;
        let m = c.springs.len();
        let mut v = st.at_start.clone();
        let (mut phi, mut dd, mut scale) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        let mut solved: Option<(Vec<f64>, Vec<f64>)> = None; // (δ, ĝ) of the last solve
        let mut last = f64::NAN;
        let mut tangents = TangentHistory::default();
        for it in 1..=settings.max_iter {
            if it > 1 {
                c.trial(s, springs, &mut v)?;
            }
            tangents.record(it, &v.delta)?;
            c.phi(&st, &v, &mut phi);
            let kept = solved.as_ref().is_some_and(|(delta, _)| *delta == v.delta);
            let floor = it > 1
                && (kept || last < settings.floor_tol_mm)
                && c.phi_at_round_off(&st, &v, &phi, settings, &mut scale);
            if floor && kept {
                let ghat = solved.map(|(_, g)| g).unwrap_or_default();
                self.finish(c, &st, &ghat, step, trial, springs)?;
                return Ok(it - 1);
            }
            c.dense.increment(st.bi, &c.bases[st.bi].g, &v.delta, &phi, &mut dd);
            let ghat = linearised_forces(&v, &dd);
            let prev = solved.as_ref().map(|(_, g)| g.as_slice());
            let norm = c.increment_norm(st.bi, settings, prev, &ghat, &dd, &st.r0, &st.at_start.g);
            if !norm.is_finite() || dd.iter().any(|x| !x.is_finite()) {
                return Err(NewtonFailure::NonFinite { iteration: it });
            }
            v.d.iter_mut().zip(&dd).for_each(|(d, x)| *d += x);
            last = norm;
            if norm < settings.tol_mm || (floor && norm < settings.floor_tol_mm) {
                self.finish(c, &st, &ghat, step, trial, springs)?;
                return Ok(it);
            }
            solved = Some((v.delta.clone(), ghat));
        }
        Err(NewtonFailure::MaxIterations { iterations: settings.max_iter, last_norm_mm: last })
    }

    /// Sets `trial` at rest on the committed displacements and returns what
    /// the condensed step starts from (adding the basis at this step size
    /// when missing).
    fn condensed_start(
        &mut self,
        c: &mut Condensed,
        step: &Step<'_>,
        trial: &mut Kinematics,
        springs: &SpringStates,
    ) -> Result<StepStart, NewtonFailure> {
        let &Step { nm, committed, ext, .. } = step;
        let n = committed.u.len();
        trial.u.clone_from(&committed.u);
        trial.follow_displacements(nm, committed);
        let mut r0 = vec![0.0; n];
        self.residual(trial, springs, ext, &mut r0);
        let bi = self.basis_index(c, nm)?;
        c.bases[bi].factor.solve_in_place(&mut r0);
        let start = c.current(springs);
        let d0 = c.start_deformations(self.structure(), bi, &start, &r0);
        Ok(StepStart { bi, r0, at_start: start, d0 })
    }

    /// Index of `c`'s basis at the step of `nm`, computed (one sparse
    /// factorization) when missing.
    fn basis_index(
        &mut self,
        c: &mut Condensed,
        nm: &NewmarkConstants,
    ) -> Result<usize, NewtonFailure> {
        match c.basis_at(nm.dt_s) {
            Some(i) => Ok(i),
            None => {
                let base_eff = self.base_values(nm).to_vec();
                c.add_basis(self.structure(), nm.dt_s, &base_eff, self.cache_mut())
            }
        }
    }

    /// Sets the trial state at u = uₙ + r₀ − Z(ĝ − gₙ): every spring, the
    /// velocities and accelerations.
    fn finish(
        &self,
        c: &Condensed,
        st: &StepStart,
        ghat: &[f64],
        step: &Step<'_>,
        trial: &mut Kinematics,
        springs: &mut SpringStates,
    ) -> Result<(), NewtonFailure> {
        let &Step { nm, committed, .. } = step;
        let n = committed.u.len();
        trial.u.iter_mut().zip(&committed.u).zip(&st.r0).for_each(|((u, un), r)| *u = un + r);
        let e: Vec<f64> = st.at_start.g.iter().zip(ghat).map(|(a, b)| a - b).collect();
        add_columns(&c.bases[st.bi].z, n, &e, &mut trial.u);
        self.set_trial_state(nm, committed, trial, springs)
    }
}

/// Round-off scale of φ = d − dₙ − Wᵀr₀ − G gₙ + G g: the sum of the
/// magnitudes of its terms (Wᵀr₀ taken as d₀ − dₙ − G gₙ).
fn phi_scale(g: &[f64], v: &SpringVectors, start: &SpringVectors, d0: &[f64], out: &mut [f64]) {
    let m = out.len();
    for i in 0..m {
        out[i] = v.d[i].abs() + d0[i].abs() + start.d[i].abs();
    }
    for b in 0..m {
        let w = v.g[b].abs() + 2.0 * start.g[b].abs();
        if w != 0.0 {
            let col = &g[b * m..(b + 1) * m];
            out.iter_mut().zip(col).for_each(|(o, gv)| *o += gv.abs() * w);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::spring_lu::spd;
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The active-set solve satisfies (I + G δ) Δd = −φ for any δ with
        /// zeros, and a kept LU is reused only for the same basis and δ.
        #[test]
        fn increment_solves_the_springs_newton_system(
            entries in proptest::collection::vec(-1.0..1.0f64, 36),
            delta in proptest::collection::vec(prop_oneof![Just(0.0), -0.9..3.0f64], 6),
            phi in proptest::collection::vec(-1.0..1.0f64, 6),
        ) {
            let m = 6;
            let g = spd(m, &entries);
            let mut sys = DenseSystem::default();
            let mut dd = vec![0.0; m];
            sys.increment(0, &g, &delta, &phi, &mut dd);
            for i in 0..m {
                let row: f64 = dd[i] + (0..m).map(|b| g[i + b * m] * delta[b] * dd[b]).sum::<f64>();
                prop_assert!((row + phi[i]).abs() < 1e-9, "row {i}: {row} vs {}", -phi[i]);
            }
            sys.increment(0, &g, &delta, &phi, &mut dd);
            prop_assert_eq!(sys.factorizations, 1);
            sys.increment(1, &g, &delta, &phi, &mut dd);
            prop_assert_eq!(sys.factorizations, 2);
        }

        /// ‖Z e‖ from ZᵀZ equals the norm of the explicit product.
        #[test]
        fn z_norm_is_the_norm_of_z_e(
            z in proptest::collection::vec(-1.0..1.0f64, 20),
            e in proptest::collection::vec(prop_oneof![Just(0.0), -1.0..1.0f64], 4),
        ) {
            let (n, m) = (5, 4);
            let mut ztz = vec![0.0; m * m];
            for a in 0..m {
                for b in 0..m {
                    ztz[a + b * m] = (0..n).map(|k| z[k + a * n] * z[k + b * n]).sum();
                }
            }
            let mut ze = vec![0.0; n];
            add_columns(&z, n, &e, &mut ze);
            prop_assert!((z_norm(&ztz, &e) - l2(&ze)).abs() < 1e-12);
        }
    }
}
