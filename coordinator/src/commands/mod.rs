//! One module per subcommand group of the `ceilfarm` binary.
pub mod calibrate;
pub mod select;
