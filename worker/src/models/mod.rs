//! Model kinds: analytic test functions and the ceiling models.

pub mod analytic;
pub mod costed;
pub mod faults;
pub mod oscillator;
