//! A shaking-table run of a generated ceiling: the specimen and parameter
//! values ([`crate::generator`]), Rayleigh damping on its first x and y
//! modes ([`damping`]), a base input in x and/or y ([`input`]) and sensors
//! at plan positions ([`sensor`]) → modal frequencies and sensor histories
//! ([`simulate`]); a linear model's run by modal superposition
//! ([`modal_response`]).
//!
//! Units at this interface are SI as a measured-data bundle states them:
//! m, s, m/s² (the FE model inside works in N, mm, s, t).

pub mod damping;
pub mod input;
pub mod modal_response;
pub mod prepare;
pub mod sensor;
pub mod simulate;

pub use damping::{check_damping_ratio, check_share, rayleigh_on_first_modes, RayleighFit};
pub use input::{sine_sweep, BaseInput, SineSweep};
pub use modal_response::{
    simulate_linear, simulate_linear_runs, simulate_linear_runs_on, LinearSimulation,
};
pub use prepare::{
    damped_model, damped_model_on, instrument, prepare, steps_per_sample, DampedModel, PreparedRun,
};
pub use sensor::{Direction, Sensor, SensorKind};
pub use simulate::{
    read_history, run_prepared, simulate, CeilingError, SensorHistory, SimOptions, Simulation,
    SpringPeak,
};
