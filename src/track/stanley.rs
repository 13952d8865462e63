//! The Stanley law (Hoffmann et al. 2007), a reference tracker: steers the front axle onto the
//! path from its heading error and its cross-track error. Registered as `stanley`.

use super::law::{LawNeeds, LawParams, SteeringLaw};
use super::local_path::LocalPath;
use super::{TrackOutput, TrackerParams};
use crate::geo::{cross, heading_vec, Pose};

/// Stanley on the latency-compensated, dead-reckoned pose, with integral action; without the
/// disturbance observer and the lost-motion compensation (a reference).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stanley {
    /// Cross-track gain k, 1/s.
    pub gain: f64,
    /// Softening speed, m/s.
    pub soft_speed: f64,
}

impl Stanley {
    pub fn new(params: &LawParams) -> Self {
        Stanley {
            gain: params.stanley_gain,
            soft_speed: params.stanley_soft_speed,
        }
    }
}

impl SteeringLaw for Stanley {
    fn needs(&self) -> LawNeeds {
        LawNeeds {
            prediction: true,
            observer: false,
            integral: true,
            lost_motion: false,
            lag_lead: false,
        }
    }

    fn steer(
        &self,
        local: &LocalPath,
        pose: &Pose,
        speed: f64,
        _wheel_angle: Option<f64>,
        params: &TrackerParams,
    ) -> TrackOutput {
        stanley(local, pose, speed, params, self.gain, self.soft_speed)
    }
}

/// Stanley steering (Hoffmann et al. 2007) on the local path: with the front axle's signed
/// distance `e` to the path (positive = path to its left) and the heading error ψ = path
/// heading − vehicle heading at the front axle's nearest point,
/// δ = ψ + atan(k·e / (v + v_soft)), clamped to ±max_wheel_angle. `gain` is k (1/s),
/// `soft_speed` is v_soft (m/s).
pub fn stanley(
    local: &LocalPath,
    pose: &Pose,
    speed: f64,
    params: &TrackerParams,
    gain: f64,
    soft_speed: f64,
) -> TrackOutput {
    let points = local.points();
    let front = pose.pos + heading_vec(pose.heading) * params.wheelbase;
    let invalid = TrackOutput::invalid(front, 0.0);
    if points.len() < 2 || !front.x.is_finite() || !front.y.is_finite() || !speed.is_finite() {
        return invalid;
    }
    // Nearest sample to the front axle, searching forward from the rear axle's.
    let mut best = (f64::INFINITY, local.index_local().min(points.len() - 2));
    for (i, q) in points.iter().enumerate().skip(local.index_local()) {
        let d = (q - front).norm();
        if d < best.0 {
            best = (d, i);
        } else if d > best.0 + 2.0 * params.wheelbase {
            break;
        }
    }
    let i = best.1.min(points.len() - 2);
    let tangent = points[i + 1] - points[i];
    if tangent.norm() <= 0.0 {
        return invalid;
    }
    let path_heading = tangent.y.atan2(tangent.x);
    let h = heading_vec(pose.heading);
    let psi = crate::geo::wrap_angle(path_heading - pose.heading);
    let e = -cross(&tangent.normalize(), &(points[i] - front));
    // e > 0: the front axle is left of the path, steer right.
    let delta = psi + (-gain * e).atan2(speed.abs() + soft_speed);
    let max = params.max_wheel_angle;
    let wheel_angle = delta.clamp(-max, max);
    TrackOutput {
        wheel_angle,
        curvature: wheel_angle.tan() / params.wheelbase,
        lookahead: (points[i] - pose.pos).norm(),
        target: points[i],
        alpha: cross(&h, &(points[i] - pose.pos)).atan2(h.dot(&(points[i] - pose.pos))),
        path_curvature: 0.0,
        valid: true,
    }
}
