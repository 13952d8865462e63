//! `[calibration]`: how `agsteer calibrate` and agsteerd's calibration mode run the procedure
//! (issue 15 point 4).
//!
//! Owns the section's keys, their defaults and their range checks, and the procedure's
//! parameters ([`crate::calibrate::CalibrationParams`]) from them and `[vehicle]`.

use super::check::Checker;
use super::Config;
use crate::calibrate::CalibrationParams;
use serde::{Deserialize, Serialize};

/// `[calibration]`: the calibration procedure.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CalibrationConfig {
    /// Every hold of the steering tests and of the drive lasts this × its nominal time
    /// (0.1..=3, default 1: about 85 s of tests at a standstill and 80 s of drive).
    pub time_scale: f64,
    /// Finish with the two-way pass for the antenna's lateral offset (the operator steers
    /// along a marked line and back; README, Calibration). Off: `vehicle.antenna_left_m`
    /// stays as configured.
    pub antenna_pass: bool,
}

impl Default for CalibrationConfig {
    fn default() -> Self {
        CalibrationConfig {
            time_scale: 1.0,
            antenna_pass: true,
        }
    }
}

impl CalibrationConfig {
    /// Checks of `[calibration]`.
    pub(crate) fn validate(&self, c: &mut Checker) {
        c.range("calibration.time_scale", self.time_scale, 0.1, 3.0);
    }
}

impl Config {
    /// The calibration procedure's parameters: the geometry and wheel-angle limit of
    /// `[vehicle]` (steps and holds 5° inside the limit), the time scale of `[calibration]`.
    pub fn calibration_params(&self) -> CalibrationParams {
        let v = &self.vehicle;
        let mut p = CalibrationParams::default();
        p.geometry.wheelbase = v.wheelbase_m;
        p.geometry.antenna_forward = v.antenna_forward_m;
        p.geometry.antenna_left = v.antenna_left_m;
        p.max_angle = (self.max_wheel_angle() - 5f64.to_radians()).max(5f64.to_radians());
        p.step = p.step.min(p.max_angle);
        p.hold_angle = p.hold_angle.min(p.max_angle);
        p.time_scale = self.calibration.time_scale;
        p.antenna_pass = self.calibration.antenna_pass;
        p
    }
}
