//! Atomic progress files: write a temp file, fsync it, rename it over the old one, fsync the
//! directory. A reader sees either the old or the new file, never a mixture. A file that fails
//! its checksum is moved aside (`*.corrupt-N`) and reported, never trusted.

use crate::guidance::progress::{Progress, ProgressError};
use std::fs::{self, File, OpenOptions};
use std::io::Write;
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

/// Write atomically (temp, fsync, rename, fsync dir).
pub fn save(path: &Path, progress: &Progress) -> Result<(), ProgressFileError> {
    let dir = path.parent().unwrap_or(Path::new("."));
    fs::create_dir_all(dir).map_err(io(dir))?;
    let tmp = path.with_extension("json.tmp");
    {
        let mut f = File::create(&tmp).map_err(io(&tmp))?;
        f.write_all(progress.encode().as_bytes())
            .map_err(io(&tmp))?;
        f.sync_all().map_err(io(&tmp))?;
    }
    fs::rename(&tmp, path).map_err(io(path))?;
    if let Ok(d) = OpenOptions::new().read(true).open(dir) {
        // Directory fsync makes the rename durable; not every filesystem supports it.
        let _ = d.sync_all();
    }
    Ok(())
}

/// Load a progress file. `Ok(None)` when there is none. A corrupt file is renamed aside and
/// reported as [`ProgressFileError::Corrupt`].
pub fn load(path: &Path) -> Result<Option<Progress>, ProgressFileError> {
    let bytes = match crate::envelope::read_bytes(path, crate::envelope::FileKind::Progress) {
        Ok(b) => b,
        Err(e) if e.is_not_found() => return Ok(None),
        Err(e) => return Err(io(path)(e.into_io())),
    };
    match Progress::decode(&bytes) {
        Ok(p) => Ok(Some(p)),
        Err(reason) => {
            let moved_to = (0u32..)
                .map(|n| path.with_extension(format!("json.corrupt-{n}")))
                .find(|p| !p.exists())
                .unwrap_or_else(|| path.with_extension("json.corrupt"));
            fs::rename(path, &moved_to).map_err(io(path))?;
            Err(ProgressFileError::Corrupt {
                path: path.to_path_buf(),
                reason,
                moved_to,
            })
        }
    }
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
}
