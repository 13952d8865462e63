//! The steering-law interface every tracker implements.
//!
//! A law turns the local path, the pose in the driving direction (see
//! [`travel_pose`](super::travel_pose)) and the speed into a wheel angle. What else the
//! controller does around it (predict the pose, steer the course over ground, add the learnt
//! offsets, compensate lost motion) the law states in [`LawNeeds`]; the controller asks the
//! law and never checks which law it runs.
//!
//! Contract: `steer` is called every control period: it must not allocate, log or block.

use super::local_path::LocalPath;
use super::{TrackOutput, TrackerParams};
use crate::geo::Pose;

/// What a law needs from the rest of the controller.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LawNeeds {
    /// A latency-compensated, dead-reckoned pose, the antenna's lean corrected from the IMU
    /// roll; `false`: the latest fix as it is.
    pub prediction: bool,
    /// The disturbance observer: steer the course over ground (the drift's crab angle) and
    /// command the estimated wheel-angle offset on top.
    pub observer: bool,
    /// Integral action on the cross-track error.
    pub integral: bool,
    /// The steering's lost-motion compensation.
    pub lost_motion: bool,
    /// The steering's lag beyond [`super::lag_lead::RESIDUAL_LAG`] cancelled by a lead on the
    /// command ([`super::lag_lead`]); the law then schedules on the residual lag.
    pub lag_lead: bool,
}

/// The laws' own gains (`[track]`), SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LawParams {
    /// The default law's longest look-ahead from the growth with speed, m
    /// (`track.predictive_ld_max_m`).
    pub predictive_ld_max: f64,
    /// The default law feeds the path's curvature forward
    /// ([`super::pure_pursuit::FeedForward`]; `track.curvature_feed_forward`).
    pub feed_forward: bool,
    /// Stanley cross-track gain k, 1/s.
    pub stanley_gain: f64,
    /// Stanley softening speed, m/s.
    pub stanley_soft_speed: f64,
    /// The LQR's cost.
    pub lqr: super::lqr::LqrWeights,
    /// The curvature scale's learning (laws that report the path's curvature).
    pub curvature: super::CurvatureScaleParams,
}

/// A steering law.
pub trait SteeringLaw: Send + Sync + std::fmt::Debug {
    /// What the controller must feed and add.
    fn needs(&self) -> LawNeeds;

    /// The command for one period: `pose` in the driving direction, `speed` ≥ 0 m/s,
    /// `wheel_angle` the measured front-wheel angle in the driving direction less the
    /// observer's sensor offset (rad; `None` before the first reading).
    fn steer(
        &self,
        local: &LocalPath,
        pose: &Pose,
        speed: f64,
        wheel_angle: Option<f64>,
        params: &TrackerParams,
    ) -> TrackOutput;
}
