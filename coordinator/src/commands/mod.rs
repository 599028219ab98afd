//! One module per subcommand group of the `ceilfarm` binary.

pub mod bundle;
pub mod calibrate;
pub mod demo;
pub mod diagnose;
pub mod farm;
pub mod fe;
pub mod gp;
pub mod pipeline;
pub mod select;
pub mod sobol;
pub mod store;
pub mod sweep;
pub mod synth;
pub mod worker;
