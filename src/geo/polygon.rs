//! Plain polygon geometry in the local ENU frame, shared by the field planner, the manoeuvre
//! planner's collision checks and the field input clean-up.
//!
//! A polygon ring is a slice of vertices, not closed (the first vertex is not repeated at the
//! end). Rings of outer boundaries are counter-clockwise; holes and obstacles are stored
//! counter-clockwise too and their role is given by where they are kept.

use super::{cross, v2, Vec2};

/// Length along a polyline, m.
pub fn polyline_length(points: &[Vec2]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// The signed area of a ring, m² (positive when counter-clockwise).
pub fn signed_area(ring: &[Vec2]) -> f64 {
    let n = ring.len();
    if n < 3 {
        return 0.0;
    }
    let mut a = 0.0;
    for i in 0..n {
        let p = &ring[i];
        let q = &ring[(i + 1) % n];
        a += p.x * q.y - q.x * p.y;
    }
    0.5 * a
}

/// Reverse `ring` in place when it is clockwise, so it ends counter-clockwise.
pub fn make_ccw(ring: &mut [Vec2]) {
    if signed_area(ring) < 0.0 {
        ring.reverse();
    }
}

/// Axis-aligned bounding box of points: (min, max). `None` when empty or not finite.
pub fn bbox<'a>(points: impl IntoIterator<Item = &'a Vec2>) -> Option<(Vec2, Vec2)> {
    let mut min = v2(f64::INFINITY, f64::INFINITY);
    let mut max = v2(f64::NEG_INFINITY, f64::NEG_INFINITY);
    for p in points {
        min = min.inf(p);
        max = max.sup(p);
    }
    (min.x.is_finite() && min.y.is_finite() && max.x.is_finite() && max.y.is_finite())
        .then_some((min, max))
}

/// Whether `p` is inside `ring` (even-odd rule; points exactly on an edge may go either way).
pub fn contains_point(ring: &[Vec2], p: &Vec2) -> bool {
    let n = ring.len();
    let mut inside = false;
    let mut j = n.wrapping_sub(1);
    for i in 0..n {
        let (a, b) = (&ring[i], &ring[j]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
            if p.x < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

/// Whether the closed segments `a0–a1` and `b0–b1` intersect (touching counts).
pub fn segments_intersect(a0: &Vec2, a1: &Vec2, b0: &Vec2, b1: &Vec2) -> bool {
    let d1 = cross(&(a1 - a0), &(b0 - a0));
    let d2 = cross(&(a1 - a0), &(b1 - a0));
    let d3 = cross(&(b1 - b0), &(a0 - b0));
    let d4 = cross(&(b1 - b0), &(a1 - b0));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let on = |p: &Vec2, q: &Vec2, r: &Vec2, d: f64| {
        d == 0.0
            && r.x >= p.x.min(q.x)
            && r.x <= p.x.max(q.x)
            && r.y >= p.y.min(q.y)
            && r.y <= p.y.max(q.y)
    };
    on(a0, a1, b0, d1) || on(a0, a1, b1, d2) || on(b0, b1, a0, d3) || on(b0, b1, a1, d4)
}

/// The point of the segment `a–b` closest to `p` (`a` when the segment has no length).
pub fn closest_point_on_segment(p: &Vec2, a: &Vec2, b: &Vec2) -> Vec2 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    a + ab * t
}

/// Distance from `p` to the segment `a–b`, m.
pub fn point_segment_distance(p: &Vec2, a: &Vec2, b: &Vec2) -> f64 {
    (p - closest_point_on_segment(p, a, b)).norm()
}

/// The crossing point of two segments, if they cross (parallel ones never do: `None`).
fn segments_intersect_point(a0: &Vec2, a1: &Vec2, b0: &Vec2, b1: &Vec2) -> Option<Vec2> {
    let r = a1 - a0;
    let s = b1 - b0;
    let den = cross(&r, &s);
    if den.abs() < 1e-12 {
        return None;
    }
    let t = cross(&(b0 - a0), &s) / den;
    let u = cross(&(b0 - a0), &r) / den;
    ((0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)).then(|| a0 + r * t)
}

/// Distance between two segments and the closest points (on the first, on the second).
pub fn segment_distance(a0: Vec2, a1: Vec2, b0: Vec2, b1: Vec2) -> (f64, Vec2, Vec2) {
    if let Some(p) = segments_intersect_point(&a0, &a1, &b0, &b1) {
        return (0.0, p, p);
    }
    // Each endpoint against the other segment; the nearest pair wins.
    let cands = [
        (a0, b0, b1, true),
        (a1, b0, b1, true),
        (b0, a0, a1, false),
        (b1, a0, a1, false),
    ]
    .map(|(p, s0, s1, p_on_a)| {
        let q = closest_point_on_segment(&p, &s0, &s1);
        let d = (p - q).norm();
        if p_on_a {
            (d, p, q)
        } else {
            (d, q, p)
        }
    });
    cands
        .into_iter()
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .unwrap_or((f64::INFINITY, a0, b0))
}

/// Whether `ring` is simple: no two non-adjacent edges meet. O(n²); fine for boundaries of a
/// few thousand vertices after clean-up, and used only on input.
pub fn self_intersection(ring: &[Vec2]) -> Option<(usize, usize)> {
    let n = ring.len();
    for i in 0..n {
        let (a0, a1) = (&ring[i], &ring[(i + 1) % n]);
        for j in i + 1..n {
            if j == i + 1 || (i == 0 && j == n - 1) {
                continue;
            }
            let (b0, b1) = (&ring[j], &ring[(j + 1) % n]);
            if segments_intersect(a0, a1, b0, b1) {
                return Some((i, j));
            }
        }
    }
    None
}

/// Points evenly spaced by arc length along a polyline, about `spacing` m apart, from its
/// first to its exact last point.
pub fn resample(points: &[Vec2], spacing: f64) -> Vec<Vec2> {
    let total = polyline_length(points);
    let Some(&first) = points.first() else {
        return Vec::new();
    };
    let n = (total / spacing).ceil().max(1.0) as usize;
    let step = total / n as f64;
    let mut out = Vec::with_capacity(n + 1);
    out.push(first);
    let (mut seg, mut at) = (0usize, 0.0);
    for k in 1..n {
        let target = k as f64 * step;
        while seg + 1 < points.len() {
            let len = (points[seg + 1] - points[seg]).norm();
            if at + len >= target {
                let f = if len > 0.0 { (target - at) / len } else { 0.0 };
                out.push(points[seg] + (points[seg + 1] - points[seg]) * f);
                break;
            }
            at += len;
            seg += 1;
        }
    }
    if let Some(&last) = points.last() {
        out.push(last);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Vec<Vec2> {
        vec![v2(0.0, 0.0), v2(2.0, 0.0), v2(2.0, 2.0), v2(0.0, 2.0)]
    }

    #[test]
    fn area_sign_and_orientation() {
        let mut s = square();
        assert_eq!(signed_area(&s), 4.0);
        s.reverse();
        assert_eq!(signed_area(&s), -4.0);
        make_ccw(&mut s);
        assert_eq!(signed_area(&s), 4.0);
    }

    #[test]
    fn containment_and_intersections() {
        let s = square();
        assert!(contains_point(&s, &v2(1.0, 1.0)));
        assert!(!contains_point(&s, &v2(3.0, 1.0)));
        assert!(self_intersection(&s).is_none());
        let bow = vec![v2(0.0, 0.0), v2(2.0, 2.0), v2(2.0, 0.0), v2(0.0, 2.0)];
        assert!(self_intersection(&bow).is_some());
        assert!(segments_intersect(
            &v2(0.0, 0.0),
            &v2(1.0, 0.0),
            &v2(1.0, 0.0),
            &v2(1.0, 1.0)
        ));
        assert!(!segments_intersect(
            &v2(0.0, 0.0),
            &v2(1.0, 0.0),
            &v2(0.0, 1.0),
            &v2(1.0, 1.0)
        ));
        assert!(
            (point_segment_distance(&v2(1.0, 1.0), &v2(0.0, 0.0), &v2(2.0, 0.0)) - 1.0).abs()
                < 1e-12
        );
    }
}
