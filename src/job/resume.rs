//! The one resume: read a saved progress through [`crate::store::progress_file`], check that
//! it belongs to the job and is possible in its plan, and say what was found.
//!
//! - A file that fails its checksum, or whose contents are impossible for the plan it claims
//!   (a block, rank or lines-done count the plan does not have, or that do not agree, a
//!   "finished" phase short of the end), is corrupt: moved aside (`*.corrupt-N`) and
//!   reported naming the file and the field, never trusted.
//! - Progress of another plan (any difference in the job's identity:
//!   [`crate::job::identity`]) is left where it is and not resumed; the report names every
//!   item that changed with its saved and current value.
//!
//! Two policies on top: the daemon starts afresh on anything but its own progress
//! ([`resume_or_start`], logged), `agsteer demo --resume` refuses to run
//! ([`require_resume`]) and says the way forward.

use super::PreparedJob;
use crate::guidance::progress::{check_against_plan, Progress, ProgressError};
use crate::store::progress_file::{self, ProgressFileError};
use std::path::Path;

/// What a progress file holds for a job.
#[derive(Debug, Clone, PartialEq)]
pub enum Saved {
    /// No progress file.
    Nothing,
    /// Progress of this job.
    Ours(Progress),
    /// Progress of another plan (left in place): what differs, one item each
    /// (`"ab.r_min: saved 6.0, now 8.1"`).
    Foreign(Vec<String>),
}

/// Read the progress at `path` and check it against `job`. A corrupt or impossible file is
/// moved aside ([`ProgressFileError::Corrupt`]).
pub fn load_saved(job: &PreparedJob, path: &Path) -> Result<Saved, ProgressFileError> {
    let Some(p) = progress_file::load(path)? else {
        return Ok(Saved::Nothing);
    };
    classify(job, p).map_err(|why| progress_file::move_aside(path, ProgressError::Content(why)))
}

/// Saved progress against `job`: another job's ([`Saved::Foreign`]) or ours, checked against
/// the plan (`Err` with the reason when its contents are impossible for it).
fn classify(job: &PreparedJob, p: Progress) -> Result<Saved, String> {
    let changes = job.definition.differences(&p.job);
    if !changes.is_empty() {
        return Ok(Saved::Foreign(changes));
    }
    check_against_plan(&p, &job.plan).map(|()| Saved::Ours(p))
}

/// [`load_saved`] leaving the file as it is (`agsteerd --check`): a corrupt or impossible
/// file is [`ProgressFileError::Invalid`], not moved.
pub fn peek_saved(job: &PreparedJob, path: &Path) -> Result<Saved, ProgressFileError> {
    let Some(p) = progress_file::peek(path)? else {
        return Ok(Saved::Nothing);
    };
    classify(job, p).map_err(|why| ProgressFileError::Invalid {
        path: path.to_path_buf(),
        reason: ProgressError::Content(why),
    })
}

/// The differences of a foreign progress, in a line.
pub fn summary(changes: &[String]) -> String {
    const SHOWN: usize = 8;
    let mut s = changes
        .iter()
        .take(SHOWN)
        .cloned()
        .collect::<Vec<_>>()
        .join("; ");
    if changes.len() > SHOWN {
        s.push_str(&format!("; and {} more", changes.len() - SHOWN));
    }
    s
}

/// The daemon's resume: the saved progress of `job`, or `None` (and a log line) when there is
/// none, it is corrupt or impossible (moved aside) or it belongs to another plan.
pub fn resume_or_start(job: &PreparedJob, path: &Path) -> Option<Progress> {
    match load_saved(job, path) {
        Ok(Saved::Ours(p)) => {
            tracing::info!(
                lines_done = p.lines_done,
                block = p.index_block,
                rank = p.index_rank,
                line_worked_m = ?p.line_worked_m,
                "resuming the job from {}",
                path.display()
            );
            Some(p)
        }
        Ok(Saved::Foreign(changes)) => {
            tracing::warn!(
                "{} was saved for another plan ({}); starting this job from the beginning (the file is overwritten at the first line change)",
                path.display(),
                summary(&changes)
            );
            None
        }
        Ok(Saved::Nothing) => None,
        Err(e) => {
            tracing::error!("{e}; starting the job from the beginning, disengaged");
            None
        }
    }
}

/// Why `--resume` cannot resume.
#[derive(Debug, thiserror::Error)]
pub enum ResumeError {
    #[error("--resume: no progress file at {}", path.display())]
    Nothing { path: std::path::PathBuf },
    #[error("--resume: {} was saved for another plan than the one {config} gives now ({}). Run without --resume to start this plan afresh (the saved progress is then overwritten), or restore the saved values to keep driving the old plan", path.display(), summary(changes))]
    OtherPlan {
        path: std::path::PathBuf,
        config: String,
        changes: Vec<String>,
    },
    #[error("--resume: {0}")]
    File(#[source] ProgressFileError),
}

/// `agsteer demo --resume`: the saved progress of `job` (configured by the file `config`), or
/// why there is none to resume.
pub fn require_resume(
    job: &PreparedJob,
    path: &Path,
    config: &Path,
) -> Result<Progress, ResumeError> {
    match load_saved(job, path).map_err(ResumeError::File)? {
        Saved::Ours(p) => {
            tracing::info!(
                lines_done = p.lines_done,
                block = p.index_block,
                rank = p.index_rank,
                line_worked_m = ?p.line_worked_m,
                "resuming from {}",
                path.display()
            );
            Ok(p)
        }
        Saved::Nothing => Err(ResumeError::Nothing {
            path: path.to_path_buf(),
        }),
        Saved::Foreign(changes) => Err(ResumeError::OtherPlan {
            path: path.to_path_buf(),
            config: config.display().to_string(),
            changes,
        }),
    }
}
