//! Files: images (PFM, PNG) and generic tables. Every write goes to a temporary file beside the
//! target and is renamed into place, so a failure never leaves a half-written output.

pub mod brick;
pub mod cut;
pub mod formats;
pub mod grid;
pub mod image;
pub mod json;
pub mod outputs;
pub mod progress;
pub mod ranges;
pub mod stream;
pub mod table;
pub mod temporaries;
pub mod values;
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
    note_input(&meta);
    Ok(meta.len())
}

thread_local! {
    /// Every file the command running on this thread has read or been told it will read, as
    /// (device, inode): no output may replace one ([`outputs`] checks before writing, and again
    /// before renaming into place). Per thread, and cleared as each command starts
    /// ([`forget_inputs`]): a program that runs many commands (the tests, the Python package)
    /// must not refuse an output because an earlier command read a file whose inode it reuses.
    static INPUTS: std::cell::RefCell<Vec<(u64, u64)>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Starts a command afresh: no file counts as its input yet.
pub fn forget_inputs() {
    INPUTS.with(|i| i.borrow_mut().clear());
}

/// Records the file `meta` describes as an input.
fn note_input(meta: &std::fs::Metadata) {
    use std::os::unix::fs::MetadataExt;
    let id = (meta.dev(), meta.ino());
    INPUTS.with(|i| {
        let mut inputs = i.borrow_mut();
        if !inputs.contains(&id) {
            inputs.push(id);
        }
    });
}

/// Records `path` as an input of this command, if it names an existing file (symbolic links
/// followed): a command calls this for the files its arguments name, before checking its
/// outputs, so that `--json VOLUME` is refused before any work.
pub fn note_input_path(path: &std::path::Path) {
    if let Ok(meta) = std::fs::metadata(path) {
        if meta.is_file() {
            note_input(&meta);
        }
    }
}

/// Whether `path` names (symbolic links followed, hard links alike) a file recorded as an input.
pub fn is_input(path: &std::path::Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata(path).is_ok_and(|m| INPUTS.with(|i| i.borrow().contains(&(m.dev(), m.ino()))))
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

/// Resizes `v` to `n` elements (new ones `value`), its growth failing as an error naming `what`
/// (see [`try_vec`]) instead of an abort.
pub fn try_resize<T: Clone>(
    v: &mut Vec<T>,
    n: usize,
    value: T,
    what: &str,
) -> Result<(), CliError> {
    if let Some(more) = n.checked_sub(v.len()) {
        v.try_reserve_exact(more).map_err(|_| {
            CliError::input(alloc_failed(
                n.saturating_mul(std::mem::size_of::<T>()),
                what,
            ))
        })?;
    }
    v.resize(n, value);
    Ok(())
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
/// `GROW_STEP` more). Capacity doubles, capped at `limit`, so a source that does deliver
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

/// The most bytes a text header (NRRD, MetaImage) may take when read ahead of its data for
/// streaming (16 MiB): past it the header is refused, never cut.
pub const MAX_HEADER_BYTES: usize = 16 << 20;

/// Reads the start of a file up to the end of its text header, as `ended` tells from the bytes
/// so far (checked after each 64 KiB read), or to the file's end: never a prefix that cuts the
/// header (a long comment would drop the fields after it). A header still open after
/// [`MAX_HEADER_BYTES`] is an error.
pub fn read_header(path: &Path, ended: impl Fn(&[u8]) -> bool) -> Result<Vec<u8>, CliError> {
    use std::io::Read;
    regular_file_len(path)?;
    let mut f = std::fs::File::open(path)
        .map_err(|e| CliError::input(format!("{}: cannot read: {e}", path.display())))?;
    let mut out = Vec::new();
    loop {
        let got = (&mut f)
            .take(1 << 16)
            .read_to_end(&mut out)
            .map_err(|e| CliError::input(format!("{}: cannot read: {e}", path.display())))?;
        if got == 0 || ended(&out) {
            return Ok(out);
        }
        if out.len() > MAX_HEADER_BYTES {
            return Err(CliError::input(format!(
                "{}: header not ended within {} MiB",
                path.display(),
                MAX_HEADER_BYTES >> 20
            )));
        }
    }
}

/// A data file a header names, opened for reading exactly the bytes the header declares.
pub struct DataFile {
    /// Buffered reader at the file's start.
    pub reader: std::io::BufReader<std::fs::File>,
    /// The length, for a regular file; `None` for a device (e.g. `/dev/zero`), which may be endless.
    pub len: Option<u64>,
}

/// Opens the data file of a header (NRRD `data file:`, MetaImage `ElementDataFile`, a NIfTI pair's
/// `.img`). Unlike [`regular_file_len`], a character or block device is accepted: it is read for
/// exactly the bytes the header declares and never to its end, so an endless stream such as
/// `/dev/zero` costs only the volume. A directory, a FIFO or a socket (whose `open` blocks until
/// a writer appears, perhaps forever) and a terminal are refused up front, before anything is read.
pub fn open_data(path: &Path) -> Result<DataFile, CliError> {
    use std::io::IsTerminal;
    use std::os::unix::fs::FileTypeExt;
    let meta = std::fs::metadata(path)
        .map_err(|e| CliError::input(format!("{}: cannot read: {e}", path.display())))?;
    let ft = meta.file_type();
    if ft.is_dir() {
        return Err(CliError::input(format!(
            "{}: is a directory, expected a data file",
            path.display()
        )));
    }
    if ft.is_fifo() || ft.is_socket() {
        return Err(CliError::input(format!(
            "{}: a FIFO or socket — refused up front, as opening it blocks until a writer appears; \
             pipe raw data through standard input with --stream - instead",
            path.display()
        )));
    }
    let file = std::fs::File::open(path)
        .map_err(|e| CliError::input(format!("{}: cannot read: {e}", path.display())))?;
    if file.is_terminal() {
        return Err(CliError::input(format!(
            "{}: a terminal, not a data file",
            path.display()
        )));
    }
    if ft.is_file() {
        note_input(&meta);
    }
    Ok(DataFile {
        reader: std::io::BufReader::new(file),
        len: ft.is_file().then_some(meta.len()),
    })
}

/// Reads exactly `n` bytes from `r` (memory grows as they arrive, see [`read_growing`]); fewer is
/// an error naming `what` and how many arrived. Nothing past the `n`th byte is read.
pub fn read_exactly(r: impl std::io::Read, n: u64, what: &str) -> Result<Vec<u8>, String> {
    let out = read_growing(r, n, what).map_err(|e| {
        if e.kind() == std::io::ErrorKind::OutOfMemory {
            e.to_string()
        } else {
            format!("cannot read: {e}")
        }
    })?;
    if (out.len() as u64) < n {
        return Err(format!(
            "{what} are truncated: expected {n} bytes, found {}",
            out.len()
        ));
    }
    Ok(out)
}

/// Passes over exactly `n` bytes of `r` (the header's field `what` says to skip them); fewer is
/// an error.
pub fn skip_exactly(r: &mut impl std::io::Read, n: u64, what: &str) -> Result<(), String> {
    use std::io::Read;
    let got = std::io::copy(&mut (&mut *r).take(n), &mut std::io::sink())
        .map_err(|e| format!("cannot read: {e}"))?;
    if got < n {
        return Err(format!(
            "{what} {n} is past the end of the data ({got} bytes)"
        ));
    }
    Ok(())
}

/// Says on stderr that `extra` bytes after a volume's samples were ignored (nothing if none): the
/// volume still renders (readers stop at the declared size, as VTK's and teem's do), but a header
/// whose sizes are too small shows rather than rendering silently wrong.
pub fn note_trailing(path: &Path, extra: u64) {
    if extra > 0 {
        eprintln!(
            "footprint: note: {}: {extra} bytes after the samples the header declares are ignored",
            path.display()
        );
    }
}
