//! `[safety]`: engage gating, input freshness and command limits.
//!
//! Owns the section's keys, their defaults and their range checks.

use super::check::{fmt_num, Checker};
use serde::{Deserialize, Serialize};

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
    /// Tracking supervision on work lines: |XTE| beyond off_line_m for off_line_time_s is
    /// `off_line`, m (0 = off) and s.
    pub off_line_m: f64,
    pub off_line_time_s: f64,
    /// The line must be acquired (|XTE| below off_line_m once) within this distance, m.
    pub off_line_acquire_m: f64,
    /// Off work lines (turns, transits, approaches, reversing): farther than this from the
    /// path for off_line_time_s is `off_path`, m (0 = off).
    pub off_path_m: f64,
    /// A weave is `tracking_unstable`: unstable_swings alternate swings (0 = off) within
    /// unstable_window_s of the XTE beyond ±unstable_xte_m (0 = not watched) or of the wheel
    /// angle beyond ±unstable_wheel_deg (0 = not watched) about its moving mean (time
    /// constant unstable_wheel_mean_s).
    pub unstable_xte_m: f64,
    pub unstable_wheel_deg: f64,
    pub unstable_swings: u32,
    pub unstable_window_s: f64,
    pub unstable_wheel_mean_s: f64,
    /// Heading against course over ground: above heading_mismatch_min_speed_kmh, a GNSS
    /// heading whose course over ground (allowing for the antenna's crab in a turn and for
    /// reversing) is more than heading_mismatch_deg off (0 = off) for heading_mismatch_time_s
    /// is `heading_mismatch`.
    pub heading_mismatch_deg: f64,
    pub heading_mismatch_time_s: f64,
    pub heading_mismatch_min_speed_kmh: f64,
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
            off_line_m: 2.0,
            off_line_time_s: 0.5,
            off_line_acquire_m: 30.0,
            off_path_m: 4.0,
            unstable_xte_m: 0.2,
            unstable_wheel_deg: 3.0,
            unstable_swings: 4,
            unstable_window_s: 40.0,
            unstable_wheel_mean_s: 2.0,
            heading_mismatch_deg: 30.0,
            heading_mismatch_time_s: 1.0,
            heading_mismatch_min_speed_kmh: 2.0,
        }
    }
}

impl SafetyConfig {
    /// The supervisor's tracking supervision, SI.
    pub fn tracking_params(&self) -> crate::safety::TrackingParams {
        crate::safety::TrackingParams {
            off_line: self.off_line_m,
            off_line_time: self.off_line_time_s,
            off_line_acquire: self.off_line_acquire_m,
            unstable_xte: self.unstable_xte_m,
            unstable_wheel: self.unstable_wheel_deg.to_radians(),
            unstable_swings: self.unstable_swings as usize,
            unstable_window: self.unstable_window_s,
            wheel_mean_tau: self.unstable_wheel_mean_s,
            off_path: self.off_path_m,
        }
    }

    /// The heading check, SI, for an antenna at (`antenna_forward`, `antenna_left`) m.
    pub fn heading_check_params(
        &self,
        antenna_forward: f64,
        antenna_left: f64,
    ) -> crate::safety::HeadingCheckParams {
        crate::safety::HeadingCheckParams {
            limit: self.heading_mismatch_deg.to_radians(),
            time: self.heading_mismatch_time_s,
            min_speed: self.heading_mismatch_min_speed_kmh / 3.6,
            antenna_forward,
            antenna_left,
        }
    }

    /// Range checks of `[safety]`.
    pub(crate) fn validate(&self, c: &mut Checker) {
        let f = self;
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
        c.range("safety.off_line_m", f.off_line_m, 0.0, 50.0);
        c.range("safety.off_line_time_s", f.off_line_time_s, 0.0, 60.0);
        c.range(
            "safety.off_line_acquire_m",
            f.off_line_acquire_m,
            1.0,
            1000.0,
        );
        c.range("safety.off_path_m", f.off_path_m, 0.0, 50.0);
        c.range("safety.unstable_xte_m", f.unstable_xte_m, 0.0, 10.0);
        c.range("safety.unstable_wheel_deg", f.unstable_wheel_deg, 0.0, 45.0);
        c.range(
            "safety.unstable_swings",
            f64::from(f.unstable_swings),
            0.0,
            crate::safety::tracking::MAX_SWINGS as f64,
        );
        if f.unstable_swings == 1 {
            c.push(
                "safety.unstable_swings",
                "1".to_string(),
                "must be 0 (off) or at least 2 (one swing is a single step, not an oscillation)",
            );
        }
        c.range("safety.unstable_window_s", f.unstable_window_s, 1.0, 600.0);
        c.range(
            "safety.unstable_wheel_mean_s",
            f.unstable_wheel_mean_s,
            0.1,
            60.0,
        );
        c.range(
            "safety.heading_mismatch_deg",
            f.heading_mismatch_deg,
            0.0,
            180.0,
        );
        if f.heading_mismatch_deg > 0.0 && f.heading_mismatch_deg < 5.0 {
            c.push(
                "safety.heading_mismatch_deg",
                fmt_num(f.heading_mismatch_deg),
                "must be 0 (off) or at least 5 (course noise and tyre slip reach a few degrees)",
            );
        }
        c.range(
            "safety.heading_mismatch_time_s",
            f.heading_mismatch_time_s,
            0.0,
            60.0,
        );
        c.range(
            "safety.heading_mismatch_min_speed_kmh",
            f.heading_mismatch_min_speed_kmh,
            0.5,
            50.0,
        );
    }
}
