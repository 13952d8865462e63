//! One control cycle, glued in the data-flow order: [`estimate`](crate::estimate) →
//! [`guidance`](crate::guidance) → [`plan`](crate::plan) → [`track`](crate::track).
//!
//! The same [`Controller`] runs in the in-process demo, the tests and the daemon. It is
//! allocation-free per cycle and never does I/O: callers feed it inputs and persist the
//! progress snapshots it hands out.

use crate::config::{Config, JobKind, LineOrder, TrackerChoice};
use crate::estimate::{
    AntennaOffset, Estimator, EstimatorParams, GnssFix, ObserverParams, VehicleEstimate,
};
use crate::geo::{heading_vec, left_normal, v2, Direction, Pose, Vec2};
use crate::guidance::progress::{JobDefinition, Progress};
use crate::guidance::{Guidance, GuidanceError, GuidanceParams, JobPlan};
use crate::plan::abline::{AbParams, AbPlan};
use crate::plan::turns::TurnParams;
use crate::track::local_path::LocalPathParams;
use crate::track::lost_motion::{LostMotion, LostMotionParams};
use crate::track::{
    pure_pursuit, stanley, steering_from_travel, travel_pose, IntegralAction, TrackOutput,
    TrackerParams,
};

pub mod node;
pub mod replay;

/// The AB planner's parameters from the configuration.
pub fn ab_params(cfg: &Config) -> AbParams {
    AbParams {
        point_a: v2(cfg.job.point_a_m[0], cfg.job.point_a_m[1]),
        point_b: v2(cfg.job.point_b_m[0], cfg.job.point_b_m[1]),
        line_width: cfg.job.line_width_m,
        line_num: cfg.job.line_num,
        r_min: cfg.turn_radius(),
        side: cfg.job.side,
        block_extra: cfg.guidance.a.max(1) as u32,
        point_spacing: cfg.guidance.point_spacing_m,
        turn: TurnParams {
            r_min: cfg.turn_radius(),
            arc_step: cfg.guidance.turn_arc_step_deg.to_radians(),
            merge_distance: cfg.guidance.turn_merge_distance_m,
            point_spacing: cfg.guidance.point_spacing_m,
            max_points: cfg.guidance.turn_max_points,
            max_curvature_rate: cfg.vehicle.max_curvature_rate_per_m2,
        },
    }
}

/// The arcs job (`job.kind = "arcs"`) from the configuration.
pub fn arcs_plan(cfg: &Config) -> Result<JobPlan, crate::plan::types::PlanError> {
    let ab = ab_params(cfg);
    let segments = crate::plan::arcs::arcs_segments(&crate::plan::arcs::ArcsParams {
        centre: ab.point_a,
        r_inner: cfg.job.arc_radius_m,
        width: cfg.job.line_width_m,
        lines: cfg.job.line_num,
        sweep: cfg.job.arc_sweep_deg.to_radians(),
        start_angle: -std::f64::consts::FRAC_PI_2,
        point_spacing: cfg.guidance.point_spacing_m,
        turn: ab.turn,
    })?;
    let job = crate::plan::job::SegmentJob::from_plan_segments(segments)?;
    Ok(JobPlan::Segments(job))
}

/// The AB job configured by `cfg`: the seed-000 block plan, or (`job.line_order =
/// "sequential"`) every line and turn in turn as a segment job.
pub fn ab_job_plan(cfg: &Config) -> Result<JobPlan, ControlError> {
    let params = ab_params(cfg);
    Ok(match cfg.job.line_order {
        LineOrder::Blocks => AbPlan::new(params)?.into(),
        LineOrder::Sequential => {
            JobPlan::Segments(crate::plan::job::SegmentJob::from_plan_segments(
                crate::plan::abline::sequential_segments(&params)?,
            )?)
        }
    })
}

/// The state machine's parameters from the configuration.
pub fn guidance_params(cfg: &Config) -> GuidanceParams {
    GuidanceParams {
        end_distance: cfg.guidance.end_distance_m,
        local: LocalPathParams {
            nodes_before: cfg.track.local_nodes_before,
            nodes_after: cfg.track.local_nodes_after,
            tangent_length: cfg.track.tangent_length_m,
            spacing: cfg.track.local_spacing_m,
        },
        search_window: 8,
    }
}

/// The tracker's parameters from the configuration.
pub fn tracker_params(cfg: &Config) -> TrackerParams {
    TrackerParams {
        wheelbase: cfg.vehicle.wheelbase_m,
        ld_min: cfg.track.ld_min_m,
        ld_gain: cfg.track.ld_gain_s,
        max_wheel_angle: cfg.max_wheel_angle(),
    }
}

/// The estimator's parameters: the predictive tracker (and Stanley) compensate latency,
/// dead-reckon and correct the antenna's lean from the IMU roll; plain pure pursuit uses the
/// latest fix as it is.
pub fn estimator_params(cfg: &Config) -> EstimatorParams {
    let predictive = cfg.track.kind != TrackerChoice::PurePursuit;
    EstimatorParams {
        wheelbase: cfg.vehicle.wheelbase_m,
        antenna: AntennaOffset {
            forward: cfg.vehicle.antenna_forward_m,
            left: cfg.vehicle.antenna_left_m,
            up: cfg.vehicle.antenna_up_m,
        },
        gnss_latency: if predictive {
            cfg.track.gnss_latency_s
        } else {
            0.0
        },
        predict: predictive,
        lead_time: if predictive {
            cfg.track.lead_time_s
        } else {
            0.0
        },
        roll_compensation: predictive,
        observer: observer_params(cfg),
    }
}

/// The disturbance observer from `[track]`: on for the default (predictive) tracker only,
/// so that pure pursuit and Stanley stay the references they are.
pub fn observer_params(cfg: &Config) -> ObserverParams {
    let t = &cfg.track;
    if t.kind != TrackerChoice::Predictive {
        return ObserverParams::default();
    }
    ObserverParams {
        bias_tau: t.observer_bias_tau_s,
        drift_tau: t.observer_drift_tau_s,
        min_speed: t.observer_min_speed_mps,
        bias_limit: t.observer_bias_limit_deg.to_radians(),
        drift_limit: t.observer_drift_limit_mps,
        slip_tau: t.observer_slip_tau_s,
        slip_limit: t.observer_slip_limit_mps_per_deg.to_degrees(),
        coast_max: t.observer_coast_max_s,
        robust: t.observer_robust,
        position_process: t.position_process_m,
    }
}

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
}

#[derive(Debug, thiserror::Error)]
pub enum ControlError {
    #[error(transparent)]
    Guidance(#[from] GuidanceError),
    #[error("cannot plan the job: {0}")]
    Plan(#[from] crate::plan::types::PlanError),
    #[error("job.kind = \"field\" or \"maneuver\" needs its plan: load it first (the daemon and `agsteer demo` read job.field_path or job.maneuver_map_path)")]
    NoPlan,
}

/// The steering law and its gains from `[track]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LawParams {
    pub kind: TrackerChoice,
    pub stanley_gain: f64,
    pub stanley_soft_speed: f64,
}

/// The steering law from the configuration.
pub fn law_params(cfg: &Config) -> LawParams {
    LawParams {
        kind: cfg.track.kind,
        stanley_gain: cfg.track.stanley_gain_per_s,
        stanley_soft_speed: cfg.track.stanley_soft_speed_mps,
    }
}

/// The integral action from the configuration (off for the plain pure-pursuit reference),
/// keeping an offset already learnt.
fn integral_action(cfg: &Config, learnt: f64) -> IntegralAction {
    let t = &cfg.track;
    let gain = if t.kind == TrackerChoice::PurePursuit {
        0.0
    } else {
        t.integral_gain_rad_per_m_s
    };
    let limit = t.integral_limit_deg.to_radians();
    IntegralAction {
        gain,
        limit,
        capture: t.integral_capture_m,
        min_speed: t.integral_min_speed_mps,
        offset: learnt.clamp(-limit, limit),
    }
}

/// The lost-motion compensation from `[track]` (off for the pure-pursuit and Stanley
/// references).
pub fn lost_motion_params(cfg: &Config) -> LostMotionParams {
    let t = &cfg.track;
    LostMotionParams {
        tau: if t.kind == TrackerChoice::Predictive {
            t.lost_motion_tau_s
        } else {
            0.0
        },
        threshold: t.lost_motion_threshold_deg.to_radians(),
        limit: t.lost_motion_limit_deg.to_radians(),
        settle: t.lost_motion_settle_s,
    }
}

/// Estimation, guidance and tracking for one job.
pub struct Controller {
    estimator: Estimator,
    guidance: Guidance,
    tracker: TrackerParams,
    law: LawParams,
    integral: IntegralAction,
    /// Time of the previous tick, s.
    last_tick: Option<f64>,
    /// Approach paths (`guidance.approach_paths`), `None` when off.
    approach: Option<ApproachSettings>,
    /// The steering's lost-motion compensation.
    lost_motion: LostMotion,
    /// Whether the supervisor engaged the previous command (the compensation learns only
    /// from commands the actuator followed).
    engaged: bool,
}

/// Whether a sampled approach path keeps the vehicle inside the field and off its obstacles.
pub type ClearanceCheck =
    std::sync::Arc<dyn Fn(&crate::plan::maneuver::path::CurvePath) -> bool + Send + Sync>;

/// How approach paths are planned (issue 6 part 5b).
#[derive(Clone)]
pub struct ApproachSettings {
    pub curve: crate::plan::maneuver::path::CurveParams,
    /// Spacing of the approach path's points, m.
    pub spacing: f64,
    /// An approach is planned when |XTE| or the heading error reach these (the engage
    /// limits), m and rad.
    pub max_xte: f64,
    pub max_heading_error: f64,
    /// The field check, when the job has a field.
    pub clear: Option<ClearanceCheck>,
}

/// Approach settings from the configuration (`None` when `guidance.approach_paths` is off or
/// `vehicle.max_curvature_rate_per_m2` is 0).
pub fn approach_settings(cfg: &Config) -> Option<ApproachSettings> {
    (cfg.guidance.approach_paths && cfg.vehicle.max_curvature_rate_per_m2 > 0.0).then(|| {
        ApproachSettings {
            curve: crate::plan::maneuver::path::CurveParams {
                kappa_max: 1.0 / cfg.vehicle.r_min_m,
                sigma_max: cfg.vehicle.max_curvature_rate_per_m2,
            },
            spacing: cfg.guidance.point_spacing_m.min(0.5),
            max_xte: cfg.safety.max_engage_xte_m,
            max_heading_error: cfg.safety.max_engage_heading_error_deg.to_radians(),
            clear: None,
        }
    })
}

impl Controller {
    /// A new job, or the continuation of `resume`.
    pub fn from_config(cfg: &Config, resume: Option<&Progress>) -> Result<Self, ControlError> {
        match cfg.job.kind {
            JobKind::Field | JobKind::Maneuver => Err(ControlError::NoPlan),
            JobKind::Arcs => Controller::with_job(cfg, arcs_plan(cfg)?, resume),
            JobKind::Ab => Controller::with_job(cfg, ab_job_plan(cfg)?, resume),
        }
    }

    /// A job given by its plan (an AB plan or a segment job such as a field plan), or the
    /// continuation of `resume` when it belongs to the same plan.
    pub fn with_job(
        cfg: &Config,
        plan: JobPlan,
        resume: Option<&Progress>,
    ) -> Result<Self, ControlError> {
        let job = JobDefinition::for_job(cfg, &plan);
        let guidance = match resume {
            Some(p) => Guidance::resume(plan, job, guidance_params(cfg), p)?,
            None => Guidance::new(plan, job, guidance_params(cfg))?,
        };
        Ok(Controller {
            estimator: Estimator::new(estimator_params(cfg)),
            guidance,
            tracker: tracker_params(cfg),
            law: law_params(cfg),
            integral: integral_action(cfg, 0.0),
            last_tick: None,
            approach: approach_settings(cfg),
            lost_motion: LostMotion::new(lost_motion_params(cfg), 0.0),
            engaged: false,
        })
    }

    /// Check approach paths against the job's field (see [`ClearanceCheck`]).
    pub fn set_approach_clearance(&mut self, clear: ClearanceCheck) {
        if let Some(a) = &mut self.approach {
            a.clear = Some(clear);
        }
    }

    /// On an engage request at time `t`: when the job has not finished a line yet and the
    /// vehicle is too far from the first line to engage, plan an approach path to the line
    /// start and drive it first. `None` when no approach is needed (or approaches are off);
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
        let est = self.estimator.estimate(t)?;
        let (xte, heading_error) = g.errors(&est.pose)?;
        if xte.abs() < a.max_xte && heading_error.abs() < a.max_heading_error {
            return None;
        }
        let to = self.path_start_pose()?;
        let always = |_: &crate::plan::maneuver::path::CurvePath| true;
        let clear: &dyn Fn(&crate::plan::maneuver::path::CurvePath) -> bool = match &a.clear {
            Some(c) => c.as_ref(),
            None => &always,
        };
        let result = crate::plan::maneuver::approach::approach_path(
            &est.pose, &to, &a.curve, a.spacing, clear,
        )
        .map(|(_, parts)| {
            let n = parts.len();
            let segments = crate::plan::job::JobSegment::from_driven_parts(
                parts,
                crate::plan::coverage::SegmentKind::Transit,
            );
            // Accepted: approach_allowed() held above.
            self.guidance.set_approach(segments);
            n
        });
        Some(result)
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
    pub fn set_engaged(&mut self, engaged: bool) {
        self.engaged = engaged;
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
        };
        let Some(est) = self.estimator.estimate(t) else {
            return Ok(out);
        };
        out.estimate = Some(est);
        self.guidance.update(&est.pose)?;
        if self.guidance.is_finished() {
            return Ok(out);
        }
        if let Some((xte, he)) = self.guidance.errors(&est.pose) {
            out.xte = Some(xte);
            out.heading_error = Some(he);
        }
        let direction = self.guidance.direction();
        out.direction = direction;
        // Reverse segments are tracked about the rear axle in the driving direction.
        let mut pose = travel_pose(&est.pose, direction);
        if self.law.kind == TrackerChoice::Predictive {
            // Steer the course over ground, not the heading, onto the path: the estimated
            // drift then leaves no standing error.
            let min = self.estimator.params().observer.min_speed;
            let drift = self.estimator.drift_velocity(est.pose.heading);
            pose = course_pose(&pose, drift, est.speed.abs(), min);
        }
        let local = self.guidance.local_path();
        let law = match self.law.kind {
            TrackerChoice::Stanley => stanley(
                local,
                &pose,
                est.speed.abs(),
                &self.tracker,
                self.law.stanley_gain,
                self.law.stanley_soft_speed,
            ),
            TrackerChoice::Predictive | TrackerChoice::PurePursuit => {
                pure_pursuit(local, &pose, est.speed.abs(), &self.tracker)
            }
        };
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
        if self.law.kind == TrackerChoice::Predictive {
            // The steering controller servos the sensed angle to the command, so a sensor
            // reading `wheel_offset` more than the wheels leaves them short by as much:
            // command the estimated offset on top.
            offset += self.estimator.wheel_offset();
        }
        if offset != 0.0 && tr.valid {
            let max = self.tracker.max_wheel_angle;
            tr.wheel_angle = (tr.wheel_angle + offset).clamp(-max, max);
        }
        if tr.valid {
            // Put the wheels where the command says despite the steering's play; learn the
            // play on work lines from commands the actuator followed.
            let measured = self.estimator.latest_wheel_angle().unwrap_or(f64::NAN);
            let learn = learning
                && self.engaged
                && est.speed.abs() >= self.estimator.params().observer.min_speed;
            let max = self.tracker.max_wheel_angle;
            tr.wheel_angle = self
                .lost_motion
                .command(tr.wheel_angle, measured, dt, learn)
                .clamp(-max, max);
        }
        if tr.wheel_angle.is_finite() {
            out.wheel_angle = Some(tr.wheel_angle);
        }
        out.track = Some(tr);
        Ok(out)
    }

    /// Replace the tracker and estimator tuning (look-ahead, gains, latency) at once.
    pub fn set_tuning(&mut self, cfg: &Config) {
        self.tracker = tracker_params(cfg);
        self.law = law_params(cfg);
        self.integral = integral_action(cfg, self.integral.offset);
        self.lost_motion.set_params(lost_motion_params(cfg));
        self.estimator.set_params(estimator_params(cfg));
    }

    pub fn guidance(&self) -> &Guidance {
        &self.guidance
    }
    pub fn guidance_mut(&mut self) -> &mut Guidance {
        &mut self.guidance
    }

    /// Where a vehicle would begin the current path: its first point, on its first segment's
    /// heading. Used to place the simulated vehicle on a resumed job.
    pub fn path_start_pose(&self) -> Option<Pose> {
        let p = self.guidance.global_path();
        if p.len() < 2 {
            return None;
        }
        let d = p[1].pos - p[0].pos;
        Some(Pose::new(p[0].pos.x, p[0].pos.y, d.y.atan2(d.x)))
    }
}
