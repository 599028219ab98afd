//! Nonlinear transient analysis of a `ceiling-fe-model` v1 file under a
//! uniform base acceleration (`MODEL_FORMAT.md`, "Transient"): Newmark-β
//! ([`newmark`]) with Newton iterations on the sparse effective tangent
//! ([`newton`]), step halving on failure ([`subdivision`]), the ground
//! record ([`excitation`]), recorders ([`recorders`]) and the history CSV
//! ([`history`]). Rayleigh damping C = αM + βK_R on the initial stiffness of
//! the beams and of the springs flagged `rayleigh`.
//!
//! Units: N, mm, s, t; accelerations mm/s².

pub mod excitation;
pub mod factor_cache;
pub mod history;
pub mod low_rank;
pub mod newmark;
pub mod newton;
pub mod recorders;
pub mod spec;
pub mod springs;
pub mod subdivision;

use std::path::{Path, PathBuf};

pub use excitation::GroundMotion;
pub use history::{write_history, write_history_csv, History};
pub use newton::{Kinematics, NewtonFailure, NewtonSettings};
pub use spec::TransientSpec;

use crate::assembly::{AssemblyError, Structure};
use crate::model::Model;
use newton::Dynamics;
use recorders::Recorders;
use springs::SpringStates;
use subdivision::{advance, StepControl, StepState};

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
    /// Newton settings (default: ‖Δu‖₂ < 1e-10 mm, 50 iterations).
    pub newton: NewtonSettings,
    /// Step halvings allowed on failure (default 6: down to Δt/64).
    pub max_halvings: u32,
    /// Run only the first this many steps (default: all).
    pub max_steps: Option<usize>,
}

impl TransientOptions {
    /// Defaults with records read relative to `base_dir`.
    pub fn new(base_dir: &Path) -> Self {
        TransientOptions {
            base_dir: base_dir.to_path_buf(),
            newton: NewtonSettings::default(),
            max_halvings: 6,
            max_steps: None,
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
}

/// Runs the model's transient analysis; `observer` hears every step.
pub fn run_model(
    model: &Model,
    opts: &TransientOptions,
    observer: &mut dyn FnMut(&StepReport),
) -> Result<History, TransientError> {
    let spec = TransientSpec::from_model(model)?;
    let ground = GroundMotion::from_spec(&spec.excitation, &opts.base_dir)?;
    let s = Structure::new(model)?;
    let (alpha, beta) =
        model.damping.as_ref().map_or((0.0, 0.0), |d| (d.alpha_m_per_s, d.beta_k_s));
    let recs = Recorders::new(&spec.recorders, &s, ground.dof)?;
    let springs = SpringStates::new(&s)
        .map_err(|f| TransientError::Material { spring: f.spring, message: f.error.to_string() })?;
    let load = influence_load(&s, ground.dof);
    let n = s.dofs.n_free;
    let mut st =
        StepState { committed: Kinematics::zeros(n), trial: Kinematics::zeros(n), springs };
    let mut sys = Dynamics::new(&s, alpha, beta);
    let ctl = StepControl {
        gamma: spec.integrator.gamma,
        beta: spec.integrator.beta,
        newton: opts.newton,
        max_halvings: opts.max_halvings,
    };
    let mut columns = vec!["t_s".to_string(), "ag_mm_s2".to_string()];
    columns.extend(recs.names.iter().cloned());
    let mut hist = History { columns, rows: Vec::new() };
    push_row(&mut hist, &recs, &st, &ground, 0.0);
    let n_steps = opts.max_steps.map_or(spec.n_steps, |m| m.min(spec.n_steps));
    for step in 1..=n_steps {
        let t0 = (step - 1) as f64 * spec.dt_s;
        let cost = match advance(&mut sys, &mut st, &ground, &load, &ctl, t0, spec.dt_s, 0) {
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
        let t = step as f64 * spec.dt_s;
        if step % spec.output_every_n_steps == 0 {
            push_row(&mut hist, &recs, &st, &ground, t);
        }
        observer(&StepReport {
            step,
            n_steps,
            t_s: t,
            iterations: cost.iterations,
            substeps: cost.substeps,
            factorizations: sys.factorizations,
        });
    }
    Ok(hist)
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

fn push_row(h: &mut History, recs: &Recorders, st: &StepState, g: &GroundMotion, t: f64) {
    let ag = g.accel_at(t);
    let mut row = vec![t, ag];
    recs.sample(&st.committed, &st.springs, ag, &mut row);
    h.rows.push(row);
}
