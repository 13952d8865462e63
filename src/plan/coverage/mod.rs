//! Coverage of a polygon field (SPEC §3, seeds 003 and 001), as a pipeline of pure stages in
//! the manner of Fields2Cover: headland → swath angle → decomposition → swaths → obstacles →
//! route → turns → one ordered list of [`PlanSegment`]s.
//!
//! Input is a [`Field`] in the local ENU frame (see [`crate::field`] for reading GeoJSON and
//! ISO 11783-10 TASKDATA into one). Every stage is a pure function of its inputs.

pub mod decompose;
pub mod geometry;
pub mod headland;
pub mod swath_angle;

use crate::geo::{Direction, Vec2};
use serde::{Deserialize, Serialize};

/// A field in the local ENU frame, metres.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Field {
    /// Outer boundary, counter-clockwise, not closed (the first vertex is not repeated).
    pub boundary: Vec<Vec2>,
    /// Obstacles (holes of the boundary and separate obstacle features), each
    /// counter-clockwise, not closed, inside the boundary.
    pub obstacles: Vec<Vec<Vec2>>,
}

/// What a plan segment is for. Serialised as the GeoJSON `kind` property.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SegmentKind {
    /// A swath: the implement works.
    Work,
    /// A turn between two swaths of one cell.
    Turn,
    /// A headland pass around the field (the implement works).
    Headland,
    /// A detour around a small obstacle, replacing the blocked stretch of a swath.
    Detour,
    /// A move between cells or from the headland to the first swath (no work).
    Transit,
}

/// One driveable piece of a field plan, in driving order.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanSegment {
    pub kind: SegmentKind,
    /// Driving direction along `points`.
    pub direction: Direction,
    /// Position of this segment in the plan (0-based, driving order).
    pub index: usize,
    /// The cell it belongs to (0-based; headland passes and transits use the cell they lead to).
    pub cell: usize,
    /// Points in driving order, local ENU metres, about `point_spacing` apart.
    pub points: Vec<Vec2>,
}

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
    /// Obstacles whose inflated extent across the swaths is at most this get an A* detour;
    /// larger ones split the swaths, m.
    pub small_obstacle_max_m: f64,
}

/// A complete field plan: segments in driving order plus the areas they were made for.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FieldPlan {
    /// Every segment in driving order (headland passes, swaths, turns, detours, transits).
    pub segments: Vec<PlanSegment>,
    /// The working area (inside the headland) as polygons: (outer ring, holes), all CCW.
    pub working_area: Vec<(Vec<Vec2>, Vec<Vec<Vec2>>)>,
    /// The headland ring: the field boundary minus the working area, as its inner boundary
    /// rings (CCW) — the outer boundary is the field's.
    pub headland_inner: Vec<Vec<Vec2>>,
    /// Number of cells after decomposition.
    pub cells: usize,
    /// Swath direction of each cell, rad CCW from East.
    pub swath_angles: Vec<f64>,
    /// Number of work swaths.
    pub swaths: usize,
}
