//! The configuration resolved once: [`Config::resolve`] turns the file into the typed SI
//! parameter sets of its consumers ([`Resolved`]): what to plan, the controller, the safety
//! supervisor, the node on the bus, the simulator, the daemon. Edge units (degrees, km/h) are
//! converted here and in [`planners`](super::planners), once; nothing below the job layer sees
//! [`Config`].
//!
//! The parameter structs are the consumers' own (`control::ControlParams`,
//! `safety::SafetyParams`, `sim::SimParams`, the planners' params); the aggregates whose
//! consumers sit above the configuration layer ([`Planning`], [`SimSetup`], [`DaemonParams`])
//! are defined here.

use super::{Config, ConfigError, CurveChoice, JobKind, LineOrder};
use crate::control::params::{
    ApproachParams, BusParams, ControlParams, CuspParams, IntegralParams,
};
use crate::estimate::{AntennaOffset, EstimatorParams, ObserverParams};
use crate::field::LoadOptions;
use crate::geo::wgs84::LatLon;
use crate::guidance::progress::JobDefinition;
use crate::guidance::GuidanceParams;
use crate::plan::abline::AbParams;
use crate::plan::arcs::ArcsParams;
use crate::plan::coverage::CoverageParams;
use crate::plan::maneuver::path::CurveParams;
use crate::plan::maneuver::search::ManeuverParams;
use crate::safety::SafetyParams;
use crate::sim::can_node::SpeedProfile;
use crate::sim::SimParams;
use crate::track::law::LawParams;
use crate::track::local_path::LocalPathParams;
use crate::track::lost_motion::LostMotionParams;
use crate::track::{SteeringResponse, TrackerParams};
use std::path::PathBuf;

/// The whole configuration as its consumers take it, SI.
#[derive(Debug, Clone)]
pub struct Resolved {
    /// What job to plan, with every planner's parameters.
    pub planning: Planning,
    pub control: ControlParams,
    pub safety: SafetyParams,
    pub bus: BusParams,
    pub sim: SimSetup,
    pub daemon: DaemonParams,
    /// The steering calibration procedure (`[calibration]`, `[vehicle]`).
    pub calibration: crate::calibrate::CalibrationParams,
}

/// What job to plan and how (`[job]`, `[guidance]`, `[field]`, `[maneuver]`, `[vehicle]`).
/// Every planner's parameters are filled in whatever the job kind, for the tools that plan
/// on their own (`agsteer plan`, `agsteer maneuver`).
#[derive(Debug, Clone)]
pub struct Planning {
    pub kind: JobKind,
    pub ab: AbParams,
    pub line_order: LineOrder,
    pub arcs: ArcsParams,
    pub field: FieldPlanning,
    pub maneuver: ManeuverPlanning,
    /// The job keys saved with progress (a segment job adds its plan's checksum).
    pub definition: JobDefinition,
    /// Origin of the local ENU frame (`job.origin_*`; a field plan may have its own).
    pub origin: LatLon,
}

/// A field job: the file and how to load and cover it.
#[derive(Debug, Clone)]
pub struct FieldPlanning {
    /// `job.field_path` as given (relative to the working directory).
    pub path: PathBuf,
    pub load: LoadOptions,
    pub coverage: CoverageParams,
}

/// A manoeuvre job, and the vehicle footprint approach paths are checked with.
#[derive(Debug, Clone)]
pub struct ManeuverPlanning {
    /// `job.maneuver_map_path`; `None` = free space.
    pub map_path: Option<PathBuf>,
    /// Start and goal poses as configured: [x m, y m, heading degrees].
    pub from: [f64; 3],
    pub to: [f64; 3],
    pub curve: CurveChoice,
    pub params: ManeuverParams,
    /// Continuous-curvature limits (κ_max = 1/r_min, σ_max).
    pub curve_params: CurveParams,
    /// Turning radius of plain Reeds-Shepp curves and of the clearance sampling, m.
    pub r_min: f64,
    /// Spacing of the manoeuvre job's points, m.
    pub spacing: f64,
}

/// The simulated vehicle and driver of the demo and `agsteer sim`.
#[derive(Debug, Clone)]
pub struct SimSetup {
    pub params: SimParams,
    /// The driver's speed profile; `None` = constant `speed`.
    pub speed_profile: Option<SpeedProfile>,
    /// Driving speed, m/s.
    pub speed: f64,
    /// Initial offset to the left of the first line, m, and heading error, rad.
    pub start_offset: f64,
    pub start_heading: f64,
    /// Simulated time limit, s (0 = from the job's length).
    pub max_time: f64,
    /// The steering controller's command timeout, s (`None` = off).
    pub command_timeout: Option<f64>,
}

/// The agsteerd process.
#[derive(Debug, Clone, PartialEq)]
pub struct DaemonParams {
    /// SocketCAN interface.
    pub interface: String,
    /// Unix socket answering status JSON; `None` = none.
    pub status_socket: Option<PathBuf>,
    /// Directory of the progress file.
    pub state_dir: PathBuf,
    /// Log filter when RUST_LOG is not set.
    pub log_level: String,
    /// SCHED_FIFO priority of the control loop; 0 = the normal scheduler.
    pub realtime_priority: u8,
}

impl Config {
    /// Every consumer's parameters, or every problem of the file (as [`Config::validate`]).
    pub fn resolve(&self) -> Result<Resolved, ConfigError> {
        let problems = self.validate();
        if !problems.is_empty() {
            return Err(ConfigError::Invalid(problems));
        }
        Ok(self.resolved())
    }

    /// Every consumer's parameters, unchecked: for a configuration validated already
    /// ([`Config::load`] does) or built in code (a test's variation, the demo's scenarios),
    /// taken as it is.
    pub fn resolved(&self) -> Resolved {
        Resolved {
            planning: self.planning(),
            control: self.control_params(),
            safety: self.safety_params(),
            bus: self.bus_params(),
            sim: self.sim_setup(),
            daemon: self.daemon_params(),
            calibration: self.calibration_params(),
        }
    }

    /// What job to plan and how.
    pub fn planning(&self) -> Planning {
        let j = &self.job;
        let map = j.maneuver_map_path.trim();
        Planning {
            kind: j.kind,
            ab: self.ab_params(),
            line_order: j.line_order,
            arcs: self.arcs_params(),
            field: FieldPlanning {
                path: PathBuf::from(&j.field_path),
                load: self.field_load_options(),
                coverage: self.coverage_params(),
            },
            maneuver: ManeuverPlanning {
                map_path: (!map.is_empty()).then(|| PathBuf::from(map)),
                from: j.maneuver_from,
                to: j.maneuver_to,
                curve: self.maneuver.curve,
                params: self.maneuver_params(),
                curve_params: self.maneuver_curve_params(),
                r_min: self.vehicle.r_min_m,
                spacing: self.guidance.point_spacing_m.min(0.5),
            },
            definition: self.job_definition(),
            origin: self.origin(),
        }
    }

    /// The job keys saved with progress: progress saved under other keys is not resumed.
    pub fn job_definition(&self) -> JobDefinition {
        let j = &self.job;
        JobDefinition {
            point_a_m: j.point_a_m,
            point_b_m: j.point_b_m,
            line_width_m: j.line_width_m,
            line_num: j.line_num,
            r_min_m: self.vehicle.r_min_m,
            side: j.side,
            a: self.guidance.a,
            point_spacing_m: self.guidance.point_spacing_m,
            plan_checksum: None,
            identity: Default::default(),
        }
    }

    /// The configured origin of the local ENU frame (`job.origin_*`).
    pub fn origin(&self) -> LatLon {
        LatLon {
            lat_deg: self.job.origin_lat_deg,
            lon_deg: self.job.origin_lon_deg,
        }
    }

    /// The controller's parameters (`[track]`, `[vehicle]`, `[guidance]`, `[control]`, the
    /// engage limits of `[safety]`).
    pub fn control_params(&self) -> ControlParams {
        let (t, v, g) = (&self.track, &self.vehicle, &self.guidance);
        ControlParams {
            dt: self.dt(),
            speed: self.speed(),
            estimator: EstimatorParams {
                wheelbase: v.wheelbase_m,
                antenna: AntennaOffset {
                    forward: v.antenna_forward_m,
                    left: v.antenna_left_m,
                    up: v.antenna_up_m,
                },
                gnss_latency: t.gnss_latency_s,
                predict: true,
                lead_time: t.lead_time_s,
                roll_compensation: true,
                observer: ObserverParams {
                    bias_tau: t.observer_bias_tau_s,
                    drift_tau: t.observer_drift_tau_s,
                    min_speed: t.observer_min_speed_mps,
                    offset_min_speed: t.observer_offset_min_speed_mps,
                    bias_limit: t.observer_bias_limit_deg.to_radians(),
                    drift_limit: t.observer_drift_limit_mps,
                    slip_tau: t.observer_slip_tau_s,
                    // Per degree of roll → per radian.
                    slip_limit: t.observer_slip_limit_mps_per_deg.to_degrees(),
                    corner_slip_tau: t.observer_corner_slip_tau_s,
                    coast_max: t.observer_coast_max_s,
                    robust: t.observer_robust,
                    position_process: t.position_process_m,
                },
            },
            tracker: TrackerParams {
                wheelbase: v.wheelbase_m,
                ld_min: t.ld_min_m,
                ld_gain: t.ld_gain_s,
                max_wheel_angle: self.max_wheel_angle(),
                steering: self.steering_response(),
            },
            tracker_kind: t.kind,
            law: LawParams {
                predictive_ld_max: t.predictive_ld_max_m,
                feed_forward: t.curvature_feed_forward,
                stanley_gain: t.stanley_gain_per_s,
                stanley_soft_speed: t.stanley_soft_speed_mps,
                lqr: crate::track::lqr::LqrWeights {
                    xte: t.lqr_xte_m,
                    heading: t.lqr_heading_deg.to_radians(),
                    rate_fraction: t.lqr_rate_fraction,
                },
                curvature: crate::track::CurvatureScaleParams {
                    gain: t.curvature_gain_per_m_s,
                    limit: t.curvature_scale_limit,
                    capture: t.integral_capture_m,
                    min_speed: t.integral_min_speed_mps,
                    max_heading_error: crate::track::CURVATURE_SCALE_MAX_HEADING_ERROR,
                },
            },
            integral: IntegralParams {
                gain: t.integral_gain_rad_per_m_s,
                limit: t.integral_limit_deg.to_radians(),
                capture: t.integral_capture_m,
                min_speed: t.integral_min_speed_mps,
            },
            lost_motion: LostMotionParams {
                tau: t.lost_motion_tau_s,
                threshold: t.lost_motion_threshold_deg.to_radians(),
                limit: t.lost_motion_limit_deg.to_radians(),
                settle: t.lost_motion_settle_s,
                initial: t.lost_motion_initial_deg.to_radians(),
            },
            approach: (g.approach_paths && v.max_curvature_rate_per_m2 > 0.0).then(|| {
                ApproachParams {
                    curve: CurveParams {
                        kappa_max: 1.0 / v.r_min_m,
                        sigma_max: v.max_curvature_rate_per_m2,
                    },
                    spacing: g.point_spacing_m.min(0.5),
                    max_xte: self.safety.max_engage_xte_m,
                    max_heading_error: self.safety.max_engage_heading_error_deg.to_radians(),
                }
            }),
            guidance: GuidanceParams {
                end_distance: g.end_distance_m,
                local: LocalPathParams {
                    nodes_before: t.local_nodes_before,
                    nodes_after: t.local_nodes_after,
                    tangent_length: t.tangent_length_m,
                    spacing: t.local_spacing_m,
                },
                search_window: 8,
            },
            cusp: CuspParams {
                decel: g.cusp_decel_mps2,
                stopped_speed: g.stopped_speed_mps,
                capture: g.cusp_capture_m,
            },
            nudge_step: g.nudge_step_m,
        }
    }

    /// The node on the bus (`[bus]`).
    pub fn bus_params(&self) -> BusParams {
        BusParams {
            source_address: self.bus.source_address,
            output: self.bus.output,
            status_period: self.bus.status_period_s,
            gnss_from_stream: self.gnss.is_stream(),
            sources: self.sources.params(),
            iso: crate::control::isobus::IsoParams {
                claim: self.isobus.claim_params(self.bus.source_address),
                source_address: self.bus.source_address,
                steering_address: self.isobus.steering_address,
                steering_function: self.isobus.steering_function,
                steer_ready_loop: self.bus.output == super::OutputKind::Curvature,
            },
            machine_info_timeout: self.isobus.machine_info_timeout_s,
            was_gain: self.vehicle.was_gain,
            was_offset: self.vehicle.was_offset_deg.to_radians(),
        }
    }

    /// The agsteerd process (`[daemon]`, `[bus]`, `[progress]`).
    pub fn daemon_params(&self) -> DaemonParams {
        DaemonParams {
            interface: self.bus.interface.clone(),
            status_socket: (!self.bus.status_socket.is_empty())
                .then(|| PathBuf::from(&self.bus.status_socket)),
            state_dir: PathBuf::from(&self.progress.state_dir),
            log_level: self.daemon.log_level.clone(),
            realtime_priority: self.daemon.realtime_priority,
        }
    }

    /// The simulated vehicle and driver (`[sim]`, the true vehicle from `[vehicle]`).
    pub fn sim_setup(&self) -> SimSetup {
        SimSetup {
            params: self.sim_params(),
            speed_profile: self.speed_profile(),
            speed: self.speed(),
            start_offset: self.sim.start_offset_m,
            start_heading: self.sim.start_heading_deg.to_radians(),
            max_time: self.sim.max_time_s,
            command_timeout: (self.sim.command_timeout_s > 0.0)
                .then_some(self.sim.command_timeout_s),
        }
    }
}

/// The share of the supervisor's lateral-acceleration limit a planned turn may use
/// ([`Config::turn_radius`]); the rest is the tracker's, for corrections and slip.
pub const TURN_LATERAL_SHARE: f64 = 0.8;

/// The share of the steering's wheel rate a planned turn's curvature rate may use
/// ([`Config::turn_curvature_rate`]); the rest is the tracker's.
pub const TURN_STEERING_SHARE: f64 = 0.8;

impl Config {
    /// Control period, s.
    pub fn dt(&self) -> f64 {
        self.control.dt_s
    }
    /// Driving speed, m/s.
    pub fn speed(&self) -> f64 {
        self.control.speed_kmh / 3.6
    }
    /// Radius of the planned turns, m: `vehicle.r_min_m`, or more when the job speed would
    /// need a lateral acceleration above [`TURN_LATERAL_SHARE`] of `safety.a_lat_max_m_s2` on
    /// it (v² / (share · a_lat_max)). The supervisor would not allow a turn at its limit to be
    /// corrected (it clamps the command's curvature to a_lat_max / v²), so a turn planned there
    /// leaves the tracker no authority against tyre slip: the envelope's soft-tyred tractor_b
    /// at 15 km/h drifted out of an 8.7 m bulb turn and started the next line 14 m off.
    pub fn turn_radius(&self) -> f64 {
        let v = self.speed();
        let a = self.safety.a_lat_max_m_s2 * TURN_LATERAL_SHARE;
        if a > 0.0 && a.is_finite() {
            self.vehicle.r_min_m.max(v * v / a)
        } else {
            self.vehicle.r_min_m
        }
    }
    /// Curvature rate of the planned turns, 1/m²: `vehicle.max_curvature_rate_per_m2`, or
    /// less when the steering could not sweep the wheels that fast at the job speed: a wheel
    /// rate ω (the slower of `safety.actuator_rate_deg_s`, which calibration measures, and
    /// `safety.max_wheel_rate_deg_s`) turns the path at dκ/ds = ω / (L·v·cos²δ) ≥ ω / (L·v),
    /// of which a turn may use [`TURN_STEERING_SHARE`]. A turn planned faster than the
    /// steering leaves every line start off the line (the envelope's 10°/s motor at 10 km/h
    /// follows 0.021 /m², not 0.1: 11 cm RMS on the straights). A lagging steering (τ,
    /// `safety.actuator_tau_s`) sweeps no faster than the margin between the supervisor's
    /// angle limit and the turn's angle over τ (below). 0 stays 0 (turns of arcs).
    pub fn turn_curvature_rate(&self) -> f64 {
        let sigma = self.vehicle.max_curvature_rate_per_m2;
        let rate = self
            .safety
            .actuator_rate_deg_s
            .min(self.safety.max_wheel_rate_deg_s)
            .to_radians();
        let v = self.speed().abs();
        // A lagging steering follows a wheel ramp at ω only τ·ω behind; the tracker can make
        // that up only by commanding ahead of the turn's angle, and the supervisor clamps the
        // command at the lateral-acceleration limit (`Config::turn_radius` leaves the margin
        // between it and the turn's angle). So the ramp may be no faster than margin / τ.
        let wheelbase = self.vehicle.wheelbase_m;
        let limit = self.safety_params().angle_limit(v);
        let margin = limit - (wheelbase / self.turn_radius()).atan();
        let tau = self.safety.actuator_tau_s;
        let rate = if tau > 0.0 && margin > 0.0 {
            rate.min(margin / tau)
        } else {
            rate
        };
        let steering = TURN_STEERING_SHARE * rate / (wheelbase * v);
        if sigma > 0.0 && steering.is_finite() && steering > 0.0 {
            sigma.min(steering)
        } else {
            sigma
        }
    }
    /// The steering's response as calibration measured it (`safety.actuator_*`), for the
    /// default law's look-ahead schedule.
    pub fn steering_response(&self) -> SteeringResponse {
        let f = &self.safety;
        SteeringResponse {
            lag: f.actuator_tau_s,
            dead_time: (f.actuator_dead_time_s - self.track.lead_time_s).max(0.0),
            rate: f
                .actuator_rate_deg_s
                .min(f.max_wheel_rate_deg_s)
                .to_radians(),
            sweep: self.turn_exit_slew(),
            vehicle_lag: 0.0,
        }
    }
    /// The wheel angle the steering still has to sweep when the planned turn's exit has been
    /// driven, rad: the turn's wheel angle atan(L / [`Config::turn_radius`]) less what the
    /// wheels sweep at the steering's rate while the exit clothoid (κ from 1/R to 0 at the
    /// planned curvature rate σ) is driven, (1/R)/(σ·v) s. 0 for turns planned within the
    /// steering's rate ([`Config::turn_curvature_rate`]); the whole angle for turns of arcs.
    /// Field jobs plan their turns at `vehicle.max_curvature_rate_per_m2`.
    pub fn turn_exit_slew(&self) -> f64 {
        let (f, v) = (&self.safety, &self.vehicle);
        let radius = self.turn_radius();
        let sweep = (v.wheelbase_m / radius).atan().min(self.max_wheel_angle());
        let sigma = match self.job.kind {
            JobKind::Field => v.max_curvature_rate_per_m2,
            // AB and arcs jobs (their CC bulbs between lines closer than 2·r_min included).
            _ => self.turn_curvature_rate(),
        };
        let rate = f
            .actuator_rate_deg_s
            .min(f.max_wheel_rate_deg_s)
            .to_radians();
        let exit_s = 1.0 / (radius * sigma * self.speed().abs());
        let residual = sweep - rate * exit_s;
        if residual.is_finite() {
            residual.clamp(0.0, sweep)
        } else {
            sweep
        }
    }
    /// Largest wheel angle, rad.
    pub fn max_wheel_angle(&self) -> f64 {
        self.vehicle.max_wheel_angle_deg.to_radians()
    }

    /// The safety supervisor's parameters, SI.
    pub fn safety_params(&self) -> crate::safety::SafetyParams {
        let f = &self.safety;
        crate::safety::SafetyParams {
            gnss_timeout: f.gnss_timeout_s,
            rtk_float_tolerance: f.rtk_float_tolerance_s,
            wheel_angle_timeout: f.wheel_angle_timeout_s,
            invalid_threshold: 5,
            min_speed: f.min_speed_kmh / 3.6,
            max_stop_time: f.max_stop_time_s,
            max_speed: f.max_speed_kmh / 3.6,
            override_angle: f.override_angle_deg.to_radians(),
            override_time: f.override_time_s,
            max_engage_xte: f.max_engage_xte_m,
            max_engage_heading_error: f.max_engage_heading_error_deg.to_radians(),
            max_wheel_angle: self.max_wheel_angle(),
            max_wheel_rate: f.max_wheel_rate_deg_s.to_radians(),
            a_lat_max: f.a_lat_max_m_s2,
            wheelbase: self.vehicle.wheelbase_m,
            actuator_dead_time: f.actuator_dead_time_s,
            actuator_tau: f.actuator_tau_s,
            actuator_rate: f.actuator_rate_deg_s.to_radians(),
            tracking: f.tracking_params(),
            heading: f
                .heading_check_params(self.vehicle.antenna_forward_m, self.vehicle.antenna_left_m),
        }
    }
}
