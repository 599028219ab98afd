//! Statistics on matrices, with no knowledge of ceilings: Gaussian-process
//! regression, Sobol' sensitivity indices, calibration by black-box
//! variational inference with an MCMC cross-check, and model selection by
//! minimum description length.

pub mod bbvi;
pub mod calibration;
pub mod evidence;
pub mod gp;
pub mod mcmc;
pub mod selection;
pub mod sobol;
pub mod validation;
