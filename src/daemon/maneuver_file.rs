//! Reading the map of a manoeuvre job (`job.maneuver_map_path`) and planning it: blocking
//! work done once at start-up, never in the control loop.

use crate::config::{Config, JobKind};
use crate::plan::coverage::Field;
use crate::plan::maneuver::job::{plan_job, ManeuverJob, ManeuverJobError};
use std::path::PathBuf;

/// Why the manoeuvre job could not be prepared.
#[derive(Debug, thiserror::Error)]
pub enum ManeuverFileError {
    #[error("job.kind is not \"maneuver\"")]
    NotAManeuverJob,
    #[error("cannot read the map {} (job.maneuver_map_path)", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("map {} (job.maneuver_map_path)", path.display())]
    Map {
        path: PathBuf,
        #[source]
        source: crate::field::FieldError,
    },
    #[error("planning the manoeuvre ([maneuver], job.maneuver_from, job.maneuver_to)")]
    Plan(#[source] ManeuverJobError),
}

/// The configured map: `None` for free space (`job.maneuver_map_path` empty).
pub fn load_map(cfg: &Config) -> Result<Option<Field>, ManeuverFileError> {
    let name = cfg.job.maneuver_map_path.trim();
    if name.is_empty() {
        return Ok(None);
    }
    let path = PathBuf::from(name);
    let text = crate::envelope::read_text(&path, crate::envelope::FileKind::Map).map_err(|e| {
        ManeuverFileError::Read {
            path: path.clone(),
            source: e.into_io(),
        }
    })?;
    crate::field::load_local_map(&text)
        .map(Some)
        .map_err(|source| ManeuverFileError::Map { path, source })
}

/// Read the map and plan the configured manoeuvre job; also returns the map.
pub fn load(cfg: &Config) -> Result<(ManeuverJob, Option<Field>), ManeuverFileError> {
    if cfg.job.kind != JobKind::Maneuver {
        return Err(ManeuverFileError::NotAManeuverJob);
    }
    let map = load_map(cfg)?;
    let job = plan_job(cfg, map.as_ref()).map_err(ManeuverFileError::Plan)?;
    Ok((job, map))
}
