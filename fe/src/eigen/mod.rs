//! Generalized eigenproblem K φ = ω² M φ on the free DOFs, lowest modes:
//! sparse block shift-invert Lanczos ([`lanczos`]) in mass-scaled
//! coordinates ([`shift_invert`]) on a supernodal Cholesky factor of K − σM
//! ([`supernodal`], ordered by AMD on node blocks, [`ordering`]; sparse LU,
//! [`factor`], if K − σM is indefinite), a dense statically condensed solver
//! for tests ([`dense`]), and the modal quantities of a model ([`modal`]:
//! frequencies, mass-normalised shapes, participation factors, effective
//! masses), and Rayleigh–Ritz reanalysis on the modes of a nearby model
//! ([`ritz`]).
//!
//! Massless DOFs (the ceiling models carry no rotational mass) give infinite
//! eigenvalues; shift-invert maps them to θ = 0, so they never appear among
//! the lowest modes. The iteration runs on the DOFs with mass; the shapes
//! are images (K − σM)⁻¹ M x on all DOFs, i.e. statically condensed exactly
//! as the dense solver does.

pub mod dense;
pub mod factor;
pub mod lanczos;
pub mod modal;
pub mod ordering;
pub mod output;
pub mod plot;
pub mod ritz;
pub mod shift_invert;
pub mod supernodal;

pub use dense::dense_eigen;
pub use lanczos::{shift_invert_lanczos, LanczosSettings};
pub use modal::{horizontal_share, modal_analysis, modal_analysis_on, ModalResult};
pub use ritz::{ritz_pairs, RitzError};

/// Eigenvalues ω² (rad²/s², ascending) and mass-normalised vectors (n_free each).
#[derive(Debug, Clone)]
pub struct Eigenpairs {
    /// ω² per mode, ascending.
    pub omega2: Vec<f64>,
    /// Mass-normalised shapes, one per mode (length n_free).
    pub vectors: Vec<Vec<f64>>,
}

/// Why the eigenproblem could not be solved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EigenError {
    /// More modes requested than DOFs with mass.
    #[error("{requested} modes requested but only {available} DOFs carry mass")]
    TooManyModes {
        /// Modes requested.
        requested: usize,
        /// DOFs with mass.
        available: usize,
    },
    /// K − σM could not be factorized.
    #[error("K - sigma M (sigma = {shift}) is singular: {message}")]
    Singular {
        /// The shift (rad²/s²).
        shift: f64,
        /// The factorization's complaint.
        message: String,
    },
    /// Lanczos did not converge in the allowed number of steps.
    #[error("Lanczos: {converged} of {requested} modes converged after {steps} steps")]
    NoConvergence {
        /// Modes converged.
        converged: usize,
        /// Modes requested.
        requested: usize,
        /// Steps taken.
        steps: usize,
    },
    /// The model could not be assembled.
    #[error(transparent)]
    Assembly(#[from] crate::assembly::AssemblyError),
}
