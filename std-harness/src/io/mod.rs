//! Files: images (PFM, PNG) and generic tables. Every write goes to a temporary file beside the
//! target and is renamed into place, so a failure never leaves a half-written output.

pub mod formats;
pub mod image;
pub mod json;
pub mod stream;
pub mod table;
pub mod volume;

use crate::CliError;
use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` atomically (temporary file in the same folder, then rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| CliError::input(format!("{}: not a file name", path.display())))?;
    let tmp = dir.join(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        CliError::input(format!("{}: cannot write: {e}", path.display()))
    })
}

/// Reads a whole file, with the path in the error.
pub fn read_file(path: &Path) -> Result<Vec<u8>, CliError> {
    if path.is_dir() {
        return Err(CliError::input(format!(
            "{}: is a directory, expected a file",
            path.display()
        )));
    }
    std::fs::read(path)
        .map_err(|e| CliError::input(format!("{}: cannot read: {e}", path.display())))
}

/// Reads at most `limit` bytes from the start of a file (for headers of files that may be huge).
pub fn read_prefix(path: &Path, limit: usize) -> Result<Vec<u8>, CliError> {
    use std::io::Read;
    if path.is_dir() {
        return Err(CliError::input(format!(
            "{}: is a directory, expected a file",
            path.display()
        )));
    }
    let f = std::fs::File::open(path)
        .map_err(|e| CliError::input(format!("{}: cannot read: {e}", path.display())))?;
    let mut out = Vec::new();
    f.take(limit as u64)
        .read_to_end(&mut out)
        .map_err(|e| CliError::input(format!("{}: cannot read: {e}", path.display())))?;
    Ok(out)
}
