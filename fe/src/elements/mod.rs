//! Element kernels: the 3D elastic beam-column ([`elastic_beam_3d`]) and the
//! zero-length one-DOF spring ([`zero_length`]). Pure functions of geometry,
//! sections and material tangents; assembly scatters their matrices.

pub mod elastic_beam_3d;
pub mod zero_length;

pub use elastic_beam_3d::{beam_global_stiffness, beam_local_stiffness, local_axes, Mat12};
pub use zero_length::{spring_dofs, spring_force_vector, spring_stiffness};
