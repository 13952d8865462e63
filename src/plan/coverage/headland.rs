//! Headland (seed 003): the working area is the boundary shrunk by w/2 + passes·w, with the
//! obstacles grown by w/2; the headland passes are driveable closed tracks around the field.

use super::geometry::{offset, Area};
use super::CoverageParams;
pub use crate::geo::polygon::resample;
use crate::geo::{cross, Vec2};
use geo::BooleanOps;

/// Added to every offset the implement must keep, m: round joins are drawn with chords,
/// which cut up to 0.3 mm inside a 6 m arc.
pub const CHORD_MARGIN: f64 = 0.005;

/// How far a path's chords may cut inside its arcs, m: points `point_spacing` apart on an arc
/// of radius ≥ r_min sag by at most spacing²/(8·r_min), plus [`CHORD_MARGIN`].
pub fn chord_margin(p: &CoverageParams) -> f64 {
    CHORD_MARGIN + p.point_spacing * p.point_spacing / (8.0 * p.r_min)
}

/// Does the ring have a reflex (interior angle > 180°) vertex? Rings are counter-clockwise.
pub fn has_reflex_vertex(ring: &[Vec2]) -> bool {
    let n = ring.len();
    (0..n).any(|i| {
        let a = ring[(i + n - 1) % n];
        let b = ring[i];
        let c = ring[(i + 1) % n];
        cross(&(b - a), &(c - b)) < -1e-9
    })
}

/// The area inside which swath centre lines stay: the boundary shrunk by
/// w/2 + headland_passes·w, minus the obstacles with their own headland
/// ([`obstacle_headland_width`], smoothed by a closing of radius r_min).
pub fn working_area(boundary: &[Vec2], obstacles: &[Vec<Vec2>], p: &CoverageParams) -> Vec<Area> {
    let inset = p.line_width / 2.0 + p.headland_passes as f64 * p.line_width;
    let outer = offset(&[(boundary.to_vec(), vec![])], -inset);
    if obstacles.is_empty() {
        return outer;
    }
    let holes = closing(obstacles, obstacle_headland_width(p), p.r_min);
    let a = geo::MultiPolygon::new(outer.iter().map(super::geometry::to_geo).collect());
    let b = geo::MultiPolygon::new(holes.iter().map(super::geometry::to_geo).collect());
    super::geometry::from_geo(&a.difference(&b))
}

/// Offset of obstacle pass `k` (0 = nearest the obstacle) from the obstacle's edge, m:
/// w/2 + k·w, but at least `r_min`: the pass rounds the obstacle's corners on arcs of that
/// radius about them.
pub fn obstacle_pass_offset(p: &CoverageParams, k: usize) -> f64 {
    (p.line_width / 2.0 + k as f64 * p.line_width).max(p.r_min) + chord_margin(p)
}

/// Width of the headland around every obstacle, m: out to the outer edge of the outermost
/// obstacle pass (w/2 when there are no headland passes).
pub fn obstacle_headland_width(p: &CoverageParams) -> f64 {
    match p.headland_passes {
        0 => p.line_width / 2.0,
        n => obstacle_pass_offset(p, n - 1) + p.line_width / 2.0,
    }
}

/// The obstacles grown by `distance` m and closed with radius `r` (grown by `distance + r`,
/// shrunk by `r`): every point is at least `distance` from the obstacles, convex corners are
/// arcs of radius `distance`, concave ones arcs of radius ≥ `r`, and near obstacles merge.
pub fn closing(obstacles: &[Vec<Vec2>], distance: f64, r: f64) -> Vec<Area> {
    let rings: Vec<Area> = obstacles.iter().map(|o| (o.clone(), vec![])).collect();
    offset(&offset(&rings, distance + r), -r)
}

/// Headland passes around the obstacles, nearest the obstacle first: closed tracks (first point
/// repeated last) at [`obstacle_pass_offset`] from them, every corner an arc of radius ≥ r_min,
/// resampled to `point_spacing`. Obstacles whose passes meet share them.
pub fn obstacle_tracks(obstacles: &[Vec<Vec2>], p: &CoverageParams) -> Vec<Vec<Vec2>> {
    let mut tracks = Vec::new();
    if obstacles.is_empty() {
        return tracks;
    }
    for k in 0..p.headland_passes {
        for (ring, _) in closing(obstacles, obstacle_pass_offset(p, k), p.r_min) {
            let mut closed = ring.clone();
            closed.push(ring[0]);
            tracks.push(resample(&closed, p.point_spacing));
        }
    }
    tracks
}

/// `areas` minus every obstacle grown by `margin` m.
pub fn subtract_obstacles(areas: &[Area], obstacles: &[Vec<Vec2>], margin: f64) -> Vec<Area> {
    if obstacles.is_empty() {
        return areas.to_vec();
    }
    let grown: Vec<Area> = offset(
        &obstacles
            .iter()
            .map(|o| (o.clone(), vec![]))
            .collect::<Vec<_>>(),
        margin,
    );
    let a = geo::MultiPolygon::new(areas.iter().map(super::geometry::to_geo).collect());
    let b = geo::MultiPolygon::new(grown.iter().map(super::geometry::to_geo).collect());
    super::geometry::from_geo(&a.difference(&b))
}

/// Offset of headland pass `k` from the boundary, m: w/2 + k·w, but never below `r_min` when
/// the boundary has a reflex corner (there the pass follows an arc of that radius about the
/// corner, and a tighter one could not be driven).
pub fn pass_offset(boundary: &[Vec2], p: &CoverageParams, k: usize) -> f64 {
    let d = p.line_width / 2.0 + k as f64 * p.line_width;
    if has_reflex_vertex(boundary) {
        d.max(p.r_min) + chord_margin(p)
    } else {
        d + CHORD_MARGIN
    }
}

/// The headland passes, outermost first: closed tracks (first point repeated last) at
/// [`pass_offset`] from the boundary with convex corners rounded to `r_min` (an opening: shrink
/// by offset + r_min, grow by r_min), resampled to `point_spacing`.
pub fn headland_tracks(boundary: &[Vec2], p: &CoverageParams) -> Vec<Vec<Vec2>> {
    let mut tracks = Vec::new();
    for k in 0..p.headland_passes {
        let d = pass_offset(boundary, p, k);
        let shrunk = offset(&[(boundary.to_vec(), vec![])], -(d + p.r_min));
        for (ring, _) in offset(&shrunk, p.r_min) {
            let mut closed = ring.clone();
            closed.push(ring[0]);
            tracks.push(resample(&closed, p.point_spacing));
        }
    }
    tracks
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;

    fn params() -> CoverageParams {
        CoverageParams {
            line_width: 6.0,
            r_min: 6.0,
            headland_passes: 2,
            point_spacing: 1.0,
            swath_angle: Default::default(),
            route: Default::default(),
            small_obstacle_max_m: 20.0,
            max_curvature_rate: 0.0,
        }
    }

    #[test]
    fn tracks_keep_their_offset_and_turn_no_tighter_than_r_min() {
        let b = vec![
            v2(0.0, 0.0),
            v2(200.0, 0.0),
            v2(200.0, 100.0),
            v2(0.0, 100.0),
        ];
        let p = params();
        let t = headland_tracks(&b, &p);
        assert_eq!(t.len(), 2);
        for (k, track) in t.iter().enumerate() {
            let d = pass_offset(&b, &p, k);
            for q in track {
                let edge = q.x.min(200.0 - q.x).min(q.y).min(100.0 - q.y);
                assert!(edge >= d - 0.05, "pass {k}: {q:?} at {edge} < {d}");
            }
            for w in track.windows(3) {
                let (a, b2, c) = (w[0], w[1], w[2]);
                let k3 = 2.0 * cross(&(b2 - a), &(c - b2)).abs()
                    / ((b2 - a).norm() * (c - b2).norm() * (c - a).norm()).max(1e-12);
                assert!(k3 <= 1.0 / p.r_min * 1.05 + 1e-6, "curvature {k3}");
            }
        }
        let wa = working_area(&b, &[], &p);
        assert!((super::super::geometry::area_m2(&wa[0]) - 170.0 * 70.0).abs() < 1.0);
    }
}
