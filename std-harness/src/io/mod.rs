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

/// `n` copies of `value` in a vector whose allocation failing is an error naming `what` and the
/// bytes it needed, not an abort (`try_reserve_exact`; under an address-space limit, or with
/// overcommit off, a request larger than memory fails here).
pub fn try_filled<T: Clone>(n: usize, value: T, what: &str) -> Result<Vec<T>, CliError> {
    let bytes = n.saturating_mul(std::mem::size_of::<T>());
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| {
        CliError::input(format!(
            "cannot allocate {bytes} bytes ({:.1} GiB) for {what}",
            bytes as f64 / (1u64 << 30) as f64
        ))
    })?;
    v.resize(n, value);
    Ok(v)
}

/// Reads a whole file, with the path in the error.
pub fn read_file(path: &Path) -> Result<Vec<u8>, CliError> {
    regular_file_len(path)?;
    std::fs::read(path)
        .map_err(|e| CliError::input(format!("{}: cannot read: {e}", path.display())))
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
