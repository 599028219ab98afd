//! One Newmark step solved by Newton iterations on the sparse effective
//! tangent K_eff = K_t + γ/(βΔt) C + 1/(βΔt²) M, converged when the 2-norm
//! of the displacement increment over the free DOFs falls below a tolerance
//! (OpenSees `test NormDispIncr`) or when the residual sits at its round-off
//! floor ([`super::round_off`]). The factorization is kept and reused while
//! the step size is unchanged: exactly, with a low-rank correction for up to
//! 6 springs whose tangent changed ([`super::low_rank`]); beyond that it is
//! refactorized, or optionally used as an approximate tangent with Krylov
//! acceleration ([`super::krylov`], `NewtonSettings::stale_max_iter`).
//! With at most [`super::condensed::CONDENSE_MAX_SPRINGS`] nonlinear
//! springs (the default `NewtonSettings::condense`) a step is solved on
//! their deformations alone instead ([`super::condensed`]: the same
//! iterates, a dense solve per iteration, no sparse refactorization).
//! A structure whose springs are all elastic is linear: its first
//! increment, solved with the exact tangent, is the step's solution, and
//! the step ends there (a second iteration would only confirm it with a
//! round-off increment, doubling the solves).
//!
//! Equation of motion relative to the base: M ü + C u̇ + F_int(u) = −M r a_g.
//! Units: N, mm, s, t.

use super::condensed::Condensed;
use super::cycle::TangentHistory;
use super::factor_cache::{CholeskyLayout, FactorCache, TangentFactor};
use super::krylov::KrylovAccelerator;
use super::low_rank::{LowRankUpdate, SpringEqs};
use super::newmark::NewmarkConstants;
use super::round_off::{at_round_off, residual_scale};
use super::springs::{SpringFailure, SpringStates};
use crate::assembly::Structure;
use crate::materials::MaterialSpec;

/// Displacement, velocity and acceleration relative to the base (free DOFs).
#[derive(Debug, Clone, PartialEq)]
pub struct Kinematics {
    /// Displacements (mm, rad).
    pub u: Vec<f64>,
    /// Velocities (mm/s, rad/s).
    pub v: Vec<f64>,
    /// Accelerations (mm/s², rad/s²).
    pub a: Vec<f64>,
}

impl Kinematics {
    /// At rest and undeformed.
    pub fn zeros(n: usize) -> Self {
        Kinematics { u: vec![0.0; n], v: vec![0.0; n], a: vec![0.0; n] }
    }

    /// Sets the velocities and accelerations of a trial state from its
    /// displacements and the `committed` state (Newmark's update).
    pub fn follow_displacements(&mut self, nm: &NewmarkConstants, committed: &Kinematics) {
        nm.update_all(&self.u, &committed.u, &committed.v, &committed.a, &mut self.v, &mut self.a);
    }
}

/// Newton settings: converged when ‖Δu‖₂ < `tol_mm`, or when the residual
/// is at its round-off floor ([`super::round_off`]: every |R_e| ≤
/// `floor_factor` ε Σ|terms of R_e|) after an increment that was solved
/// with the exact tangent and left every spring's tangent as it was, or
/// that was below `floor_tol_mm`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonSettings {
    /// Converged when ‖Δu‖₂ < this (mm).
    pub tol_mm: f64,
    /// Iterations before giving up.
    pub max_iter: usize,
    /// Multiple of ε Σ|terms| below which a residual is round-off.
    pub floor_factor: f64,
    /// Largest ‖Δu‖₂ accepted with a round-off residual (mm) when the
    /// increment changed a spring's tangent or was solved approximately.
    pub floor_tol_mm: f64,
    /// Krylov-accelerated iterations allowed per step on a kept factor whose
    /// tangent differs in more springs than the low-rank correction takes,
    /// before refactorizing (0: refactorize at once). Above 0 the step is
    /// never condensed.
    pub stale_max_iter: usize,
    /// Solve on the nonlinear springs' deformations when there are at most
    /// [`super::condensed::CONDENSE_MAX_SPRINGS`] of them ([`super::condensed`]).
    pub condense: bool,
}

impl Default for NewtonSettings {
    /// The fixtures' settings: 1e-10 mm, 50 iterations; a round-off
    /// residual (64 ε) also converges (after an exact increment that kept
    /// the springs' tangents, or one below 1e-7 mm); condensed onto the
    /// nonlinear springs when they are few.
    fn default() -> Self {
        NewtonSettings {
            tol_mm: 1e-10,
            max_iter: 50,
            floor_factor: 64.0,
            floor_tol_mm: 1e-7,
            stale_max_iter: 0,
            condense: true,
        }
    }
}

/// Why a Newton step failed.
#[derive(Debug, Clone, PartialEq)]
pub enum NewtonFailure {
    /// No convergence within the allowed iterations.
    MaxIterations {
        /// Iterations done.
        iterations: usize,
        /// Last ‖Δu‖₂ (mm).
        last_norm_mm: f64,
    },
    /// The iterations returned to the spring tangents of an earlier one
    /// (not the last), so on piecewise-linear springs they cycle.
    Cycling {
        /// Iteration whose tangents repeat.
        iteration: usize,
        /// The earlier iteration with the same tangents.
        earlier: usize,
    },
    /// The increment became NaN or infinite (singular or unstable tangent).
    NonFinite {
        /// Iteration at which it happened.
        iteration: usize,
    },
    /// The effective tangent could not be factorized.
    Singular {
        /// The factorization's complaint.
        message: String,
    },
    /// A spring material refused its trial deformation.
    Material(SpringFailure),
}

impl std::fmt::Display for NewtonFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NewtonFailure::MaxIterations { iterations, last_norm_mm } => {
                write!(f, "no convergence in {iterations} Newton iterations (|du| = {last_norm_mm:.3e} mm)")
            }
            NewtonFailure::Cycling { iteration, earlier } => {
                write!(f, "Newton iteration {iteration} returned to the spring tangents of iteration {earlier}: cycling")
            }
            NewtonFailure::NonFinite { iteration } => {
                write!(f, "non-finite displacement increment at Newton iteration {iteration}")
            }
            NewtonFailure::Singular { message } => {
                write!(f, "singular effective tangent: {message}")
            }
            NewtonFailure::Material(m) => write!(f, "spring {}: {}", m.spring, m.error),
        }
    }
}

/// Most springs whose tangent may differ from the factored one before a
/// full refactorization. A new spring in the correction costs one solve
/// with the kept factor; a refactorization of a 6 m x 4.8 m grid costs
/// about as much as four to six such solves. On its Pinching4 sweep (6000
/// steps, 126 hysteretic connections) 6 rather than 24 trades 22 907
/// column solves for 4 056 and 3 523 factorizations for 5 056, and the
/// run's CPU time fell by about a tenth (fastest of five: 4.2 -> 3.7 s).
const MAX_RANK: usize = 6;

/// An approximate-tangent iteration must shrink the increment by at least
/// this factor, else the next iteration refactorizes.
const STALE_MIN_CONTRACTION: f64 = 0.5;

/// Most directions kept by the Krylov accelerator.
const KRYLOV_MAX_DIM: usize = 8;

/// The operator an iteration solved with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Operator {
    /// The current tangent (factor plus exact low-rank correction).
    Exact,
    /// A kept factorization of an earlier tangent.
    Stale,
}

/// What a sparse Newton step carries from one iteration to the next.
struct SparseIteration {
    /// Residual (N), overwritten by the increment Δu (mm); (n_dof).
    r: Vec<f64>,
    /// Round-off scale of the residual (N); (n_dof).
    scale: Vec<f64>,
    /// Last ‖Δu‖₂ (mm); NaN before the first increment.
    last: f64,
    /// The last increment was solved with the exact tangent.
    exact_solve: bool,
    /// Spring tangents of the last exact solve (N/mm).
    solved_tangents: Vec<f64>,
    /// Approximate-tangent iterations done in this step.
    stale_iters: usize,
    /// Approximate-tangent iterations still allowed in this step.
    allow_stale: bool,
    /// The operator the Krylov accelerator's directions belong to.
    krylov_operator: Option<u64>,
}

impl SparseIteration {
    /// Before the first iteration of a step on `n` DOFs.
    fn new(n: usize, settings: &NewtonSettings) -> Self {
        SparseIteration {
            r: vec![0.0; n],
            scale: vec![0.0; n],
            last: f64::NAN,
            exact_solve: false,
            solved_tangents: Vec::new(),
            stale_iters: 0,
            allow_stale: settings.stale_max_iter > 0,
            krylov_operator: None,
        }
    }
}

/// One time step's fixed inputs: the Newmark constants of its size, the
/// committed state it starts from, the external load Σ M r a_g at its end
/// (N) and the Newton settings.
#[derive(Debug, Clone, Copy)]
pub struct Step<'a> {
    /// Newmark constants at the step size.
    pub nm: &'a NewmarkConstants,
    /// The committed state at the step start.
    pub committed: &'a Kinematics,
    /// External load at the step end (N), one per free DOF.
    pub ext: &'a [f64],
    /// Newton settings.
    pub settings: &'a NewtonSettings,
}

/// The constant parts of the dynamic system and the factorization cache.
pub struct Dynamics<'a> {
    s: &'a Structure,
    /// Damping C = αM + βK_R on the pattern.
    c_values: Vec<f64>,
    diag: Vec<usize>,
    /// Step of the cached beam + mass + damping part.
    base_dt_s: f64,
    base_eff: Vec<f64>,
    factored_tangents: Option<Vec<f64>>,
    factor: Option<TangentFactor>,
    cache: FactorCache,
    low_rank: LowRankUpdate,
    spring_eqs: Vec<SpringEqs>,
    changes: Vec<(usize, f64)>,
    /// Number of factorizations done.
    pub factorizations: usize,
    /// Number of low-rank (Woodbury) corrections set up on a kept factor.
    pub low_rank_updates: usize,
    /// Number of Krylov-accelerated iterations on a kept approximate tangent.
    pub stale_iterations: usize,
    /// Changes whenever the factor or its correction changes.
    operator_id: u64,
    krylov: KrylovAccelerator,
    work: Vec<f64>,
    /// Every spring elastic: one exact increment solves a step.
    linear: bool,
    /// The condensation onto the nonlinear springs, when they are few.
    condensed: Option<Condensed>,
}

impl<'a> Dynamics<'a> {
    /// The system of a structure with Rayleigh coefficients α (1/s) and β
    /// (s), factorized with the given Cholesky layout.
    pub fn new(
        s: &'a Structure,
        alpha_m_per_s: f64,
        beta_k_s: f64,
        layout: CholeskyLayout,
    ) -> Self {
        let diag = s.diagonal_positions();
        let mut kr = s.beam_values.clone();
        let k0: Vec<f64> = s
            .springs
            .iter()
            .map(|sp| if sp.rayleigh { sp.material.initial_tangent() } else { 0.0 })
            .collect();
        s.add_spring_tangents(&mut kr, &k0);
        let mut c_values: Vec<f64> = kr.iter().map(|k| beta_k_s * k).collect();
        for (eq, m) in s.mass.iter().enumerate() {
            c_values[diag[eq]] += alpha_m_per_s * m;
        }
        let n = s.pattern.n;
        Dynamics {
            s,
            c_values,
            diag,
            base_dt_s: f64::NAN,
            base_eff: Vec::new(),
            factored_tangents: None,
            factor: None,
            cache: FactorCache::new(&s.pattern, layout),
            low_rank: LowRankUpdate::default(),
            spring_eqs: s.springs.iter().map(|sp| sp.eqs).collect(),
            changes: Vec::new(),
            factorizations: 0,
            low_rank_updates: 0,
            stale_iterations: 0,
            operator_id: 0,
            krylov: KrylovAccelerator::default(),
            work: vec![0.0; n],
            linear: s.springs.iter().all(|sp| matches!(sp.material, MaterialSpec::Elastic { .. })),
            condensed: Condensed::of(s),
        }
    }

    /// The structure.
    pub fn structure(&self) -> &'a Structure {
        self.s
    }

    /// Dense factorizations of condensed steps so far.
    pub fn dense_factorizations(&self) -> usize {
        self.condensed.as_ref().map_or(0, Condensed::dense_factorizations)
    }

    /// The beam, mass and damping part of the effective tangent at the
    /// step of `nm` (recomputed when the step changes, which also drops the
    /// kept factor).
    pub(super) fn base_values(&mut self, nm: &NewmarkConstants) -> &[f64] {
        if self.base_dt_s != nm.dt_s {
            self.base_eff = self
                .s
                .beam_values
                .iter()
                .zip(&self.c_values)
                .map(|(k, c)| k + nm.c_damp * c)
                .collect();
            for (eq, m) in self.s.mass.iter().enumerate() {
                self.base_eff[self.diag[eq]] += nm.c_mass * m;
            }
            self.base_dt_s = nm.dt_s;
            self.factor = None;
        }
        &self.base_eff
    }

    /// The factorization cache of the pattern (counts a factorization).
    pub(super) fn cache_mut(&mut self) -> &mut FactorCache {
        self.factorizations += 1;
        &mut self.cache
    }

    /// Solves done for low-rank correction columns so far.
    pub fn column_solves(&self) -> usize {
        self.low_rank.column_solves
    }

    /// Chooses the operator of this iteration: the factor with an exact
    /// low-rank correction for the current spring tangents (`Exact`), the
    /// kept operator as an approximate tangent when `allow_stale` and too many
    /// springs changed (`Stale`), or else a fresh factorization (`Exact`).
    fn prepare_operator(
        &mut self,
        nm: &NewmarkConstants,
        tangents: &[f64],
        allow_stale: bool,
    ) -> Result<Operator, NewtonFailure> {
        self.base_values(nm);
        if let (Some(base), Some(t0)) = (&self.factor, &self.factored_tangents) {
            self.changes.clear();
            for (k, (a, b)) in tangents.iter().zip(t0).enumerate() {
                if a != b && self.spring_eqs[k].iter().any(Option::is_some) {
                    self.changes.push((k, a - b));
                }
            }
            if self.low_rank.is(&self.changes) {
                return Ok(Operator::Exact);
            }
            if self.changes.len() <= MAX_RANK {
                let n = self.s.pattern.n;
                self.operator_id += 1;
                if self.low_rank.set(base, &self.spring_eqs, n, &self.changes) {
                    self.low_rank_updates += 1;
                    return Ok(Operator::Exact);
                }
            }
            if allow_stale {
                return Ok(Operator::Stale);
            }
        }
        let mut values = self.base_eff.clone();
        self.s.add_spring_tangents(&mut values, tangents);
        let f = self
            .cache
            .factor(&self.s.pattern, &values)
            .map_err(|message| NewtonFailure::Singular { message })?;
        self.factor = Some(f);
        self.factored_tangents = Some(tangents.to_vec());
        self.low_rank.reset();
        self.operator_id += 1;
        self.factorizations += 1;
        Ok(Operator::Exact)
    }

    /// Residual R = −Σ M r a_g − M a − C v − K_beam u − F_springs into `out`
    /// (one pass over the pattern for K_beam u + C v); `ext` is Σ M r a_g.
    pub(super) fn residual(
        &mut self,
        trial: &Kinematics,
        springs: &SpringStates,
        ext: &[f64],
        out: &mut [f64],
    ) {
        let p = &self.s.pattern;
        let (kb, cv) = (&self.s.beam_values, &self.c_values);
        for k in 0..out.len() {
            out[k] = -ext[k] - self.s.mass[k] * trial.a[k];
        }
        for c in 0..p.n {
            let (uc, vc) = (trial.u[c], trial.v[c]);
            for q in p.col_ptr[c]..p.col_ptr[c + 1] {
                out[p.row_idx[q]] -= kb[q] * uc + cv[q] * vc;
            }
        }
        let mut fs = std::mem::take(&mut self.work);
        fs.iter_mut().for_each(|x| *x = 0.0);
        springs.add_forces(self.s, &mut fs);
        for k in 0..out.len() {
            out[k] -= fs[k];
        }
        self.work = fs;
    }

    /// Solves `step` from its committed state to a converged `trial`;
    /// returns the number of iterations.
    pub fn solve_step(
        &mut self,
        step: &Step<'_>,
        trial: &mut Kinematics,
        springs: &mut SpringStates,
    ) -> Result<usize, NewtonFailure> {
        springs.begin_step(self.s, step.nm, step.committed);
        if step.settings.condense && step.settings.stale_max_iter == 0 {
            if let Some(mut c) = self.condensed.take() {
                let res = self.solve_step_condensed(&mut c, step, trial, springs);
                self.condensed = Some(c);
                return res;
            }
        }
        self.solve_step_sparse(step, trial, springs)
    }

    /// [`Dynamics::solve_step`] on every free DOF with the sparse tangent;
    /// returns the number of iterations.
    fn solve_step_sparse(
        &mut self,
        step: &Step<'_>,
        trial: &mut Kinematics,
        springs: &mut SpringStates,
    ) -> Result<usize, NewtonFailure> {
        let &Step { nm, committed, ext, settings } = step;
        trial.u.clone_from(&committed.u);
        let mut st = SparseIteration::new(committed.u.len(), settings);
        let mut tangents = TangentHistory::default();
        for it in 1..=settings.max_iter {
            self.set_trial_state(nm, committed, trial, springs)?;
            // Only exact iterates are fixed by their predecessor's pieces.
            if settings.stale_max_iter == 0 {
                tangents.record(it, &springs.tangent_n_mm)?;
            }
            self.residual(trial, springs, ext, &mut st.r);
            // An increment solved with the exact tangent that left every
            // spring on the tangent it was solved with is, for springs
            // linear on that segment, the step's solution: a round-off
            // residual confirms it, and a further solve would only move
            // round-off around.
            let kept = st.exact_solve && springs.tangent_n_mm == st.solved_tangents;
            let floor = it > 1
                && (kept || st.last < settings.floor_tol_mm)
                && self.residual_at_round_off(trial, springs, ext, settings, &mut st);
            if floor && kept {
                return Ok(it - 1);
            }
            let op = self.solve_increment(nm, &springs.tangent_n_mm, settings, &mut st)?;
            let norm = st.r.iter().map(|x| x * x).sum::<f64>().sqrt();
            if !norm.is_finite() {
                return Err(NewtonFailure::NonFinite { iteration: it });
            }
            if op == Operator::Stale && norm > STALE_MIN_CONTRACTION * st.last {
                st.allow_stale = false;
            }
            trial.u.iter_mut().zip(&st.r).for_each(|(u, d)| *u += d);
            st.last = norm;
            let exact = self.linear && op == Operator::Exact;
            if exact || norm < settings.tol_mm || (floor && norm < settings.floor_tol_mm) {
                self.set_trial_state(nm, committed, trial, springs)?;
                return Ok(it);
            }
        }
        Err(NewtonFailure::MaxIterations { iterations: settings.max_iter, last_norm_mm: st.last })
    }

    /// Sets every spring at `trial.u`, then the trial velocities and
    /// accelerations from `committed` (Newmark's update).
    pub(super) fn set_trial_state(
        &self,
        nm: &NewmarkConstants,
        committed: &Kinematics,
        trial: &mut Kinematics,
        springs: &mut SpringStates,
    ) -> Result<(), NewtonFailure> {
        springs.set_trial(self.s, &trial.u).map_err(NewtonFailure::Material)?;
        trial.follow_displacements(nm, committed);
        Ok(())
    }

    /// Whether the residual `st.r` is at its round-off floor (fills
    /// `st.scale` with its scale, N).
    fn residual_at_round_off(
        &self,
        trial: &Kinematics,
        springs: &SpringStates,
        ext: &[f64],
        settings: &NewtonSettings,
        st: &mut SparseIteration,
    ) -> bool {
        residual_scale(self.s, &self.c_values, trial, springs, ext, &mut st.scale);
        at_round_off(&st.r, &st.scale, settings.floor_factor)
    }

    /// Overwrites the residual `st.r` with the increment Δu (mm) solved with
    /// the operator chosen for spring tangents `tangents` (N/mm); returns
    /// that operator.
    fn solve_increment(
        &mut self,
        nm: &NewmarkConstants,
        tangents: &[f64],
        settings: &NewtonSettings,
        st: &mut SparseIteration,
    ) -> Result<Operator, NewtonFailure> {
        let allow = st.allow_stale && st.stale_iters < settings.stale_max_iter;
        let op = self.prepare_operator(nm, tangents, allow)?;
        st.exact_solve = op == Operator::Exact;
        if st.exact_solve {
            tangents.clone_into(&mut st.solved_tangents);
        }
        if let Some(f) = &self.factor {
            f.solve_in_place(&mut st.r);
            self.low_rank.correct(&self.spring_eqs, &mut st.r);
        }
        if op == Operator::Stale {
            self.accelerate_stale(st);
        } else {
            st.krylov_operator = None;
        }
        Ok(op)
    }

    /// Krylov acceleration of an increment `st.r` solved with a kept
    /// approximate tangent (restarted when that operator changed).
    fn accelerate_stale(&mut self, st: &mut SparseIteration) {
        if st.krylov_operator != Some(self.operator_id) {
            self.krylov.reset();
            st.krylov_operator = Some(self.operator_id);
        }
        self.krylov.accelerate(&mut st.r, KRYLOV_MAX_DIM);
        st.stale_iters += 1;
        self.stale_iterations += 1;
    }
}
