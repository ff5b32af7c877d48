//! The std harness for Footprint: the `footprint` command line, file I/O, the table preprocessor
//! and an f64 reference renderer that uses no tables, against which the core is verified.
//!
//! # Layers
//! Data flows one way, top to bottom; no module imports one above it, and no command imports
//! another (`tests/layering.rs` checks both):
//!
//! ```text
//! cli        parse the command line, dispatch (nothing imports it)
//!  └ commands   one thin adapter per subcommand: parse, call, report
//!     └ charts     sweeps and plots for `chart`
//!        └ pipeline   stages/ (load → prepare → bands), ends/ (what draws a frame), quality/
//!           └ plan       the render plan, resolved once from the arguments
//!              └ args, metrics   shared argument structs; image comparisons
//!                 └ scene, tf   the built-in volume; transfer functions
//!                    └ io, reference   files and formats; the f64 reference
//!                       └ dispatch, threads, cancel   N → const N (once); threads; interruption
//! ```
//!
//! - [`cli`]: the entry point [`run`].
//! - [`commands`]: one module per subcommand.
//! - [`charts`]: `footprint chart`'s sweeps and drawing.
//! - [`pipeline`]: the render pipeline the commands share.
//! - [`plan`](mod@plan): the render plan, every flag-only compatibility rule in one function.
//! - [`args`]: argument structs and value parsers shared by several commands.
//! - [`metrics`]: PSNR, RMSE, max error; max relative footprint difference.
//! - [`reference`](mod@reference): the f64, table-free footprint (exact line integrals) and renderer.
//! - [`io`]: volume formats, streaming sources, images, tables, JSON (written atomically).
//! - [`dispatch`]: runtime table size → const generic.
//! - [`threads`]: scoped threads that run their work inline where none can be started.
//! - [`cancel`]: a render interrupted from outside (the Python package's Ctrl-C).

// `!(x > y)` sends NaN down the rejecting branch, on purpose (as in the core).
#![allow(clippy::neg_cmp_op_on_partial_ord)]

/// `println!` that never panics: a closed stdout (`footprint … | head`) is not an error worth a
/// crash, and the output files are already written by then. Any other failure to write (a full
/// disk, `> /dev/full`) is remembered ([`stdout_failure`]): the command line then exits 2 with
/// it, instead of losing its report and saying it succeeded.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if !$crate::QUIET.load(std::sync::atomic::Ordering::Relaxed) {
            if let Err(e) = writeln!(std::io::stdout().lock(), $($arg)*) {
                $crate::note_stdout_failure(e);
            }
        }
    }};
}

/// The first failure to write standard output other than a closed pipe, if any (see [`say!`]).
static STDOUT_FAILURE: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

/// Remembers `e`, a failed write to standard output, unless it is a closed pipe (the reader
/// has gone, as `| head` does: not an error).
pub fn note_stdout_failure(e: std::io::Error) {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        return;
    }
    let mut failure = STDOUT_FAILURE
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    failure.get_or_insert_with(|| e.to_string());
}

/// Standard output flushed, and the first failure to write it since the last call (cleared).
pub fn stdout_failure() -> Option<String> {
    use std::io::Write as _;
    if let Err(e) = std::io::stdout().lock().flush() {
        note_stdout_failure(e);
    }
    STDOUT_FAILURE
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .take()
}

/// When set, [`say!`] prints nothing: a program calling the commands (the Python package) takes
/// their results from the values and files they return, not from standard output.
pub static QUIET: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Prints a warning to standard error: `footprint: warning: …`, one line. The command goes on.
#[macro_export]
macro_rules! warn {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr().lock(), "footprint: warning: {}", format_args!($($arg)*));
    }};
}

pub mod args;
pub mod builtin;
pub mod cancel;
pub mod charts;
pub mod cli;
pub mod commands;
pub mod dispatch;
pub mod distributed;
pub mod io;
pub mod metrics;
pub mod pipeline;
pub mod plan;
pub mod reference;
pub mod scene;
pub mod tf;
pub mod threads;

pub use cli::{run, run_with};

use std::fmt;

/// An error for people: a one-line message and the process exit code it maps to.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CliError {
    /// One line, no trailing newline.
    pub message: String,
    /// 2 = bad input or I/O failure, 1 = a check (such as `compare --max-diff`) failed.
    pub code: i32,
    /// Already printed to standard error (an MPI rank says its own failure at once, before the
    /// job ends: `distributed::mpi::agree`); the command line does not print it again.
    pub said: bool,
}

impl CliError {
    /// Bad input or I/O: exit code 2.
    pub fn input(message: impl Into<String>) -> Self {
        CliError {
            message: one_line(message.into()),
            code: 2,
            said: false,
        }
    }
    /// A check that ran and failed: exit code 1.
    pub fn check(message: impl Into<String>) -> Self {
        CliError {
            message: one_line(message.into()),
            code: 1,
            said: false,
        }
    }
}

/// `message` with its control characters (newlines, tabs, escapes — which a file's own bytes
/// can bring into a message, quoted by a parser) written as escapes: an error is always one line,
/// and never sends a terminal control sequence.
fn one_line(message: String) -> String {
    if !message.chars().any(char::is_control) {
        return message;
    }
    message
        .chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
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
