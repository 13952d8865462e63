//! A manoeuvre job (`job.kind = "maneuver"`): the configured manoeuvre planned with
//! `[maneuver]` on a map, and the found path handed to the guidance as segments split at its
//! cusps. Shared by `agsteer demo`, `agsteer sim`, `agsteerd` and `agsteer maneuver`.
//!
//! Pure: the caller reads the map file and times the planning.

use super::collision::CollisionMap;
use super::drive::split_at_cusps;
use super::path::CurvePath;
use super::search::{plan_maneuver, ManeuverError, ManeuverResult};
use super::steering::{CcSteering, RsSteering};
use crate::config::{Config, CurveChoice};
use crate::geo::Pose;
use crate::plan::coverage::{Field, SegmentKind};
use crate::plan::job::SegmentJob;

/// Why a manoeuvre job could not be prepared.
#[derive(Debug, thiserror::Error)]
pub enum ManeuverJobError {
    #[error("the map: {0}")]
    Map(#[from] super::collision::MapError),
    #[error(transparent)]
    Plan(#[from] ManeuverError),
    #[error("no manoeuvre found from {from:?} to {to:?}: {why}")]
    NotFound {
        from: [f64; 3],
        to: [f64; 3],
        why: String,
    },
    #[error("the manoeuvre cannot be driven as a segment job: {0}")]
    Job(#[from] crate::plan::types::PlanError),
}

/// The collision map of `field` (or free space) with the configured broad-phase cell.
pub fn collision_map(
    cfg: &Config,
    field: Option<&Field>,
) -> Result<CollisionMap, ManeuverJobError> {
    Ok(match field {
        Some(f) => CollisionMap::new(
            Some(f.boundary.clone()),
            f.obstacles.clone(),
            cfg.maneuver.grid_cell_m,
        )?,
        None => CollisionMap::free(),
    })
}

/// Plan from `from` to `to` on `map` with the curve family `curve` and `[maneuver]`.
pub fn plan_configured(
    cfg: &Config,
    map: &CollisionMap,
    curve: CurveChoice,
    from: &Pose,
    to: &Pose,
) -> Result<ManeuverResult, ManeuverError> {
    let params = cfg.maneuver_params();
    match curve {
        CurveChoice::Cc => plan_maneuver(
            map,
            &CcSteering {
                params: cfg.maneuver_curve_params(),
            },
            &params,
            from,
            to,
        ),
        CurveChoice::Rs => plan_maneuver(
            map,
            &RsSteering {
                r_min_m: cfg.vehicle.r_min_m,
            },
            &params,
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
    cfg: &Config,
    field: &Field,
) -> Result<crate::control::ClearanceCheck, ManeuverJobError> {
    let map = collision_map(cfg, Some(field))?;
    let params = cfg.maneuver_params();
    let footprint = params.footprint;
    let spacing = footprint.sample_spacing_m(params.sample_tolerance_m, 1.0 / cfg.vehicle.r_min_m);
    Ok(std::sync::Arc::new(move |path: &CurvePath| {
        map.path_clear(&footprint, path, spacing)
    }))
}

/// A pose from `[x m, y m, heading degrees]`.
pub fn pose_of(p: [f64; 3]) -> Pose {
    Pose::new(p[0], p[1], p[2].to_radians())
}

/// `path` as the guidance drives it: one transit segment per part between cusps, points every
/// `spacing_m`.
pub fn segment_job(
    path: &CurvePath,
    spacing_m: f64,
) -> Result<SegmentJob, crate::plan::types::PlanError> {
    SegmentJob::from_driven_parts(split_at_cusps(path, spacing_m), SegmentKind::Transit)
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
pub fn plan_job(cfg: &Config, field: Option<&Field>) -> Result<ManeuverJob, ManeuverJobError> {
    let map = collision_map(cfg, field)?;
    let (from, to) = (cfg.job.maneuver_from, cfg.job.maneuver_to);
    let result = plan_configured(cfg, &map, cfg.maneuver.curve, &pose_of(from), &pose_of(to))?;
    let Some(path) = result.path.clone() else {
        return Err(ManeuverJobError::NotFound {
            from,
            to,
            why: result.failure.clone().unwrap_or_default(),
        });
    };
    let job = segment_job(&path, cfg.guidance.point_spacing_m.min(0.5))?;
    Ok(ManeuverJob { result, path, job })
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
        let clear = field_clearance(&cfg, &field).unwrap();
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
