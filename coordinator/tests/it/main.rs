//! The coordinator's integration tests, one module per subject.

#[cfg(feature = "zenoh")]
mod security_attacks;
#[cfg(feature = "zenoh")]
mod security_sigterm;
