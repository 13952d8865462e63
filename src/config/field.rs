//! `[field]`: field coverage planning (headland passes, swath direction, route, obstacles,
//! boundary clean-up, ENU origin).
//!
//! Owns the section's keys, their defaults and their range checks.

use super::check::Checker;
use serde::{Deserialize, Serialize};

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
    /// Headland passes "first" (before the swaths) or "last" (after them).
    pub headland_order: crate::plan::coverage::HeadlandOrder,
    /// Sections the implement switches off on its own where they leave the working area
    /// (section control at the headland), 1..=64; 1 = none, the whole width works wherever a
    /// swath runs.
    pub sections: usize,
    /// Overlap of neighbouring passes' footprints (swath to swath, ring to ring, the outermost
    /// swaths onto the inner headland pass), m, 0 ≤ overlap < line_width_m / 2: the passes are
    /// `job.line_width_m − overlap_m` apart, so a steering error of up to half of it leaves no
    /// strip unworked. 0 = the footprints meet exactly.
    pub overlap_m: f64,
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
            headland_order: crate::plan::coverage::HeadlandOrder::First,
            sections: 1,
            overlap_m: 0.0,
        }
    }
}

impl FieldConfig {
    /// Range checks of `[field]`; `line_width_m` is `job.line_width_m`.
    pub(crate) fn validate(&self, line_width_m: f64, c: &mut Checker) {
        let fc = self;
        if !(fc.overlap_m >= 0.0 && fc.overlap_m < line_width_m / 2.0) {
            c.push(
                "field.overlap_m",
                fc.overlap_m.to_string(),
                &format!(
                    "must be at least 0 and less than half of job.line_width_m ({line_width_m} m)"
                ),
            );
        }
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
        if !(1..=64).contains(&fc.sections) {
            c.push(
                "field.sections",
                fc.sections.to_string(),
                "must be in 1..=64",
            );
        }
        c.range(
            "field.boundary_tolerance_m",
            fc.boundary_tolerance_m,
            0.0,
            10.0,
        );
    }
}
