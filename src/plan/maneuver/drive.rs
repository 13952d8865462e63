//! How a manoeuvre path is handed to the guidance: split at its cusps into parts driven in one
//! direction, each sampled into points the local path and the tracker follow.

use super::path::{CurvePath, PathSample};
use crate::geo::{Direction, Pose, Vec2};

/// One part of a path driven in one direction.
#[derive(Debug, Clone, PartialEq)]
pub struct DrivenPart {
    pub direction: Direction,
    /// Points along the part, local ENU m, about the requested spacing apart, both ends
    /// included exactly.
    pub points: Vec<Vec2>,
    /// Pose at the end of the part (heading of the vehicle, not of travel), rad.
    pub end: Pose,
}

/// The parts of `path` between its cusps (segments of zero length are skipped), each sampled
/// every `spacing_m` metres.
pub fn split_at_cusps(path: &CurvePath, spacing_m: f64) -> Vec<DrivenPart> {
    split_at_cusps_while(path, spacing_m, &mut |_| true).unwrap_or_default()
}

/// [`split_at_cusps`] when every point passes `keep`, else `None`, found at the first point
/// refused without sampling the rest of the path.
pub fn split_at_cusps_while(
    path: &CurvePath,
    spacing_m: f64,
    keep: &mut dyn FnMut(&Vec2) -> bool,
) -> Option<Vec<DrivenPart>> {
    let mut parts = Vec::new();
    let mut samples: Vec<PathSample> = Vec::new();
    let mut pose = path.start;
    let mut i = 0;
    let segs = &path.segments;
    while i < segs.len() {
        if segs[i].length <= 0.0 {
            i += 1;
            continue;
        }
        let direction = segs[i].direction;
        let mut j = i;
        while j < segs.len() && (segs[j].direction == direction || segs[j].length <= 0.0) {
            j += 1;
        }
        let part = CurvePath {
            start: pose,
            segments: segs[i..j].to_vec(),
        };
        if !part.sample_while(spacing_m, &mut samples, keep) {
            return None;
        }
        let end = part.end_pose();
        parts.push(DrivenPart {
            direction,
            points: samples.iter().map(|s| s.pose.pos).collect(),
            end,
        });
        pose = end;
        i = j;
    }
    Some(parts)
}
