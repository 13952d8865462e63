//! `[vehicle]`: the tractor's geometry (wheelbase, turning radius, wheel angle, antenna,
//! body rectangle).
//!
//! Owns the section's keys, their defaults and their range checks. The checks come in two
//! parts (steering geometry, body rectangle) because the problems are reported in the order
//! they always were: the body after `[safety]`.

use super::check::{fmt_num, Checker};
use serde::{Deserialize, Serialize};

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
    /// the continuous-curvature turns and manoeuvres, docs/METHODS.md, Curves). It comes from the
    /// steering speed: about max wheel rate (rad/s) / (wheelbase (m) · speed in turns (m/s));
    /// 30°/s, 3 m and 6 km/h give 0.10. 0 = turns of arcs only (curvature steps at their ends; and
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
    /// Wheel-angle sensor gain: it reads `was_gain` × the true angle + `was_offset_deg`
    /// (measured by `agsteer calibrate`). Angles from the bus are corrected, commands sent in
    /// the sensor's terms.
    pub was_gain: f64,
    /// Wheel-angle sensor reading of straight-ahead wheels, degrees (`agsteer calibrate`).
    pub was_offset_deg: f64,
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
            was_gain: 1.0,
            was_offset_deg: 0.0,
        }
    }
}

impl VehicleConfig {
    /// Range checks of the steering geometry and antenna keys.
    pub(crate) fn validate_steering(&self, c: &mut Checker) {
        let v = self;
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
        c.range("vehicle.was_gain", v.was_gain, 0.5, 2.0);
        c.range("vehicle.was_offset_deg", v.was_offset_deg, -10.0, 10.0);
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
    }

    /// Range checks of the body rectangle (manoeuvre collision checks).
    pub(crate) fn validate_body(&self, c: &mut Checker) {
        let v = self;
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
    }
}
