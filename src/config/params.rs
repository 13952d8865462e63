//! Parameter builders: the edge units of the file (degrees, km/h) converted to the SI
//! parameter structs of the planners and the supervisor.

use super::{Config, FieldOrigin, SwathAngleChoice};

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
