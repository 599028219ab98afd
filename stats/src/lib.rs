//! Statistics on matrices, with no knowledge of ceilings: Gaussian-process
//! regression, Sobol' sensitivity indices, calibration by black-box
//! variational inference with an MCMC cross-check, and model selection by
//! minimum description length.
