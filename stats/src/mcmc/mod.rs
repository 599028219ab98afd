//! MCMC.
