//! Everything `agsteerd` loads before its loop starts, loaded by the one function the daemon
//! and `agsteerd --check` share ([`load`]): the configuration resolved, the job set up (a
//! field or TASKDATA file read and planned, a manoeuvre map read and the manoeuvre planned),
//! the NTRIP password file read, the state directory and the status socket's path checked.
//! What `--check` adds is only what must not change anything on disk: the saved progress is
//! read and judged as the daemon's resume judges it ([`progress_outlook`]), without moving a
//! corrupt file aside.
//!
//! Contract: blocking, done once before the loop; file access goes through [`crate::store`].

use super::resume::{peek_saved, summary, Saved};
use super::{prepare, JobDetail, JobError, PreparedJob};
use crate::config::{Config, ConfigError, GnssConfig, Resolved};
use crate::store::{progress_file, DirProblem, PrivateFileError};
use std::path::PathBuf;

/// What the daemon starts with.
#[derive(Debug)]
pub struct Startup {
    pub resolved: Resolved,
    pub job: PreparedJob,
    /// The progress file in `progress.state_dir`.
    pub progress_path: PathBuf,
    /// The NTRIP password (`gnss.ntrip_password`, or the first line of
    /// `gnss.ntrip_password_file`) when GNSS comes from a byte stream; `None` on the bus.
    pub ntrip_password: Option<String>,
    /// What will not stop the daemon but loses something (progress that cannot be saved, a
    /// status socket that cannot be created), each naming the key and the path.
    pub warnings: Vec<String>,
}

/// What stops the daemon before its loop starts.
#[derive(Debug, thiserror::Error)]
pub enum StartupError {
    #[error(transparent)]
    Config(#[from] ConfigError),
    #[error(transparent)]
    Job(#[from] JobError),
    #[error(transparent)]
    Password(#[from] PasswordFileError),
    #[error("progress.state_dir: {problem}")]
    StateDir { path: PathBuf, problem: DirProblem },
    #[error("bus.status_socket: {problem}")]
    StatusSocket { path: PathBuf, problem: DirProblem },
}

/// Errors reading the NTRIP password file.
#[derive(Debug, thiserror::Error)]
pub enum PasswordFileError {
    #[error("gnss.ntrip_password_file = {path:?}: cannot read it: {source}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("gnss.ntrip_password_file = {path:?}: mode {mode:o} lets others read it; it must be readable only by the daemon's user (chmod 600)")]
    Mode { path: String, mode: u32 },
}

/// The NTRIP password: `gnss.ntrip_password`, or the first line of
/// `gnss.ntrip_password_file`, which must not be readable by group or others.
pub fn ntrip_password(g: &GnssConfig) -> Result<String, PasswordFileError> {
    if g.ntrip_password_file.is_empty() {
        return Ok(g.ntrip_password.clone());
    }
    let path = g.ntrip_password_file.clone();
    crate::store::read_private_line(std::path::Path::new(&path)).map_err(|e| match e {
        PrivateFileError::Read(source) => PasswordFileError::Read { path, source },
        PrivateFileError::Mode(mode) => PasswordFileError::Mode { path, mode },
    })
}

/// Load what the daemon starts with, as it starts with it; nothing is written.
pub fn load(cfg: &Config) -> Result<Startup, StartupError> {
    let resolved = cfg.resolve()?;
    let job = prepare(&resolved.planning)?;
    let mut warnings = Vec::new();
    // The state directory: progress can never be saved into a file that is not a directory;
    // a directory this user cannot write (or create) loses progress, which is logged.
    let state_dir = resolved.daemon.state_dir.clone();
    match crate::store::writable_dir(&state_dir) {
        Err(problem @ DirProblem::NotADirectory { .. }) => {
            return Err(StartupError::StateDir {
                path: state_dir,
                problem,
            })
        }
        Err(problem) => warnings.push(format!(
            "progress.state_dir: {problem}: progress will not be saved"
        )),
        // Existing: the directory's owner and mode as saving checks them.
        Ok(()) if state_dir.exists() => {
            if let Err(e) = progress_file::check_state_dir(&state_dir) {
                warnings.push(format!(
                    "progress.state_dir: {e}: progress will not be saved"
                ));
            }
        }
        Ok(()) => {}
    }
    if let Some(socket) = &resolved.daemon.status_socket {
        // Something else at the socket's path stops the daemon (it would not bind there).
        crate::store::socket_path_free(socket).map_err(|problem| StartupError::StatusSocket {
            path: socket.clone(),
            problem,
        })?;
        if let Some(dir) = socket.parent().filter(|d| !d.as_os_str().is_empty()) {
            if let Err(problem) = crate::store::writable_dir(dir) {
                warnings.push(format!(
                    "bus.status_socket: {problem}: the daemon cannot bind its status socket {}",
                    socket.display()
                ));
            }
        }
    }
    let ntrip_password = match cfg.gnss.stream() {
        Some(_) => Some(ntrip_password(&cfg.gnss)?),
        None => None,
    };
    Ok(Startup {
        progress_path: progress_file::progress_path(&state_dir),
        resolved,
        job,
        ntrip_password,
        warnings,
    })
}

/// What the daemon will do with the saved progress (read, not changed), in words.
pub fn progress_outlook(startup: &Startup) -> Result<String, String> {
    let path = &startup.progress_path;
    Ok(
        match peek_saved(&startup.job, path).map_err(|e| match e {
            progress_file::ProgressFileError::Invalid { .. } => format!(
                "{e}: the daemon moves it aside and starts the job from the beginning, disengaged"
            ),
            _ => format!("{e}: the daemon starts the job from the beginning, disengaged"),
        })? {
            Saved::Nothing => format!(
                "no progress in {}: the job starts from the beginning",
                path.display()
            ),
            Saved::Ours(p) => format!(
                "{}: resumes this job ({} lines done, block {}, rank {})",
                path.display(),
                p.lines_done,
                p.index_block,
                p.index_rank
            ),
            Saved::Foreign(changes) => format!(
                "{} belongs to another plan ({}): the job starts from the beginning",
                path.display(),
                summary(&changes)
            ),
        },
    )
}

/// One line saying what was planned (`None` for AB lines and arcs).
pub fn planned(job: &PreparedJob) -> Option<String> {
    match &job.detail {
        JobDetail::Field(fj) => Some(format!(
            "field {} plans into {} segments (checksum {:08x})",
            fj.path.display(),
            fj.job.len(),
            fj.job.checksum()
        )),
        JobDetail::Maneuver(mj, map) => Some(format!(
            "manoeuvre on {} plans into {} segments ({:.1} m, {} cusps, checksum {:08x})",
            if map.is_some() {
                "its map"
            } else {
                "free space"
            },
            mj.job.len(),
            mj.path.length(),
            mj.path.cusps(),
            mj.job.checksum()
        )),
        JobDetail::Lines => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn password_file_must_be_private() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("ntrip");
        std::fs::write(&path, "s3cret\n").unwrap();
        let g = GnssConfig {
            ntrip_password_file: path.display().to_string(),
            ..GnssConfig::default()
        };
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o644)).unwrap();
        let e = ntrip_password(&g).unwrap_err().to_string();
        assert!(
            e.contains("gnss.ntrip_password_file") && e.contains("644"),
            "{e}"
        );
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).unwrap();
        assert_eq!(ntrip_password(&g).unwrap(), "s3cret");
        let missing = GnssConfig {
            ntrip_password_file: dir.path().join("none").display().to_string(),
            ..GnssConfig::default()
        };
        let e = ntrip_password(&missing).unwrap_err().to_string();
        assert!(
            e.contains("gnss.ntrip_password_file") && e.contains("cannot read"),
            "{e}"
        );
        let inline = GnssConfig {
            ntrip_password: "hunter2".into(),
            ..GnssConfig::default()
        };
        assert_eq!(ntrip_password(&inline).unwrap(), "hunter2");
    }
}
