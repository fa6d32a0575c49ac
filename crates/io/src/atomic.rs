//! Output files: checking an output path before any work starts, and writing
//! atomically (a temporary file beside the target, then a rename), so that a
//! failed or interrupted run never leaves a half-written result.
//!
//! Rules, the same for every command:
//! - the directory the file goes into must exist and be a directory;
//! - a symbolic link is written through: the file it points to is replaced,
//!   the link stays (links are followed to their final target);
//! - an existing target that is not a regular file (a directory, FIFO, socket
//!   or device node) is refused, never replaced;
//! - an interruption never leaves a temporary file: the Ctrl-C handlers call
//!   [`remove_temp_files`], which waits for the writes in progress to finish
//!   (each is a complete file renamed into place), stops new ones from
//!   starting, and deletes any registered temporary file left.

use crate::DataError;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Temporary files being written right now (removed by [`remove_temp_files`]).
static IN_PROGRESS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Held shared by every write, taken exclusively (and kept) by [`remove_temp_files`].
static WRITING: std::sync::RwLock<()> = std::sync::RwLock::new(());

/// Symbolic links followed at most (as the kernel's limit, ELOOP beyond).
const MAX_LINKS: usize = 40;

fn other(file: &Path, message: impl Into<String>) -> DataError {
    DataError::Other {
        file: file.display().to_string(),
        message: message.into(),
    }
}

/// The file a write to `path` really replaces: `path` itself, or the final
/// target of a chain of symbolic links (which need not exist yet).
pub fn resolve_output(path: &Path) -> Result<PathBuf, DataError> {
    let mut p = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let target = std::fs::read_link(&p).map_err(|e| DataError::Io {
                    file: p.display().to_string(),
                    source: e,
                })?;
                p = match p.parent() {
                    Some(dir) if target.is_relative() => dir.join(target),
                    _ => target,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(other(path, format!("more than {MAX_LINKS} levels of symbolic links")))
}

fn describe(ft: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if ft.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if ft.is_socket() {
            return "a socket";
        }
        if ft.is_block_device() || ft.is_char_device() {
            return "a device node";
        }
    }
    if ft.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

/// The directory a file at `target` goes into (`.` for a bare name).
fn parent_dir(target: &Path) -> PathBuf {
    match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Checks that `path` can be written as an output file, before the work that
/// produces it starts: its directory exists and is a directory, and the target
/// (after following symbolic links) is absent or a regular file. Returns the
/// resolved target. `what` names the option in the message (e.g. `--out`).
pub fn check_output_path(path: impl AsRef<Path>, what: &str) -> Result<PathBuf, DataError> {
    let path = path.as_ref();
    let target = resolve_output(path)?;
    let shown = if target == path {
        format!("{what} {}", path.display())
    } else {
        format!("{what} {} (a link to {})", path.display(), target.display())
    };
    if target.file_name().is_none() || path.as_os_str().to_string_lossy().ends_with('/') {
        return Err(other(Path::new(&shown), "not a file name"));
    }
    let dir = parent_dir(&target);
    match std::fs::metadata(&dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            return Err(other(
                Path::new(&shown),
                format!("`{}` is not a directory", dir.display()),
            ))
        }
        Err(_) => {
            return Err(other(
                Path::new(&shown),
                format!("the directory `{}` does not exist", dir.display()),
            ))
        }
    }
    if let Ok(m) = std::fs::symlink_metadata(&target) {
        let ft = m.file_type();
        if !ft.is_file() {
            return Err(other(
                Path::new(&shown),
                format!("the target is {}; refusing to replace it", describe(&ft)),
            ));
        }
    }
    Ok(target)
}

/// For signal handlers, just before the process exits: waits until the atomic
/// writes in progress have finished, blocks every later write for the rest of
/// the process's life, and deletes any temporary file still registered.
pub fn remove_temp_files() {
    let guard = WRITING.write().unwrap_or_else(|p| p.into_inner());
    // Never released: no write may start between this and the exit.
    std::mem::forget(guard);
    remove_registered();
}

/// Deletes every registered temporary file.
fn remove_registered() {
    // A poisoned lock still holds the list.
    let list = match IN_PROGRESS.lock() {
        Ok(g) => g.clone(),
        Err(p) => p.into_inner().clone(),
    };
    for t in list {
        let _ = std::fs::remove_file(t);
    }
}

fn register(tmp: &Path, add: bool) {
    let mut g = match IN_PROGRESS.lock() {
        Ok(g) => g,
        Err(p) => p.into_inner(),
    };
    if add {
        g.push(tmp.to_path_buf());
    } else {
        g.retain(|t| t != tmp);
    }
}

/// Writes a file atomically with `write`, which is given the temporary path to
/// create and fill. The target is checked as by [`check_output_path`]
/// (symbolic links are written through, non-regular files refused); on error
/// nothing is left at the target (an older file stays as it was) and the
/// temporary file is removed.
pub fn write_atomic_with<E: std::fmt::Display>(
    path: impl AsRef<Path>,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), DataError> {
    let path = path.as_ref();
    let target = check_output_path(path, "output")?;
    let name = target
        .file_name()
        .ok_or_else(|| other(path, "not a file name"))?
        .to_string_lossy()
        .into_owned();
    // The temporary name keeps the extension, for writers that choose the format by it.
    let ext = target
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    let tmp = parent_dir(&target).join(format!(".{name}.{}.tmp{ext}", std::process::id()));
    let _writing = WRITING.read().unwrap_or_else(|p| p.into_inner());
    register(&tmp, true);
    let result = match write(&tmp) {
        Ok(()) => std::fs::rename(&tmp, &target).map_err(|e| DataError::Io {
            file: path.display().to_string(),
            source: e,
        }),
        Err(e) => Err(other(path, e.to_string())),
    };
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    register(&tmp, false);
    result
}

/// Writes `bytes` to `path` atomically (see [`write_atomic_with`]): a temporary
/// file in the same directory is written and synced, then renamed over the target.
pub fn write_atomic(path: impl AsRef<Path>, bytes: &[u8]) -> Result<(), DataError> {
    write_atomic_with(path, |tmp| -> std::io::Result<()> {
        let mut f = std::fs::File::create(tmp)?;
        f.write_all(bytes)?;
        f.sync_all()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    /// `remove_temp_files` removes every write in flight, so the tests of this
    /// module (which write files) run one at a time.
    static SERIAL: Mutex<()> = Mutex::new(());
    fn serial() -> std::sync::MutexGuard<'static, ()> {
        SERIAL.lock().unwrap_or_else(|p| p.into_inner())
    }
    #[test]
    fn writes_and_replaces() {
        let _s = serial();
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("out.csv");
        write_atomic(&p, b"a").unwrap();
        write_atomic(&p, b"bb").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"bb");
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 1, "no temp file left");
    }
    #[test]
    fn failure_leaves_nothing() {
        let _s = serial();
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("missing_dir").join("out.csv");
        let e = write_atomic(&p, b"a").unwrap_err().to_string();
        assert!(e.contains("missing_dir") && e.contains("does not exist"), "{e}");
        assert!(!p.exists());
        // A failing writer leaves no temporary file.
        let p = d.path().join("x.bin");
        let r = write_atomic_with(&p, |tmp| {
            std::fs::write(tmp, b"half").map_err(|e| e.to_string())?;
            Err::<(), _>("encoder failed".to_string())
        });
        assert!(r.unwrap_err().to_string().contains("encoder failed"));
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
    }
    #[cfg(unix)]
    #[test]
    fn symlinks_are_written_through() {
        let _s = serial();
        let d = tempfile::tempdir().unwrap();
        let real = d.path().join("real.csv");
        std::fs::write(&real, b"old").unwrap();
        let link = d.path().join("link.csv");
        std::os::unix::fs::symlink("real.csv", &link).unwrap();
        write_atomic(&link, b"new").unwrap();
        assert!(
            std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink(),
            "the link stays a link"
        );
        assert_eq!(std::fs::read(&real).unwrap(), b"new");
        // A dangling link creates its target.
        let dangling = d.path().join("dangling.csv");
        std::os::unix::fs::symlink(d.path().join("made.csv"), &dangling).unwrap();
        write_atomic(&dangling, b"x").unwrap();
        assert_eq!(std::fs::read(d.path().join("made.csv")).unwrap(), b"x");
        // A loop of links is an error, not a hang.
        let a = d.path().join("a");
        let b = d.path().join("b");
        std::os::unix::fs::symlink(&b, &a).unwrap();
        std::os::unix::fs::symlink(&a, &b).unwrap();
        assert!(write_atomic(&a, b"x")
            .unwrap_err()
            .to_string()
            .contains("symbolic links"));
    }
    #[cfg(unix)]
    #[test]
    fn non_regular_targets_are_refused() {
        let _s = serial();
        let d = tempfile::tempdir().unwrap();
        let fifo = d.path().join("pipe");
        let st = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
        assert!(st.success());
        let e = write_atomic(&fifo, b"x").unwrap_err().to_string();
        assert!(e.contains("FIFO") && e.contains("refusing"), "{e}");
        assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo_like());
        let e = check_output_path("/dev/null", "--out").unwrap_err().to_string();
        assert!(e.contains("--out /dev/null") && e.contains("device"), "{e}");
        let e = check_output_path(d.path(), "--out").unwrap_err().to_string();
        assert!(e.contains("directory"), "{e}");
        // Through a link to a device: still refused, and the link is named.
        let link = d.path().join("null.csv");
        std::os::unix::fs::symlink("/dev/null", &link).unwrap();
        let e = write_atomic(&link, b"x").unwrap_err().to_string();
        assert!(e.contains("a link to /dev/null") && e.contains("device"), "{e}");
        // A file as the directory.
        std::fs::write(d.path().join("f"), b"").unwrap();
        let e = check_output_path(d.path().join("f").join("o.csv"), "--out")
            .unwrap_err()
            .to_string();
        assert!(e.contains("is not a directory"), "{e}");
    }

    /// FIFO check without a Unix-only trait in the assertion above.
    trait FifoLike {
        fn is_fifo_like(&self) -> bool;
    }
    impl FifoLike for std::fs::FileType {
        fn is_fifo_like(&self) -> bool {
            #[cfg(unix)]
            {
                use std::os::unix::fs::FileTypeExt;
                self.is_fifo()
            }
            #[cfg(not(unix))]
            {
                false
            }
        }
    }

    #[test]
    fn temp_files_are_registered_and_removed() {
        let _s = serial();
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("slow.bin");
        write_atomic_with(&p, |tmp| -> std::io::Result<()> {
            std::fs::write(tmp, b"partial")?;
            // What a signal handler does when a write is cut short.
            remove_registered();
            assert!(!tmp.exists(), "the handler removed the temporary file");
            Ok(())
        })
        .unwrap_err();
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
    }
}
