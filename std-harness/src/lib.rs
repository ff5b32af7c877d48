//! The std harness for Footprint: the `footprint` command line, file I/O, the table preprocessor
//! and an f64 reference renderer that uses no tables, against which the core is verified.
//!
//! - [`cli`]: argument parsing and the entry point [`run`].
//! - [`commands`]: one module per subcommand.
//! - [`reference`]: the f64, table-free footprint (exact line integrals).
//! - [`io`]: image and table files (always written atomically: temporary file, then rename).
//! - [`dispatch`]: runtime table size → const generic.

// `!(x > y)` sends NaN down the rejecting branch, on purpose (as in the core).
#![allow(clippy::neg_cmp_op_on_partial_ord)]

/// `println!` that never panics: a closed stdout (`footprint … | head`) is not an error worth a
/// crash, and the output files are already written by then.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout().lock(), $($arg)*);
    }};
}

pub mod cli;
pub mod commands;
pub mod dispatch;
pub mod io;
pub mod quality;
pub mod reference;
pub mod scene;
pub mod tf;

pub use cli::run;

use std::fmt;

/// An error for people: a one-line message and the process exit code it maps to.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CliError {
    /// One line, no trailing newline.
    pub message: String,
    /// 2 = bad input or I/O failure, 1 = a check (such as `compare --max-diff`) failed.
    pub code: i32,
}

impl CliError {
    /// Bad input or I/O: exit code 2.
    pub fn input(message: impl Into<String>) -> Self {
        CliError {
            message: message.into(),
            code: 2,
        }
    }
    /// A check that ran and failed: exit code 1.
    pub fn check(message: impl Into<String>) -> Self {
        CliError {
            message: message.into(),
            code: 1,
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for CliError {}

impl From<footprint::Error> for CliError {
    fn from(e: footprint::Error) -> Self {
        CliError::input(e.to_string())
    }
}

macro_rules! from_core_error {
    ($($ty:ty),*) => {$(
        impl From<$ty> for CliError {
            fn from(e: $ty) -> Self {
                CliError::input(e.to_string())
            }
        }
    )*};
}
from_core_error!(
    footprint::KernelSpecError,
    footprint::GeometryError,
    footprint::TableError,
    footprint::BufferError,
    footprint::frame::FrameError
);
