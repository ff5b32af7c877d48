//! One module per subcommand.

pub mod compare;
pub mod splat;
pub mod tables;
