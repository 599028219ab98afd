//! Nonlinear transient analysis of a `ceiling-fe-model` v1 file under a
//! uniform base acceleration (`MODEL_FORMAT.md`, "Transient"): Newmark-β
//! ([`newmark`]) with Newton iterations on the sparse effective tangent
//! ([`newton`]), step halving on failure ([`subdivision`]), the ground
//! record ([`excitation`]), recorders ([`recorders`]) and the history CSV
//! ([`history`]). Rayleigh damping C = αM + βK_R on the initial stiffness of
//! the beams and of the springs flagged `rayleigh`, or on those springs'
//! last committed tangents ([`tangent_damping`]).
//!
//! Units: N, mm, s, t; accelerations mm/s².

pub mod condensed;
pub mod cycle;
pub mod excitation;
pub mod factor_cache;
pub mod history;
pub mod krylov;
pub mod low_rank;
pub mod newmark;
pub mod newton;
pub mod recorders;
pub mod round_off;
pub mod spec;
pub mod spring_lu;
pub mod springs;
pub mod subdivision;
pub mod tangent_damping;

use std::path::{Path, PathBuf};

pub use excitation::{BaseMotion, GroundMotion};
pub use factor_cache::CholeskyLayout;
pub use history::{write_history, write_history_csv, History};
pub use newton::{Kinematics, NewtonFailure, NewtonSettings};
pub use spec::TransientSpec;

use crate::assembly::{AssemblyError, Structure};
use crate::model::Model;
use newton::Dynamics;
use recorders::Recorders;
use springs::SpringStates;
use subdivision::{advance, StepControl, StepCost, StepState};

/// Why a transient run could not be set up or did not finish.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TransientError {
    /// The analysis block is missing or malformed.
    #[error("transient analysis block: {message}")]
    Spec {
        /// What is wrong.
        message: String,
    },
    /// The ground-motion record could not be used.
    #[error("record {path}: {message}")]
    Record {
        /// The record file (with line when known).
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A recorder names something the model lacks.
    #[error("recorder {recorder}: {message}")]
    Recorder {
        /// The recorder as written.
        recorder: String,
        /// What is wrong.
        message: String,
    },
    /// The model could not be assembled.
    #[error(transparent)]
    Assembly(#[from] AssemblyError),
    /// A spring material could not be built.
    #[error("spring {spring}: {message}")]
    Material {
        /// Spring id.
        spring: u64,
        /// The material's complaint.
        message: String,
    },
    /// A step failed to converge even at the smallest sub-step.
    #[error("no convergence at t = {t_s} s (sub-step {dt_s} s, step {step}): {reason}")]
    NoConvergence {
        /// Time at which the failing sub-step starts (s).
        t_s: f64,
        /// Size of the failing sub-step (s).
        dt_s: f64,
        /// The analysis step (1-based) that failed.
        step: usize,
        /// Why Newton failed.
        reason: String,
        /// Rows recorded up to the last converged output step.
        history: Box<History>,
    },
    /// An output file could not be written.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        message: String,
    },
}

/// Solver choices that the model file does not fix.
#[derive(Debug, Clone, PartialEq)]
pub struct TransientOptions {
    /// Folder that record CSV paths are relative to (the model file's folder).
    pub base_dir: PathBuf,
    /// Newton settings (default: ‖Δu‖₂ < 1e-10 mm or a round-off residual,
    /// 50 iterations).
    pub newton: NewtonSettings,
    /// Step halvings allowed on failure (default 6: down to Δt/64).
    pub max_halvings: u32,
    /// Run only the first this many steps (default: all).
    pub max_steps: Option<usize>,
    /// Layout of the tangent's Cholesky factor (default supernodal).
    pub cholesky: CholeskyLayout,
}

impl TransientOptions {
    /// Defaults with records read relative to `base_dir`.
    pub fn new(base_dir: &Path) -> Self {
        TransientOptions {
            base_dir: base_dir.to_path_buf(),
            newton: NewtonSettings::default(),
            max_halvings: 6,
            max_steps: None,
            cholesky: CholeskyLayout::default(),
        }
    }
}

/// What the observer hears after each analysis step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    /// Step number (1-based).
    pub step: usize,
    /// Steps in the run.
    pub n_steps: usize,
    /// Time at the end of the step (s).
    pub t_s: f64,
    /// Newton iterations in this step (all sub-steps).
    pub iterations: usize,
    /// Sub-steps (1 without subdivision).
    pub substeps: usize,
    /// Factorizations so far.
    pub factorizations: usize,
    /// Low-rank (Woodbury) corrections of a kept factorization so far.
    pub low_rank_updates: usize,
    /// Solves for low-rank correction columns so far.
    pub column_solves: usize,
    /// Krylov-accelerated iterations on a kept approximate tangent so far.
    pub stale_iterations: usize,
    /// Dense factorizations of condensed steps so far ([`condensed`]).
    pub dense_factorizations: usize,
}

/// Runs the model's transient analysis; `observer` hears every step.
pub fn run_model(
    model: &Model,
    opts: &TransientOptions,
    observer: &mut dyn FnMut(&StepReport),
) -> Result<History, TransientError> {
    let spec = TransientSpec::from_model(model)?;
    let components = spec
        .components()
        .iter()
        .map(|e| GroundMotion::from_spec(e, &opts.base_dir))
        .collect::<Result<Vec<_>, _>>()?;
    let ground = BaseMotion { components };
    let plan = Plan {
        base: &ground,
        dt_s: spec.dt_s,
        n_steps: spec.n_steps,
        gamma: spec.integrator.gamma,
        beta: spec.integrator.beta,
        output_every_n_steps: spec.output_every_n_steps,
        recorders: &spec.recorders,
    };
    run_plan(model, &plan, opts, observer)
}

/// What to integrate, when it does not come from the model's analysis block.
#[derive(Debug, Clone, Copy)]
pub struct Plan<'a> {
    /// Base motion (one component per DOF).
    pub base: &'a BaseMotion,
    /// Analysis step (s).
    pub dt_s: f64,
    /// Number of steps.
    pub n_steps: usize,
    /// Newmark γ.
    pub gamma: f64,
    /// Newmark β.
    pub beta: f64,
    /// One output row every this many steps (≥ 1).
    pub output_every_n_steps: usize,
    /// Recorded channels.
    pub recorders: &'a [spec::RecorderSpec],
}

/// Runs a transient of `model` (its masses, damping, springs) under `plan`.
pub fn run_plan(
    model: &Model,
    plan: &Plan<'_>,
    opts: &TransientOptions,
    observer: &mut dyn FnMut(&StepReport),
) -> Result<History, TransientError> {
    let ground = plan.base;
    let s = Structure::new(model)?;
    let (alpha, beta) =
        model.damping.as_ref().map_or((0.0, 0.0), |d| (d.alpha_m_per_s, d.beta_k_s));
    let dofs: Vec<u8> = ground.components.iter().map(|g| g.dof).collect();
    let recs = Recorders::new(plan.recorders, &s, &dofs)?;
    let mut st = at_rest(model, &s, beta)?;
    let loads: Vec<Vec<f64>> = dofs.iter().map(|d| influence_load(&s, *d)).collect();
    let mut sys = Dynamics::new(&s, alpha, beta, opts.cholesky);
    let ctl = StepControl {
        gamma: plan.gamma,
        beta: plan.beta,
        newton: opts.newton,
        max_halvings: opts.max_halvings,
    };
    let mut hist = History { columns: columns(&dofs, &recs), rows: Vec::new() };
    push_row(&mut hist, &recs, &st, ground, 0.0);
    let n_steps = opts.max_steps.map_or(plan.n_steps, |m| m.min(plan.n_steps));
    let every = plan.output_every_n_steps.max(1);
    for step in 1..=n_steps {
        let t0 = (step - 1) as f64 * plan.dt_s;
        let cost = match advance(&mut sys, &mut st, ground, &loads, &ctl, t0, plan.dt_s, 0) {
            Ok(c) => c,
            Err(f) => {
                return Err(TransientError::NoConvergence {
                    t_s: f.t_s,
                    dt_s: f.dt_s,
                    step,
                    reason: f.reason.to_string(),
                    history: Box::new(hist),
                })
            }
        };
        let t = step as f64 * plan.dt_s;
        if step % every == 0 {
            push_row(&mut hist, &recs, &st, ground, t);
        }
        observer(&step_report(step, n_steps, t, &cost, &sys));
    }
    Ok(hist)
}

/// The state at rest and undeformed, springs at their initial state (with
/// the committed-tangent share of the Rayleigh term `beta`, if the model's
/// damping asks for one).
fn at_rest(model: &Model, s: &Structure, beta: f64) -> Result<StepState, TransientError> {
    let mut springs = SpringStates::new(s)
        .map_err(|f| TransientError::Material { spring: f.spring, message: f.error.to_string() })?;
    let share = committed_share(model)?;
    if share > 0.0 {
        springs = springs.with_committed_tangent_damping(s, share * beta);
    }
    let n = s.dofs.n_free;
    Ok(StepState { committed: Kinematics::zeros(n), trial: Kinematics::zeros(n), springs })
}

/// What the observer hears after `step` of `n_steps` (time `t_s`).
fn step_report(
    step: usize,
    n_steps: usize,
    t_s: f64,
    cost: &StepCost,
    sys: &Dynamics<'_>,
) -> StepReport {
    StepReport {
        step,
        n_steps,
        t_s,
        iterations: cost.iterations,
        substeps: cost.substeps,
        factorizations: sys.factorizations,
        low_rank_updates: sys.low_rank_updates,
        column_solves: sys.column_solves(),
        stale_iterations: sys.stale_iterations,
        dense_factorizations: sys.dense_factorizations(),
    }
}

/// The share of the model's Rayleigh stiffness term on the committed
/// tangent ([`crate::model::Damping::committed_share`]; 0 without damping).
fn committed_share(model: &Model) -> Result<f64, TransientError> {
    model.damping.as_ref().map_or(Ok(0.0), |d| {
        d.committed_share().map_err(|found| TransientError::Spec {
            message: format!(
                "damping: stiffness {:?}, committed_share {found}: expected \"initial\", or \"committed\" with a share 0..=1",
                d.extra.get("stiffness")
            ),
        })
    })
}

/// `t_s`, the base acceleration column(s), then the recorder names.
fn columns(dofs: &[u8], recs: &Recorders) -> Vec<String> {
    let mut columns = vec!["t_s".to_string()];
    if dofs.len() == 1 {
        columns.push("ag_mm_s2".into());
    } else {
        columns.extend(dofs.iter().map(|d| format!("ag_dof{d}_mm_s2")));
    }
    columns.extend(recs.names.iter().cloned());
    columns
}

/// Reads a model file and runs its transient analysis (records relative to its folder).
pub fn run_model_file(
    path: &Path,
    observer: &mut dyn FnMut(&StepReport),
) -> Result<History, Box<dyn std::error::Error + Send + Sync>> {
    let model = crate::model::read_model(path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    Ok(run_model(&model, &TransientOptions::new(dir), observer)?)
}

/// M r: the lumped mass of every free equation in the excitation DOF (t).
fn influence_load(s: &Structure, dof: u8) -> Vec<f64> {
    let mut load = vec![0.0; s.dofs.n_free];
    for eqs in &s.dofs.eqs {
        if let Some(e) = eqs[usize::from(dof) - 1] {
            load[e] = s.mass[e];
        }
    }
    load
}

fn push_row(h: &mut History, recs: &Recorders, st: &StepState, g: &BaseMotion, t: f64) {
    let mut ag = Vec::with_capacity(g.components.len());
    g.accel_at(t, &mut ag);
    let mut row = vec![t];
    row.extend_from_slice(&ag);
    recs.sample(&st.committed, &st.springs, &ag, &mut row);
    h.rows.push(row);
}
