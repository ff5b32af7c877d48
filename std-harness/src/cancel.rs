//! Interrupting a render from outside: a program that embeds the harness (the Python package,
//! whose Ctrl-C must not wait for a long frame to end) calls [`request`] and every render in
//! progress ends at its next sheet or slab with [`interrupted`]'s error; [`clear`] lets later
//! renders run. The command line never requests it: a signal there ends the process
//! ([`crate::io::temporaries::remove_on_signals`]).
//!
//! A request reaches every render of the process in progress (it is one counter, not one per
//! render): Ctrl-C means "stop", whichever thread is rendering.

use std::sync::atomic::{AtomicUsize, Ordering};

/// Requests in force (each [`request`] until its [`clear`]).
static REQUESTS: AtomicUsize = AtomicUsize::new(0);

/// The text of the error an interrupted render ends with.
pub const INTERRUPTED: &str = "interrupted";

/// Asks every render in progress to stop at its next sheet or slab.
pub fn request() {
    REQUESTS.fetch_add(1, Ordering::SeqCst);
}

/// Withdraws one [`request`] (once the interrupted render has returned).
pub fn clear() {
    let _ = REQUESTS.fetch_update(Ordering::SeqCst, Ordering::SeqCst, |n| n.checked_sub(1));
}

/// `Err` ([`interrupted`]) while a stop is requested: what the render loops call between
/// sheets and slabs (one atomic load).
#[inline]
pub fn check() -> Result<(), crate::CliError> {
    if REQUESTS.load(Ordering::Relaxed) > 0 {
        Err(interrupted())
    } else {
        Ok(())
    }
}

/// The error of an interrupted render.
pub fn interrupted() -> crate::CliError {
    crate::CliError::input(INTERRUPTED)
}
