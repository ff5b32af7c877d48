//! The temporary files an output is written to before its rename: created exclusively under an
//! unpredictable name, never through a link, and removed on every way out but SIGKILL.
//!
//! **Creation.** A temporary is `.NAME.tmp-PID.RANDOM` beside its output (`RANDOM`: eight
//! characters from the `tempfile` crate's generator). It is opened `O_CREAT | O_EXCL` (Rust's
//! `create_new`), which fails on any existing name, a symbolic link included, dangling or not:
//! nothing planted in the folder in advance can be followed or truncated, and a name that is taken
//! is simply drawn again. The PID in the name tells a later run whose leftover it is
//! ([`super::outputs::clean_leftovers`]).
//!
//! **Signals.** Every temporary this process holds is listed in one registry, under one lock,
//! from the moment it is created (the lock is held across the `open`) until it is renamed into
//! place or removed. [`remove_on_signals`] starts a thread that, on SIGINT, SIGTERM or SIGHUP,
//! takes that lock, removes every listed file (and every folder listed as in progress), and ends
//! the process as the signal's default action would (exit status 128 + the signal). Holding the
//! lock to the end means no temporary can be created or renamed after the sweep. The command line
//! installs it; a program that embeds the harness (the Python package) keeps its own signal
//! handling, and a temporary there is removed when its [`Temporary`] is dropped.

use std::fs::{File, OpenOptions};
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// What this process holds on disk that is not yet an output: temporaries (files) and folders
/// being filled (removed whole, as `chart --out DIR` creates its folder).
#[derive(Default)]
struct Live {
    files: Vec<PathBuf>,
    folders: Vec<PathBuf>,
}

static LIVE: Mutex<Live> = Mutex::new(Live {
    files: Vec::new(),
    folders: Vec::new(),
});

fn live() -> MutexGuard<'static, Live> {
    LIVE.lock().unwrap_or_else(PoisonError::into_inner)
}

/// One temporary file, open for writing: removed when dropped unless [`Temporary::persist`]
/// renamed it into place.
pub struct Temporary {
    path: PathBuf,
    file: Option<File>,
}

impl Temporary {
    /// Creates a new temporary in `dir` whose name starts with `prefix` (`.NAME.tmp-`): the PID,
    /// a dot and random characters follow (see the module docs).
    pub fn create(dir: &Path, prefix: &str) -> io::Result<Temporary> {
        let prefix = format!("{prefix}{}.", std::process::id());
        let mut live = live();
        let named = tempfile::Builder::new()
            .prefix(&prefix)
            .rand_bytes(8)
            .make_in(dir, |path| {
                let mut options = OpenOptions::new();
                options.write(true).create_new(true);
                #[cfg(unix)]
                {
                    use std::os::unix::fs::OpenOptionsExt as _;
                    // The mode a plain `File::create` gives (less the umask), not 0600: the
                    // output keeps the permissions a written file always had.
                    options.mode(0o666).custom_flags(libc::O_NOFOLLOW);
                }
                options.open(path)
            })?;
        // Keep the file; its removal is ours (on drop, on a failure, on a signal).
        let (file, path) = named.keep().map_err(|e| e.error)?;
        live.files.push(path.clone());
        Ok(Temporary {
            path,
            file: Some(file),
        })
    }

    /// The temporary's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The open file.
    pub fn file(&mut self) -> &mut File {
        self.file
            .as_mut()
            .expect("a temporary's file is open until it is persisted")
    }

    /// Renames the temporary to `target` (replacing it), closing it first; on failure the
    /// temporary is removed.
    pub fn persist(mut self, target: &Path) -> io::Result<()> {
        self.file = None;
        let mut live = live();
        let result = std::fs::rename(&self.path, target);
        if result.is_err() {
            let _ = std::fs::remove_file(&self.path);
        }
        live.files.retain(|p| p != &self.path);
        // Renamed or removed: nothing left for drop to do.
        self.path = PathBuf::new();
        result
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        if self.path.as_os_str().is_empty() {
            return;
        }
        self.file = None;
        let mut live = live();
        let _ = std::fs::remove_file(&self.path);
        live.files.retain(|p| p != &self.path);
    }
}

/// A folder this process created to fill (`chart --out DIR`): removed with what it holds if the
/// process is signalled before [`Folder::done`], or if dropped before it.
pub struct Folder {
    path: Option<PathBuf>,
}

impl Folder {
    /// Creates `path` and the folders missing above it, and lists the topmost one created as in
    /// progress (removed whole, with what it holds, unless [`Folder::done`] is called).
    pub fn create_all(path: &Path) -> io::Result<Folder> {
        let mut top = path;
        while let Some(parent) = top.parent() {
            if parent.as_os_str().is_empty() || parent.exists() {
                break;
            }
            top = parent;
        }
        let mut live = live();
        std::fs::create_dir_all(path)?;
        live.folders.push(top.to_path_buf());
        Ok(Folder {
            path: Some(top.to_path_buf()),
        })
    }

    /// The folder is complete: it stays.
    pub fn done(mut self) {
        if let Some(p) = self.path.take() {
            live().folders.retain(|f| f != &p);
        }
    }
}

impl Drop for Folder {
    fn drop(&mut self) {
        if let Some(p) = self.path.take() {
            let mut live = live();
            let _ = std::fs::remove_dir_all(&p);
            live.folders.retain(|f| f != &p);
        }
    }
}

/// Starts (once per process) the thread that removes every temporary and unfinished folder on
/// SIGINT, SIGTERM or SIGHUP and then ends the process as the signal would have (see the module
/// docs). Where the handler cannot be installed, signals keep their default action (and a
/// temporary may stay, as after SIGKILL, for the next run to clean).
pub fn remove_on_signals() {
    #[cfg(unix)]
    {
        static STARTED: std::sync::Once = std::sync::Once::new();
        STARTED.call_once(|| {
            use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
            let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])
            else {
                return;
            };
            let _ = std::thread::Builder::new()
                .name("footprint-signals".into())
                .spawn(move || {
                    if let Some(signal) = signals.forever().next() {
                        // Held until the process ends: nothing is created or renamed after.
                        let live = live();
                        for f in &live.files {
                            let _ = std::fs::remove_file(f);
                        }
                        for d in &live.folders {
                            let _ = std::fs::remove_dir_all(d);
                        }
                        let _ = signal_hook::low_level::emulate_default_handler(signal);
                        // A signal whose default is not to end the process (none of the three):
                        // end it anyway, with the shell's convention.
                        std::process::exit(128 + signal);
                    }
                });
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A link planted at every name the temporary could take is never followed: the planted
    /// target keeps its bytes (the third campaign's first defect).
    #[cfg(unix)]
    #[test]
    fn a_planted_link_is_never_followed() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim");
        std::fs::write(&victim, b"precious").unwrap();
        // The old name scheme, for this PID: what an attacker could predict.
        let old = dir
            .path()
            .join(format!(".o.png.tmp-{}", std::process::id()));
        std::os::unix::fs::symlink(&victim, &old).unwrap();
        let mut t = Temporary::create(dir.path(), ".o.png.tmp-").unwrap();
        use std::io::Write as _;
        t.file().write_all(b"image").unwrap();
        assert_ne!(t.path(), old.as_path());
        t.persist(&dir.path().join("o.png")).unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"precious");
        assert_eq!(std::fs::read(dir.path().join("o.png")).unwrap(), b"image");
        assert!(!live().files.iter().any(|f| f.starts_with(dir.path())));
    }

    /// A dropped temporary is removed and unlisted.
    #[test]
    fn dropped_temporaries_are_removed() {
        let dir = tempfile::tempdir().unwrap();
        let t = Temporary::create(dir.path(), ".x.tmp-").unwrap();
        let path = t.path().to_path_buf();
        assert!(path.exists());
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        assert!(
            name.starts_with(&format!(".x.tmp-{}.", std::process::id())),
            "{name}"
        );
        drop(t);
        assert!(!path.exists());
        assert!(!live().files.contains(&path));
    }
}
