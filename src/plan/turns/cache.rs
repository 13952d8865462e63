//! Turns between parallel swaths (seed 003) that may reverse, chosen by [`turn_shape`] from
//! the lateral gap g against 2·r_min: a pi turn (two quarter arcs and a straight, g > 2r), a
//! semicircle (g = 2r, the arcs merge), or a fishtail (g < 2r: forward arc, reverse along the
//! transition line, forward arc).
//!
//! All turns between parallel swaths of a cell are alike up to a rigid motion, so each shape
//! is solved once in a canonical frame — start at the origin heading +x, end at (0, ±g)
//! heading −x — and then moved onto every pair of swath ends ([`TurnCache`]).

use super::{arc_points, pi_turn, turn_shape, ShortTurn, TurnParams, TurnShape};
use crate::geo::{v2, Direction, Vec2};
use crate::plan::types::PlanError;

/// One driven part of a turn.
#[derive(Debug, Clone, PartialEq)]
pub struct TurnPart {
    pub direction: Direction,
    pub points: Vec<Vec2>,
}

/// The canonical turn for a gap `g` (m) to the left (`left`) or right.
pub fn canonical_turn(g: f64, left: bool, p: &TurnParams) -> Result<Vec<TurnPart>, PlanError> {
    let r = p.r_min;
    let parts = if turn_shape(g, r, ShortTurn::Fishtail) == TurnShape::Pi {
        let mut out = Vec::new();
        pi_turn(v2(0.0, 0.0), v2(1.0, 0.0), v2(0.0, g), p, &mut out)?;
        vec![TurnPart {
            direction: Direction::Forward,
            points: out.iter().map(|q| q.pos).collect(),
        }]
    } else if p.max_curvature_rate > 0.0 {
        cc_fishtail(g, p)
    } else {
        // Fishtail: forward quarter arc about (0, r) to (r, r) heading +y; reverse down the
        // transition line x = r to (r, g − r); forward quarter arc about (0, g − r) to (0, g).
        let mut a1 = Vec::new();
        arc_points(
            v2(0.0, r),
            v2(0.0, 0.0),
            v2(r, r),
            true,
            p.arc_step,
            true,
            &mut a1,
        );
        let back = crate::geo::polygon::resample(&[v2(r, r), v2(r, g - r)], p.point_spacing);
        let mut a2 = Vec::new();
        arc_points(
            v2(0.0, g - r),
            v2(r, g - r),
            v2(0.0, g),
            true,
            p.arc_step,
            true,
            &mut a2,
        );
        vec![
            TurnPart {
                direction: Direction::Forward,
                points: a1.iter().map(|q| q.pos).collect(),
            },
            TurnPart {
                direction: Direction::Reverse,
                points: back,
            },
            TurnPart {
                direction: Direction::Forward,
                points: a2.iter().map(|q| q.pos).collect(),
            },
        ]
    };
    Ok(if left {
        parts
    } else {
        parts
            .into_iter()
            .map(|t| TurnPart {
                direction: t.direction,
                points: t.points.iter().map(|q| v2(q.x, -q.y)).collect(),
            })
            .collect()
    })
}

/// The continuous-curvature fishtail to the left (docs/METHODS.md, Curves): a forward CC quarter
/// turn (clothoid + arc + clothoid at κ_max = 1/r_min and σ_max) from the origin heading +x ends at
/// (d, d) heading +y (a symmetric quarter turn ends as far along as across); reverse straight down
/// x = d to (d, g − d); a second forward CC quarter turn ends at (0, g) heading −x. Curvature is
/// zero at both cusps and both ends, so the steering never has to jump.
fn cc_fishtail(g: f64, p: &TurnParams) -> Vec<TurnPart> {
    use crate::geo::Pose;
    use crate::plan::maneuver::drive::split_at_cusps;
    use crate::plan::maneuver::path::{CurvePath, CurveSegment};
    let (quarter, d) = super::cc_quarter_turn(p, true);
    let mut segments = quarter.clone();
    segments.push(CurveSegment::line(
        Direction::Reverse,
        (2.0 * d - g).max(0.0),
    ));
    segments.extend(quarter);
    let path = CurvePath {
        start: Pose::new(0.0, 0.0, 0.0),
        segments,
    };
    split_at_cusps(&path, p.point_spacing.min(0.5))
        .into_iter()
        .map(|part| TurnPart {
            direction: part.direction,
            points: part.points,
        })
        .collect()
}

/// Canonical turns solved once per (gap, side) and reused.
#[derive(Debug, Default)]
pub struct TurnCache {
    shapes: Vec<((i64, bool), Vec<TurnPart>)>,
    /// Shapes solved (cache misses).
    pub solved: usize,
}

impl TurnCache {
    /// The turn from swath end `p1` (heading `dir`, unit) to the next swath start `p2` (which
    /// must be level with `p1` along `dir`), moved from the canonical frame.
    pub fn turn(
        &mut self,
        p1: Vec2,
        dir: Vec2,
        p2: Vec2,
        params: &TurnParams,
    ) -> Result<Vec<TurnPart>, PlanError> {
        let lateral = crate::geo::cross(&dir, &(p2 - p1));
        let key = ((lateral.abs() * 1000.0).round() as i64, lateral > 0.0);
        let shape = match self.shapes.iter().find(|(k, _)| *k == key) {
            Some((_, s)) => s.clone(),
            None => {
                let s = canonical_turn(lateral.abs(), lateral > 0.0, params)?;
                self.solved += 1;
                self.shapes.push((key, s.clone()));
                s
            }
        };
        let nrm = crate::geo::left_normal(&dir);
        Ok(shape
            .into_iter()
            .map(|t| TurnPart {
                direction: t.direction,
                points: t
                    .points
                    .iter()
                    .map(|q| p1 + dir * q.x + nrm * q.y)
                    .collect(),
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(r: f64) -> TurnParams {
        TurnParams {
            r_min: r,
            arc_step: 5f64.to_radians(),
            merge_distance: 0.05,
            point_spacing: 1.0,
            max_points: 500,
            max_curvature_rate: 0.0,
        }
    }

    #[test]
    fn cc_fishtail_ends_on_the_next_line_with_zero_curvature_cusps() {
        let mut p = params(6.0);
        p.max_curvature_rate = 0.06;
        for left in [true, false] {
            let f = canonical_turn(6.0, left, &p).unwrap();
            assert_eq!(f.len(), 3, "fishtail");
            assert_eq!(f[1].direction, Direction::Reverse);
            let side = if left { 1.0 } else { -1.0 };
            let end = *f[2].points.last().unwrap();
            assert!((end - v2(0.0, 6.0 * side)).norm() < 1e-6, "{end:?}");
            // The reverse leg is straight and the parts meet exactly.
            assert!((f[0].points.last().unwrap() - f[1].points[0]).norm() < 1e-9);
            assert!((f[1].points.last().unwrap() - f[2].points[0]).norm() < 1e-9);
            let r = &f[1].points;
            assert!(r.iter().all(|q| (q.x - r[0].x).abs() < 1e-9));
            // Clothoids make the quarter turn reach further than an arc: d > r_min.
            assert!(f[0].points.last().unwrap().x > 6.0);
            // Headings: +y at the first cusp (three-point check of the last points).
            let a = &f[0].points;
            let dir = a[a.len() - 1] - a[a.len() - 2];
            assert!(
                dir.x.abs() < 0.01 * dir.norm() && dir.y * side > 0.0,
                "{dir:?}"
            );
        }
    }

    #[test]
    fn turn_kinds_by_gap_and_reuse() {
        let p = params(6.0);
        assert_eq!(canonical_turn(18.0, true, &p).unwrap().len(), 1, "pi");
        assert_eq!(
            canonical_turn(12.0, true, &p).unwrap().len(),
            1,
            "semicircle"
        );
        let f = canonical_turn(6.0, true, &p).unwrap();
        assert_eq!(f.len(), 3, "fishtail");
        assert_eq!(f[1].direction, Direction::Reverse);
        let end = *f[2].points.last().unwrap();
        assert!((end - v2(0.0, 6.0)).norm() < 1e-9);
        let right = canonical_turn(6.0, false, &p).unwrap();
        assert!((right[2].points.last().unwrap().y + 6.0).abs() < 1e-9);
        let mut cache = TurnCache::default();
        for k in 0..10 {
            let y = k as f64 * 12.0;
            let t = cache
                .turn(v2(100.0, y), v2(1.0, 0.0), v2(100.0, y + 12.0), &p)
                .unwrap();
            let last = *t.last().unwrap().points.last().unwrap();
            assert!((last - v2(100.0, y + 12.0)).norm() < 1e-9);
        }
        assert_eq!(cache.solved, 1);
    }
}
