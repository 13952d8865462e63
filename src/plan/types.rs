//! The types every planner and the job layer share: [`PlanError`], the [`Field`] polygon,
//! [`SegmentKind`], [`PlanSegment`] and the [`Side`] of an AB job's lines.
//!
//! Contract: plain data and their checks, no planning. Everything in `plan::*` may use these;
//! this module uses only [`crate::geo`].

use crate::geo::polygon::point_segment_distance;
use crate::geo::{Direction, Vec2};
use serde::{Deserialize, Serialize};

/// Why a plan cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    #[error("{name} = {value}: {rule}")]
    Invalid {
        name: &'static str,
        value: f64,
        rule: &'static str,
    },
    #[error("turn impossible ({reason}); lateral distance {distance:.3} m")]
    Turn { reason: &'static str, distance: f64 },
}

impl PlanError {
    /// `Ok` when `ok` and `value` is finite, else an `Invalid` error for `name`.
    pub(crate) fn check(name: &'static str, value: f64, ok: bool) -> Result<(), PlanError> {
        if ok && value.is_finite() {
            Ok(())
        } else {
            Err(PlanError::Invalid {
                name,
                value,
                rule: "must be finite and in range",
            })
        }
    }
}

/// Side of A→B on which the following lines of an AB job are laid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    Left,
    #[default]
    Right,
}

/// A field in the local ENU frame, metres.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Field {
    /// Outer boundary, counter-clockwise, not closed (the first vertex is not repeated).
    pub boundary: Vec<Vec2>,
    /// Obstacles (holes of the boundary and separate obstacle features), each
    /// counter-clockwise, not closed, inside the boundary.
    pub obstacles: Vec<Vec<Vec2>>,
}

impl Field {
    /// Is `q` inside the boundary and outside every obstacle?
    pub fn contains(&self, q: &Vec2) -> bool {
        crate::geo::polygon::contains_point(&self.boundary, q)
            && !self
                .obstacles
                .iter()
                .any(|o| crate::geo::polygon::contains_point(o, q))
    }

    /// The distance from `q` to the nearest edge of the boundary or of an obstacle, m.
    pub fn distance_to_edges(&self, q: &Vec2) -> f64 {
        std::iter::once(&self.boundary)
            .chain(self.obstacles.iter())
            .flat_map(|ring| {
                let n = ring.len();
                (0..n).map(move |i| point_segment_distance(q, &ring[i], &ring[(i + 1) % n]))
            })
            .fold(f64::INFINITY, f64::min)
    }
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

impl PlanSegment {
    /// Length along the points, m.
    pub fn length(&self) -> f64 {
        crate::geo::polygon::polyline_length(&self.points)
    }
}
