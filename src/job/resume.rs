//! The one resume: read a saved progress through [`crate::store::progress_file`], check that
//! it belongs to the job, and say what was found. A corrupt file is moved aside by the store
//! and reported; progress of another job is left where it is (it may still be wanted for its
//! own job) and not resumed.
//!
//! Two policies on top: the daemon starts afresh on anything but its own progress
//! ([`resume_or_start`], logged), `agsteer demo --resume` refuses to run
//! ([`require_resume`]).

use crate::guidance::progress::{JobDefinition, Progress};
use crate::store::progress_file::{self, ProgressFileError};
use std::path::Path;

/// What a progress file holds for a job.
#[derive(Debug, Clone, PartialEq)]
pub enum Saved {
    /// No progress file.
    Nothing,
    /// Progress of this job.
    Ours(Progress),
    /// Progress of another job (left in place).
    Foreign(Foreign),
}

/// Why saved progress belongs to another job.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Foreign {
    /// Another segment plan (or an AB job's progress for a segment job, or back): the plan
    /// checksums differ.
    OtherPlan {
        saved: Option<u32>,
        expected: Option<u32>,
    },
    /// Same plan checksum, other job keys.
    OtherJob,
}

/// A plan checksum for messages.
pub fn checksum_text(c: Option<u32>) -> String {
    c.map_or_else(|| "none (AB job)".into(), |c| format!("{c:08x}"))
}

/// Read the progress at `path` and check it against the job `expected`. A corrupt file is
/// moved aside ([`ProgressFileError::Corrupt`]).
pub fn load_saved(expected: &JobDefinition, path: &Path) -> Result<Saved, ProgressFileError> {
    Ok(match progress_file::load(path)? {
        None => Saved::Nothing,
        Some(p) if p.job == *expected => Saved::Ours(p),
        Some(p) if p.job.plan_checksum != expected.plan_checksum => {
            Saved::Foreign(Foreign::OtherPlan {
                saved: p.job.plan_checksum,
                expected: expected.plan_checksum,
            })
        }
        Some(_) => Saved::Foreign(Foreign::OtherJob),
    })
}

/// The daemon's resume: the saved progress of the job `expected`, or `None` (and a log line)
/// when there is none, it is corrupt (moved aside) or it belongs to another job (other
/// parameters, or another field plan).
pub fn resume_or_start(expected: &JobDefinition, path: &Path) -> Option<Progress> {
    match load_saved(expected, path) {
        Ok(Saved::Ours(p)) => {
            tracing::info!(
                lines_done = p.lines_done,
                block = p.index_block,
                rank = p.index_rank,
                "resuming the job from {}",
                path.display()
            );
            Some(p)
        }
        Ok(Saved::Foreign(Foreign::OtherPlan { saved, expected })) => {
            tracing::warn!(
                "{} belongs to another field plan (checksum {}, this plan {}); starting this job from the beginning",
                path.display(),
                checksum_text(saved),
                checksum_text(expected)
            );
            None
        }
        Ok(Saved::Foreign(Foreign::OtherJob)) => {
            tracing::warn!(
                "{} belongs to another job (its parameters differ); starting this job from the beginning",
                path.display()
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
    #[error("--resume: {} was saved for another field plan (checksum {}, this plan {}); run without --resume to start afresh", path.display(), checksum_text(*saved), checksum_text(*expected))]
    OtherPlan {
        path: std::path::PathBuf,
        saved: Option<u32>,
        expected: Option<u32>,
    },
    #[error("--resume: {} belongs to another job (its job parameters differ from {config}); run without --resume to start afresh", path.display())]
    OtherJob {
        path: std::path::PathBuf,
        config: String,
    },
    #[error("--resume")]
    File(#[source] ProgressFileError),
}

/// `agsteer demo --resume`: the saved progress of the job `expected` (defined by the
/// configuration file `config`), or why there is none to resume.
pub fn require_resume(
    expected: &JobDefinition,
    path: &Path,
    config: &Path,
) -> Result<Progress, ResumeError> {
    match load_saved(expected, path).map_err(ResumeError::File)? {
        Saved::Ours(p) => {
            tracing::info!(
                lines_done = p.lines_done,
                block = p.index_block,
                rank = p.index_rank,
                "resuming from {}",
                path.display()
            );
            Ok(p)
        }
        Saved::Nothing => Err(ResumeError::Nothing {
            path: path.to_path_buf(),
        }),
        Saved::Foreign(Foreign::OtherPlan { saved, expected }) => Err(ResumeError::OtherPlan {
            path: path.to_path_buf(),
            saved,
            expected,
        }),
        Saved::Foreign(Foreign::OtherJob) => Err(ResumeError::OtherJob {
            path: path.to_path_buf(),
            config: config.display().to_string(),
        }),
    }
}
