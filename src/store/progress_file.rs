//! Atomic progress files: write a temp file, fsync it, rename it over the old one, fsync the
//! directory. A reader sees either the old or the new file, never a mixture. A file that fails
//! its checksum is moved aside (`*.corrupt-N`) and reported, never trusted.
//!
//! State files are opened as state files, not as inputs:
//! - the temp file is created exclusively (`O_EXCL`, mode 0600) under a random name in the
//!   state directory (the `tempfile` crate), so nothing planted under a guessed name (a symlink
//!   to another file) is written through;
//! - the progress file is opened with `O_NOFOLLOW | O_NONBLOCK` and must be a regular file: a
//!   symlink, a FIFO, a directory or a device where it should be is refused naming the path
//!   and what was found, both when reading and before the rename that would replace it;
//! - the state directory is created with mode 0700; an existing one must be a directory owned
//!   by this process's user and not writable by every user.

use crate::guidance::progress::{Progress, ProgressError};
use std::fs::{self, OpenOptions};
use std::io::{Read, Write};
use std::os::unix::fs::{DirBuilderExt, MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

/// File name of the progress file inside the state directory.
pub const PROGRESS_FILE_NAME: &str = "progress.json";

#[derive(Debug, thiserror::Error)]
pub enum ProgressFileError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path} is corrupt ({reason}); moved aside to {moved_to}")]
    Corrupt {
        path: PathBuf,
        reason: ProgressError,
        moved_to: PathBuf,
    },
    #[error("{path} is {found}, not a regular file: refused as a state file (remove it)")]
    NotAFile { path: PathBuf, found: &'static str },
    #[error("state directory {path}: {reason}")]
    UnsafeDir { path: PathBuf, reason: String },
    #[error("{path}: {size} bytes, over the limit of {limit} bytes for a progress file")]
    TooLarge {
        path: PathBuf,
        size: u64,
        limit: u64,
    },
    /// A corrupt file read by [`peek`], which leaves it where it is.
    #[error("{path} is corrupt ({reason})")]
    Invalid {
        path: PathBuf,
        reason: ProgressError,
    },
}

impl ProgressFileError {
    /// The file or directory the error is about.
    pub fn path(&self) -> &Path {
        match self {
            ProgressFileError::Io { path, .. }
            | ProgressFileError::Corrupt { path, .. }
            | ProgressFileError::NotAFile { path, .. }
            | ProgressFileError::UnsafeDir { path, .. }
            | ProgressFileError::TooLarge { path, .. }
            | ProgressFileError::Invalid { path, .. } => path,
        }
    }
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> ProgressFileError + '_ {
    move |source| ProgressFileError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// The progress file path in a state directory.
pub fn progress_path(state_dir: &Path) -> PathBuf {
    state_dir.join(PROGRESS_FILE_NAME)
}

fn type_name(t: fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if t.is_symlink() {
        "a symbolic link"
    } else if t.is_dir() {
        "a directory"
    } else if t.is_fifo() {
        "a FIFO"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_block_device() || t.is_char_device() {
        "a device"
    } else {
        "not a regular file"
    }
}

/// Create the state directory `dir` (mode 0700, parents as needed) or check the existing one:
/// a directory owned by this process's user, not writable by every user (a group-writable
/// one is accepted: a umask of 002 makes every directory so).
pub fn ensure_state_dir(dir: &Path) -> Result<(), ProgressFileError> {
    match fs::metadata(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            fs::DirBuilder::new()
                .recursive(true)
                .mode(0o700)
                .create(dir)
                .map_err(io(dir))?;
            Ok(())
        }
        Err(e) => Err(io(dir)(e)),
        Ok(_) => check_state_dir(dir),
    }
}

/// Check the existing state directory `dir` as [`ensure_state_dir`] does, creating nothing
/// (`agsteerd --check`).
pub fn check_state_dir(dir: &Path) -> Result<(), ProgressFileError> {
    let unsafe_dir = |reason: String| ProgressFileError::UnsafeDir {
        path: dir.to_path_buf(),
        reason,
    };
    let m = fs::metadata(dir).map_err(io(dir))?;
    if !m.is_dir() {
        return Err(unsafe_dir(format!("is {}", type_name(m.file_type()))));
    }
    // SAFETY: geteuid has no preconditions and cannot fail.
    let me = unsafe { libc::geteuid() };
    if m.uid() != me {
        return Err(unsafe_dir(format!(
            "owned by uid {}, not by this process's uid {me}",
            m.uid()
        )));
    }
    if m.mode() & 0o002 != 0 {
        return Err(unsafe_dir(format!(
            "mode {:o} lets every user write in it (chmod o-w)",
            m.mode() & 0o7777
        )));
    }
    Ok(())
}

/// Refuse whatever is at `path` unless it is nothing or a regular file (not followed).
fn check_target(path: &Path) -> Result<(), ProgressFileError> {
    match fs::symlink_metadata(path) {
        Ok(m) if !m.file_type().is_file() => Err(ProgressFileError::NotAFile {
            path: path.to_path_buf(),
            found: type_name(m.file_type()),
        }),
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(io(path)(e)),
    }
}

/// Write atomically: an exclusive temp file with a random name in the same directory, fsync,
/// rename over `path`, fsync the directory. The directory is created (0700) or checked
/// ([`ensure_state_dir`]); a non-regular file at `path` is refused, not replaced.
pub fn save(path: &Path, progress: &Progress) -> Result<(), ProgressFileError> {
    save_bytes(path, ".progress.json.", progress.encode().as_bytes())
}

/// [`save`]'s atomic write of any state file's `bytes` (temp files named `prefix`*`.tmp`).
pub(crate) fn save_bytes(path: &Path, prefix: &str, bytes: &[u8]) -> Result<(), ProgressFileError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    ensure_state_dir(dir)?;
    check_target(path)?;
    let mut tmp = tempfile::Builder::new()
        .prefix(prefix)
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(io(dir))?;
    tmp.write_all(bytes).map_err(io(tmp.path()))?;
    tmp.as_file().sync_all().map_err(io(path))?;
    // Checked again just before the rename (the window left is the rename itself, which
    // replaces a link or a file and never writes through one).
    check_target(path)?;
    tmp.persist(path).map_err(|e| io(path)(e.error))?;
    // Directory fsync makes the rename durable; not every filesystem supports it.
    if let Ok(d) = OpenOptions::new().read(true).open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// The bytes of the state file at `path` (`None` when there is none), opened without
/// following a link and without blocking on a FIFO, refused unless a regular file.
pub(crate) fn read_state_file(path: &Path) -> Result<Option<Vec<u8>>, ProgressFileError> {
    let file = match OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path)
    {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        // ELOOP: the last component is a symbolic link.
        Err(e) if e.raw_os_error() == Some(libc::ELOOP) => {
            return Err(ProgressFileError::NotAFile {
                path: path.to_path_buf(),
                found: "a symbolic link",
            })
        }
        Err(e) => return Err(io(path)(e)),
    };
    let meta = file.metadata().map_err(io(path))?;
    if !meta.file_type().is_file() {
        return Err(ProgressFileError::NotAFile {
            path: path.to_path_buf(),
            found: type_name(meta.file_type()),
        });
    }
    let limit = crate::envelope::FileKind::Progress.max_bytes();
    let mut bytes = Vec::new();
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io(path))?;
    if bytes.len() as u64 > limit {
        return Err(ProgressFileError::TooLarge {
            path: path.to_path_buf(),
            size: meta.len().max(bytes.len() as u64),
            limit,
        });
    }
    Ok(Some(bytes))
}

/// Remove the temp files a crash during [`save`] left beside `path` (regular files named
/// `.progress.json.*.tmp`; they never hold the progress, the rename does).
fn remove_stale_temps(path: &Path) {
    let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) else {
        return;
    };
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let name = name.to_string_lossy();
        let ours = name.starts_with(".progress.json.") && name.ends_with(".tmp");
        if ours && entry.file_type().is_ok_and(|t| t.is_file()) {
            if let Err(e) = fs::remove_file(entry.path()) {
                tracing::warn!("could not remove {}: {e}", entry.path().display());
            }
        }
    }
}

/// Move a corrupt state file other than the progress file aside (`*.corrupt-N`), saying why.
pub(crate) fn move_aside_as(path: &Path, reason: String) -> ProgressFileError {
    move_aside(path, ProgressError::Content(reason))
}

/// Move a corrupt file aside (`*.corrupt-N`) and say where.
pub fn move_aside(path: &Path, reason: ProgressError) -> ProgressFileError {
    let moved_to = (0u32..1000)
        .map(|n| path.with_extension(format!("json.corrupt-{n}")))
        .find(|p| fs::symlink_metadata(p).is_err())
        .unwrap_or_else(|| path.with_extension("json.corrupt"));
    if let Err(e) = fs::rename(path, &moved_to) {
        return io(path)(e);
    }
    ProgressFileError::Corrupt {
        path: path.to_path_buf(),
        reason,
        moved_to,
    }
}

/// Load a progress file. `Ok(None)` when there is none. A corrupt file is renamed aside and
/// reported as [`ProgressFileError::Corrupt`]; a symlink, FIFO, directory or device at `path`
/// is refused ([`ProgressFileError::NotAFile`]) and left alone.
pub fn load(path: &Path) -> Result<Option<Progress>, ProgressFileError> {
    remove_stale_temps(path);
    match peek(path) {
        Err(ProgressFileError::Invalid { path, reason }) => Err(move_aside(&path, reason)),
        other => other,
    }
}

/// Read a progress file and leave it as it is (`agsteerd --check`): `Ok(None)` when there is
/// none, [`ProgressFileError::Invalid`] when it is corrupt; refused as [`load`] refuses.
pub fn peek(path: &Path) -> Result<Option<Progress>, ProgressFileError> {
    let Some(bytes) = read_state_file(path)? else {
        return Ok(None);
    };
    Progress::decode(&bytes)
        .map(Some)
        .map_err(|reason| ProgressFileError::Invalid {
            path: path.to_path_buf(),
            reason,
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::guidance::progress::{Phase, PROGRESS_VERSION};

    fn sample() -> Progress {
        Progress {
            version: PROGRESS_VERSION,
            job: crate::config::Config::default().job_definition(),
            index_block: 0,
            index_rank: 3,
            phase: Phase::Work,
            lines_done: 3,
            nudge_m: 0.0,
            line_worked_m: None,
        }
    }

    #[test]
    fn save_load_and_overwrite() {
        let dir = tempfile::tempdir().unwrap();
        let path = progress_path(dir.path());
        assert!(load(&path).unwrap().is_none());
        let mut p = sample();
        save(&path, &p).unwrap();
        p.lines_done = 4;
        save(&path, &p).unwrap();
        assert_eq!(load(&path).unwrap(), Some(p));
        assert!(!path.with_extension("json.tmp").exists());
    }

    #[test]
    fn corrupt_file_is_moved_aside() {
        let dir = tempfile::tempdir().unwrap();
        let path = progress_path(dir.path());
        let enc = sample().encode();
        fs::write(&path, &enc[..enc.len() / 2]).unwrap();
        match load(&path) {
            Err(ProgressFileError::Corrupt { moved_to, .. }) => {
                assert!(moved_to.exists());
                assert!(!path.exists());
            }
            other => panic!("expected Corrupt, got {other:?}"),
        }
        // The next load starts clean.
        assert!(load(&path).unwrap().is_none());
    }

    fn victim(dir: &Path) -> PathBuf {
        let v = dir.join("victim.txt");
        fs::write(&v, "precious").unwrap();
        v
    }

    #[test]
    fn a_symlink_at_the_progress_file_is_refused_both_ways() {
        let dir = tempfile::tempdir().unwrap();
        let path = progress_path(dir.path());
        let v = victim(dir.path());
        std::os::unix::fs::symlink(&v, &path).unwrap();
        let e = save(&path, &sample()).unwrap_err();
        assert!(
            matches!(
                e,
                ProgressFileError::NotAFile {
                    found: "a symbolic link",
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("progress.json"), "{e}");
        let e = load(&path).unwrap_err();
        assert!(matches!(e, ProgressFileError::NotAFile { .. }), "{e}");
        assert_eq!(fs::read_to_string(&v).unwrap(), "precious");
        assert!(fs::symlink_metadata(&path)
            .unwrap()
            .file_type()
            .is_symlink());
    }

    #[test]
    fn a_symlink_at_the_old_temp_name_is_not_written_through() {
        // The attack: OUT/progress.json.tmp pointing at another file.
        let dir = tempfile::tempdir().unwrap();
        let path = progress_path(dir.path());
        let v = victim(dir.path());
        std::os::unix::fs::symlink(&v, path.with_extension("json.tmp")).unwrap();
        save(&path, &sample()).unwrap();
        assert_eq!(fs::read_to_string(&v).unwrap(), "precious");
        assert_eq!(load(&path).unwrap(), Some(sample()));
        // Nothing but the file, the victim and the planted link is left.
        let mut names: Vec<String> = fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, ["progress.json", "progress.json.tmp", "victim.txt"]);
    }

    #[test]
    fn a_fifo_or_a_directory_at_the_progress_file_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = progress_path(dir.path());
        let c = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        // No writer: a blocking open would hang here.
        let e = load(&path).unwrap_err();
        assert!(
            matches!(
                e,
                ProgressFileError::NotAFile {
                    found: "a FIFO",
                    ..
                }
            ),
            "{e}"
        );
        let e = save(&path, &sample()).unwrap_err();
        assert!(
            matches!(
                e,
                ProgressFileError::NotAFile {
                    found: "a FIFO",
                    ..
                }
            ),
            "{e}"
        );
        fs::remove_file(&path).unwrap();
        fs::create_dir(&path).unwrap();
        let e = load(&path).unwrap_err();
        assert!(
            matches!(
                e,
                ProgressFileError::NotAFile {
                    found: "a directory",
                    ..
                }
            ),
            "{e}"
        );
        let e = save(&path, &sample()).unwrap_err();
        assert!(e.to_string().contains("progress.json") && e.to_string().contains("directory"));
    }

    #[test]
    fn the_state_directory_is_created_0700_and_checked() {
        let dir = tempfile::tempdir().unwrap();
        let state = dir.path().join("a/b/state");
        save(&progress_path(&state), &sample()).unwrap();
        let mode = fs::metadata(&state).unwrap().mode() & 0o777;
        assert_eq!(mode, 0o700, "{mode:o}");
        // A world-writable one is refused, naming it.
        use std::os::unix::fs::PermissionsExt;
        fs::set_permissions(&state, fs::Permissions::from_mode(0o777)).unwrap();
        let e = save(&progress_path(&state), &sample()).unwrap_err();
        assert!(matches!(e, ProgressFileError::UnsafeDir { .. }), "{e}");
        assert!(
            e.to_string().contains("state") && e.to_string().contains("777"),
            "{e}"
        );
        // A file where the directory should be.
        let file = dir.path().join("plain");
        fs::write(&file, "x").unwrap();
        let e = ensure_state_dir(&file).unwrap_err();
        assert!(e.to_string().contains("plain"), "{e}");
    }

    #[test]
    fn peek_reports_a_corrupt_file_and_leaves_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = progress_path(dir.path());
        assert!(peek(&path).unwrap().is_none());
        save(&path, &sample()).unwrap();
        assert_eq!(peek(&path).unwrap(), Some(sample()));
        let enc = sample().encode();
        fs::write(&path, &enc[..enc.len() / 2]).unwrap();
        assert!(matches!(
            peek(&path),
            Err(ProgressFileError::Invalid { .. })
        ));
        assert!(path.exists(), "peek moved the file");
        assert_eq!(fs::read_to_string(&path).unwrap(), &enc[..enc.len() / 2]);
    }
}
