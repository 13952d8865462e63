//! `[sim]`: the vehicle simulator (sensors, actuator, disturbances, driver's speed profile).
//!
//! Owns the section's keys, their defaults and their range checks.

use super::check::{fmt_num, Checker};
use crate::sim::can_node::SpeedProfile;
use crate::sim::{Disturbances, LateralDynamics, SimParams};
use serde::{Deserialize, Serialize};

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
    /// Initial lateral offset of the vehicle from line A→B (positive = left), m. A field job
    /// or a resumed one starts this far left of its current path's start.
    pub start_offset_m: f64,
    /// Initial heading error relative to A→B (a field or resumed job: its current path),
    /// degrees.
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
    /// A wrong GNSS heading: from `heading_bias_at_s` on, the reported heading (not the
    /// course over ground) is this far off, degrees (a receiver's heading 90° off).
    pub heading_bias_deg: f64,
    pub heading_bias_at_s: f64,
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
    /// The steering controller's command timeout, s: with no valid steering command for this
    /// long it leaves automatic steering, and the simulated driver centres the wheels and
    /// keeps straight (0 = off: the last command is held for ever, as no real ECU does).
    pub command_timeout_s: f64,
    // The true vehicle where it differs from the controller's model (`[vehicle]`).
    /// True wheelbase − `vehicle.wheelbase_m`, m.
    pub wheelbase_error_m: f64,
    /// True antenna position − `vehicle.antenna_*_m`: forward, left, up, m.
    pub antenna_error_forward_m: f64,
    pub antenna_error_left_m: f64,
    pub antenna_error_up_m: f64,
    /// Wheel-angle sensor gain: it reads this × the true angle (+ `was_bias_deg`).
    pub was_gain: f64,
    /// The dynamic lateral model (tyre slip); off = the kinematic bicycle.
    pub tyre_slip: bool,
    /// Mass, kg; yaw moment of inertia, kg·m²; centre of gravity ahead of the rear axle, m.
    pub mass_kg: f64,
    pub yaw_inertia_kg_m2: f64,
    pub cg_ahead_of_rear_m: f64,
    /// Cornering stiffness of the front and rear axle (both tyres), N per degree of slip.
    pub cornering_stiffness_front_n_per_deg: f64,
    pub cornering_stiffness_rear_n_per_deg: f64,
    /// Tyre relaxation length, m.
    pub relaxation_length_m: f64,
    /// Tyre-soil friction coefficient (lateral force limit / axle load).
    pub tyre_friction: f64,
    /// Implement side draft: lateral force at the hitch, N (positive pulls right), and the
    /// hitch's distance behind the rear axle, m.
    pub implement_side_force_n: f64,
    pub implement_hitch_m: f64,
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
            heading_bias_deg: 0.0,
            heading_bias_at_s: 0.0,
            actuator_deadband_deg: 0.0,
            actuator_backlash_deg: 0.0,
            speed_min_kmh: 4.0,
            speed_max_kmh: 0.0,
            speed_turn_angle_deg: 5.0,
            command_timeout_s: 0.25,
            wheelbase_error_m: 0.0,
            antenna_error_forward_m: 0.0,
            antenna_error_left_m: 0.0,
            antenna_error_up_m: 0.0,
            was_gain: 1.0,
            tyre_slip: false,
            mass_kg: 8000.0,
            yaw_inertia_kg_m2: 18_000.0,
            cg_ahead_of_rear_m: 1.2,
            cornering_stiffness_front_n_per_deg: 2100.0,
            cornering_stiffness_rear_n_per_deg: 4200.0,
            relaxation_length_m: 0.6,
            tyre_friction: 0.6,
            implement_side_force_n: 0.0,
            implement_hitch_m: 1.0,
        }
    }
}

impl SimConfig {
    /// Range checks of `[sim]`.
    pub(crate) fn validate(&self, c: &mut Checker) {
        let s = self;
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
        c.range("sim.heading_bias_deg", s.heading_bias_deg, -180.0, 180.0);
        c.range("sim.heading_bias_at_s", s.heading_bias_at_s, 0.0, 1e6);
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
        c.range("sim.wheelbase_error_m", s.wheelbase_error_m, -2.0, 2.0);
        c.range(
            "sim.antenna_error_forward_m",
            s.antenna_error_forward_m,
            -2.0,
            2.0,
        );
        c.range(
            "sim.antenna_error_left_m",
            s.antenna_error_left_m,
            -2.0,
            2.0,
        );
        c.range("sim.antenna_error_up_m", s.antenna_error_up_m, -2.0, 2.0);
        c.range("sim.was_gain", s.was_gain, 0.7, 1.3);
        c.range("sim.command_timeout_s", s.command_timeout_s, 0.0, 10.0);
        c.range("sim.mass_kg", s.mass_kg, 300.0, 60_000.0);
        c.range(
            "sim.yaw_inertia_kg_m2",
            s.yaw_inertia_kg_m2,
            50.0,
            1_000_000.0,
        );
        c.range("sim.cg_ahead_of_rear_m", s.cg_ahead_of_rear_m, 0.01, 20.0);
        c.range(
            "sim.cornering_stiffness_front_n_per_deg",
            s.cornering_stiffness_front_n_per_deg,
            50.0,
            100_000.0,
        );
        c.range(
            "sim.cornering_stiffness_rear_n_per_deg",
            s.cornering_stiffness_rear_n_per_deg,
            50.0,
            100_000.0,
        );
        c.range("sim.relaxation_length_m", s.relaxation_length_m, 0.05, 5.0);
        c.range("sim.tyre_friction", s.tyre_friction, 0.1, 1.5);
        c.range(
            "sim.implement_side_force_n",
            s.implement_side_force_n,
            -50_000.0,
            50_000.0,
        );
        c.range("sim.implement_hitch_m", s.implement_hitch_m, 0.0, 10.0);
        if s.implement_side_force_n != 0.0 && !s.tyre_slip {
            c.push(
                "sim.implement_side_force_n",
                fmt_num(s.implement_side_force_n),
                "needs sim.tyre_slip = true (the kinematic model has no tyre to push against)",
            );
        }
    }

    /// Checks of `[sim]` against `[vehicle]`: the true wheelbase stays physical, the centre of
    /// gravity between the axles.
    /// A command timeout (when on) must outlast two control periods: the steering controller
    /// would otherwise drop out between two commands.
    pub(crate) fn validate_command_timeout(&self, dt_s: f64, c: &mut Checker) {
        let t = self.command_timeout_s;
        if t > 0.0 && dt_s.is_finite() && t < 2.0 * dt_s {
            c.push(
                "sim.command_timeout_s",
                super::check::fmt_num(t),
                &format!(
                    "must be 0 (off) or at least two control periods (control.dt_s = {})",
                    super::check::fmt_num(dt_s)
                ),
            );
        }
    }

    pub(crate) fn validate_plant(&self, wheelbase_m: f64, c: &mut Checker) {
        let s = self;
        let true_wheelbase = wheelbase_m + s.wheelbase_error_m;
        if true_wheelbase.is_nan() || true_wheelbase < 0.5 {
            c.push(
                "sim.wheelbase_error_m",
                fmt_num(s.wheelbase_error_m),
                "vehicle.wheelbase_m + sim.wheelbase_error_m must be at least 0.5",
            );
        }
        if s.tyre_slip && (s.cg_ahead_of_rear_m >= true_wheelbase || s.cg_ahead_of_rear_m.is_nan())
        {
            c.push(
                "sim.cg_ahead_of_rear_m",
                fmt_num(s.cg_ahead_of_rear_m),
                "must be less than the true wheelbase (vehicle.wheelbase_m + sim.wheelbase_error_m)",
            );
        }
    }
}

impl super::Config {
    /// The simulator's parameters: the true vehicle is the controller's model (`[vehicle]`) plus
    /// the plant's own errors (`[sim]`).
    pub fn sim_params(&self) -> SimParams {
        let cfg = self;
        let s = &cfg.sim;
        SimParams {
            // The true vehicle: the controller's model plus the plant's own errors.
            wheelbase: cfg.vehicle.wheelbase_m + s.wheelbase_error_m,
            max_wheel_angle: cfg.max_wheel_angle(),
            antenna_forward: cfg.vehicle.antenna_forward_m + s.antenna_error_forward_m,
            antenna_left: cfg.vehicle.antenna_left_m + s.antenna_error_left_m,
            antenna_up: cfg.vehicle.antenna_up_m + s.antenna_error_up_m,
            was_gain: s.was_gain,
            lateral: s.tyre_slip.then(|| LateralDynamics {
                mass: s.mass_kg,
                yaw_inertia: s.yaw_inertia_kg_m2,
                cg_ahead_of_rear: s.cg_ahead_of_rear_m,
                // Per degree → per radian.
                cornering_stiffness_front: s.cornering_stiffness_front_n_per_deg.to_degrees(),
                cornering_stiffness_rear: s.cornering_stiffness_rear_n_per_deg.to_degrees(),
                relaxation_length: s.relaxation_length_m,
                friction: s.tyre_friction,
                side_force: s.implement_side_force_n,
                hitch_behind_rear: s.implement_hitch_m,
            }),
            dead_time: s.actuator_dead_time_s,
            tau: s.actuator_tau_s,
            max_rate: s.actuator_rate_deg_s.to_radians(),
            gnss_rate_hz: s.gnss_rate_hz,
            gnss_latency: s.gnss_latency_s,
            gnss_sigma: s.gnss_sigma_m,
            heading_sigma: s.heading_sigma_deg.to_radians(),
            was_rate_hz: s.was_rate_hz,
            was_noise: s.was_noise_deg.to_radians(),
            step: s.step_s,
            seed: s.seed,
            accel: s.accel_mps2,
            dist: Disturbances {
                gnss_markov_sigma: s.gnss_markov_sigma_m,
                gnss_markov_tau: s.gnss_markov_tau_s,
                multipath_rate: s.gnss_multipath_rate_per_h / 3600.0,
                multipath_magnitude: s.gnss_multipath_m,
                multipath_duration: s.gnss_multipath_duration_s,
                float_windows: s
                    .gnss_float_windows_s
                    .iter()
                    .map(|w| (w[0], w[1]))
                    .collect(),
                float_sigma: s.gnss_float_sigma_m,
                float_tau: s.gnss_float_tau_s,
                terrain_slope: s.terrain_slope_deg.to_radians(),
                terrain_downhill: s.terrain_downhill_deg.to_radians(),
                terrain_slope_amp: s.terrain_slope_amp_deg.to_radians(),
                terrain_wavelength: s.terrain_wavelength_m,
                imu_rate_hz: s.imu_rate_hz,
                imu_noise: s.imu_noise_deg.to_radians(),
                // Per degree of roll → per radian.
                slip_per_roll: s.slip_per_roll_mps_per_deg.to_degrees(),
                slip: s.slip_mps,
                was_bias: s.was_bias_deg.to_radians(),
                heading_bias: s.heading_bias_deg.to_radians(),
                heading_bias_at: s.heading_bias_at_s,
                deadband: s.actuator_deadband_deg.to_radians(),
                backlash: s.actuator_backlash_deg.to_radians(),
            },
            ..SimParams::default()
        }
    }

    /// The simulated driver's speed profile, if one is set.
    pub fn speed_profile(&self) -> Option<SpeedProfile> {
        let s = &self.sim;
        (s.speed_max_kmh > 0.0).then(|| SpeedProfile {
            min: s.speed_min_kmh / 3.6,
            max: s.speed_max_kmh / 3.6,
            turn_angle: s.speed_turn_angle_deg.to_radians(),
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::config::Config;

    #[test]
    fn command_timeout_outlasts_two_control_periods() {
        let problems = |t: f64, dt: f64| {
            let mut cfg = Config::default();
            cfg.sim.command_timeout_s = t;
            cfg.control.dt_s = dt;
            cfg.validate()
                .into_iter()
                .filter(|p| p.key == "sim.command_timeout_s")
                .count()
        };
        assert_eq!(problems(0.25, 0.02), 0);
        assert_eq!(problems(0.0, 0.2), 0, "0 is off");
        assert_eq!(problems(0.25, 0.2), 1, "shorter than two periods");
        assert_eq!(problems(-1.0, 0.02), 1);
        assert_eq!(problems(f64::NAN, 0.02), 1);
    }
}
