//! One control cycle, glued in the data-flow order: [`estimate`](crate::estimate) →
//! [`guidance`](crate::guidance) → [`plan`](crate::plan) → [`track`](crate::track).
//!
//! The same [`Controller`] runs in the in-process demo, the tests and the daemon. It is built
//! from [`ControlParams`] (resolved once from the configuration by the configuration layer),
//! the job's plan and its definition; it never sees the configuration file. It is
//! allocation-free per cycle and never does I/O: callers feed it inputs and persist the
//! progress snapshots it hands out. The steering law is a [`SteeringLaw`] from the tracker
//! registry; what the law needs around it (prediction, the observer, integral action,
//! lost-motion compensation) the law says, and the controller does no more than that.

use crate::estimate::{Estimator, GnssFix, VehicleEstimate};
use crate::geo::{heading_vec, left_normal, Direction, Pose, Vec2};
use crate::guidance::progress::{JobDefinition, Progress};
use crate::guidance::{Guidance, GuidanceError, JobPlan};
use crate::track::lag_lead::LagLead;
use crate::track::law::SteeringLaw;
use crate::track::lost_motion::LostMotion;
use crate::track::{
    curvature_along, registry, steering_from_travel, travel_pose, CurvatureScale, IntegralAction,
    TrackOutput, CURVATURE_SCALE_MIN_CURVATURE,
};

pub mod isobus;
pub mod node;
pub mod operator;
pub mod params;
pub mod replay;

pub use params::{ApproachParams, ControlParams, CuspParams, IntegralParams};

/// Largest crab angle the drift estimate may turn the steered course by, rad.
const MAX_CRAB: f64 = 0.2;

/// The travel-direction pose turned onto the course over ground: the heading plus the crab
/// angle of the estimated `drift` (world m/s) at speed `speed` (m/s, > 0 in the travel
/// direction). Below `min_speed` the crab is not defined and the pose is returned as is.
pub fn course_pose(pose: &Pose, drift: Vec2, speed: f64, min_speed: f64) -> Pose {
    if speed < min_speed || drift == Vec2::zeros() {
        return *pose;
    }
    let lateral = drift.dot(&left_normal(&heading_vec(pose.heading)));
    let crab = lateral.atan2(speed).clamp(-MAX_CRAB, MAX_CRAB);
    Pose::new(pose.pos.x, pose.pos.y, pose.heading + crab)
}

/// The result of one cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlOutput {
    /// Commanded front-wheel angle, rad (positive left). `None` when there is nothing to
    /// steer by (no fix yet, job finished).
    pub wheel_angle: Option<f64>,
    /// The estimate the command was computed from.
    pub estimate: Option<VehicleEstimate>,
    /// Cross-track error (positive = left of the path), m.
    pub xte: Option<f64>,
    /// Heading error, rad.
    pub heading_error: Option<f64>,
    /// The tracker's detail.
    pub track: Option<TrackOutput>,
    /// Driving direction of the path being followed.
    pub direction: Direction,
    /// The path's curvature at the vehicle, 1/m (positive left), when there is a path.
    pub path_curvature: Option<f64>,
}

#[derive(Debug, thiserror::Error)]
pub enum ControlError {
    #[error(transparent)]
    Guidance(#[from] GuidanceError),
}

/// Estimation, guidance and tracking for one job.
pub struct Controller {
    params: ControlParams,
    estimator: Estimator,
    guidance: Guidance,
    law: Box<dyn SteeringLaw>,
    integral: IntegralAction,
    /// The learnt error of the wheel angle curves need (`track::CurvatureScale`).
    curvature: CurvatureScale,
    /// The same error learnt on the turns (paths other than work lines, driven forward while
    /// engaged) and added there on top of `curvature`: a turn at the job's speed with dynamic
    /// tyres slips more than the work lines' curves do (or the work lines are straight and
    /// teach `curvature` nothing), and ran wide into the next line.
    turn_curvature: CurvatureScale,
    /// Time of the previous tick, s.
    last_tick: Option<f64>,
    /// Approach paths (`guidance.approach_paths`), `None` when off.
    approach: Option<ApproachSettings>,
    /// The steering's lost-motion compensation.
    lost_motion: LostMotion,
    /// The lead on the steering's lag (laws that ask for it; `track::lag_lead`).
    lag_lead: LagLead,
    /// Whether the supervisor engaged the previous command (the compensation learns only
    /// from commands the actuator followed).
    engaged: bool,
}

/// Whether a sampled approach path keeps the vehicle inside the field and off its obstacles.
pub type ClearanceCheck =
    std::sync::Arc<dyn Fn(&crate::plan::maneuver::path::CurvePath) -> bool + Send + Sync>;

/// Approach paths as planned: the parameters and the field check, when the job has a field.
#[derive(Clone)]
struct ApproachSettings {
    params: ApproachParams,
    clear: Option<ClearanceCheck>,
}

impl Controller {
    /// The job `plan` (an AB plan or a segment job such as a field plan) defined by
    /// `definition` (saved with progress), new or the continuation of `resume` when it belongs
    /// to the same job.
    pub fn new(
        params: &ControlParams,
        plan: JobPlan,
        definition: JobDefinition,
        resume: Option<&Progress>,
    ) -> Result<Self, ControlError> {
        let guidance = match resume {
            Some(p) => Guidance::resume(plan, definition, params.guidance.clone(), p)?,
            None => Guidance::new(plan, definition, params.guidance.clone())?,
        };
        let law = registry::law(params.tracker_kind, &params.law, &params.tracker, params.dt);
        let needs = law.needs();
        Ok(Controller {
            estimator: Estimator::new(params.estimator_for(needs)),
            guidance,
            integral: params.integral_for(needs, 0.0),
            curvature: params.curvature_scale_for(needs, 0.0),
            turn_curvature: params.curvature_scale_for(needs, 0.0),
            last_tick: None,
            approach: params.approach.map(|params| ApproachSettings {
                params,
                clear: None,
            }),
            lost_motion: LostMotion::new(params.lost_motion_for(needs), params.lost_motion.initial),
            lag_lead: params.lag_lead_for(needs),
            engaged: false,
            law,
            params: params.clone(),
        })
    }

    /// The parameters it runs with.
    pub fn params(&self) -> &ControlParams {
        &self.params
    }

    /// Check approach paths against the job's field (see [`ClearanceCheck`]).
    pub fn set_approach_clearance(&mut self, clear: ClearanceCheck) {
        if let Some(a) = &mut self.approach {
            a.clear = Some(clear);
        }
    }

    /// On an engage request at time `t`: when the vehicle is too far from the path to engage
    /// (at the job's start, or resumed after a restart or a manual drive), plan an approach
    /// path to where the current line's work stopped (its start if not worked yet; in a turn:
    /// the next work line's start, or where no clear way leads there in a field plan's
    /// transit, the start of the segment it is in) and drive it first. `None` when no approach is needed (or approaches are off);
    /// else the number of parts (1 + cusps) or why none could be planned. Runs the analytic
    /// connection and the field check only (well under a millisecond).
    pub fn plan_approach(
        &mut self,
        t: f64,
    ) -> Option<Result<usize, crate::plan::maneuver::approach::ApproachError>> {
        let a = self.approach.as_ref()?;
        let g = &self.guidance;
        if !g.approach_allowed() {
            return None;
        }
        let est = self.job_estimate(t)?;
        let (xte, heading_error) = g.errors(&est.pose)?;
        if xte.abs() < a.params.max_xte && heading_error.abs() < a.params.max_heading_error {
            return None;
        }
        let always = |_: &crate::plan::maneuver::path::CurvePath| true;
        let clear: &dyn Fn(&crate::plan::maneuver::path::CurvePath) -> bool = match &a.clear {
            Some(c) => c.as_ref(),
            None => &always,
        };
        let plan = |skip: bool| {
            let to = g.approach_target_with(skip)?;
            Some(crate::plan::maneuver::approach::approach_path(
                &est.pose,
                &to,
                &a.params.curve,
                a.params.spacing,
                clear,
            ))
        };
        // In a field plan's turn or transit: to the next work segment, else (no clear way
        // there) back to the start of the segment it is in.
        let mut skip = true;
        let mut result = plan(true)?;
        if result.is_err() && g.approach_can_skip() {
            if let Some(r) = plan(false).filter(Result::is_ok) {
                (result, skip) = (r, false);
            }
        }
        let result = result.map(|(_, parts)| {
            let n = parts.len();
            let segments = crate::plan::job::JobSegment::from_driven_parts(
                parts,
                crate::plan::coverage::SegmentKind::Transit,
            );
            // Accepted: approach_allowed() held above.
            self.guidance.set_approach_with(segments, skip);
            n
        });
        Some(result)
    }

    /// The estimate at `t` in the job's frame: moved right by the operator's nudge, so that
    /// the vehicle tracks every path shifted left by it (issue 16 point 5).
    fn job_estimate(&self, t: f64) -> Option<VehicleEstimate> {
        let mut est = self.estimator.estimate(t)?;
        let nudge = self.guidance.nudge_m();
        if nudge != 0.0 {
            est.pose.pos -= left_normal(&self.guidance.reference_direction()) * nudge;
        }
        Some(est)
    }

    /// `est` moved forward to the point that turns without the cornering slip, along the
    /// course over ground with the observer's drift velocity `drift` (laws with the observer,
    /// forward only).
    fn slip_free_estimate(&self, mut est: VehicleEstimate, drift: Option<Vec2>) -> VehicleEstimate {
        if let Some(drift) = drift {
            let lead = self.estimator.slip_free_lead(est.speed);
            if lead > 0.0 {
                let min = self.estimator.params().observer.min_speed;
                let course = course_pose(&est.pose, drift, est.speed.abs(), min).heading;
                est.pose.pos += heading_vec(course) * lead;
            }
        }
        est
    }

    /// The vehicle's estimated position at `t` (local ENU m, not shifted by the nudge).
    pub fn position(&self, t: f64) -> Option<Vec2> {
        self.estimator.estimate(t).map(|e| e.pose.pos)
    }

    pub fn on_fix(&mut self, fix: &GnssFix) {
        self.estimator.on_fix(fix);
    }

    /// The quality of the next fixes: the disturbance observer learns only from RTK-fixed
    /// ones and coasts through RTK-float ones.
    pub fn set_fix_quality(&mut self, fixed: bool, float: bool) {
        self.estimator.set_learning(fixed);
        self.estimator.set_coasting(float);
    }

    pub fn on_wheel_angle(&mut self, t: f64, angle: f64) {
        self.estimator.on_wheel_angle(t, angle);
    }

    /// Whether the safety supervisor engaged the latest command (the actuator steers by the
    /// next ones).
    /// An approach is kept only while engaged: one planned for an engage the supervisor
    /// refused, or given back before it was driven, is dropped (the job back on its path;
    /// the next engage plans from where the vehicle is then).
    pub fn set_engaged(&mut self, engaged: bool) {
        self.engaged = engaged;
        if !engaged {
            self.guidance.cancel_approach();
        }
    }

    /// The learnt lost motion of the steering (backlash + actuator deadband), rad.
    pub fn lost_motion(&self) -> f64 {
        self.lost_motion.estimate
    }

    /// One control period at time `t` (s, controller clock).
    pub fn tick(&mut self, t: f64) -> Result<ControlOutput, ControlError> {
        let mut out = ControlOutput {
            wheel_angle: None,
            estimate: None,
            xte: None,
            heading_error: None,
            track: None,
            direction: Direction::Forward,
            path_curvature: None,
        };
        let Some(est) = self.job_estimate(t) else {
            return Ok(out);
        };
        out.estimate = Some(est);
        // Guidance and the law follow the point that turns without the tyres' cornering slip
        // (`Estimator::slip_free_lead`; the rear axle where the law has no observer, or when
        // reversing), moved along the course over ground: on a straight with a crab it keeps
        // the rear axle's offset. Its XTE is the one reported. (The drift velocity, for the
        // laws with the observer, is worked out once per period: the course below uses it too.)
        let needs = self.law.needs();
        let drift = needs
            .observer
            .then(|| self.estimator.drift_velocity(est.pose.heading));
        let est = self.slip_free_estimate(est, drift);
        self.guidance.update(&est.pose)?;
        if self.guidance.is_finished() {
            return Ok(out);
        }
        if let Some((xte, he)) = self.guidance.errors(&est.pose) {
            out.xte = Some(xte);
            out.heading_error = Some(he);
            // Inside the engage gate the line is being worked (engaged or steered by the
            // driver): a resume out of the gate rejoins it where this stopped.
            if let Some(a) = &self.approach {
                if xte.abs() < a.params.max_xte && he.abs() < a.params.max_heading_error {
                    self.guidance.mark_worked();
                }
            }
        }
        let direction = self.guidance.direction();
        out.direction = direction;
        // Reverse segments are tracked about the rear axle in the driving direction.
        let mut pose = travel_pose(&est.pose, direction);
        if let Some(drift) = drift {
            // Steer the course over ground, not the heading, onto the path: the estimated
            // drift then leaves no standing error.
            let min = self.estimator.params().observer.min_speed;
            pose = course_pose(&pose, drift, est.speed.abs(), min);
        }
        let local = self.guidance.local_path();
        let path_curvature = curvature_along(local.points(), local.index_local(), 1.0, 1.0);
        out.path_curvature = Some(path_curvature);
        if needs.observer {
            // The drift is kept per direction of straight driving (estimate::drift_memory).
            self.estimator.set_work(
                direction == Direction::Forward && self.guidance.tag() == crate::geo::Tag::Work,
            );
            self.estimator
                .set_straight(path_curvature.abs() < CURVATURE_SCALE_MIN_CURVATURE);
        }
        // The wheels as they are, in the driving direction, less the sensor's estimated offset.
        let sensor_offset = if needs.observer {
            self.estimator.wheel_offset_for_steering()
        } else {
            0.0
        };
        let wheel = self.estimator.latest_wheel_angle().map(|a| {
            let a = a - sensor_offset;
            match direction {
                Direction::Forward => a,
                Direction::Reverse => -a,
            }
        });
        // The vehicle's lag as learnt so far, for the law's curvature feed-forward.
        let mut tracker = self.params.tracker.clone();
        tracker.steering.vehicle_lag = self.estimator.vehicle_lag();
        let law = self
            .law
            .steer(local, &pose, est.speed.abs(), wheel, &tracker);
        let mut tr = steering_from_travel(law, direction);
        // Integral action: learnt on work paths driven forward, applied on every path (the
        // disturbances it cancels do not stop at a line's end).
        let dt = self.last_tick.map_or(0.0, |last| t - last);
        self.last_tick = Some(t);
        let learning =
            direction == Direction::Forward && self.guidance.tag() == crate::geo::Tag::Work;
        let mut offset = self
            .integral
            .update(out.xte.unwrap_or(f64::NAN), est.speed, dt, learning);
        // Curves: the wheel angle the path's curvature needs beyond the model's, learnt (only
        // laws that report the path's curvature, in the vehicle's frame after the reversal).
        offset += self.curvature.update(
            (
                out.xte.unwrap_or(f64::NAN),
                out.heading_error.unwrap_or(f64::NAN),
            ),
            tr.path_curvature,
            est.speed,
            dt,
            learning,
        );
        {
            // Turns: their own share beyond the work lines' scale, learnt and added only there.
            let turning =
                direction == Direction::Forward && self.guidance.tag() != crate::geo::Tag::Work;
            let add = self.turn_curvature.update(
                (
                    out.xte.unwrap_or(f64::NAN),
                    out.heading_error.unwrap_or(f64::NAN),
                ),
                tr.path_curvature,
                est.speed,
                dt,
                turning && self.engaged,
            );
            if turning {
                offset += add;
            }
        }
        // The steering controller servos the sensed angle to the command, so a sensor reading
        // `sensor_offset` more than the wheels leaves them short by as much: command the
        // estimated offset on top (0 without the observer).
        offset += sensor_offset;
        if offset != 0.0 && tr.valid {
            let max = self.params.tracker.max_wheel_angle;
            tr.wheel_angle = (tr.wheel_angle + offset).clamp(-max, max);
        }
        if tr.valid {
            let max = self.params.tracker.max_wheel_angle;
            // Turn the wheels when the law asks despite the steering's lag (the filter passes
            // the demand through where the law does not ask or the steering is quick).
            self.lag_lead.set_vehicle_lag(self.estimator.vehicle_lag());
            tr.wheel_angle = self.lag_lead.command(tr.wheel_angle, dt).clamp(-max, max);
            // Put the wheels where the command says despite the steering's play; learn the
            // play on work lines from commands the actuator followed.
            let measured = self.estimator.latest_wheel_angle().unwrap_or(f64::NAN);
            let learn = learning
                && self.engaged
                && est.speed.abs() >= self.estimator.params().observer.min_speed;
            tr.wheel_angle = self
                .lost_motion
                .command(tr.wheel_angle, measured, dt, learn)
                .clamp(-max, max);
        } else {
            self.lag_lead.reset();
        }
        if tr.wheel_angle.is_finite() {
            out.wheel_angle = Some(tr.wheel_angle);
        }
        out.track = Some(tr);
        Ok(out)
    }

    /// Replace the tracker and estimator tuning (law, look-ahead, gains, latency) at once,
    /// keeping the learnt offsets. The job, the guidance, approach and cusp parameters stay as
    /// they were.
    pub fn set_tuning(&mut self, params: &ControlParams) {
        if params.tracker_kind != self.params.tracker_kind
            || params.law != self.params.law
            || params.tracker != self.params.tracker
            || params.dt != self.params.dt
        {
            self.law = registry::law(params.tracker_kind, &params.law, &params.tracker, params.dt);
        }
        let needs = self.law.needs();
        self.integral = params.integral_for(needs, self.integral.offset);
        self.curvature = params.curvature_scale_for(needs, self.curvature.scale);
        self.turn_curvature = params.curvature_scale_for(needs, self.turn_curvature.scale);
        self.lost_motion.set_params(params.lost_motion_for(needs));
        self.lag_lead = params.lag_lead_for(needs);
        self.estimator.set_params(params.estimator_for(needs));
        self.params = ControlParams {
            approach: self.params.approach,
            guidance: self.params.guidance.clone(),
            cusp: self.params.cusp,
            ..params.clone()
        };
    }

    pub fn guidance(&self) -> &Guidance {
        &self.guidance
    }
    pub fn guidance_mut(&mut self) -> &mut Guidance {
        &mut self.guidance
    }

    /// Where a vehicle would begin the current path: its first point, on the path's tangent
    /// there, and the path's curvature over its first 2 m (1/m, positive left; see
    /// [`crate::track::curvature_along`]). The tangent is the chord to the point 2 m along less
    /// half the angle the curvature turns over it (a chord of a 1 m-sampled R 15 m arc is 2°
    /// off the tangent). Used to place the simulated vehicle on a job's or a resumed job's
    /// path.
    pub fn path_start(&self) -> Option<(Pose, f64)> {
        let points: Vec<crate::geo::Vec2> =
            self.guidance.global_path().iter().map(|p| p.pos).collect();
        if points.len() < 2 {
            return None;
        }
        let curvature = crate::track::curvature_along(&points, 0, 1.0, 1.0);
        let chord = crate::track::point_along(&points, 0, 2.0) - points[0];
        let heading = chord.y.atan2(chord.x) - 0.5 * curvature * chord.norm();
        Some((Pose::new(points[0].x, points[0].y, heading), curvature))
    }
}
