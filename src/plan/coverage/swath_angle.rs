//! Swath direction (seed 003): for a convex area the number of swaths is ceil(D / w), with D
//! the span across the swaths, and the minimum span of a convex polygon always lies across one
//! of its edges. So only the hull's edge directions are tested, with rotating calipers (one
//! antipodal pointer moving once round the hull): O(n) after the O(n log n) hull, no angle
//! stepping.

use super::geometry::convex_hull;
use crate::geo::{cross, Vec2};

/// The minimum-span edge direction of the convex hull of `points`: (angle rad CCW from East in
/// [0, π), span across it m). `None` for fewer than three non-collinear points.
pub fn min_span(points: &[Vec2]) -> Option<(f64, f64)> {
    let hull = convex_hull(points);
    let n = hull.len();
    if n < 3 {
        return None;
    }
    let mut best: Option<(f64, f64)> = None;
    let mut j = 1;
    let dist = |i: usize, k: usize| {
        let a = hull[i];
        let d = hull[(i + 1) % n] - a;
        cross(&d, &(hull[k] - a)) / d.norm()
    };
    for i in 0..n {
        // Advance the antipodal vertex while it gets farther from edge i.
        while dist(i, (j + 1) % n) >= dist(i, j) {
            j = (j + 1) % n;
            if j == i {
                break;
            }
        }
        let span = dist(i, j);
        let d = hull[(i + 1) % n] - hull[i];
        let angle = d.y.atan2(d.x).rem_euclid(std::f64::consts::PI);
        if best.is_none_or(|b| span < b.1 - 1e-9) {
            best = Some((angle, span));
        }
    }
    best
}

/// Span of `points` across the direction `angle` (rad), m.
pub fn span_across(points: &[Vec2], angle: f64) -> f64 {
    let nrm = crate::geo::v2(-angle.sin(), angle.cos());
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for p in points {
        let s = nrm.dot(p);
        lo = lo.min(s);
        hi = hi.max(s);
    }
    (hi - lo).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;

    #[test]
    fn calipers_equal_brute_force_over_edges() {
        let mut rng = 12345u64;
        let mut next = || {
            rng = rng
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((rng >> 11) as f64 / (1u64 << 53) as f64) * 200.0
        };
        for _ in 0..200 {
            let pts: Vec<Vec2> = (0..12).map(|_| v2(next(), next() * 0.6)).collect();
            let (angle, span) = min_span(&pts).unwrap();
            let hull = convex_hull(&pts);
            let brute = (0..hull.len())
                .map(|i| {
                    let d = hull[(i + 1) % hull.len()] - hull[i];
                    span_across(&pts, d.y.atan2(d.x))
                })
                .fold(f64::INFINITY, f64::min);
            assert!((span - brute).abs() < 1e-6, "{span} vs {brute}");
            assert!((span_across(&pts, angle) - span).abs() < 1e-6);
        }
        // A 200 × 100 rectangle rotated by 30°: swaths along the long side.
        let r: Vec<Vec2> = [
            v2(0.0, 0.0),
            v2(200.0, 0.0),
            v2(200.0, 100.0),
            v2(0.0, 100.0),
        ]
        .iter()
        .map(|p| super::super::geometry::rotate(p, 30f64.to_radians()))
        .collect();
        let (angle, span) = min_span(&r).unwrap();
        assert!((angle - 30f64.to_radians()).abs() < 1e-9 && (span - 100.0).abs() < 1e-9);
    }
}
