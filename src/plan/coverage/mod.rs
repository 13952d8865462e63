//! Coverage of a polygon field (SPEC §3, seeds 003 and 001), as a pipeline of pure stages in
//! the manner of Fields2Cover: headland → swath angle → decomposition → swaths → obstacles →
//! route → turns → one ordered list of [`PlanSegment`]s.
//!
//! Input is a [`Field`] in the local ENU frame (see [`crate::field`] for reading GeoJSON and
//! ISO 11783-10 TASKDATA into one). Every stage is a pure function of its inputs.

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
