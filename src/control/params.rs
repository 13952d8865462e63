//! The controller's parameters, SI, as the configuration layer resolves them once
//! ([`crate::config::Config::resolve`]).
//!
//! [`ControlParams`] holds what the file says; which parts a steering law uses (prediction, the
//! disturbance observer, integral action, lost-motion compensation) the law itself states
//! ([`LawNeeds`]), and the `for_law` methods here apply that, in this one place.

use crate::estimate::{EstimatorParams, ObserverParams};
use crate::guidance::GuidanceParams;
use crate::plan::maneuver::path::CurveParams;
use crate::track::lag_lead::LagLead;
use crate::track::law::{LawNeeds, LawParams};
use crate::track::lost_motion::LostMotionParams;
use crate::track::registry::TrackerKind;
use crate::track::CurvatureScale;
use crate::track::{IntegralAction, TrackerParams};
use serde::{Deserialize, Serialize};

/// Everything one [`Controller`](super::Controller) (and its node's cusp handling) needs.
#[derive(Debug, Clone, PartialEq)]
pub struct ControlParams {
    /// Control period, s.
    pub dt: f64,
    /// Driving speed of the job, m/s (the simulator's and the demo's; turns are planned for it).
    pub speed: f64,
    /// The estimator with prediction and the observer as configured; [`Self::estimator_for`]
    /// gives what a law runs with.
    pub estimator: EstimatorParams,
    /// Vehicle geometry and look-ahead of every law.
    pub tracker: TrackerParams,
    /// Which law steers, and the laws' own gains.
    pub tracker_kind: TrackerKind,
    pub law: LawParams,
    /// Integral action as configured (its learnt offset starts at 0).
    pub integral: IntegralParams,
    pub lost_motion: LostMotionParams,
    /// Approach paths to the line start (`None` when off).
    pub approach: Option<ApproachParams>,
    pub guidance: GuidanceParams,
    pub cusp: CuspParams,
    /// One step of the operator's nudge, m.
    pub nudge_step: f64,
}

/// Integral action on the cross-track error (see [`IntegralAction`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntegralParams {
    /// Gain, rad of wheel angle per (m · s); 0 = off.
    pub gain: f64,
    /// Largest offset, rad.
    pub limit: f64,
    /// Learns only while |XTE| is below this, m.
    pub capture: f64,
    /// Learns only above this speed, m/s.
    pub min_speed: f64,
}

/// How approach paths are planned (issue 6 part 5b).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ApproachParams {
    pub curve: CurveParams,
    /// Spacing of the approach path's points, m.
    pub spacing: f64,
    /// An approach is planned when |XTE| or the heading error reach these (the engage
    /// limits), m and rad.
    pub max_xte: f64,
    pub max_heading_error: f64,
}

/// How a change of driving direction is handled (docs/METHODS.md, Manoeuvres at work: the node asks
/// for it on the bus before each cusp, waits until the vehicle has stopped and turned, then steers
/// on).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CuspParams {
    /// Stop when within the stopping distance at this deceleration, m/s².
    pub decel: f64,
    /// Below this speed the vehicle counts as stopped, m/s.
    pub stopped_speed: f64,
    /// A vehicle stopped within this distance of a cusp moves on to the next segment, m.
    pub capture: f64,
}

impl ControlParams {
    /// The estimator a law with `needs` runs with: without prediction, the latest fix as it
    /// is (no latency compensation, dead reckoning or roll correction); without the observer,
    /// no disturbance estimates.
    pub fn estimator_for(&self, needs: LawNeeds) -> EstimatorParams {
        let mut e = self.estimator.clone();
        if !needs.prediction {
            e.gnss_latency = 0.0;
            e.predict = false;
            e.lead_time = 0.0;
            e.roll_compensation = false;
        }
        if !needs.observer {
            e.observer = ObserverParams::default();
        }
        e
    }

    /// Integral action for a law with `needs`, keeping an offset already `learnt` (clamped to
    /// the limit).
    pub fn integral_for(&self, needs: LawNeeds, learnt: f64) -> IntegralAction {
        let i = &self.integral;
        IntegralAction {
            gain: if needs.integral { i.gain } else { 0.0 },
            limit: i.limit,
            capture: i.capture,
            min_speed: i.min_speed,
            offset: learnt.clamp(-i.limit, i.limit),
        }
    }

    /// A curvature scale for a law with `needs` (learning nothing when it has no integral
    /// action), keeping a scale already `learnt` (clamped to the limit).
    pub fn curvature_scale_for(&self, needs: LawNeeds, learnt: f64) -> CurvatureScale {
        CurvatureScale::new(
            self.law.curvature.for_needs(needs),
            self.tracker.wheelbase,
            learnt,
        )
    }

    /// The lead on the steering's calibrated lag (and the vehicle's learnt one) for a law with
    /// `needs` (off when it does not use it).
    pub fn lag_lead_for(&self, needs: LawNeeds) -> LagLead {
        if needs.lag_lead {
            LagLead::new(self.tracker.steering.lag)
        } else {
            LagLead::off()
        }
    }

    /// The lost-motion compensation for a law with `needs` (off when it does not use it).
    pub fn lost_motion_for(&self, needs: LawNeeds) -> LostMotionParams {
        LostMotionParams {
            tau: if needs.lost_motion {
                self.lost_motion.tau
            } else {
                0.0
            },
            ..self.lost_motion
        }
    }
}

/// What the steering output is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum OutputKind {
    /// The proprietary steering-angle frame.
    #[default]
    Angle,
    /// ISO 11783-7 Guidance System Command (curvature).
    Curvature,
    /// Both.
    Both,
}

/// The node on the bus.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BusParams {
    /// agsteer's J1939 source address.
    pub source_address: u8,
    /// Which steering frames are sent.
    pub output: OutputKind,
    /// Guidance status frame period, s.
    pub status_period: f64,
    /// GNSS comes from a byte stream (`gnss.source`): GNSS inputs from the bus are ignored.
    pub gnss_from_stream: bool,
    /// The address claim and the steering ECU (ISO 11783).
    pub iso: super::isobus::IsoParams,
    /// With the steer-ready loop: Guidance Machine Info older than this is stale, s.
    pub machine_info_timeout: f64,
    /// Which source each GNSS input is taken from (`[sources]`).
    pub sources: crate::input::source::SourceParams,
    /// The wheel-angle sensor reads `was_gain` × the true angle + `was_offset` (rad): angles
    /// received are corrected, commands sent in the sensor's terms.
    pub was_gain: f64,
    pub was_offset: f64,
}
