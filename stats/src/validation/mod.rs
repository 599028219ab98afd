//! Validation of surrogate predictions: held-out metrics and, for the GP,
//! the leave-one-out shortcut (`stats::gp::Gp::loo`).

pub mod metrics;

pub use metrics::{validate, Validation};
