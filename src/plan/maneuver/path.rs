//! A manoeuvre path: segments of constant curvature rate (lines, arcs, clothoids), each driven
//! forward or in reverse.

use crate::geo::Direction;
use serde::{Deserialize, Serialize};

/// The shape of one segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveKind {
    /// Zero curvature.
    Line,
    /// Constant non-zero curvature.
    Arc,
    /// Curvature changing linearly with arc length (sharpness ≠ 0).
    Clothoid,
}

/// One segment of a path. Curvature varies linearly along it:
/// κ(s) = `kappa_start` + `sharpness`·s for s in [0, `length`], with s the distance driven.
/// Curvature is the steering curvature tan(δ)/wheelbase (positive = wheels turned left,
/// SPEC §1), whatever the driving direction: along a segment the heading changes by κ·ds with
/// ds the signed displacement (negative in reverse), as in the kinematic bicycle model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CurveSegment {
    pub kind: CurveKind,
    pub direction: Direction,
    /// Length driven, m (≥ 0).
    pub length: f64,
    /// Curvature at the start, 1/m.
    pub kappa_start: f64,
    /// Curvature at the end, 1/m.
    pub kappa_end: f64,
    /// Curvature rate along the distance driven, 1/m².
    pub sharpness: f64,
}
