//! Pure pursuit, the seed-000 law: steer onto the arc through the preview point one look-ahead
//! along the local path. Registered twice: `predictive` (the default: the predicted pose, the
//! disturbance observer's course and wheel offset, integral action, lost-motion compensation)
//! and `pure_pursuit` (the plain reference on the latest fix).

use super::law::{LawNeeds, SteeringLaw};
use super::local_path::LocalPath;
use super::{
    curvature_along, lookahead, point_along, scheduled_lookahead, TrackOutput, TrackerParams,
};
use crate::geo::{cross, heading_vec, Pose};

/// Pure pursuit with what the controller feeds it chosen by `needs`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PurePursuit {
    pub needs: LawNeeds,
    /// The look-ahead is scheduled on the steering's response ([`scheduled_lookahead`]), its
    /// growth with speed (`ld_gain`) stopping at this distance, m; `None`: the seed's
    /// `ld_min`/`ld_gain` alone.
    pub scheduled: Option<f64>,
}

impl PurePursuit {
    /// The default tracker: pure pursuit on a latency-compensated, dead-reckoned pose, steering
    /// the course over ground with every compensation on; its look-ahead grows with speed up
    /// to `ld_max` m (`track.predictive_ld_max_m`), or further where the steering's response
    /// needs it.
    pub fn predictive(ld_max: f64) -> Self {
        PurePursuit {
            needs: LawNeeds {
                prediction: true,
                observer: true,
                integral: true,
                lost_motion: true,
            },
            scheduled: Some(ld_max),
        }
    }

    /// The plain seed-000 reference: the latest fix as it is, nothing added.
    pub fn plain() -> Self {
        PurePursuit {
            needs: LawNeeds {
                prediction: false,
                observer: false,
                integral: false,
                lost_motion: false,
            },
            scheduled: None,
        }
    }
}

impl SteeringLaw for PurePursuit {
    fn needs(&self) -> LawNeeds {
        self.needs
    }

    fn steer(
        &self,
        local: &LocalPath,
        pose: &Pose,
        speed: f64,
        _wheel_angle: Option<f64>,
        params: &TrackerParams,
    ) -> TrackOutput {
        let ld = match self.scheduled {
            Some(ld_max) => {
                let growth = (params.ld_gain * speed.abs()).min(ld_max);
                scheduled_lookahead(
                    &TrackerParams {
                        ld_gain: 0.0,
                        ..*params
                    },
                    params.response_time(),
                    speed,
                )
                .max(growth)
            }
            None => lookahead(params, speed),
        };
        pure_pursuit_at(local, pose, ld, params)
    }
}

/// Half the chord over which the path's curvature at the preview point is measured, m.
const PATH_CURVATURE_HALF_M: f64 = 1.0;

/// Seed-000 pure pursuit: from the nearest local point integrate the look-ahead along the
/// local path to the preview point; α is the angle from the heading to it;
/// κ = 2·sin α / Ld and δ = atan(L·κ).
pub fn pure_pursuit(
    local: &LocalPath,
    pose: &Pose,
    speed: f64,
    params: &TrackerParams,
) -> TrackOutput {
    pure_pursuit_at(local, pose, lookahead(params, speed), params)
}

/// [`pure_pursuit`] with the look-ahead `ld` (m) given.
pub fn pure_pursuit_at(
    local: &LocalPath,
    pose: &Pose,
    ld: f64,
    params: &TrackerParams,
) -> TrackOutput {
    let points = local.points();
    let invalid = TrackOutput::invalid(pose.pos, ld);
    if points.is_empty()
        || !pose.pos.x.is_finite()
        || !pose.pos.y.is_finite()
        || !pose.heading.is_finite()
        || !ld.is_finite()
        || ld <= 0.0
    {
        return invalid;
    }
    let target = point_along(points, local.index_local(), ld);
    let to = target - pose.pos;
    let h = heading_vec(pose.heading);
    let alpha = cross(&h, &to).atan2(h.dot(&to));
    let curvature = 2.0 * alpha.sin() / ld;
    let max = params.max_wheel_angle;
    let wheel_angle = (params.wheelbase * curvature).atan().clamp(-max, max);
    TrackOutput {
        wheel_angle,
        curvature,
        lookahead: ld,
        target,
        alpha,
        path_curvature: curvature_along(points, local.index_local(), ld, PATH_CURVATURE_HALF_M),
        valid: true,
    }
}
