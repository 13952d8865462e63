//! A manoeuvre job (`job.kind = "maneuver"`): the map read (through [`crate::store`]), the
//! configured manoeuvre planned with `[maneuver]` on it, and the found path handed to the
//! guidance as segments split at its cusps. Part of the one job set-up
//! ([`crate::job::prepare`]) of `agsteerd`, `agsteer demo` and `agsteer sim`; `agsteer
//! maneuver` plans with the same functions.
//!
//! Also the check of approach paths against a field ([`field_clearance`]), with the same
//! vehicle footprint.

use crate::config::{Config, CurveChoice, JobKind, ManeuverPlanning};
use crate::control::ClearanceCheck;
use crate::geo::Pose;
use crate::plan::job::SegmentJob;
use crate::plan::maneuver::collision::{CollisionMap, MapError};
use crate::plan::maneuver::path::CurvePath;
use crate::plan::maneuver::search::{plan_maneuver, ManeuverError, ManeuverResult};
use crate::plan::maneuver::steering::{CcSteering, RsSteering};
use crate::plan::types::{Field, PlanError};
use std::path::PathBuf;

/// Why a manoeuvre could not be planned.
#[derive(Debug, thiserror::Error)]
pub enum ManeuverJobError {
    #[error("the map: {0}")]
    Map(#[from] MapError),
    #[error(transparent)]
    Plan(#[from] ManeuverError),
    #[error("no manoeuvre found from {from:?} to {to:?}: {why}")]
    NotFound {
        from: [f64; 3],
        to: [f64; 3],
        why: String,
    },
    #[error("the manoeuvre cannot be driven as a segment job: {0}")]
    Job(#[from] PlanError),
}

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

/// The collision map of `field` (or free space) with the configured broad-phase cell.
pub fn collision_map(
    planning: &ManeuverPlanning,
    field: Option<&Field>,
) -> Result<CollisionMap, ManeuverJobError> {
    Ok(match field {
        Some(f) => CollisionMap::new(
            Some(f.boundary.clone()),
            f.obstacles.clone(),
            planning.params.grid_cell_m,
        )?,
        None => CollisionMap::free(),
    })
}

/// Plan from `from` to `to` on `map` with the curve family `curve` and `[maneuver]`.
pub fn plan_configured(
    planning: &ManeuverPlanning,
    map: &CollisionMap,
    curve: CurveChoice,
    from: &Pose,
    to: &Pose,
) -> Result<ManeuverResult, ManeuverError> {
    let params = &planning.params;
    match curve {
        CurveChoice::Cc => plan_maneuver(
            map,
            &CcSteering {
                params: planning.curve_params,
            },
            params,
            from,
            to,
        ),
        CurveChoice::Rs => plan_maneuver(
            map,
            &RsSteering {
                r_min_m: planning.r_min,
            },
            params,
            from,
            to,
        ),
    }
}

/// The check of approach paths against `field` (issue 6 part 5b): the `[maneuver]` vehicle
/// footprint swept along the path, sampled so that no point of it moves more than
/// `maneuver.sample_tolerance_m` between samples, must stay inside the boundary and off the
/// obstacles.
pub fn field_clearance(
    planning: &ManeuverPlanning,
    field: &Field,
) -> Result<ClearanceCheck, ManeuverJobError> {
    let map = collision_map(planning, Some(field))?;
    let params = &planning.params;
    let footprint = params.footprint;
    let spacing = footprint.sample_spacing_m(params.sample_tolerance_m, 1.0 / planning.r_min);
    Ok(std::sync::Arc::new(move |path: &CurvePath| {
        map.path_clear(&footprint, path, spacing)
    }))
}

/// A pose from `[x m, y m, heading degrees]`.
pub fn pose_of(p: [f64; 3]) -> Pose {
    Pose::new(p[0], p[1], p[2].to_radians())
}

/// A planned manoeuvre job.
#[derive(Debug, Clone)]
pub struct ManeuverJob {
    pub result: ManeuverResult,
    pub path: CurvePath,
    pub job: SegmentJob,
}

/// Plan the configured manoeuvre (`job.maneuver_from` → `job.maneuver_to`, `[maneuver]`) on
/// `field` (the map, `None` = free space).
pub fn plan_job(
    planning: &ManeuverPlanning,
    field: Option<&Field>,
) -> Result<ManeuverJob, ManeuverJobError> {
    let map = collision_map(planning, field)?;
    let (from, to) = (planning.from, planning.to);
    let result = plan_configured(planning, &map, planning.curve, &pose_of(from), &pose_of(to))?;
    let Some(path) = result.path.clone() else {
        return Err(ManeuverJobError::NotFound {
            from,
            to,
            why: result.failure.clone().unwrap_or_default(),
        });
    };
    let job = SegmentJob::from_curve_path(&path, planning.spacing)?;
    Ok(ManeuverJob { result, path, job })
}

/// The configured map (`job.maneuver_map_path`): `None` for free space.
pub fn load_map(planning: &ManeuverPlanning) -> Result<Option<Field>, ManeuverFileError> {
    let Some(path) = &planning.map_path else {
        return Ok(None);
    };
    let text = crate::store::read_input(path, crate::envelope::FileKind::Map).map_err(|e| {
        ManeuverFileError::Read {
            path: path.clone(),
            source: e.into_io(),
        }
    })?;
    crate::field::load_local_map(&text)
        .map(Some)
        .map_err(|source| ManeuverFileError::Map {
            path: path.clone(),
            source,
        })
}

/// Read the map and plan the manoeuvre; also returns the map.
pub fn load(
    planning: &ManeuverPlanning,
) -> Result<(ManeuverJob, Option<Field>), ManeuverFileError> {
    let map = load_map(planning)?;
    let job = plan_job(planning, map.as_ref()).map_err(ManeuverFileError::Plan)?;
    Ok((job, map))
}

/// [`load`] the configuration's manoeuvre job; [`ManeuverFileError::NotAManeuverJob`] for
/// another kind.
pub fn load_config(cfg: &Config) -> Result<(ManeuverJob, Option<Field>), ManeuverFileError> {
    if cfg.job.kind != JobKind::Maneuver {
        return Err(ManeuverFileError::NotAManeuverJob);
    }
    load(&cfg.planning().maneuver)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::{v2, Direction};
    use crate::plan::maneuver::path::CurveSegment;

    #[test]
    fn field_clearance_rejects_paths_that_leave_the_field() {
        let cfg = Config::default();
        let field = Field {
            boundary: vec![v2(0.0, 0.0), v2(100.0, 0.0), v2(100.0, 50.0), v2(0.0, 50.0)],
            obstacles: vec![vec![
                v2(60.0, 20.0),
                v2(70.0, 20.0),
                v2(70.0, 30.0),
                v2(60.0, 30.0),
            ]],
        };
        let clear = field_clearance(&cfg.planning().maneuver, &field).unwrap();
        let straight = |x: f64, y: f64, length: f64| CurvePath {
            start: Pose::new(x, y, 0.0),
            segments: vec![CurveSegment::line(Direction::Forward, length)],
        };
        assert!(clear(&straight(10.0, 10.0, 40.0)));
        // Out through the east edge, and into the obstacle.
        assert!(!clear(&straight(10.0, 10.0, 95.0)));
        assert!(!clear(&straight(10.0, 25.0, 55.0)));
        // Along the south edge: the vehicle's half width sticks out.
        assert!(!clear(&straight(10.0, 0.5, 20.0)));
    }
}
