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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;
    use crate::plan::maneuver::reeds_shepp::reeds_shepp_paths;

    /// With every point kept, [`split_at_cusps_while`] gives [`split_at_cusps`]'s parts; with
    /// one point refused it gives none, having asked no point after that one.
    #[test]
    fn a_path_refused_at_a_point_is_not_sampled_past_it() {
        let start = Pose {
            pos: v2(0.0, 0.0),
            heading: 0.0,
        };
        let goal = Pose {
            pos: v2(2.0, 6.0),
            heading: std::f64::consts::PI,
        };
        let paths = reeds_shepp_paths(&start, &goal, 5.0);
        assert!(!paths.is_empty());
        for path in &paths {
            let all = split_at_cusps(path, 0.5);
            let kept = split_at_cusps_while(path, 0.5, &mut |_| true);
            assert_eq!(kept.as_ref(), Some(&all));
            let points: Vec<Vec2> = all.iter().flat_map(|p| p.points.clone()).collect();
            let refused = points[points.len() / 2];
            let mut asked = 0;
            let none = split_at_cusps_while(path, 0.5, &mut |q| {
                asked += 1;
                (q - refused).norm() > 1e-12
            });
            assert!(none.is_none());
            let first = points
                .iter()
                .position(|q| (q - refused).norm() <= 1e-12)
                .unwrap_or(points.len());
            assert_eq!(asked, first + 1, "{} points", points.len());
        }
    }
}
