//! The coverage planner's parameters (typed SI values, resolved from the configuration by the
//! caller) and its result.

use super::PlanSegment;
use super::Vec2;
use crate::plan::types::PlanError;
use serde::{Deserialize, Serialize};

/// How the swath direction is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "objective")]
pub enum SwathAngle {
    /// Minimum span of the convex hull (rotating calipers over the edge directions; seed 003).
    #[default]
    MinSpan,
    /// The least total number of turns across the cells after decomposition.
    MinTurns,
    /// A fixed direction, rad CCW from East (e.g. parallel to an AB line or the longest edge).
    Fixed { angle: f64 },
}

/// Order of the swaths inside a cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RouteOrder {
    /// Boustrophedon when `line_width ≥ 2·r_min`, else the seed-000 block skip order.
    #[default]
    Auto,
    /// Adjacent swaths in turn (fishtail turns when `line_width < 2·r_min`).
    Sequential,
    /// The seed-000 block/TSP skip order.
    Skip,
}

/// When the headland passes are driven.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HeadlandOrder {
    /// Headland passes first, outermost first (the swaths' turns then run on worked ground;
    /// mowing, spraying, harvest).
    #[default]
    First,
    /// Swaths first, then the headland passes, innermost first: tillage and seeding work the
    /// headland last, over the tracks their turns left.
    Last,
}

/// Everything the coverage planner needs besides the field. Units in the names' docs.
#[derive(Debug, Clone, PartialEq)]
pub struct CoverageParams {
    /// Implement working width = swath spacing, m.
    pub line_width: f64,
    /// Minimum turning radius, m.
    pub r_min: f64,
    /// Number of headland passes around the field (each `line_width` wide).
    pub headland_passes: usize,
    /// Spacing of plan points, m.
    pub point_spacing: f64,
    /// Swath direction objective.
    pub swath_angle: SwathAngle,
    /// Swath order inside each cell.
    pub route: RouteOrder,
    /// Obstacles whose largest dimension ([`obstacle_size`]) is at most this are passed on
    /// detours (the swaths run through them; each blocked stretch becomes a smooth path round
    /// the obstacle); larger ones get headland passes and split the swaths, m.
    pub small_obstacle_max_m: f64,
    /// Largest curvature rate per metre driven, 1/m², for continuous-curvature fishtail turns
    /// (clothoid + arc + clothoid); 0 = fishtails of arcs only.
    pub max_curvature_rate: f64,
    /// Headland passes before or after the swaths.
    pub headland_order: HeadlandOrder,
    /// Sections the implement switches off where they leave the working area (section
    /// control); 1 = none. See [`FieldPlan::sections`].
    pub sections: usize,
    /// Overlap of neighbouring passes' footprints, m (0 ≤ overlap < line_width / 2): swaths,
    /// headland passes and the outermost swaths against the inner pass lie
    /// [`pass_spacing`](Self::pass_spacing) apart.
    pub overlap: f64,
}

/// A complete field plan: segments in driving order plus the areas they were made for.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FieldPlan {
    /// Every segment in driving order (headland passes, swaths, turns, detours, transits).
    pub segments: Vec<PlanSegment>,
    /// The working area (inside the headland) as polygons: (outer ring, holes), all CCW.
    pub working_area: Vec<(Vec<Vec2>, Vec<Vec<Vec2>>)>,
    /// Number of cells after decomposition.
    pub cells: usize,
    /// Swath direction of each cell, rad CCW from East.
    pub swath_angles: Vec<f64>,
    /// Number of work swaths.
    pub swaths: usize,
    /// Overlap of adjacent swath footprints from balancing, m² (estimate: the extra width
    /// times the mean swath length).
    pub overlap_m2: f64,
    /// Turn shapes solved in the canonical frame (each reused for every alike turn).
    pub turn_shapes_solved: usize,
    /// What the planner could not make clear, each naming the place (local frame, m).
    pub warnings: Vec<String>,
    /// Places where the plan goes on with no transit inside the field (each also a warning).
    pub transit_gaps: usize,
    /// Sections of the implement the plan was made for: above 1, each section of a swath works
    /// only where some ground under it is not the headland passes' (the implement's section
    /// control switches it off over the headland), the swaths run on until their whole band
    /// has reached the headland, and they are exactly `line_width` apart (what the span leaves
    /// over lies on a headland pass). 0 or 1: the whole width works wherever a swath runs.
    pub sections: usize,
    /// Overlap of neighbouring passes the plan was made with ([`CoverageParams::overlap`]), m.
    pub pass_overlap_m: f64,
}

impl CoverageParams {
    /// The implement and obstacle limits here; r_min, the point spacing and the curvature rate
    /// as the turns check them.
    pub(super) fn validate(&self) -> Result<(), PlanError> {
        PlanError::check("line_width", self.line_width, self.line_width > 0.0)?;
        PlanError::check(
            "overlap",
            self.overlap,
            self.overlap >= 0.0 && self.overlap < self.line_width / 2.0,
        )?;
        PlanError::check(
            "sections",
            self.sections as f64,
            (1..=64).contains(&self.sections),
        )?;
        PlanError::check(
            "small_obstacle_max_m",
            self.small_obstacle_max_m,
            self.small_obstacle_max_m >= 0.0,
        )?;
        self.turn_params().validate()
    }

    /// Distance between neighbouring passes, m: the line width less the overlap.
    pub fn pass_spacing(&self) -> f64 {
        self.line_width - self.overlap
    }

    pub(super) fn turn_params(&self) -> crate::plan::turns::TurnParams {
        crate::plan::turns::TurnParams {
            r_min: self.r_min,
            arc_step: 2f64.to_radians(),
            merge_distance: 0.05,
            point_spacing: self.point_spacing,
            max_points: 100_000,
            max_curvature_rate: self.max_curvature_rate,
        }
    }
}
