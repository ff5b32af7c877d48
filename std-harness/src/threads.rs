//! Scoped threads that may fail to start. The operating system refuses threads past its limits
//! (`--threads 2000` at 2048², a process limit, an address-space cap that leaves no room for
//! another stack); [`spawn`] then runs that thread's work on the calling thread instead. Every
//! caller splits its work into pieces whose results do not depend on which thread runs them (the
//! bands, sheet ranges and row chunks the pipeline hands out), so the output is the same bits as
//! with every thread started: only the parallelism is lost, never the image.

use std::sync::{Arc, Mutex, PoisonError};
use std::thread::{Scope, ScopedJoinHandle};

/// A piece of work handed to [`spawn`]: running on its own thread, or already done on the
/// caller's because no thread could be started.
pub enum Task<'scope, T> {
    /// Running on a thread of its own.
    Spawned(ScopedJoinHandle<'scope, T>),
    /// Run on the calling thread.
    Done(T),
}

impl<T> Task<'_, T> {
    /// The work's result (waits for its thread). A panic in the thread is carried on.
    pub fn join(self) -> T {
        match self {
            Task::Spawned(h) => h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)),
            Task::Done(t) => t,
        }
    }
}

/// Starts `work` on a new thread of `scope`, or, where the operating system refuses one, runs
/// it now on the calling thread (see the module docs).
pub fn spawn<'scope, 'env, T, F>(scope: &'scope Scope<'scope, 'env>, work: F) -> Task<'scope, T>
where
    F: FnOnce() -> T + Send + 'scope,
    T: Send + 'scope,
{
    // The work waits in a slot the thread takes it from, so that a refused thread (which drops
    // its closure) leaves it for the caller.
    let slot = Arc::new(Mutex::new(Some(work)));
    let theirs = Arc::clone(&slot);
    let started = std::thread::Builder::new().spawn_scoped(scope, move || {
        let work = theirs
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take()
            .expect("a started thread finds its work");
        work()
    });
    match started {
        Ok(handle) => Task::Spawned(handle),
        Err(_) => {
            let work = slot
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .take()
                .expect("a refused thread leaves its work");
            Task::Done(work())
        }
    }
}

/// The most threads a render starts (`--threads` above it renders on this many): every image is
/// the same bits for any count, a thread more than the cores never helps, and each costs a
/// stack, so `--threads 2000` must not exhaust the address space before the first voxel.
pub const MAX_THREADS: usize = 256;

/// `n` threads, with 0 meaning every core, and at most [`MAX_THREADS`].
pub fn count(n: usize) -> usize {
    match n {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    }
    .min(MAX_THREADS)
}

#[cfg(test)]
mod tests {
    /// Work runs once, on a thread or inline, and its result comes back in order.
    #[test]
    fn results_in_order() {
        let out: Vec<usize> = std::thread::scope(|s| {
            let tasks: Vec<_> = (0..8).map(|i| super::spawn(s, move || i * i)).collect();
            tasks.into_iter().map(super::Task::join).collect()
        });
        assert_eq!(out, (0..8).map(|i| i * i).collect::<Vec<_>>());
    }
}
