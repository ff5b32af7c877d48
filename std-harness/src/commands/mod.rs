//! One module per subcommand.

pub mod bench;
pub mod chart;
pub mod compare;
pub mod info;
pub mod probe;
pub mod render;
pub mod splat;
pub mod tables;
pub mod verify;
