//! From a validated model to sparse global matrices on the free DOFs:
//! equation numbering with fixities removed ([`dof_map`]), a fixed sparse
//! pattern with precomputed scatter positions ([`pattern`]), and the
//! assembled structure with its element loop ([`structure`]).
//!
//! The transient solver reuses all three: the beams' part of K is constant
//! ([`Structure::beam_values`]); springs add their tangents each iteration
//! ([`Structure::add_spring_tangents`]).

pub mod dof_map;
pub mod pattern;
pub mod structure;

pub use dof_map::DofMap;
pub use pattern::SparsePattern;
pub use structure::{AssemblyError, Structure};
