//! Files: images (PFM, PNG) and generic tables. Every write goes to a temporary file beside the
//! target and is renamed into place, so a failure never leaves a half-written output.

pub mod formats;
pub mod image;
pub mod json;
pub mod outputs;
pub mod stream;
pub mod table;
pub mod volume;

use crate::CliError;
use std::path::Path;

/// Writes `bytes` to `path` atomically (temporary file in the same folder, then rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    outputs::write_one(path, bytes)
}

/// The length of `path` if it is a regular file. A directory, and a FIFO, device or socket (whose
/// `open` or `read` can block forever, or never end), are refused up front, from `stat` alone,
/// before anything opens them: every volume, data file, table and image is read from a regular
/// file; a pipe is read only as standard input (`--stream -`).
pub fn regular_file_len(path: &Path) -> Result<u64, CliError> {
    let meta = std::fs::metadata(path)
        .map_err(|e| CliError::input(format!("{}: cannot read: {e}", path.display())))?;
    if meta.is_dir() {
        return Err(CliError::input(format!(
            "{}: is a directory, expected a file",
            path.display()
        )));
    }
    if !meta.is_file() {
        return Err(CliError::input(format!(
            "{}: not a regular file (a FIFO, device or socket) — refused, as reading it could \
             block forever; pipe data through standard input with --stream - instead",
            path.display()
        )));
    }
    Ok(meta.len())
}

/// The one-line message for an allocation of `bytes` bytes for `what` that memory refused.
pub fn alloc_failed(bytes: usize, what: &str) -> String {
    format!(
        "cannot allocate {bytes} bytes ({:.1} GiB) for {what}",
        bytes as f64 / (1u64 << 30) as f64
    )
}

/// An empty vector with room for exactly `n` elements, or [`alloc_failed`]'s message if memory
/// refuses (`try_reserve_exact`: under an address-space limit, or with overcommit off, a request
/// larger than memory fails here instead of aborting the process).
pub fn try_vec<T>(n: usize, what: &str) -> Result<Vec<T>, String> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| alloc_failed(n.saturating_mul(std::mem::size_of::<T>()), what))?;
    Ok(v)
}

/// `n` copies of `value` in a vector whose allocation failing is an error naming `what` and the
/// bytes it needed, not an abort (see [`try_vec`]).
pub fn try_filled<T: Clone>(n: usize, value: T, what: &str) -> Result<Vec<T>, CliError> {
    let mut v = try_vec(n, what).map_err(CliError::input)?;
    v.resize(n, value);
    Ok(v)
}

/// Bytes a growing read asks memory for at a time, at most (4 MiB).
const GROW_STEP: usize = 4 << 20;

/// Reads `r` until its end or `limit` bytes, whichever comes first, growing the buffer as data
/// arrives: a source that declares much and delivers little costs only what it delivers (at most
/// [`GROW_STEP`] more). Capacity doubles, capped at `limit`, so a source that does deliver
/// `limit` bytes ends with one exact-size buffer and memory for at most twice its data.
/// Memory refusing is an error of kind `OutOfMemory` whose text is [`alloc_failed`]'s (naming
/// `what`), never an abort.
pub fn read_growing(mut r: impl std::io::Read, limit: u64, what: &str) -> std::io::Result<Vec<u8>> {
    let limit = usize::try_from(limit).unwrap_or(usize::MAX);
    let mut out: Vec<u8> = Vec::new();
    while out.len() < limit {
        let len = out.len();
        let want = (limit - len).min(GROW_STEP);
        if out.capacity() < len + want {
            let target = (len + want).max(out.capacity().saturating_mul(2).min(limit));
            out.try_reserve_exact(target - len).map_err(|_| {
                std::io::Error::new(std::io::ErrorKind::OutOfMemory, alloc_failed(target, what))
            })?;
        }
        out.resize(len + want, 0);
        let mut got = 0;
        while got < want {
            match r.read(&mut out[len + got..]) {
                Ok(0) => break,
                Ok(n) => got += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
        out.truncate(len + got);
        if got < want {
            break;
        }
    }
    Ok(out)
}

/// Reads a whole file, with the path in the error; the buffer is reserved fallibly from the
/// file's length (a file larger than memory is an error, not an abort).
pub fn read_file(path: &Path) -> Result<Vec<u8>, CliError> {
    let len = regular_file_len(path)?;
    let f = std::fs::File::open(path)
        .map_err(|e| CliError::input(format!("{}: cannot read: {e}", path.display())))?;
    let cannot = |e: &dyn std::fmt::Display| CliError::input(format!("{}: {e}", path.display()));
    let len = usize::try_from(len).map_err(|_| cannot(&"larger than this machine can address"))?;
    let mut out = try_vec(len, "the file").map_err(|e| cannot(&e))?;
    use std::io::Read;
    f.take(len as u64)
        .read_to_end(&mut out)
        .map_err(|e| cannot(&format!("cannot read: {e}")))?;
    Ok(out)
}

/// Reads at most `limit` bytes from the start of a file (for headers of files that may be huge).
pub fn read_prefix(path: &Path, limit: usize) -> Result<Vec<u8>, CliError> {
    use std::io::Read;
    regular_file_len(path)?;
    let f = std::fs::File::open(path)
        .map_err(|e| CliError::input(format!("{}: cannot read: {e}", path.display())))?;
    let mut out = Vec::new();
    f.take(limit as u64)
        .read_to_end(&mut out)
        .map_err(|e| CliError::input(format!("{}: cannot read: {e}", path.display())))?;
    Ok(out)
}
