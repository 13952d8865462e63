//! A proof that no transit keeping the implement clear joins two points, for the transit
//! attempts of [`super::plan_field`] between parts of a field that only a neck too narrow for
//! the implement joins (de_bb_holes_irregular at w ≥ 6 m: each such attempt along the headland
//! solved and checked some thousand curves, ~1 ms, to find no way).
//!
//! A transit's points are all clear (each at least `half` from every edge, inside the field,
//! off the obstacles), and its consecutive points lie at most `gap` apart (the point spacing
//! of its curves, the spacing of the headland rings it follows). Every point of the polyline
//! through them then lies within `gap / 2` of a clear point, so more than `half - gap / 2`
//! from every edge: the whole way lies in one connected piece of the field shrunk by that
//! depth. Two points in different pieces of it (shrunk a little less, for the clipper's round
//! joins) are joined by no transit with the implement clear, whatever its curves. The coarse
//! waypoint grid proves no such thing: a neck narrower than its step holds no node but may
//! hold a transit.

use super::geometry::{self, Area};
use super::Field;
use crate::geo::Vec2;
use std::cell::OnceCell;

/// The pieces of one field shrunk for one clearance test, found when first asked.
pub(super) struct Apart<'a> {
    field: &'a Field,
    /// How far the field is shrunk, m (≤ 0: no proof).
    depth: f64,
    pieces: OnceCell<Vec<Area>>,
}

/// Slack taken off the depth, m, beyond the round joins' chords: the clipper's rounding.
const SLACK_M: f64 = 0.01;

impl<'a> Apart<'a> {
    /// For the test that keeps points `half` m from the edges of `field` and transits whose
    /// consecutive points lie at most `gap` m apart.
    pub(super) fn new(field: &'a Field, half: f64, gap: f64) -> Self {
        // A round join's chords may lie outside its arc by up to the radius times
        // (1 / cos(angle / 2) − 1): shrinking that much less keeps every piece whole.
        let chords = half * (1.0 / (geometry::JOIN_ANGLE / 2.0).cos() - 1.0);
        Apart {
            field,
            depth: half - gap / 2.0 - chords - SLACK_M,
            pieces: OnceCell::new(),
        }
    }

    /// Are `a` and `b` in different pieces of the shrunk field, so that no transit with every
    /// point clear joins them? `false` when that is not known (either point in no piece).
    pub(super) fn apart(&self, a: &Vec2, b: &Vec2) -> bool {
        if self.depth.is_nan() || self.depth <= 0.0 {
            return false;
        }
        let pieces = self.pieces.get_or_init(|| {
            let whole = (self.field.boundary.clone(), self.field.obstacles.clone());
            geometry::offset(&[whole], -self.depth)
        });
        let piece = |q: &Vec2| pieces.iter().position(|piece| geometry::in_area(piece, q));
        matches!((piece(a), piece(b)), (Some(i), Some(j)) if i != j)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;
    use crate::plan::coverage::implement_clear;

    /// Two 60 × 60 m squares joined by a corridor 4 m wide: at half 1.5 m a point of the
    /// corridor is clear, so the squares are one piece; at half 3 m they are apart, and no
    /// chain of clear points 1 m apart joins them (a search over a 0.25 m raster of clear
    /// points, each joined to those within 1 m, finds none).
    #[test]
    fn pieces_joined_only_by_a_narrow_neck_are_apart() {
        let field = Field {
            boundary: vec![
                v2(0.0, 0.0),
                v2(60.0, 0.0),
                v2(60.0, 28.0),
                v2(80.0, 28.0),
                v2(80.0, 0.0),
                v2(140.0, 0.0),
                v2(140.0, 60.0),
                v2(80.0, 60.0),
                v2(80.0, 32.0),
                v2(60.0, 32.0),
                v2(60.0, 60.0),
                v2(0.0, 60.0),
            ],
            obstacles: vec![vec![
                v2(20.0, 20.0),
                v2(25.0, 20.0),
                v2(25.0, 25.0),
                v2(20.0, 25.0),
            ]],
        };
        let (a, b) = (v2(30.0, 45.0), v2(110.0, 45.0));
        // Chain connectivity of clear points on a raster, spacing ≤ gap.
        let chained = |half: f64, gap: f64| {
            let h = 0.25;
            let (nx, ny) = ((140.0 / h) as usize + 1, (60.0 / h) as usize + 1);
            let at = |i: usize, j: usize| v2(i as f64 * h, j as f64 * h);
            let ok: Vec<bool> = (0..nx * ny)
                .map(|k| implement_clear(&field, half, &at(k % nx, k / nx)))
                .collect();
            let idx = |q: Vec2| (q.y / h).round() as usize * nx + (q.x / h).round() as usize;
            let mut seen = vec![false; nx * ny];
            let mut stack = vec![idx(a)];
            seen[idx(a)] = true;
            let reach = (gap / h).floor() as i64;
            while let Some(k) = stack.pop() {
                let (i, j) = ((k % nx) as i64, (k / nx) as i64);
                for di in -reach..=reach {
                    for dj in -reach..=reach {
                        let (u, v) = (i + di, j + dj);
                        if u < 0 || v < 0 || u >= nx as i64 || v >= ny as i64 {
                            continue;
                        }
                        if ((di * di + dj * dj) as f64).sqrt() * h > gap + 1e-9 {
                            continue;
                        }
                        let n = v as usize * nx + u as usize;
                        if ok[n] && !seen[n] {
                            seen[n] = true;
                            stack.push(n);
                        }
                    }
                }
            }
            seen[idx(b)]
        };
        for (half, gap) in [
            (1.5, 1.0),
            (1.9, 1.0),
            (2.5, 1.0),
            (2.6, 1.0),
            (3.0, 2.0),
            (3.0, 1.0),
        ] {
            let apart = Apart::new(&field, half, gap).apart(&a, &b);
            let joined = chained(half, gap);
            // Sound: never apart where a chain joins them.
            assert!(!(apart && joined), "half {half} gap {gap}");
        }
        assert!(!Apart::new(&field, 1.5, 1.0).apart(&a, &b));
        assert!(Apart::new(&field, 3.0, 1.0).apart(&a, &b));
        assert!(Apart::new(&field, 2.6, 1.0).apart(&a, &b));
        // Points in one piece (either side of the obstacle) are not apart.
        assert!(!Apart::new(&field, 3.0, 1.0).apart(&v2(10.0, 10.0), &a));
        // A point in no piece (outside the field): nothing known.
        assert!(!Apart::new(&field, 3.0, 1.0).apart(&v2(70.0, 10.0), &a));
    }
}
