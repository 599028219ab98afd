//! One module per subcommand group of the `ceilfarm` binary.

pub mod bundle;
pub mod sweep;
pub mod worker;
