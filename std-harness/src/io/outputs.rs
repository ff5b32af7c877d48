//! A command's output files: checked before any work, written all together or not at all.
//!
//! [`check`] runs first (before a volume is read or a frame rendered) and refuses an output whose
//! folder is missing or not writable, a path that is a folder, an extension the file's kind does
//! not support (`--out x.jpg` is refused, not filled with PNG bytes), and two outputs naming the
//! same file. [`write_all`] writes every file to a temporary name beside its target (synced), and
//! only when all of them are written renames them into place; if any write fails, every
//! temporary is removed and no output appears. A rename can fail only if the file system changes
//! under the command (a folder removed or made read-only between the check and the rename); the
//! files renamed before it then stay, and the error names the one that failed.
//!
//! **Devices and pipes.** An output naming an existing file that is neither a regular file nor a
//! folder (`/dev/null`, `/dev/stdout`, a FIFO; symbolic links followed) is written in place,
//! never replaced: renaming a temporary over it would replace the device with a regular file (as
//! root, `--json /dev/null` did exactly that to this machine's `/dev/null`). It cannot be taken
//! back, so it is written after every regular output is written to its temporary and before any
//! is renamed into place: a device that fails (`/dev/full`, a closed pipe) leaves no output.
//!
//! **Scene.** No output may name a file the command reads (`--json VOLUME`, an NRRD's detached
//! data file, a `--tf` file; through symbolic or hard links alike): [`check`] refuses the inputs
//! its command names, and [`write_all`] every file read since (`crate::io::is_input`).
//!
//! **Temporaries.** An output is written to `.NAME.tmp-PID.RANDOM` beside it, created
//! exclusively (`O_EXCL`: never through a link, never over an existing file) under a name no one
//! can predict ([`super::temporaries`]); where `.NAME.tmp-` would pass a file name's 255 bytes,
//! `NAME` is cut and a hash of the whole name added (`.PREFIX~HASH.tmp-`), so any name the file
//! system takes can be written. A file-size limit (`ulimit -f`) makes the write fail with an
//! error instead of killing the process ([`ignore_file_size_signal`]), so the temporary is
//! removed as after any failed write; SIGINT, SIGTERM and SIGHUP remove it before the process
//! ends ([`super::temporaries::remove_on_signals`]).
//!
//! **After SIGKILL.** A kill between a temporary's creation and its rename leaves
//! the temporary beside the output (never a partial `NAME`). The next run that writes `NAME`
//! removes such leftovers ([`clean_leftovers`]): regular files (never a link) whose process no
//! longer runs (on Linux, no `/proc/PID`), or, where that cannot be told, that are more than a
//! day old.

use super::temporaries::Temporary;
use crate::CliError;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Extensions a colour image output may have: `.png` (8-bit) or `.pfm` (float RGB).
pub const RGB_EXTENSIONS: [&str; 2] = ["png", "pfm"];

/// Extensions a single-channel output may have (`footprint splat`'s weights).
pub const GREY_EXTENSIONS: [&str; 2] = ["pfm", "png"];

/// One output a command will write: the flag that named it (for messages), its path and the
/// extensions its kind may have (empty: any).
#[derive(Clone, Copy, Debug)]
pub struct Planned<'a> {
    /// The flag, e.g. `--out`.
    pub flag: &'a str,
    /// Where it goes.
    pub path: &'a Path,
    /// Lower-case extensions accepted, e.g. `["png", "pfm"]`; empty accepts any.
    pub extensions: &'a [&'a str],
}

/// Whether `path` names an existing file that is neither a regular file nor a folder (a device
/// such as `/dev/null`, a FIFO; symbolic links followed, so `/dev/stdout` counts): written in
/// place, never replaced (see the module docs).
pub fn is_special(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// The lower-case extension of `path`, if any.
pub fn extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}

fn folder(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The longest file name most file systems take, bytes.
const NAME_MAX: usize = 255;

/// The part of a temporary's name before the PID: `.NAME.tmp-`, or, where a temporary with that
/// prefix could pass [`NAME_MAX`], `.PREFIX~HASH.tmp-` with `NAME` cut on a character boundary
/// and the FNV-1a hash of the whole name (see the module docs).
fn temporary_prefix(name: &str) -> String {
    // Room after the prefix for the PID (at most 10 digits), a dot and 8 random characters.
    const PID: usize = 10 + 1 + 8;
    let plain = format!(".{name}.tmp-");
    if plain.len() + PID <= NAME_MAX {
        return plain;
    }
    let hash = name.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    });
    let tail = format!("~{hash:016x}.tmp-");
    let mut cut = NAME_MAX - PID - tail.len() - 1;
    while !name.is_char_boundary(cut) {
        cut -= 1;
    }
    format!(".{}{tail}", &name[..cut])
}

/// A new temporary beside `path`, the name `path` is written under before its rename (see the
/// module docs).
fn temporary(path: &Path) -> Result<Temporary, std::io::Error> {
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file name"))?;
    Temporary::create(folder(path), &temporary_prefix(&name.to_string_lossy()))
}

/// Makes a write past the file-size limit (`ulimit -f`) fail with an error (EFBIG) instead of
/// killing the process with SIGXFSZ, which would leave its temporary behind: called once, first
/// thing, by the command line.
pub fn ignore_file_size_signal() {
    // SAFETY: setting a signal's disposition to SIG_IGN installs no handler and touches no
    // memory of this process; SIGXFSZ is a valid signal number.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

/// Removes `.NAME.tmp-PID` files that a killed run left beside `path` (see the module docs);
/// returns how many. Errors are ignored: this is tidying, not a precondition.
pub fn clean_leftovers(path: &Path) -> usize {
    let Some(name) = path.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return 0;
    };
    let prefix = temporary_prefix(&name);
    let Ok(entries) = std::fs::read_dir(folder(path)) else {
        return 0;
    };
    let own = std::process::id();
    let proc_fs = Path::new("/proc/self").exists();
    let mut removed = 0;
    for e in entries.flatten() {
        let file = e.file_name().to_string_lossy().into_owned();
        // `.NAME.tmp-PID.RANDOM` (and `.NAME.tmp-PID`, as runs before 2026-12-06 named them).
        let Some(pid) = file
            .strip_prefix(&prefix)
            .and_then(|p| p.split('.').next())
            .and_then(|p| p.parse::<u32>().ok())
        else {
            continue;
        };
        // Only what a run of ours can have left: a regular file (a link is never one).
        if pid == own || !e.file_type().is_ok_and(|t| t.is_file()) {
            continue;
        }
        let stale = if proc_fs {
            !Path::new(&format!("/proc/{pid}")).exists()
        } else {
            e.metadata()
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| t.elapsed().ok())
                .is_some_and(|age| age.as_secs() > 86_400)
        };
        if stale && std::fs::remove_file(e.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// Checks every planned output before any work is done (see the module docs), and removes
/// leftovers of killed runs beside each ([`clean_leftovers`]).
pub fn check(outputs: &[Planned<'_>]) -> Result<(), CliError> {
    for o in outputs {
        clean_leftovers(o.path);
    }
    for (i, o) in outputs.iter().enumerate() {
        let shown = o.path.display();
        let flag = o.flag;
        if o.path.is_dir() {
            return Err(CliError::input(format!(
                "{flag} {shown}: is a directory, expected a file name"
            )));
        }
        if o.path.file_name().is_none() {
            return Err(CliError::input(format!("{flag} {shown}: not a file name")));
        }
        if !o.extensions.is_empty() {
            let ext = extension(o.path);
            if !ext.as_deref().is_some_and(|e| o.extensions.contains(&e)) {
                let list: Vec<String> = o.extensions.iter().map(|e| format!(".{e}")).collect();
                return Err(CliError::input(format!(
                    "{flag} {shown}: cannot write {} files (use {})",
                    ext.map_or("extension-less".to_string(), |e| format!(".{e}")),
                    list.join(" or ")
                )));
            }
        }
        if super::is_input(o.path) {
            return Err(CliError::input(format!(
                "{flag} {shown}: is an input of this command, which it would replace: \
                 name another file"
            )));
        }
        let dir = folder(o.path);
        if is_special(o.path) {
            // Written in place: no folder probe (a temporary beside a device is never made).
        } else if !dir.is_dir() {
            return Err(CliError::input(format!(
                "{flag} {shown}: directory {} does not exist",
                dir.display()
            )));
        } else {
            // Probe: a temporary as the write will make one, created and removed.
            temporary(o.path).map(drop).map_err(|e| {
                CliError::input(format!(
                    "{flag} {shown}: cannot write in {}: {e}",
                    dir.display()
                ))
            })?;
        }
        for other in &outputs[..i] {
            if same_file(other.path, o.path) {
                return Err(CliError::input(format!(
                    "{} and {flag} both name {shown}",
                    other.flag
                )));
            }
        }
    }
    Ok(())
}

fn same_file(a: &Path, b: &Path) -> bool {
    let canon =
        |p: &Path| -> Option<PathBuf> { Some(folder(p).canonicalize().ok()?.join(p.file_name()?)) };
    a == b || matches!((canon(a), canon(b)), (Some(x), Some(y)) if x == y)
}

/// Writes every `(path, bytes)` all-or-nothing (see the module docs): regular files to their
/// temporaries, then devices and pipes in place, then the temporaries renamed into place.
pub fn write_all<B: AsRef<[u8]>>(files: &[(&Path, B)]) -> Result<(), CliError> {
    if let Some((path, _)) = files.iter().find(|(p, _)| super::is_input(p)) {
        return Err(CliError::input(format!(
            "{}: is a file this command read, which it would replace: name another file \
             (no output written)",
            path.display()
        )));
    }
    // Each temporary is removed when dropped: on any early return below, none stays.
    let mut written: Vec<(Temporary, &Path)> = Vec::with_capacity(files.len());
    for (path, bytes) in files.iter().filter(|(p, _)| !is_special(p)) {
        let (path, bytes) = (*path, bytes.as_ref());
        let result = temporary(path).and_then(|mut tmp| {
            tmp.file().write_all(bytes)?;
            tmp.file().sync_all()?;
            Ok(tmp)
        });
        match result {
            Ok(tmp) => written.push((tmp, path)),
            Err(e) => {
                return Err(CliError::input(format!(
                    "{}: cannot write: {e} (no output written)",
                    path.display()
                )))
            }
        }
    }
    for (path, bytes) in files.iter().filter(|(p, _)| is_special(p)) {
        let result = write_in_place(path, bytes.as_ref());
        if let Err(e) = result {
            return Err(CliError::input(format!(
                "{}: cannot write: {e} (no file output written)",
                path.display()
            )));
        }
    }
    for (tmp, path) in written {
        tmp.persist(path)
            .map_err(|e| CliError::input(format!("{}: cannot write: {e}", path.display())))?;
    }
    Ok(())
}

/// Writes `bytes` into a device or pipe that is already there (see the module docs): opened
/// without creating or truncating, and refused if what was opened turns out to be a regular file
/// (swapped in since it was looked at).
fn write_in_place(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut f = std::fs::OpenOptions::new().write(true).open(path)?;
    if f.metadata()?.is_file() {
        return Err(std::io::Error::other(
            "became a regular file since it was checked",
        ));
    }
    f.write_all(bytes)?;
    f.flush()
}

/// Writes one file atomically (temporary beside it, then rename).
pub fn write_one(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    write_all(&[(path, bytes)])
}

/// Files a command writes into one folder (`chart --out DIR`), all at the end, all or nothing:
/// gathered in memory as the work goes, then written by [`write_all`]. A folder that does not
/// exist is created only then, and removed again (with any folder created above it) if a write
/// fails or a signal ends the process first ([`super::temporaries::Folder`]).
pub struct Batch {
    dir: PathBuf,
    files: Vec<(PathBuf, Vec<u8>)>,
}

impl Batch {
    /// A batch for `dir`, checked before any work: `dir` is a folder, or does not exist and its
    /// nearest existing ancestor is a folder this process can write in.
    pub fn new(flag: &str, dir: &Path) -> Result<Batch, CliError> {
        let shown = dir.display();
        let mut at = dir;
        while !at.exists() {
            match at.parent() {
                Some(p) if !p.as_os_str().is_empty() => at = p,
                _ => {
                    at = Path::new(".");
                    break;
                }
            }
        }
        if !at.is_dir() {
            return Err(CliError::input(format!(
                "{flag} {shown}: {} is not a directory",
                at.display()
            )));
        }
        Temporary::create(at, ".footprint-probe.tmp-")
            .map(drop)
            .map_err(|e| {
                CliError::input(format!(
                    "{flag} {shown}: cannot write in {}: {e}",
                    at.display()
                ))
            })?;
        Ok(Batch {
            dir: dir.to_path_buf(),
            files: Vec::new(),
        })
    }

    /// Adds `DIR/name`.
    pub fn add(&mut self, name: &str, bytes: impl Into<Vec<u8>>) {
        self.files.push((self.dir.join(name), bytes.into()));
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Writes every file added (see the type's docs).
    pub fn commit(self) -> Result<(), CliError> {
        let created = if self.dir.is_dir() {
            None
        } else {
            Some(
                super::temporaries::Folder::create_all(&self.dir).map_err(|e| {
                    CliError::input(format!("{}: cannot create: {e}", self.dir.display()))
                })?,
            )
        };
        let files: Vec<(&Path, &[u8])> = self
            .files
            .iter()
            .map(|(p, b)| (p.as_path(), b.as_slice()))
            .collect();
        write_all(&files)?;
        if let Some(folder) = created {
            folder.done();
        }
        Ok(())
    }
}

/// [`check`] for the usual pair: a colour image (`--out`, `.png` or `.pfm`) and a JSON summary
/// (`--json`), either optional.
pub fn check_image_and_json(out: Option<&Path>, json: Option<&Path>) -> Result<(), CliError> {
    let mut planned = Vec::new();
    if let Some(path) = out {
        planned.push(Planned {
            flag: "--out",
            path,
            extensions: &RGB_EXTENSIONS,
        });
    }
    if let Some(path) = json {
        planned.push(Planned {
            flag: "--json",
            path,
            extensions: &[],
        });
    }
    check(&planned)
}
