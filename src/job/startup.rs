//! Everything `agsteerd` loads before its loop starts, loaded by the one function the daemon
//! and `agsteerd --check` share ([`load`]): the configuration resolved, the job set up (a
//! field or TASKDATA file read and planned, a manoeuvre map read and the manoeuvre planned),
//! the NTRIP password file read, the state directory and the status socket's path checked.
//! What `--check` adds is only what must not change anything on disk: the saved progress is
//! read and judged as the daemon's resume judges it ([`progress_outlook`]), without moving a
//! corrupt file aside.
//!
//! Contract: blocking, done once before the loop; file access goes through [`crate::store`]
//! (and the configuration's password-file reader).

use super::resume::{peek_saved, summary, Saved};
use super::{prepare, JobDetail, JobError, PreparedJob};
use crate::config::{Config, ConfigError, PasswordFileError, Resolved};
use crate::store::{progress_file, DirProblem};
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
        Some(_) => Some(crate::config::ntrip_password(&cfg.gnss)?),
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
