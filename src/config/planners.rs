//! The planners' parameters from the file: AB lines, arcs, field coverage and loading,
//! manoeuvres. Part of [`Config::resolve`]; edge units converted here, once.

use super::{Config, FieldOrigin, LineSide, SwathAngleChoice};
use crate::geo::v2;
use crate::plan::abline::AbParams;
use crate::plan::arcs::ArcsParams;
use crate::plan::turns::TurnParams;

impl Config {
    /// The AB planner's parameters (turns planned at [`Config::turn_radius`] and
    /// [`Config::turn_curvature_rate`]).
    pub fn ab_params(&self) -> AbParams {
        let (j, g) = (&self.job, &self.guidance);
        AbParams {
            point_a: v2(j.point_a_m[0], j.point_a_m[1]),
            point_b: v2(j.point_b_m[0], j.point_b_m[1]),
            line_width: j.line_width_m,
            line_num: j.line_num,
            r_min: self.turn_radius(),
            side: match j.side {
                LineSide::Left => LineSide::Left,
                LineSide::Right => LineSide::Right,
            },
            block_extra: g.a.max(1) as u32,
            point_spacing: g.point_spacing_m,
            turn: TurnParams {
                r_min: self.turn_radius(),
                arc_step: g.turn_arc_step_deg.to_radians(),
                merge_distance: g.turn_merge_distance_m,
                point_spacing: g.point_spacing_m,
                max_points: g.turn_max_points,
                max_curvature_rate: self.turn_curvature_rate(),
            },
        }
    }

    /// The arcs job's shape (`job.kind = "arcs"`): about `job.point_a_m`, the first line
    /// starting due South of it, heading East.
    pub fn arcs_params(&self) -> ArcsParams {
        let ab = self.ab_params();
        ArcsParams {
            centre: ab.point_a,
            r_inner: self.job.arc_radius_m,
            width: self.job.line_width_m,
            lines: self.job.line_num,
            sweep: self.job.arc_sweep_deg.to_radians(),
            start_angle: -std::f64::consts::FRAC_PI_2,
            point_spacing: self.guidance.point_spacing_m,
            turn: ab.turn,
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
            headland_order: f.headland_order,
            sections: f.sections,
            overlap: f.overlap_m,
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
