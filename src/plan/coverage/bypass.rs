//! A swath's way round a small obstacle built from arcs, without a search: leave the line on an
//! arc of radius `r_leave` (≥ r_min), go round a circle about the obstacle (radius the
//! obstacle's reach plus the implement's half width, at least r_min), come back on an arc of
//! radius `r_leave`. The three arcs are tangent where they meet (the first and last circles
//! touch the middle one from outside, so their centres lie `r_leave + radius` apart), which
//! makes the curvature at most 1/r_min everywhere. This is the bypass a driver steers round a
//! pylon; it costs a few trigonometric evaluations where the waypoint search costs thousands of
//! Dubins curves.

use crate::geo::{heading_vec, left_normal, v2, wrap_angle, Vec2};

/// One piece of a path: a straight from a point, or an arc about a centre.
#[derive(Debug, Clone, Copy)]
enum Piece {
    /// Start point, unit direction, length m.
    Line(Vec2, Vec2, f64),
    /// Centre, radius m, sense (+1 left, −1 right), heading at the start rad, swept angle rad
    /// (≥ 0).
    Arc(Vec2, f64, f64, f64, f64),
}

impl Piece {
    fn length(&self) -> f64 {
        match *self {
            Piece::Line(_, _, l) => l,
            Piece::Arc(_, r, _, _, sweep) => r * sweep,
        }
    }

    fn at(&self, s: f64) -> Vec2 {
        match *self {
            Piece::Line(a, d, _) => a + d * s,
            Piece::Arc(c, r, sense, h0, _) => {
                c - left_normal(&heading_vec(h0 + sense * s / r)) * (sense * r)
            }
        }
    }
}

/// Points evenly spaced (about `step` m) along consecutive pieces, both ends included.
fn sample(pieces: &[Piece], step: f64) -> Vec<Vec2> {
    let total: f64 = pieces.iter().map(Piece::length).sum();
    let n = (total / step).ceil().max(1.0) as usize;
    let mut out = Vec::with_capacity(n + 1);
    let (mut k, mut start) = (0usize, 0.0);
    for i in 0..=n {
        let s = total * i as f64 / n as f64;
        while k + 1 < pieces.len() && s > start + pieces[k].length() {
            start += pieces[k].length();
            k += 1;
        }
        out.push(pieces[k].at((s - start).clamp(0.0, pieces[k].length())));
    }
    out
}

/// The bypass from `from` to `to` (both on one straight line, heading `heading` rad, `to`
/// ahead) round the circle of radius `radius` m about `centre`, passing it on the `side`
/// (+1 left, −1 right), leaving and rejoining the line on arcs of radius `r_leave` m; `None`
/// when the line misses the circle on that side's far edge or the arcs do not fit between
/// `from` and `to`. Points about `step` m apart.
#[allow(clippy::too_many_arguments)]
pub fn bypass(
    from: Vec2,
    heading: f64,
    to: Vec2,
    centre: Vec2,
    radius: f64,
    r_leave: f64,
    side: f64,
    step: f64,
) -> Option<Vec<Vec2>> {
    let d = heading_vec(heading);
    let n = left_normal(&d);
    let length = (to - from).dot(&d);
    // The obstacle in the line's frame: along (cx) and across (e, left positive).
    let (cx, e) = ((centre - from).dot(&d), (centre - from).dot(&n));
    // Passing on `side`, the leave arc's centre is `r_leave` to that side of the line; it
    // touches the circle about the obstacle from outside.
    let across = side * r_leave - e;
    let reach = r_leave + radius;
    if across.abs() >= reach || radius <= 0.0 || r_leave <= 0.0 {
        return None;
    }
    let along = (reach * reach - across * across).sqrt();
    let (x1, x3) = (cx - along, cx + along);
    if x1 < 0.0 || x3 > length {
        return None;
    }
    let local = |x: f64, y: f64| from + d * x + n * y;
    let o1 = local(x1, side * r_leave);
    let o3 = local(x3, side * r_leave);
    // Heading where the leave arc meets the circle: the path there runs square to the line
    // between the two centres, the obstacle on the far side from `side`.
    let towards = centre - o1;
    let h_meet = wrap_angle(towards.y.atan2(towards.x) + side * std::f64::consts::FRAC_PI_2);
    let turn = wrap_angle(h_meet - heading) * side;
    if !(0.0..std::f64::consts::PI).contains(&turn) {
        return None;
    }
    let pieces = [
        Piece::Line(from, d, x1),
        Piece::Arc(o1, r_leave, side, heading, turn),
        Piece::Arc(centre, radius, -side, h_meet, 2.0 * turn),
        Piece::Arc(o3, r_leave, side, wrap_angle(heading - side * turn), turn),
        Piece::Line(local(x3, 0.0), d, length - x3),
    ];
    let mut pts = sample(&pieces, step);
    if let Some(last) = pts.last_mut() {
        *last = to;
    }
    Some(pts)
}

/// The centre and reach (largest distance from the centre of its vertices) of the obstacles
/// together: the centre of their vertices' bounding box.
pub fn enclosing_circle<'a>(obstacles: impl Iterator<Item = &'a Vec<Vec2>> + Clone) -> (Vec2, f64) {
    let all = obstacles.flat_map(|o| o.iter());
    let (lo, hi) = crate::geo::polygon::bbox(all.clone()).unwrap_or((v2(0.0, 0.0), v2(0.0, 0.0)));
    let c = 0.5 * (lo + hi);
    let r = all.map(|q| (q - c).norm()).fold(0.0, f64::max);
    (c, r)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curvature(w: &[Vec2]) -> f64 {
        let (a, b, c) = (w[0], w[1], w[2]);
        2.0 * crate::geo::cross(&(b - a), &(c - b)).abs()
            / ((b - a).norm() * (c - b).norm() * (c - a).norm()).max(1e-12)
    }

    #[test]
    fn a_bypass_keeps_its_distance_and_its_curvature() {
        let centre = v2(50.0, 1.0);
        for (side, r_leave) in [(1.0, 5.0), (-1.0, 5.0), (1.0, 15.0), (-1.0, 12.0)] {
            let pts = bypass(
                v2(0.0, 0.0),
                0.0,
                v2(100.0, 0.0),
                centre,
                7.0,
                r_leave,
                side,
                1.0,
            )
            .unwrap();
            assert!((pts[0] - v2(0.0, 0.0)).norm() < 1e-9);
            assert!((pts[pts.len() - 1] - v2(100.0, 0.0)).norm() < 1e-9);
            for q in &pts {
                assert!((q - centre).norm() >= 7.0 - 0.02, "{q:?} inside");
            }
            for w in pts.windows(3) {
                assert!(curvature(w) <= 1.0 / 5.0 * 1.01, "{}", curvature(w));
            }
            // It passed on the side asked for.
            let far = pts.iter().map(|q| q.y * side).fold(f64::MIN, f64::max);
            assert!(far > 7.0 + side - 0.1, "{far}");
        }
        // Too close to the start for the leave arc.
        assert!(bypass(
            v2(45.0, 0.0),
            0.0,
            v2(100.0, 0.0),
            centre,
            7.0,
            5.0,
            1.0,
            1.0
        )
        .is_none());
    }
}
