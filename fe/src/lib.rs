//! Finite-element model of suspended ceilings (units N, mm, s, t).
//!
//! Roles: [`materials`] hold one-dimensional force-deformation laws with
//! trial and committed state; elements turn node displacements into forces;
//! solvers assemble and integrate, reporting through observers. Nothing here
//! knows about the farm or statistics.

pub mod assembly;
pub mod ceiling;
pub mod eigen;
pub mod elements;
pub mod generator;
pub mod materials;
pub mod model;
pub mod run;
pub mod transient;
