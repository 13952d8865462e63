//! The files agsteer reads and writes besides its configuration: the progress file (atomic,
//! checksummed; a corrupt one is moved aside), the job's input files (a field, a manoeuvre
//! map, a TASKDATA file), private files (the NTRIP password), and whether the directories it
//! writes into can be written.
//!
//! Contract: file I/O only, blocking, done at start-up or on a writer thread, never in the
//! control loop. What the bytes mean is decided elsewhere ([`crate::guidance::progress`]
//! encodes progress, [`crate::field`] parses fields); whether a saved progress belongs to the
//! job is the job layer's question ([`crate::job::resume`]).

pub mod calibration_file;
pub mod jobs_file;
pub mod progress_file;

use crate::envelope::{FileError, FileKind};
use std::path::{Path, PathBuf};

/// Read a job's input file (a field, a manoeuvre map) as text, through the bounded reader of
/// the input envelope (a directory, FIFO, device or over-size file is refused at once).
pub fn read_input(path: &Path, kind: FileKind) -> Result<String, FileError> {
    crate::envelope::read_text(path, kind)
}

/// Why a private file (one only its owner may read) cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum PrivateFileError {
    #[error("cannot read it: {0}")]
    Read(#[source] std::io::Error),
    /// Its permission bits (the low nine) let the group or others read or write it.
    #[error("mode {0:o} lets others read it")]
    Mode(u32),
}

/// The first line of a file that only its owner may read or write (a secret such as the
/// NTRIP password), without its line end; "" for an empty file.
pub fn read_private_line(path: &Path) -> Result<String, PrivateFileError> {
    use std::os::unix::fs::PermissionsExt;
    let meta = std::fs::metadata(path).map_err(PrivateFileError::Read)?;
    let mode = meta.permissions().mode() & 0o777;
    if mode & 0o077 != 0 {
        return Err(PrivateFileError::Mode(mode));
    }
    let text = std::fs::read_to_string(path).map_err(PrivateFileError::Read)?;
    Ok(text.lines().next().unwrap_or("").trim_end().to_string())
}

/// Why a directory agsteer writes into (the state directory, the status socket's) cannot
/// be used as it stands.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DirProblem {
    #[error("{} exists and is not a directory", path.display())]
    NotADirectory { path: PathBuf },
    #[error("{} is not writable by this user", path.display())]
    NotWritable { path: PathBuf },
    #[error("{} does not exist and cannot be created: {} is not a writable directory", path.display(), ancestor.display())]
    CannotCreate { path: PathBuf, ancestor: PathBuf },
    #[error("{} exists and is not a socket (the daemon removes only a stale socket)", path.display())]
    NotASocket { path: PathBuf },
}

/// Whether files can be written in `dir`, as it is now (nothing is created): an existing
/// writable directory, or a missing one whose nearest existing ancestor is a writable
/// directory (the daemon creates it on its first save). Writable is asked of the kernel for
/// this process's user (`access(2)`, `W_OK`).
pub fn writable_dir(dir: &Path) -> Result<(), DirProblem> {
    match std::fs::metadata(dir) {
        Ok(m) if !m.is_dir() => Err(DirProblem::NotADirectory {
            path: dir.to_path_buf(),
        }),
        Ok(_) if !writable(dir) => Err(DirProblem::NotWritable {
            path: dir.to_path_buf(),
        }),
        Ok(_) => Ok(()),
        Err(_) => {
            let ancestor = dir
                .ancestors()
                .skip(1)
                .map(|a| {
                    if a.as_os_str().is_empty() {
                        Path::new(".")
                    } else {
                        a
                    }
                })
                .find(|a| a.exists())
                .unwrap_or(Path::new("/"));
            if !ancestor.is_dir() {
                Err(DirProblem::NotADirectory {
                    path: ancestor.to_path_buf(),
                })
            } else if writable(ancestor) {
                Ok(())
            } else {
                Err(DirProblem::CannotCreate {
                    path: dir.to_path_buf(),
                    ancestor: ancestor.to_path_buf(),
                })
            }
        }
    }
}

fn writable(path: &Path) -> bool {
    use std::os::unix::ffi::OsStrExt;
    let Ok(c) = std::ffi::CString::new(path.as_os_str().as_bytes()) else {
        return false;
    };
    // SAFETY: access(2) reads the NUL-terminated path and nothing else.
    unsafe { libc::access(c.as_ptr(), libc::W_OK) == 0 }
}

/// Whether a Unix socket can be bound at `path` after the daemon's clean-up (which removes a
/// stale socket there, and nothing else): `Err` names what is in the way.
pub fn socket_path_free(path: &Path) -> Result<(), DirProblem> {
    use std::os::unix::fs::FileTypeExt;
    match std::fs::symlink_metadata(path) {
        Ok(m) if !m.file_type().is_socket() => Err(DirProblem::NotASocket {
            path: path.to_path_buf(),
        }),
        _ => Ok(()),
    }
}
