//! The one TOML configuration file a service technician edits.
//!
//! Every section is `deny_unknown_fields` and every key has a default, so a file only needs the
//! keys it changes. Edge units (degrees, km/h) are converted to SI by the accessor methods, in
//! this one place. [`Config::validate`] reports every problem at once, each naming the key, the
//! value and the rule. `--set key.path=value` overrides are applied to the TOML tree before it
//! is deserialised, so they go through exactly the same checks as the file.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::Path;

/// Everything that can go wrong loading a configuration.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("cannot read {path}: {source}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("{0}")]
    Parse(String),
    #[error("bad override `{0}`: expected key.path=value")]
    BadOverride(String),
    #[error("{}", .0.iter().map(|p| p.to_string()).collect::<Vec<_>>().join("\n"))]
    Invalid(Vec<Problem>),
}

/// One validation problem: `key = value: rule`.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    pub key: String,
    pub value: String,
    pub rule: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {}: {}", self.key, self.value, self.rule)
    }
}

/// The kind of job the guidance runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum JobKind {
    /// Parallel AB lines (SPEC §2).
    #[default]
    Ab,
    /// A field coverage plan (SPEC §3) made from the field at `job.field_path`.
    Field,
    /// Concentric circular work lines about `job.point_a_m` (the curved lines of the accuracy
    /// suite): `job.line_num` arcs from radius `job.arc_radius_m` outwards, `job.line_width_m`
    /// apart, each sweeping `job.arc_sweep_deg`, joined by headland turns.
    Arcs,
    /// A manoeuvre with reversing (SPEC §4) from `job.maneuver_from` to `job.maneuver_to` on
    /// the map at `job.maneuver_map_path`, planned at start-up with `[maneuver]`.
    Maneuver,
}

/// In which order the lines of an AB job are driven.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum LineOrder {
    /// The seed-000 order: blocks of `N = 2·ceil(2·r_min/line_width) + a` lines driven in a
    /// skip order so that every turn is a forward pi turn (SPEC §2).
    #[default]
    Blocks,
    /// Adjacent lines in turn. Lines closer than `2·r_min` are joined by a fishtail turn with
    /// a reversal (continuous-curvature when `vehicle.max_curvature_rate_per_m2` > 0). Needs a
    /// finite `line_num`.
    Sequential,
}

/// Side of A→B on which the following lines are laid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum LineSide {
    Left,
    #[default]
    Right,
}

/// Which tracker steers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum TrackerChoice {
    /// Pure pursuit on a latency-compensated, dead-reckoned pose (the default).
    #[default]
    Predictive,
    /// Plain seed-000 pure pursuit on the latest fix: the reference.
    PurePursuit,
    /// Stanley steering on the same latency-compensated, dead-reckoned pose.
    Stanley,
}

/// `[job]`: what to drive.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct JobConfig {
    /// Job kind: "ab" (parallel lines from A and B) or "field" (a coverage plan of the field
    /// at `field_path`).
    pub kind: JobKind,
    /// For `kind = "field"`: the field, a GeoJSON (WGS-84) or ISO 11783-10 TASKDATA.XML file.
    /// A relative path is taken from the working directory (as every path in the
    /// configuration), not from the configuration file's directory. Read and planned once
    /// when agsteerd or `agsteer demo` starts.
    pub field_path: String,
    /// For `kind = "maneuver"`: the map, GeoJSON in local metres (boundary polygon, holes and
    /// `"obstacle": true` features are obstacles; see `agsteer maneuver`); empty = free space.
    pub maneuver_map_path: String,
    /// For `kind = "maneuver"`: start pose [x m, y m, heading degrees CCW from East], local
    /// ENU about `job.origin_*`.
    pub maneuver_from: [f64; 3],
    /// For `kind = "maneuver"`: goal pose [x m, y m, heading degrees].
    pub maneuver_to: [f64; 3],
    /// Point A of the first work line, local ENU [east, north], m.
    pub point_a_m: [f64; 2],
    /// Point B of the first work line, local ENU [east, north], m.
    pub point_b_m: [f64; 2],
    /// Spacing between adjacent work lines (implement working width), m.
    pub line_width_m: f64,
    /// Number of work lines; 0 = unlimited (until the operator stops).
    pub line_num: u64,
    /// Side of A→B on which further lines are laid: "left" or "right".
    pub side: LineSide,
    /// For `kind = "ab"`: "blocks" (the seed-000 skip order, forward turns only) or
    /// "sequential" (adjacent lines in turn, fishtail turns with a reversal where the lines
    /// are closer than 2·r_min; needs `line_num` ≥ 1).
    pub line_order: LineOrder,
    /// WGS-84 latitude of the local ENU origin, degrees.
    pub origin_lat_deg: f64,
    /// WGS-84 longitude of the local ENU origin, degrees.
    pub origin_lon_deg: f64,
    /// For `kind = "arcs"`: radius of the first (innermost) line, m.
    pub arc_radius_m: f64,
    /// For `kind = "arcs"`: sweep of every line, degrees (the first starts due South of the
    /// centre, heading East, and runs counter-clockwise).
    pub arc_sweep_deg: f64,
}

impl Default for JobConfig {
    fn default() -> Self {
        JobConfig {
            kind: JobKind::Ab,
            field_path: String::new(),
            maneuver_map_path: String::new(),
            maneuver_from: [0.0, 0.0, 0.0],
            maneuver_to: [20.0, 0.0, 0.0],
            point_a_m: [0.0, 0.0],
            point_b_m: [0.0, 150.0],
            line_width_m: 3.0,
            line_num: 12,
            side: LineSide::Right,
            line_order: LineOrder::Blocks,
            origin_lat_deg: 52.0,
            origin_lon_deg: 5.0,
            arc_radius_m: 30.0,
            arc_sweep_deg: 270.0,
        }
    }
}

/// `[guidance]`: how the job is broken into lines, blocks and turns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GuidanceConfig {
    /// The seed's `a` in N = 2·ceil(2·r_min/line_width) + a, an integer ≥ 1.
    pub a: i64,
    /// Spacing of global path points, m.
    pub point_spacing_m: f64,
    /// Angular step between turn-arc points, degrees.
    pub turn_arc_step_deg: f64,
    /// Two turn arcs whose ends are closer than this are merged into one, m.
    pub turn_merge_distance_m: f64,
    /// Cap on the number of points of a turn's straight part.
    pub turn_max_points: usize,
    /// The path counts as "near its end" within this distance of its last point, m.
    pub end_distance_m: f64,
    /// Before a cusp (a change of driving direction) the daemon asks the tractor to stop
    /// when the remaining distance is within the stopping distance at this deceleration, m/s².
    pub cusp_decel_mps2: f64,
    /// Below this speed the vehicle counts as stopped (for a change of direction), m/s.
    pub stopped_speed_mps: f64,
    /// A vehicle stopped within this distance of a cusp moves on to the next segment, m.
    pub cusp_capture_m: f64,
    /// Approach paths: when the operator engages at the start of a line too far from it to
    /// engage (|XTE| ≥ `safety.max_engage_xte_m` or heading error ≥
    /// `safety.max_engage_heading_error_deg`), plan a continuous-curvature path (reversing
    /// where shorter, κ_max = 1/`vehicle.r_min_m`, σ_max = `vehicle.max_curvature_rate_per_m2`)
    /// from the vehicle to the line start, inside the field when the job has one, and drive
    /// it first. false = refuse to engage there, as without approach paths.
    pub approach_paths: bool,
}

impl Default for GuidanceConfig {
    fn default() -> Self {
        GuidanceConfig {
            a: 1,
            point_spacing_m: 1.0,
            turn_arc_step_deg: 5.0,
            turn_merge_distance_m: 0.05,
            turn_max_points: 500,
            end_distance_m: 0.3,
            cusp_decel_mps2: 0.5,
            stopped_speed_mps: 0.05,
            cusp_capture_m: 1.0,
            approach_paths: true,
        }
    }
}

/// `[vehicle]`: geometry of the tractor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VehicleConfig {
    /// Wheelbase (rear axle to front axle), m.
    pub wheelbase_m: f64,
    /// Minimum turning radius used for turns, m. Turns are planned with a larger radius when
    /// the job speed needs it: v² / `safety.a_lat_max_m_s2` (15 km/h at 2 m/s²: 8.7 m).
    pub r_min_m: f64,
    /// Largest front-wheel angle either way, degrees.
    pub max_wheel_angle_deg: f64,
    /// Largest rate of change of the steering curvature per metre driven, 1/m² (σ_max of
    /// the continuous-curvature turns and manoeuvres, SPEC §4). It comes from the steering
    /// speed: about max wheel rate (rad/s) / (wheelbase (m) · speed in turns (m/s)); 30°/s,
    /// 3 m and 6 km/h give 0.10. 0 = turns of arcs only (curvature steps at their ends; and
    /// manoeuvres only with `maneuver.curve = "rs"`).
    pub max_curvature_rate_per_m2: f64,
    /// GNSS antenna position ahead of the rear-axle centre, m.
    pub antenna_forward_m: f64,
    /// GNSS antenna position left of the rear-axle centre, m.
    pub antenna_left_m: f64,
    /// GNSS antenna height above the rear-axle centre, m.
    pub antenna_up_m: f64,
    /// Overall length of the vehicle rectangle (manoeuvre collision checks), m.
    pub length_m: f64,
    /// Overall width of the vehicle rectangle, m.
    pub width_m: f64,
    /// Distance of the rear axle ahead of the vehicle's rear edge, m.
    pub rear_axle_from_rear_m: f64,
}

impl Default for VehicleConfig {
    fn default() -> Self {
        VehicleConfig {
            wheelbase_m: 3.0,
            r_min_m: 5.0,
            max_wheel_angle_deg: 35.0,
            max_curvature_rate_per_m2: 0.1,
            antenna_forward_m: 1.0,
            antenna_left_m: 0.0,
            antenna_up_m: 3.0,
            length_m: 4.5,
            width_m: 2.5,
            rear_axle_from_rear_m: 1.0,
        }
    }
}

/// `[control]`: the control loop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ControlConfig {
    /// Control period, s (0.005..=0.5).
    pub dt_s: f64,
    /// Driving speed in the simulator and demo, km/h.
    pub speed_kmh: f64,
}

impl Default for ControlConfig {
    fn default() -> Self {
        ControlConfig {
            dt_s: 0.02,
            speed_kmh: 10.0,
        }
    }
}

/// `[track]`: local path and tracker.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrackConfig {
    /// "predictive" (default) or "pure_pursuit" (plain reference).
    pub kind: TrackerChoice,
    /// Minimum look-ahead distance, m.
    pub ld_min_m: f64,
    /// Look-ahead growth with speed, s: Ld = max(ld_min_m, ld_gain_s · v).
    pub ld_gain_s: f64,
    /// Global points before the nearest one used as local-path nodes.
    pub local_nodes_before: usize,
    /// Global points after the nearest one used as local-path nodes.
    pub local_nodes_after: usize,
    /// B-spline tangent length at each node, m.
    pub tangent_length_m: f64,
    /// Local path sample spacing, m.
    pub local_spacing_m: f64,
    /// Known GNSS latency (fix measured this long before it arrives), s. Predictive only.
    pub gnss_latency_s: f64,
    /// Extra prediction horizon (about the actuator dead time), s. Predictive only.
    pub lead_time_s: f64,
    /// Stanley cross-track gain k, 1/s: δ = ψ + atan(k·e / (v + stanley_soft_speed_mps)).
    pub stanley_gain_per_s: f64,
    /// Stanley softening speed, m/s.
    pub stanley_soft_speed_mps: f64,
    /// Integral action on the XTE, rad of wheel angle per (m · s); 0 = off.
    pub integral_gain_rad_per_m_s: f64,
    /// Largest wheel-angle offset the integral action may learn, degrees.
    pub integral_limit_deg: f64,
    /// The integral action learns only while |XTE| is below this, m.
    pub integral_capture_m: f64,
    /// The integral action learns only above this speed, m/s.
    pub integral_min_speed_mps: f64,
    /// Disturbance observer (predictive tracker only; see
    /// [`ObserverParams`](crate::estimate::ObserverParams)): time constant of the wheel-angle
    /// offset estimate, s (0 = off).
    pub observer_bias_tau_s: f64,
    /// Time constant of the world-frame drift (slip) estimate, s (0 = off).
    pub observer_drift_tau_s: f64,
    /// The observer learns only above this speed, m/s.
    pub observer_min_speed_mps: f64,
    /// Largest wheel-angle offset the observer may estimate, degrees.
    pub observer_bias_limit_deg: f64,
    /// Largest drift speed the observer may estimate, m/s.
    pub observer_drift_limit_mps: f64,
    /// Time constant of the slope-slip coefficient (lateral slip per degree of IMU roll) at 2°
    /// of roll, s (0 = off).
    pub observer_slip_tau_s: f64,
    /// Largest slope-slip coefficient, m/s per degree of roll.
    pub observer_slip_limit_mps_per_deg: f64,
    /// Through an RTK-float period, dead-reckon from the last fixed position for at most this
    /// long instead of following the float positions, s (0 = off).
    pub observer_coast_max_s: f64,
    /// Lost-motion compensation (predictive tracker only; see
    /// [`LostMotion`](crate::track::lost_motion::LostMotion)): time constant of the steering's
    /// lost-motion (backlash + actuator deadband) estimate, s (0 = off).
    pub lost_motion_tau_s: f64,
    /// The command is pushed the other way only when the measured wheel angle is past the
    /// demand by this much, degrees (above the wheel-angle sensor's noise).
    pub lost_motion_threshold_deg: f64,
    /// Largest lost motion the compensation may learn, degrees.
    pub lost_motion_limit_deg: f64,
    /// The estimate learns only this long after the push direction changed, with a steady
    /// demand, s (about the actuator's settling time).
    pub lost_motion_settle_s: f64,
}

impl Default for TrackConfig {
    fn default() -> Self {
        TrackConfig {
            kind: TrackerChoice::Predictive,
            ld_min_m: 3.0,
            ld_gain_s: 1.2,
            local_nodes_before: 1,
            local_nodes_after: 10,
            tangent_length_m: 0.25,
            local_spacing_m: 0.1,
            gnss_latency_s: 0.05,
            lead_time_s: 0.05,
            stanley_gain_per_s: 2.5,
            stanley_soft_speed_mps: 1.0,
            integral_gain_rad_per_m_s: 0.0,
            integral_limit_deg: 3.0,
            integral_capture_m: 0.3,
            integral_min_speed_mps: 0.5,
            observer_bias_tau_s: 20.0,
            observer_drift_tau_s: 60.0,
            observer_min_speed_mps: 1.0,
            observer_bias_limit_deg: 3.0,
            observer_drift_limit_mps: 0.3,
            observer_slip_tau_s: 30.0,
            observer_slip_limit_mps_per_deg: 0.05,
            observer_coast_max_s: 30.0,
            lost_motion_tau_s: 5.0,
            lost_motion_threshold_deg: 0.1,
            lost_motion_limit_deg: 1.0,
            lost_motion_settle_s: 0.5,
        }
    }
}

/// `[sim]`: the vehicle simulator.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimConfig {
    /// Random seed: the same seed gives the same run.
    pub seed: u64,
    /// Internal integration step, s.
    pub step_s: f64,
    /// GNSS update rate, Hz.
    pub gnss_rate_hz: f64,
    /// GNSS latency (measurement to delivery), s.
    pub gnss_latency_s: f64,
    /// GNSS position white noise σ per axis, m.
    pub gnss_sigma_m: f64,
    /// Dual-antenna heading noise σ, degrees.
    pub heading_sigma_deg: f64,
    /// Wheel-angle sensor rate, Hz.
    pub was_rate_hz: f64,
    /// Wheel-angle sensor noise σ, degrees.
    pub was_noise_deg: f64,
    /// Steering actuator dead time, s.
    pub actuator_dead_time_s: f64,
    /// Steering actuator first-order lag time constant, s.
    pub actuator_tau_s: f64,
    /// Steering actuator rate limit, degrees/s.
    pub actuator_rate_deg_s: f64,
    /// Initial lateral offset of the vehicle from line A→B (positive = left), m.
    pub start_offset_m: f64,
    /// Initial heading error relative to A→B, degrees.
    pub start_heading_deg: f64,
    /// Stop the simulation after this much simulated time even if unfinished, s (0 = auto).
    pub max_time_s: f64,
    /// The simulated tractor's acceleration and braking when a direction request changes its
    /// speed, m/s².
    pub accel_mps2: f64,
    // Disturbances, all off by default.
    /// Correlated GNSS position error per axis (first-order Gauss-Markov): stationary σ, m
    /// (0 = off), and time constant, s.
    pub gnss_markov_sigma_m: f64,
    pub gnss_markov_tau_s: f64,
    /// Multipath jumps: mean rate per hour (0 = off), magnitude (random direction), m, and
    /// duration, s.
    pub gnss_multipath_rate_per_h: f64,
    pub gnss_multipath_m: f64,
    pub gnss_multipath_duration_s: f64,
    /// RTK-float windows `[[start_s, duration_s], ...]` of simulated time: 129029 reports RTK
    /// float and a Gauss-Markov error (σ m, τ s) per axis is added.
    pub gnss_float_windows_s: Vec<[f64; 2]>,
    pub gnss_float_sigma_m: f64,
    pub gnss_float_tau_s: f64,
    /// Terrain: slope, degrees (0 = flat), falling towards `terrain_downhill_deg` (CCW from
    /// East), varying by ±`terrain_slope_amp_deg` sinusoidally with `terrain_wavelength_m`
    /// along the contour direction.
    pub terrain_slope_deg: f64,
    pub terrain_downhill_deg: f64,
    pub terrain_slope_amp_deg: f64,
    pub terrain_wavelength_m: f64,
    /// IMU roll/pitch frame rate, Hz (0 = no IMU), and noise σ, degrees.
    pub imu_rate_hz: f64,
    pub imu_noise_deg: f64,
    /// Side-slope slip to the right (downhill for positive roll), m/s per degree of roll, and a
    /// constant slip to the right, m/s.
    pub slip_per_roll_mps_per_deg: f64,
    pub slip_mps: f64,
    /// Wheel-angle sensor bias, degrees.
    pub was_bias_deg: f64,
    /// Actuator deadband (half-width), degrees, and backlash (total play), degrees.
    pub actuator_deadband_deg: f64,
    pub actuator_backlash_deg: f64,
    /// Speed profile of the simulated driver going forward, km/h: `speed_max_kmh` on the
    /// straight, slowing to `speed_min_kmh` in turns (|wheel angle| above
    /// `speed_turn_angle_deg`), at `accel_mps2`. `speed_max_kmh` = 0: constant
    /// `control.speed_kmh`.
    pub speed_min_kmh: f64,
    pub speed_max_kmh: f64,
    pub speed_turn_angle_deg: f64,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            seed: 1,
            step_s: 0.001,
            gnss_rate_hz: 10.0,
            gnss_latency_s: 0.05,
            gnss_sigma_m: 0.01,
            heading_sigma_deg: 0.1,
            was_rate_hz: 100.0,
            was_noise_deg: 0.05,
            actuator_dead_time_s: 0.05,
            actuator_tau_s: 0.15,
            actuator_rate_deg_s: 30.0,
            start_offset_m: 0.0,
            start_heading_deg: 0.0,
            max_time_s: 0.0,
            accel_mps2: 0.5,
            gnss_markov_sigma_m: 0.0,
            gnss_markov_tau_s: 60.0,
            gnss_multipath_rate_per_h: 0.0,
            gnss_multipath_m: 0.1,
            gnss_multipath_duration_s: 10.0,
            gnss_float_windows_s: Vec::new(),
            gnss_float_sigma_m: 0.2,
            gnss_float_tau_s: 10.0,
            terrain_slope_deg: 0.0,
            terrain_downhill_deg: 0.0,
            terrain_slope_amp_deg: 0.0,
            terrain_wavelength_m: 100.0,
            imu_rate_hz: 0.0,
            imu_noise_deg: 0.0,
            slip_per_roll_mps_per_deg: 0.0,
            slip_mps: 0.0,
            was_bias_deg: 0.0,
            actuator_deadband_deg: 0.0,
            actuator_backlash_deg: 0.0,
            speed_min_kmh: 4.0,
            speed_max_kmh: 0.0,
            speed_turn_angle_deg: 5.0,
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

/// `[bus]`: the CAN side.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BusConfig {
    /// SocketCAN interface, e.g. "can0" or "vcan0".
    pub interface: String,
    /// agsteer's J1939 source address (0..=253).
    pub source_address: u8,
    /// Steering output: "angle", "curvature" (ISOBUS) or "both".
    pub output: OutputKind,
    /// Guidance status frame period, s.
    pub status_period_s: f64,
    /// Unix socket answering status JSON ("" = none).
    pub status_socket: String,
}

impl Default for BusConfig {
    fn default() -> Self {
        BusConfig {
            interface: "can0".to_string(),
            source_address: 0x2A,
            output: OutputKind::Angle,
            status_period_s: 0.1,
            status_socket: "/run/agsteer/status.sock".to_string(),
        }
    }
}

/// `[safety]`: engage gating, input freshness and command limits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SafetyConfig {
    /// GNSS older than this disengages, s.
    pub gnss_timeout_s: f64,
    /// RTK float is tolerated this long, s (0 = never).
    pub rtk_float_tolerance_s: f64,
    /// Wheel angle older than this disengages, s.
    pub wheel_angle_timeout_s: f64,
    /// Allowed speed range, km/h.
    pub min_speed_kmh: f64,
    pub max_speed_kmh: f64,
    /// While the daemon has asked for a stop to change direction (a cusp of a manoeuvre), the
    /// speed may be below min_speed_kmh for at most this long, s.
    pub max_stop_time_s: f64,
    /// Measured wheel angle this far from the command…, degrees
    pub override_angle_deg: f64,
    /// …for longer than this is an operator override, s.
    pub override_time_s: f64,
    /// Engaging needs |XTE| below this, m.
    pub max_engage_xte_m: f64,
    /// Engaging needs |heading error| below this, degrees.
    pub max_engage_heading_error_deg: f64,
    /// Largest commanded wheel-angle rate, degrees/s.
    pub max_wheel_rate_deg_s: f64,
    /// Largest lateral acceleration v²·κ, m/s².
    pub a_lat_max_m_s2: f64,
    /// Actuator model for override detection: dead time, s; lag, s; rate, degrees/s.
    pub actuator_dead_time_s: f64,
    pub actuator_tau_s: f64,
    pub actuator_rate_deg_s: f64,
}

impl Default for SafetyConfig {
    fn default() -> Self {
        SafetyConfig {
            gnss_timeout_s: 0.3,
            rtk_float_tolerance_s: 0.0,
            wheel_angle_timeout_s: 0.1,
            min_speed_kmh: 0.5,
            max_speed_kmh: 25.0,
            max_stop_time_s: 10.0,
            override_angle_deg: 8.0,
            override_time_s: 0.5,
            max_engage_xte_m: 1.0,
            max_engage_heading_error_deg: 60.0,
            max_wheel_rate_deg_s: 45.0,
            a_lat_max_m_s2: 2.0,
            actuator_dead_time_s: 0.05,
            actuator_tau_s: 0.15,
            actuator_rate_deg_s: 30.0,
        }
    }
}

/// `[daemon]`: the agsteerd process.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DaemonConfig {
    /// Log filter when RUST_LOG is not set: "error", "warn", "info", "debug" or "trace".
    pub log_level: String,
    /// SCHED_FIFO priority of the control loop (1..=99); 0 = the normal scheduler. Needs root
    /// or CAP_SYS_NICE.
    pub realtime_priority: u8,
}

impl Default for DaemonConfig {
    fn default() -> Self {
        DaemonConfig {
            log_level: "info".to_string(),
            realtime_priority: 0,
        }
    }
}

/// `[progress]`: where job progress is kept across power loss.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ProgressConfig {
    /// Directory of the progress file (the daemon's state directory).
    pub state_dir: String,
}

impl Default for ProgressConfig {
    fn default() -> Self {
        ProgressConfig {
            state_dir: "/var/lib/agsteer".to_string(),
        }
    }
}

/// How `[field]` chooses the swath direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SwathAngleChoice {
    /// Minimum span of the convex hull.
    MinSpan,
    /// Fewest turns over the cells.
    MinTurns,
    /// `field.swath_angle_deg`.
    Fixed,
}

/// Where `[field]` takes the local ENU origin from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FieldOrigin {
    /// Centre of the boundary's lat/lon bounding box.
    Auto,
    /// `job.origin_lat_deg` / `job.origin_lon_deg`.
    Config,
}

/// `[field]`: field coverage planning (`agsteer plan`). Width from `job.line_width_m`, r_min
/// from `vehicle.r_min_m`, point spacing from `guidance.point_spacing_m`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FieldConfig {
    /// Headland passes around the boundary, each `job.line_width_m` wide.
    pub headland_passes: usize,
    /// Swath direction objective: "min_span", "min_turns" or "fixed".
    pub swath_angle: SwathAngleChoice,
    /// Swath direction for `swath_angle = "fixed"`, degrees CCW from East.
    pub swath_angle_deg: f64,
    /// Swath order in a cell: "auto", "sequential" or "skip".
    pub route: crate::plan::coverage::RouteOrder,
    /// Obstacles whose largest dimension is at most this are passed on detours; larger ones get
    /// headland passes and split the swaths, m.
    pub small_obstacle_max_m: f64,
    /// Boundary clean-up tolerance (largest distance of a dropped point), m; 0 = no fitting.
    pub boundary_tolerance_m: f64,
    /// ENU origin: "auto" (boundary bounding-box centre) or "config" (job.origin_*).
    pub origin: FieldOrigin,
}

impl Default for FieldConfig {
    fn default() -> Self {
        FieldConfig {
            headland_passes: 2,
            swath_angle: SwathAngleChoice::MinSpan,
            swath_angle_deg: 0.0,
            route: crate::plan::coverage::RouteOrder::Auto,
            small_obstacle_max_m: 15.0,
            boundary_tolerance_m: 0.1,
            origin: FieldOrigin::Auto,
        }
    }
}

/// Which curves `[maneuver]` plans with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum CurveChoice {
    /// Continuous curvature: clothoid turns, CC Reeds-Shepp connections.
    #[default]
    Cc,
    /// Plain Reeds-Shepp: arcs and lines (curvature jumps where they meet).
    Rs,
}

/// `[maneuver]`: manoeuvres with reversing in tight spaces (`agsteer maneuver`, SPEC §4). The
/// vehicle rectangle is `vehicle.length_m` × `vehicle.width_m` with the rear axle
/// `vehicle.rear_axle_from_rear_m` ahead of its rear edge; the largest curvature is
/// 1 / `vehicle.r_min_m`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ManeuverConfig {
    /// Curve family: "cc" (continuous curvature, the default) or "rs" (plain Reeds-Shepp).
    pub curve: CurveChoice,
    /// Implement rigidly mounted behind the vehicle: length, m (0 = none), width, m, and
    /// distance of its front edge behind the rear axle, m.
    pub implement_length_m: f64,
    pub implement_width_m: f64,
    pub implement_hitch_m: f64,
    /// Clearance kept around the vehicle (and implement) rectangle, m. Must be at least half
    /// of `sample_tolerance_m` so that sampled checks cover the continuous sweep.
    pub clearance_m: f64,
    /// Largest distance any point of the vehicle moves between two collision samples, m.
    pub sample_tolerance_m: f64,
    /// Cell size of the collision broad-phase grid, m.
    pub grid_cell_m: f64,
    /// Straight-line expansion: leg length, m; join distance, m; most levels; most legs per
    /// tree.
    pub expansion_step_m: f64,
    pub expansion_join_m: f64,
    pub expansion_max_depth: usize,
    pub expansion_max_legs: usize,
    /// Reversing patterns tried at the goal, written for an arrival from the goal's left
    /// (mirrored l ↔ r for the right): curves l/r, `_`, directions p (forward) / n (reverse).
    /// Empty = no pattern stage.
    pub goal_patterns: Vec<String>,
    /// Search primitives: heading-change step, degrees; largest heading change, degrees;
    /// length of the straight primitive, m.
    pub heading_step_deg: f64,
    pub primitive_max_deg: f64,
    pub straight_step_m: f64,
    /// Cost factor on reverse driving (≥ 1) and cost of each change of direction, m.
    pub reverse_penalty: f64,
    pub cusp_penalty_m: f64,
    /// Duplicate-detection grid of the search: position cell, m; heading cell, degrees.
    pub xy_resolution_m: f64,
    pub heading_resolution_deg: f64,
    /// Most node expansions over all searches of one plan.
    pub max_expansions: usize,
    /// Most expansions of the search to one goal pattern's start (part of max_expansions).
    pub pattern_max_expansions: usize,
    /// Most expansions of the search straight to the goal (part of max_expansions; the rest is
    /// left for the fallback).
    pub search_max_expansions: usize,
    /// Try the analytic connection to the goal every this many expansions (1 = each).
    pub analytic_every: usize,
    /// Expansions spent after the first solution looking for a cheaper one.
    pub extra_expansions: usize,
    /// Points per leg tried by the fallback (search between the rough route's first and last
    /// legs).
    pub fallback_points: usize,
}

impl Default for ManeuverConfig {
    fn default() -> Self {
        ManeuverConfig {
            curve: CurveChoice::Cc,
            implement_length_m: 0.0,
            implement_width_m: 0.0,
            implement_hitch_m: 0.5,
            clearance_m: 0.15,
            sample_tolerance_m: 0.3,
            grid_cell_m: 2.0,
            expansion_step_m: 5.0,
            expansion_join_m: 0.5,
            expansion_max_depth: 8,
            expansion_max_legs: 200,
            goal_patterns: vec!["lrlr_pnpn".to_string(), "lr_pn".to_string()],
            heading_step_deg: 10.0,
            primitive_max_deg: 180.0,
            straight_step_m: 2.0,
            reverse_penalty: 1.5,
            cusp_penalty_m: 5.0,
            xy_resolution_m: 1.0,
            heading_resolution_deg: 10.0,
            max_expansions: 4000,
            pattern_max_expansions: 600,
            search_max_expansions: 2500,
            analytic_every: 1,
            extra_expansions: 40,
            fallback_points: 3,
        }
    }
}

impl Config {
    /// The curve limits of manoeuvres: κ_max = 1 / vehicle.r_min_m, σ_max =
    /// vehicle.max_curvature_rate_per_m2.
    pub fn maneuver_curve_params(&self) -> crate::plan::maneuver::steering::CurveParams {
        crate::plan::maneuver::steering::CurveParams {
            kappa_max: 1.0 / self.vehicle.r_min_m,
            sigma_max: self.vehicle.max_curvature_rate_per_m2,
        }
    }

    /// The manoeuvre planner's parameters from `[maneuver]` and `[vehicle]`, SI.
    pub fn maneuver_params(&self) -> crate::plan::maneuver::search::ManeuverParams {
        use crate::plan::maneuver::collision::{Footprint, ImplementBox, VehicleBox};
        use crate::plan::maneuver::expansion::ExpansionParams;
        let m = &self.maneuver;
        let v = &self.vehicle;
        crate::plan::maneuver::search::ManeuverParams {
            footprint: Footprint {
                vehicle: VehicleBox {
                    length_m: v.length_m,
                    width_m: v.width_m,
                    rear_axle_from_rear_m: v.rear_axle_from_rear_m,
                },
                implement: (m.implement_length_m > 0.0).then_some(ImplementBox {
                    length_m: m.implement_length_m,
                    width_m: m.implement_width_m,
                    hitch_offset_m: m.implement_hitch_m,
                }),
                margin_m: m.clearance_m,
            },
            sample_tolerance_m: m.sample_tolerance_m,
            grid_cell_m: m.grid_cell_m,
            expansion: ExpansionParams {
                step_m: m.expansion_step_m,
                join_m: m.expansion_join_m,
                max_depth: m.expansion_max_depth,
                max_legs: m.expansion_max_legs,
            },
            goal_patterns: m.goal_patterns.clone(),
            heading_step_rad: m.heading_step_deg.to_radians(),
            primitive_max_rad: m.primitive_max_deg.to_radians(),
            straight_step_m: m.straight_step_m,
            reverse_penalty: m.reverse_penalty,
            cusp_penalty_m: m.cusp_penalty_m,
            xy_resolution_m: m.xy_resolution_m,
            heading_resolution_rad: m.heading_resolution_deg.to_radians(),
            max_expansions: m.max_expansions,
            pattern_max_expansions: m.pattern_max_expansions,
            search_max_expansions: m.search_max_expansions,
            analytic_every: m.analytic_every,
            extra_expansions: m.extra_expansions,
            fallback_points: m.fallback_points,
        }
    }
}

impl Config {
    /// Coverage planner parameters from `[field]`, `job`, `vehicle` and `guidance`.
    pub fn coverage_params(&self) -> crate::plan::coverage::CoverageParams {
        use crate::plan::coverage::{CoverageParams, SwathAngle};
        let f = &self.field;
        CoverageParams {
            line_width: self.job.line_width_m,
            r_min: self.turn_radius(),
            headland_passes: f.headland_passes,
            point_spacing: self.guidance.point_spacing_m,
            swath_angle: match f.swath_angle {
                SwathAngleChoice::MinSpan => SwathAngle::MinSpan,
                SwathAngleChoice::MinTurns => SwathAngle::MinTurns,
                SwathAngleChoice::Fixed => SwathAngle::Fixed {
                    angle: f.swath_angle_deg.to_radians(),
                },
            },
            route: f.route,
            small_obstacle_max_m: f.small_obstacle_max_m,
            max_curvature_rate: self.vehicle.max_curvature_rate_per_m2,
        }
    }

    /// Field loading options from `[field]` (and `job.origin_*` when `field.origin = "config"`).
    pub fn field_load_options(&self) -> crate::field::LoadOptions {
        crate::field::LoadOptions {
            origin: match self.field.origin {
                FieldOrigin::Auto => None,
                FieldOrigin::Config => Some(crate::geo::wgs84::LatLon {
                    lat_deg: self.job.origin_lat_deg,
                    lon_deg: self.job.origin_lon_deg,
                }),
            },
            boundary_tolerance_m: self.field.boundary_tolerance_m,
        }
    }
}

/// The whole configuration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct Config {
    pub job: JobConfig,
    pub guidance: GuidanceConfig,
    pub vehicle: VehicleConfig,
    pub control: ControlConfig,
    pub track: TrackConfig,
    pub sim: SimConfig,
    pub progress: ProgressConfig,
    pub bus: BusConfig,
    pub safety: SafetyConfig,
    pub daemon: DaemonConfig,
    pub field: FieldConfig,
    pub maneuver: ManeuverConfig,
}

/// Apply `key.path=value` overrides to a TOML tree. The value is parsed as a TOML value
/// (`3`, `2.5`, `true`, `[1, 2]`, `"text"`); anything that does not parse is taken as a string.
pub fn apply_overrides(root: &mut toml::Table, overrides: &[String]) -> Result<(), ConfigError> {
    for ov in overrides {
        let (key, raw) = ov
            .split_once('=')
            .ok_or_else(|| ConfigError::BadOverride(ov.clone()))?;
        let key = key.trim();
        if key.is_empty() || key.split('.').any(|p| p.trim().is_empty()) {
            return Err(ConfigError::BadOverride(ov.clone()));
        }
        let raw = raw.trim();
        let value = match format!("v = {raw}").parse::<toml::Table>() {
            Ok(mut t) => t
                .remove("v")
                .unwrap_or(toml::Value::String(raw.to_string())),
            Err(_) => toml::Value::String(raw.to_string()),
        };
        let parts: Vec<&str> = key.split('.').map(str::trim).collect();
        let (last, parents) = parts
            .split_last()
            .ok_or_else(|| ConfigError::BadOverride(ov.clone()))?;
        let mut table = &mut *root;
        for p in parents {
            let entry = table
                .entry(p.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            table = entry.as_table_mut().ok_or_else(|| {
                ConfigError::Parse(format!("override `{ov}`: `{p}` is not a section"))
            })?;
        }
        table.insert(last.to_string(), value);
    }
    Ok(())
}

/// Edit distance between two keys (for "did you mean").
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != *cb))
                .min(prev[j + 1] + 1)
                .min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// Add "did you mean `key`?" to serde's unknown-field messages.
fn suggest_nearest(msg: String) -> String {
    let Some(start) = msg.find("unknown field `") else {
        return msg;
    };
    let rest = &msg[start + "unknown field `".len()..];
    let Some(end) = rest.find('`') else {
        return msg;
    };
    let unknown = &rest[..end];
    // serde says "expected `a`", "expected `a` or `b`" or "expected one of `a`, `b`, …".
    let Some(list) = rest.find("expected ").map(|i| &rest[i..]) else {
        return msg;
    };
    let list = list.lines().next().unwrap_or("");
    let best = list
        .split('`')
        .skip(1)
        .step_by(2)
        .min_by_key(|k| edit_distance(unknown, k));
    match best {
        Some(k) => {
            // Put the hint on the first line, before serde's "in `section`" line.
            let (first, more) = msg.split_once('\n').unwrap_or((msg.as_str(), ""));
            let more = more.trim();
            if more.is_empty() {
                format!("{first}; did you mean `{k}`?")
            } else {
                format!("{first}; did you mean `{k}`? ({more})")
            }
        }
        None => msg,
    }
}

impl Config {
    /// Parse TOML text with overrides, without validating.
    pub fn parse_with(text: &str, overrides: &[String]) -> Result<Config, ConfigError> {
        let mut root: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| ConfigError::Parse(e.to_string()))?;
        apply_overrides(&mut root, overrides)?;
        Config::deserialize(root).map_err(|e| ConfigError::Parse(suggest_nearest(e.to_string())))
    }

    /// Read, override and validate a configuration file.
    pub fn load(path: &Path, overrides: &[String]) -> Result<Config, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
            path: path.display().to_string(),
            source,
        })?;
        let cfg = Config::parse_with(&text, overrides)?;
        let problems = cfg.validate();
        if problems.is_empty() {
            Ok(cfg)
        } else {
            Err(ConfigError::Invalid(problems))
        }
    }

    /// Every problem in the configuration, all at once.
    pub fn validate(&self) -> Vec<Problem> {
        let mut c = Checker::default();
        let j = &self.job;
        c.finite2("job.point_a_m", j.point_a_m);
        c.finite2("job.point_b_m", j.point_b_m);
        let ab = ((j.point_b_m[0] - j.point_a_m[0]).powi(2)
            + (j.point_b_m[1] - j.point_a_m[1]).powi(2))
        .sqrt();
        if ab.is_finite() && ab < 1.0 {
            c.push(
                "job.point_b_m",
                format!("{:?}", j.point_b_m),
                "must be at least 1 m from job.point_a_m",
            );
        }
        c.range("job.line_width_m", j.line_width_m, 0.1, 100.0);
        if j.kind == JobKind::Ab && j.line_order == LineOrder::Sequential && j.line_num == 0 {
            c.push(
                "job.line_num",
                "0".to_string(),
                "must be at least 1 when job.line_order = \"sequential\" (the whole job is planned at start)",
            );
        }
        for (key, pose) in [
            ("job.maneuver_from", j.maneuver_from),
            ("job.maneuver_to", j.maneuver_to),
        ] {
            if pose.iter().any(|v| !v.is_finite()) {
                c.push(
                    key,
                    format!("{pose:?}"),
                    "must be [x m, y m, heading degrees], all finite",
                );
            }
        }
        if j.kind == JobKind::Field && j.field_path.trim().is_empty() {
            c.push(
                "job.field_path",
                format!("{:?}", j.field_path),
                "must name a GeoJSON or TASKDATA.XML file when job.kind = \"field\"",
            );
        }
        c.range("job.arc_radius_m", j.arc_radius_m, 1.0, 10_000.0);
        c.range("job.arc_sweep_deg", j.arc_sweep_deg, 1.0, 359.0);
        if j.kind == JobKind::Arcs && !(1..=1000).contains(&j.line_num) {
            c.push(
                "job.line_num",
                j.line_num.to_string(),
                "must be in 1..=1000 when job.kind = \"arcs\"",
            );
        }
        c.range("job.origin_lat_deg", j.origin_lat_deg, -89.0, 89.0);
        c.range("job.origin_lon_deg", j.origin_lon_deg, -180.0, 180.0);
        let fc = &self.field;
        if fc.headland_passes > 50 {
            c.push(
                "field.headland_passes",
                fc.headland_passes.to_string(),
                "must be in 0..=50",
            );
        }
        c.range("field.swath_angle_deg", fc.swath_angle_deg, -360.0, 360.0);
        c.range(
            "field.small_obstacle_max_m",
            fc.small_obstacle_max_m,
            0.0,
            1000.0,
        );
        c.range(
            "field.boundary_tolerance_m",
            fc.boundary_tolerance_m,
            0.0,
            10.0,
        );

        let g = &self.guidance;
        if g.a < 1 {
            c.push("guidance.a", g.a.to_string(), "must be an integer >= 1");
        }
        c.range("guidance.point_spacing_m", g.point_spacing_m, 0.05, 10.0);
        c.range("guidance.turn_arc_step_deg", g.turn_arc_step_deg, 0.1, 10.0);
        c.range(
            "guidance.turn_merge_distance_m",
            g.turn_merge_distance_m,
            0.0,
            5.0,
        );
        if g.turn_max_points < 2 {
            c.push(
                "guidance.turn_max_points",
                g.turn_max_points.to_string(),
                "must be an integer >= 2",
            );
        }
        c.range("guidance.end_distance_m", g.end_distance_m, 0.0, 10.0);
        c.range("guidance.cusp_decel_mps2", g.cusp_decel_mps2, 0.05, 5.0);
        c.range(
            "guidance.stopped_speed_mps",
            g.stopped_speed_mps,
            0.001,
            1.0,
        );
        c.range("guidance.cusp_capture_m", g.cusp_capture_m, 0.05, 10.0);

        let v = &self.vehicle;
        c.range("vehicle.wheelbase_m", v.wheelbase_m, 0.5, 20.0);
        c.range("vehicle.r_min_m", v.r_min_m, 0.5, 100.0);
        c.range(
            "vehicle.max_curvature_rate_per_m2",
            v.max_curvature_rate_per_m2,
            0.0,
            10.0,
        );
        c.range(
            "vehicle.max_wheel_angle_deg",
            v.max_wheel_angle_deg,
            1.0,
            80.0,
        );
        c.range(
            "vehicle.antenna_forward_m",
            v.antenna_forward_m,
            -20.0,
            20.0,
        );
        c.range("vehicle.antenna_left_m", v.antenna_left_m, -10.0, 10.0);
        c.range("vehicle.antenna_up_m", v.antenna_up_m, 0.0, 10.0);
        if v.wheelbase_m.is_finite() && v.max_wheel_angle_deg.is_finite() && v.r_min_m.is_finite() {
            let r_steer = v.wheelbase_m / v.max_wheel_angle_deg.to_radians().tan();
            if v.r_min_m + 1e-9 < r_steer {
                c.push(
                    "vehicle.r_min_m",
                    v.r_min_m.to_string(),
                    &format!(
                        "must be >= wheelbase / tan(max wheel angle) = {r_steer:.2} m, the tightest radius the vehicle can steer"
                    ),
                );
            }
        }

        c.range("control.dt_s", self.control.dt_s, 0.005, 0.5);
        c.range("control.speed_kmh", self.control.speed_kmh, 0.5, 30.0);

        let t = &self.track;
        c.range("track.ld_min_m", t.ld_min_m, 0.2, 50.0);
        c.range("track.ld_gain_s", t.ld_gain_s, 0.0, 10.0);
        if t.local_nodes_after < 1 {
            c.push(
                "track.local_nodes_after",
                t.local_nodes_after.to_string(),
                "must be an integer >= 1",
            );
        }
        if t.local_nodes_before + t.local_nodes_after > 64 {
            c.push(
                "track.local_nodes_after",
                t.local_nodes_after.to_string(),
                "local_nodes_before + local_nodes_after must be <= 64",
            );
        }
        c.range("track.tangent_length_m", t.tangent_length_m, 0.01, 5.0);
        c.range("track.local_spacing_m", t.local_spacing_m, 0.01, 1.0);
        c.range("track.gnss_latency_s", t.gnss_latency_s, 0.0, 1.0);
        c.range("track.lead_time_s", t.lead_time_s, 0.0, 1.0);
        c.range("track.stanley_gain_per_s", t.stanley_gain_per_s, 0.0, 50.0);
        c.range(
            "track.stanley_soft_speed_mps",
            t.stanley_soft_speed_mps,
            0.01,
            10.0,
        );
        c.range(
            "track.integral_gain_rad_per_m_s",
            t.integral_gain_rad_per_m_s,
            0.0,
            1.0,
        );
        c.range("track.integral_limit_deg", t.integral_limit_deg, 0.0, 10.0);
        c.range("track.integral_capture_m", t.integral_capture_m, 0.01, 5.0);
        c.range(
            "track.integral_min_speed_mps",
            t.integral_min_speed_mps,
            0.0,
            10.0,
        );
        c.range(
            "track.observer_bias_tau_s",
            t.observer_bias_tau_s,
            0.0,
            600.0,
        );
        c.range(
            "track.observer_drift_tau_s",
            t.observer_drift_tau_s,
            0.0,
            600.0,
        );
        c.range(
            "track.observer_min_speed_mps",
            t.observer_min_speed_mps,
            0.1,
            10.0,
        );
        c.range(
            "track.observer_bias_limit_deg",
            t.observer_bias_limit_deg,
            0.0,
            10.0,
        );
        c.range(
            "track.observer_drift_limit_mps",
            t.observer_drift_limit_mps,
            0.0,
            2.0,
        );
        c.range(
            "track.observer_slip_tau_s",
            t.observer_slip_tau_s,
            0.0,
            600.0,
        );
        c.range(
            "track.observer_slip_limit_mps_per_deg",
            t.observer_slip_limit_mps_per_deg,
            0.0,
            1.0,
        );
        c.range(
            "track.observer_coast_max_s",
            t.observer_coast_max_s,
            0.0,
            600.0,
        );
        c.range("track.lost_motion_tau_s", t.lost_motion_tau_s, 0.0, 600.0);
        c.range(
            "track.lost_motion_threshold_deg",
            t.lost_motion_threshold_deg,
            0.0,
            2.0,
        );
        c.range(
            "track.lost_motion_limit_deg",
            t.lost_motion_limit_deg,
            0.0,
            5.0,
        );
        c.range(
            "track.lost_motion_settle_s",
            t.lost_motion_settle_s,
            0.0,
            10.0,
        );

        let s = &self.sim;
        c.range("sim.step_s", s.step_s, 0.0001, 0.01);
        c.range("sim.gnss_rate_hz", s.gnss_rate_hz, 0.5, 100.0);
        c.range("sim.gnss_latency_s", s.gnss_latency_s, 0.0, 1.0);
        c.range("sim.gnss_sigma_m", s.gnss_sigma_m, 0.0, 10.0);
        c.range("sim.heading_sigma_deg", s.heading_sigma_deg, 0.0, 10.0);
        c.range("sim.was_rate_hz", s.was_rate_hz, 1.0, 1000.0);
        c.range("sim.was_noise_deg", s.was_noise_deg, 0.0, 5.0);
        c.range("sim.actuator_dead_time_s", s.actuator_dead_time_s, 0.0, 1.0);
        c.range("sim.actuator_tau_s", s.actuator_tau_s, 0.0, 5.0);
        c.range("sim.actuator_rate_deg_s", s.actuator_rate_deg_s, 1.0, 500.0);
        c.range("sim.start_offset_m", s.start_offset_m, -50.0, 50.0);
        c.range("sim.start_heading_deg", s.start_heading_deg, -90.0, 90.0);
        c.range("sim.max_time_s", s.max_time_s, 0.0, 1e7);
        c.range("sim.accel_mps2", s.accel_mps2, 0.05, 10.0);
        c.range("sim.gnss_markov_sigma_m", s.gnss_markov_sigma_m, 0.0, 1.0);
        c.range("sim.gnss_markov_tau_s", s.gnss_markov_tau_s, 0.1, 3600.0);
        c.range(
            "sim.gnss_multipath_rate_per_h",
            s.gnss_multipath_rate_per_h,
            0.0,
            3600.0,
        );
        c.range("sim.gnss_multipath_m", s.gnss_multipath_m, 0.0, 10.0);
        c.range(
            "sim.gnss_multipath_duration_s",
            s.gnss_multipath_duration_s,
            0.1,
            600.0,
        );
        for (i, w) in s.gnss_float_windows_s.iter().enumerate() {
            if !(w[0].is_finite() && w[0] >= 0.0 && w[1].is_finite() && w[1] > 0.0) {
                c.push(
                    &format!("sim.gnss_float_windows_s[{i}]"),
                    format!("{w:?}"),
                    "must be [start_s, duration_s] with start_s >= 0 and duration_s > 0",
                );
            }
        }
        c.range("sim.gnss_float_sigma_m", s.gnss_float_sigma_m, 0.0, 10.0);
        c.range("sim.gnss_float_tau_s", s.gnss_float_tau_s, 0.1, 3600.0);
        c.range("sim.terrain_slope_deg", s.terrain_slope_deg, -30.0, 30.0);
        c.range(
            "sim.terrain_downhill_deg",
            s.terrain_downhill_deg,
            -360.0,
            360.0,
        );
        c.range(
            "sim.terrain_slope_amp_deg",
            s.terrain_slope_amp_deg,
            0.0,
            30.0,
        );
        c.range(
            "sim.terrain_wavelength_m",
            s.terrain_wavelength_m,
            1.0,
            100_000.0,
        );
        if s.terrain_slope_deg.abs() + s.terrain_slope_amp_deg > 30.0 {
            c.push(
                "sim.terrain_slope_amp_deg",
                fmt_num(s.terrain_slope_amp_deg),
                "|sim.terrain_slope_deg| + sim.terrain_slope_amp_deg must be at most 30",
            );
        }
        c.range("sim.imu_rate_hz", s.imu_rate_hz, 0.0, 1000.0);
        c.range("sim.imu_noise_deg", s.imu_noise_deg, 0.0, 5.0);
        c.range(
            "sim.slip_per_roll_mps_per_deg",
            s.slip_per_roll_mps_per_deg,
            -1.0,
            1.0,
        );
        c.range("sim.slip_mps", s.slip_mps, -2.0, 2.0);
        c.range("sim.was_bias_deg", s.was_bias_deg, -10.0, 10.0);
        c.range(
            "sim.actuator_deadband_deg",
            s.actuator_deadband_deg,
            0.0,
            5.0,
        );
        c.range(
            "sim.actuator_backlash_deg",
            s.actuator_backlash_deg,
            0.0,
            10.0,
        );
        let b = &self.bus;
        if b.interface.trim().is_empty() || b.interface.len() > 15 {
            c.push(
                "bus.interface",
                format!("{:?}", b.interface),
                "must be an interface name of 1 to 15 characters",
            );
        }
        if b.source_address > 253 {
            c.push(
                "bus.source_address",
                b.source_address.to_string(),
                "must be a J1939 address in 0..=253",
            );
        }
        c.range("bus.status_period_s", b.status_period_s, 0.01, 10.0);
        let f = &self.safety;
        c.range("safety.gnss_timeout_s", f.gnss_timeout_s, 0.05, 5.0);
        c.range(
            "safety.rtk_float_tolerance_s",
            f.rtk_float_tolerance_s,
            0.0,
            3600.0,
        );
        c.range(
            "safety.wheel_angle_timeout_s",
            f.wheel_angle_timeout_s,
            0.02,
            2.0,
        );
        c.range("safety.min_speed_kmh", f.min_speed_kmh, 0.0, 50.0);
        c.range("safety.max_stop_time_s", f.max_stop_time_s, 0.0, 120.0);
        c.range("safety.max_speed_kmh", f.max_speed_kmh, 0.5, 60.0);
        if f.min_speed_kmh >= f.max_speed_kmh {
            c.push(
                "safety.min_speed_kmh",
                fmt_num(f.min_speed_kmh),
                "must be below safety.max_speed_kmh",
            );
        }
        c.range("safety.override_angle_deg", f.override_angle_deg, 0.5, 90.0);
        c.range("safety.override_time_s", f.override_time_s, 0.0, 10.0);
        c.range("safety.max_engage_xte_m", f.max_engage_xte_m, 0.01, 50.0);
        c.range(
            "safety.max_engage_heading_error_deg",
            f.max_engage_heading_error_deg,
            1.0,
            180.0,
        );
        c.range(
            "safety.max_wheel_rate_deg_s",
            f.max_wheel_rate_deg_s,
            1.0,
            500.0,
        );
        c.range("safety.a_lat_max_m_s2", f.a_lat_max_m_s2, 0.1, 20.0);
        c.range(
            "safety.actuator_dead_time_s",
            f.actuator_dead_time_s,
            0.0,
            0.5,
        );
        c.range("safety.actuator_tau_s", f.actuator_tau_s, 0.0, 5.0);
        c.range(
            "safety.actuator_rate_deg_s",
            f.actuator_rate_deg_s,
            1.0,
            500.0,
        );
        c.range("vehicle.length_m", v.length_m, 0.5, 40.0);
        c.range("vehicle.width_m", v.width_m, 0.3, 20.0);
        c.range(
            "vehicle.rear_axle_from_rear_m",
            v.rear_axle_from_rear_m,
            0.0,
            40.0,
        );
        if v.rear_axle_from_rear_m > v.length_m {
            c.push(
                "vehicle.rear_axle_from_rear_m",
                fmt_num(v.rear_axle_from_rear_m),
                "must be at most vehicle.length_m",
            );
        }
        self.validate_maneuver(&mut c);
        if !["error", "warn", "info", "debug", "trace"].contains(&self.daemon.log_level.as_str()) {
            c.push(
                "daemon.log_level",
                format!("{:?}", self.daemon.log_level),
                "must be one of error, warn, info, debug, trace",
            );
        }
        if self.daemon.realtime_priority > 99 {
            c.push(
                "daemon.realtime_priority",
                self.daemon.realtime_priority.to_string(),
                "must be in 0..=99 (0 = normal scheduling)",
            );
        }
        if self.progress.state_dir.trim().is_empty() {
            c.push("progress.state_dir", "\"\"".into(), "must not be empty");
        }
        c.problems
    }

    fn validate_maneuver(&self, c: &mut Checker) {
        let m = &self.maneuver;
        if m.curve == CurveChoice::Cc && self.vehicle.max_curvature_rate_per_m2 <= 0.0 {
            c.push(
                "vehicle.max_curvature_rate_per_m2",
                fmt_num(self.vehicle.max_curvature_rate_per_m2),
                "must be > 0 for continuous-curvature manoeuvres (maneuver.curve = \"cc\")",
            );
        }
        c.range(
            "maneuver.implement_length_m",
            m.implement_length_m,
            0.0,
            40.0,
        );
        if m.implement_length_m > 0.0 {
            c.range("maneuver.implement_width_m", m.implement_width_m, 0.1, 60.0);
        }
        c.range("maneuver.implement_hitch_m", m.implement_hitch_m, 0.0, 20.0);
        c.range("maneuver.clearance_m", m.clearance_m, 0.0, 5.0);
        c.range(
            "maneuver.sample_tolerance_m",
            m.sample_tolerance_m,
            0.01,
            2.0,
        );
        if m.clearance_m.is_finite() && m.clearance_m < 0.5 * m.sample_tolerance_m {
            c.push(
                "maneuver.clearance_m",
                fmt_num(m.clearance_m),
                "must be at least half of maneuver.sample_tolerance_m, or sampled checks may miss a corner cut between samples",
            );
        }
        c.range("maneuver.grid_cell_m", m.grid_cell_m, 0.1, 1000.0);
        c.range("maneuver.expansion_step_m", m.expansion_step_m, 0.5, 100.0);
        c.range("maneuver.expansion_join_m", m.expansion_join_m, 0.0, 20.0);
        let count = |c: &mut Checker, key: &str, v: usize, lo: usize, hi: usize| {
            if !(lo..=hi).contains(&v) {
                c.push(
                    key,
                    v.to_string(),
                    &format!("must be an integer in {lo}..={hi}"),
                );
            }
        };
        count(
            c,
            "maneuver.expansion_max_depth",
            m.expansion_max_depth,
            1,
            100,
        );
        count(
            c,
            "maneuver.expansion_max_legs",
            m.expansion_max_legs,
            2,
            100_000,
        );
        for (i, pat) in m.goal_patterns.iter().enumerate() {
            if crate::plan::maneuver::search::parse_pattern(pat).is_err() {
                c.push(
                    &format!("maneuver.goal_patterns[{i}]"),
                    format!("{pat:?}"),
                    "must be curves l/r, `_`, then as many directions p/n, e.g. \"lrlr_pnpn\"",
                );
            }
        }
        c.range("maneuver.heading_step_deg", m.heading_step_deg, 1.0, 90.0);
        c.range(
            "maneuver.primitive_max_deg",
            m.primitive_max_deg,
            0.0,
            180.0,
        );
        c.range("maneuver.straight_step_m", m.straight_step_m, 0.1, 50.0);
        c.range("maneuver.reverse_penalty", m.reverse_penalty, 1.0, 100.0);
        c.range("maneuver.cusp_penalty_m", m.cusp_penalty_m, 0.0, 1000.0);
        c.range("maneuver.xy_resolution_m", m.xy_resolution_m, 0.05, 50.0);
        c.range(
            "maneuver.heading_resolution_deg",
            m.heading_resolution_deg,
            1.0,
            90.0,
        );
        count(
            c,
            "maneuver.max_expansions",
            m.max_expansions,
            1,
            10_000_000,
        );
        count(
            c,
            "maneuver.pattern_max_expansions",
            m.pattern_max_expansions,
            0,
            10_000_000,
        );
        count(
            c,
            "maneuver.search_max_expansions",
            m.search_max_expansions,
            1,
            10_000_000,
        );
        count(c, "maneuver.analytic_every", m.analytic_every, 1, 10_000);
        count(
            c,
            "maneuver.extra_expansions",
            m.extra_expansions,
            0,
            10_000_000,
        );
        count(c, "maneuver.fallback_points", m.fallback_points, 1, 100);
    }

    /// The keys that cannot change while the daemon runs a job: those defining the job (the
    /// field planning of `[field]` included), the bus identity and the control period.
    /// Returns the ones that differ in `new`.
    pub fn fixed_key_changes(&self, new: &Config) -> Vec<&'static str> {
        let mut v = Vec::new();
        let mut check = |key: &'static str, same: bool| {
            if !same {
                v.push(key);
            }
        };
        check("job", self.job == new.job);
        check("field", self.field == new.field);
        check("guidance", self.guidance == new.guidance);
        check(
            "vehicle.r_min_m",
            self.vehicle.r_min_m == new.vehicle.r_min_m,
        );
        check("control.dt_s", self.control.dt_s == new.control.dt_s);
        check("bus.interface", self.bus.interface == new.bus.interface);
        check(
            "bus.source_address",
            self.bus.source_address == new.bus.source_address,
        );
        check(
            "bus.status_socket",
            self.bus.status_socket == new.bus.status_socket,
        );
        check(
            "progress.state_dir",
            self.progress.state_dir == new.progress.state_dir,
        );
        v
    }

    /// The resolved configuration as TOML text.
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self).unwrap_or_else(|e| format!("# cannot print: {e}"))
    }

    /// Control period, s.
    pub fn dt(&self) -> f64 {
        self.control.dt_s
    }
    /// Driving speed, m/s.
    pub fn speed(&self) -> f64 {
        self.control.speed_kmh / 3.6
    }
    /// Radius of the planned turns, m: `vehicle.r_min_m`, or more when the job speed would
    /// need a lateral acceleration above `safety.a_lat_max_m_s2` on it (v² / a_lat_max). The
    /// supervisor would not allow the tighter turn at that speed, so it is not planned.
    pub fn turn_radius(&self) -> f64 {
        let v = self.speed();
        let a = self.safety.a_lat_max_m_s2;
        if a > 0.0 && a.is_finite() {
            self.vehicle.r_min_m.max(v * v / a)
        } else {
            self.vehicle.r_min_m
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
        }
    }
}

#[derive(Default)]
struct Checker {
    problems: Vec<Problem>,
}

impl Checker {
    fn push(&mut self, key: &str, value: String, rule: &str) {
        self.problems.push(Problem {
            key: key.to_string(),
            value,
            rule: rule.to_string(),
        });
    }
    fn range(&mut self, key: &str, v: f64, lo: f64, hi: f64) {
        if !(v.is_finite() && v >= lo && v <= hi) {
            self.push(
                key,
                fmt_num(v),
                &format!("must be in {}..={}", fmt_num(lo), fmt_num(hi)),
            );
        }
    }
    fn finite2(&mut self, key: &str, v: [f64; 2]) {
        if !(v[0].is_finite() && v[1].is_finite()) {
            self.push(
                key,
                format!("{v:?}"),
                "must be two finite numbers [east, north]",
            );
        }
    }
}

fn fmt_num(v: f64) -> String {
    if v.is_finite() && v == v.trunc() && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        format!("{v}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turns_are_planned_no_tighter_than_the_speed_allows() {
        let mut cfg = Config::default();
        // 10 km/h, 2 m/s²: v²/a = 3.9 m < r_min 5 m.
        assert_eq!(cfg.turn_radius(), cfg.vehicle.r_min_m);
        cfg.control.speed_kmh = 15.0;
        let v: f64 = 15.0 / 3.6;
        assert!((cfg.turn_radius() - v * v / 2.0).abs() < 1e-12);
        assert!(cfg.coverage_params().r_min > 8.0);
        assert!(crate::control::ab_params(&cfg).turn.r_min > 8.0);
    }

    #[test]
    fn defaults_are_valid() {
        assert!(Config::default().validate().is_empty());
    }

    #[test]
    fn messages_name_key_value_and_rule() {
        let cfg = Config::parse_with(
            "[guidance]\na = 0\n[control]\ndt_s = 2\n",
            &["vehicle.wheelbase_m=-1".to_string()],
        )
        .unwrap();
        let msgs: Vec<String> = cfg.validate().iter().map(|p| p.to_string()).collect();
        assert!(msgs.contains(&"guidance.a = 0: must be an integer >= 1".to_string()));
        assert!(msgs.contains(&"control.dt_s = 2: must be in 0.005..=0.5".to_string()));
        assert!(msgs
            .iter()
            .any(|m| m.starts_with("vehicle.wheelbase_m = -1: must be in")));
        assert!(msgs.len() >= 3, "all problems at once: {msgs:?}");
    }

    #[test]
    fn sim_disturbance_keys_parse_and_validate() {
        let cfg = Config::parse_with(
            "[sim]\ngnss_float_windows_s = [[60.0, 20.0], [-1.0, 5.0]]\nwas_bias_deg = 12\n\
             actuator_backlash_deg = -1\nterrain_slope_deg = 25\nterrain_slope_amp_deg = 10\n",
            &[],
        )
        .unwrap();
        assert_eq!(cfg.sim.gnss_float_windows_s[0], [60.0, 20.0]);
        let msgs: Vec<String> = cfg.validate().iter().map(|p| p.to_string()).collect();
        assert!(msgs.contains(
            &"sim.gnss_float_windows_s[1] = [-1.0, 5.0]: must be [start_s, duration_s] with \
              start_s >= 0 and duration_s > 0"
                .to_string()
        ));
        assert!(msgs.contains(&"sim.was_bias_deg = 12: must be in -10..=10".to_string()));
        assert!(msgs.contains(&"sim.actuator_backlash_deg = -1: must be in 0..=10".to_string()));
        assert!(msgs
            .iter()
            .any(|m| m.starts_with("sim.terrain_slope_amp_deg = 10: |sim.terrain_slope_deg|")));
        assert_eq!(msgs.len(), 4, "{msgs:?}");
        // The defaults are all off.
        let d = SimConfig::default();
        assert!(d.gnss_markov_sigma_m == 0.0 && d.gnss_multipath_rate_per_h == 0.0);
        assert!(d.gnss_float_windows_s.is_empty() && d.terrain_slope_deg == 0.0);
        assert!(d.imu_rate_hz == 0.0 && d.slip_mps == 0.0 && d.slip_per_roll_mps_per_deg == 0.0);
        assert!(d.was_bias_deg == 0.0);
        assert!(d.actuator_deadband_deg == 0.0 && d.actuator_backlash_deg == 0.0);
    }

    #[test]
    fn observer_and_arcs_keys_parse_and_validate() {
        let cfg = Config::parse_with(
            "[track]\nobserver_drift_tau_s = -1\nobserver_min_speed_mps = 0\n\
             observer_slip_limit_mps_per_deg = 2\nobserver_coast_max_s = 700\n\
             [job]\nkind = \"arcs\"\narc_sweep_deg = 360\nline_num = 0\n",
            &[],
        )
        .unwrap();
        assert_eq!(cfg.job.kind, JobKind::Arcs);
        let msgs: Vec<String> = cfg.validate().iter().map(|p| p.to_string()).collect();
        for m in [
            "track.observer_drift_tau_s = -1: must be in 0..=600",
            "track.observer_min_speed_mps = 0: must be in 0.1..=10",
            "track.observer_slip_limit_mps_per_deg = 2: must be in 0..=1",
            "track.observer_coast_max_s = 700: must be in 0..=600",
            "job.arc_sweep_deg = 360: must be in 1..=359",
            "job.line_num = 0: must be in 1..=1000 when job.kind = \"arcs\"",
        ] {
            assert!(msgs.contains(&m.to_string()), "{m} not in {msgs:?}");
        }
        assert_eq!(msgs.len(), 6, "{msgs:?}");
        // The observer is on by default (the default tracker uses it).
        let t = TrackConfig::default();
        assert!(t.observer_bias_tau_s > 0.0 && t.observer_drift_tau_s > 0.0);
        assert!(t.observer_slip_tau_s > 0.0 && t.observer_coast_max_s > 0.0);
        assert!(Config::default().validate().is_empty());
    }

    #[test]
    fn unknown_keys_are_rejected() {
        let err = Config::parse_with("[control]\ndt = 0.1\n", &[]).unwrap_err();
        assert!(err.to_string().contains("unknown field `dt`"), "{err}");
        let err = Config::parse_with("", &["track.nope=1".into()]).unwrap_err();
        assert!(err.to_string().contains("nope"), "{err}");
        let err = Config::parse_with("[control]\nspeed_kmn = 9\n", &[]).unwrap_err();
        assert!(
            err.to_string().contains("did you mean `speed_kmh`?"),
            "{err}"
        );
        let err = Config::parse_with("[vehicel]\n", &[]).unwrap_err();
        assert!(err.to_string().contains("did you mean `vehicle`?"), "{err}");
    }

    #[test]
    fn overrides_parse_values_and_strings() {
        let cfg = Config::parse_with(
            "",
            &[
                "track.kind = pure_pursuit".into(),
                "job.line_num=100".into(),
                "job.point_b_m=[10.0, 20.5]".into(),
            ],
        )
        .unwrap();
        assert_eq!(cfg.track.kind, TrackerChoice::PurePursuit);
        assert_eq!(cfg.job.line_num, 100);
        assert_eq!(cfg.job.point_b_m, [10.0, 20.5]);
        assert!(matches!(
            Config::parse_with("", &["noequals".into()]),
            Err(ConfigError::BadOverride(_))
        ));
    }

    #[test]
    fn nan_is_a_problem_not_a_panic() {
        let cfg = Config::parse_with("[control]\nspeed_kmh = nan\n", &[]).unwrap();
        let msgs: Vec<String> = cfg.validate().iter().map(|p| p.to_string()).collect();
        assert!(msgs
            .iter()
            .any(|m| m.starts_with("control.speed_kmh = NaN")));
    }

    #[test]
    fn job_keys_are_fixed_tuning_keys_are_not() {
        let a = Config::default();
        let tuned = Config::parse_with(
            "[track]\nld_min_m = 4.0\n[safety]\na_lat_max_m_s2 = 1.5\n",
            &[],
        )
        .unwrap();
        assert!(a.fixed_key_changes(&tuned).is_empty());
        let moved =
            Config::parse_with("[job]\nline_width_m = 4.0\n[vehicle]\nr_min_m = 6.0\n", &[])
                .unwrap();
        assert_eq!(a.fixed_key_changes(&moved), vec!["job", "vehicle.r_min_m"]);
        // [field] shapes the running field plan: a SIGHUP cannot change it either.
        let replanned = Config::parse_with("[field]\nheadland_passes = 1\n", &[]).unwrap();
        assert_eq!(a.fixed_key_changes(&replanned), vec!["field"]);
    }

    #[test]
    fn field_section_parses_validates_and_builds_params() {
        let cfg = Config::parse_with(
            "[field]\nswath_angle = \"fixed\"\nswath_angle_deg = 90\nroute = \"skip\"\norigin = \"config\"\n",
            &[],
        )
        .unwrap();
        let p = cfg.coverage_params();
        assert!(
            matches!(p.swath_angle, crate::plan::coverage::SwathAngle::Fixed { angle } if (angle - std::f64::consts::FRAC_PI_2).abs() < 1e-12)
        );
        assert_eq!(p.route, crate::plan::coverage::RouteOrder::Skip);
        assert_eq!(p.line_width, cfg.job.line_width_m);
        assert_eq!(
            cfg.field_load_options().origin.map(|o| o.lat_deg),
            Some(cfg.job.origin_lat_deg)
        );
        let bad = Config::parse_with("[field]\nboundary_tolerance_m = -1\n", &[]).unwrap();
        assert!(bad
            .validate()
            .iter()
            .any(|p| p.key == "field.boundary_tolerance_m"));
        assert!(Config::parse_with("[field]\nswath_angle = \"diagonal\"\n", &[]).is_err());
    }

    #[test]
    fn maneuver_section_parses_validates_and_builds_params() {
        let cfg = Config::parse_with(
            "[maneuver]\ncurve = \"rs\"\nimplement_length_m = 2.0\nimplement_width_m = 3.0\n\
             goal_patterns = [\"rlr_pnp\"]\n[vehicle]\nlength_m = 5.0\n",
            &["maneuver.heading_step_deg=5".into()],
        )
        .unwrap();
        assert!(cfg.validate().is_empty(), "{:?}", cfg.validate());
        assert_eq!(cfg.maneuver.curve, CurveChoice::Rs);
        let p = cfg.maneuver_params();
        assert_eq!(p.footprint.vehicle.length_m, 5.0);
        assert_eq!(p.footprint.implement.map(|i| i.width_m), Some(3.0));
        assert!((p.heading_step_rad - 5f64.to_radians()).abs() < 1e-12);
        assert!((cfg.maneuver_curve_params().kappa_max - 1.0 / cfg.vehicle.r_min_m).abs() < 1e-12);
        let bad = Config::parse_with(
            "[maneuver]\ngoal_patterns = [\"lrx_pn\"]\nclearance_m = 0.05\nsample_tolerance_m = 0.3\n\
             max_expansions = 0\nreverse_penalty = 0.5\n[vehicle]\nrear_axle_from_rear_m = 9\n",
            &[],
        )
        .unwrap();
        let keys: Vec<String> = bad.validate().into_iter().map(|p| p.key).collect();
        for k in [
            "maneuver.goal_patterns[0]",
            "maneuver.clearance_m",
            "maneuver.max_expansions",
            "maneuver.reverse_penalty",
            "vehicle.rear_axle_from_rear_m",
        ] {
            assert!(keys.iter().any(|x| x == k), "{k} in {keys:?}");
        }
        assert!(Config::parse_with("[maneuver]\ncurve = \"dubins\"\n", &[]).is_err());
    }

    #[test]
    fn r_min_must_be_steerable() {
        let cfg = Config::parse_with("[vehicle]\nr_min_m = 1.0\n", &[]).unwrap();
        assert!(cfg.validate().iter().any(|p| p.key == "vehicle.r_min_m"));
    }
}
