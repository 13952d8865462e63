//! Turn geometry between parallel lines, as pure functions writing into a caller's buffer.
//!
//! * [`pi_turn`]: the seed-000 turn for lines at least `2·r_min` apart: a quarter arc off the
//!   current line, a straight across the headland (or nothing, when the arcs meet), a quarter
//!   arc onto the next line.
//! * [`bulb_turn`]: a forward-only turn for lines closer than `2·r_min`: an arc away from the
//!   next line, a large arc the other way, and an arc back, all of radius `r_min` and tangent
//!   to each other (an "omega" or bulb turn).
//!
//! Every point carries [`Tag::Turn`](crate::geo::Tag); the first point is exactly the end of the
//! current line and the last exactly the start of the next one.

use super::PlanError;
use crate::geo::{cross, left_normal, v2, PathPoint, Vec2};
use std::f64::consts::TAU;

/// Shape parameters of every turn.
#[derive(Debug, Clone, PartialEq)]
pub struct TurnParams {
    /// Turning radius, m.
    pub r_min: f64,
    /// Largest angle between consecutive arc points, rad (the seed asks for 10° or finer).
    pub arc_step: f64,
    /// Two arcs whose ends are closer than this are joined directly (no straight), m.
    pub merge_distance: f64,
    /// Target spacing of the points of a straight, m.
    pub point_spacing: f64,
    /// Cap on the number of interior points of a straight.
    pub max_points: usize,
}

impl TurnParams {
    pub(crate) fn validate(&self) -> Result<(), PlanError> {
        PlanError::check("r_min", self.r_min, self.r_min > 0.0)?;
        PlanError::check(
            "arc_step",
            self.arc_step,
            self.arc_step > 0.0 && self.arc_step <= 10f64.to_radians() + 1e-12,
        )?;
        PlanError::check(
            "merge_distance",
            self.merge_distance,
            self.merge_distance >= 0.0,
        )?;
        PlanError::check(
            "point_spacing",
            self.point_spacing,
            self.point_spacing > 0.0,
        )?;
        if self.max_points < 1 {
            return Err(PlanError::Invalid {
                name: "max_points",
                value: self.max_points as f64,
                rule: "must be >= 1",
            });
        }
        Ok(())
    }
}

/// Append the points of an arc about `centre` from `from` to `to`, turning counter-clockwise
/// when `ccw`, with steps of at most `step` rad. `from` itself is appended only when
/// `include_start`; `to` is appended exactly.
pub fn arc_points(
    centre: Vec2,
    from: Vec2,
    to: Vec2,
    ccw: bool,
    step: f64,
    include_start: bool,
    out: &mut Vec<PathPoint>,
) {
    let r = (from - centre).norm();
    let a0 = (from.y - centre.y).atan2(from.x - centre.x);
    let a1 = (to.y - centre.y).atan2(to.x - centre.x);
    let mut sweep = if ccw { a1 - a0 } else { a0 - a1 }.rem_euclid(TAU);
    if sweep > TAU - 1e-12 {
        sweep = 0.0;
    }
    let sign = if ccw { 1.0 } else { -1.0 };
    // At least two steps, so every arc has an interior point and a well-defined tangent.
    let n = ((sweep / step).ceil() as usize).max(2);
    if include_start {
        out.push(PathPoint::turn(from));
    }
    for i in 1..n {
        let a = a0 + sign * sweep * i as f64 / n as f64;
        out.push(PathPoint::turn(centre + v2(a.cos(), a.sin()) * r));
    }
    out.push(PathPoint::turn(to));
}

/// Append the interior points and the end of a straight from `a` to `b` (spacing at most
/// `spacing`, at most `max_points` interior points).
fn straight_points(a: Vec2, b: Vec2, spacing: f64, max_points: usize, out: &mut Vec<PathPoint>) {
    let len = (b - a).norm();
    let n = ((len / spacing).ceil() as usize).clamp(1, max_points + 1);
    for i in 1..n {
        out.push(PathPoint::turn(a + (b - a) * (i as f64 / n as f64)));
    }
    out.push(PathPoint::turn(b));
}

/// Unit normal from the current line toward the next one, and the lateral distance.
fn toward_next(p1: &Vec2, dir1: &Vec2, p2: &Vec2) -> (Vec2, f64) {
    let lateral = cross(dir1, &(p2 - p1));
    let n = if lateral >= 0.0 {
        left_normal(dir1)
    } else {
        -left_normal(dir1)
    };
    (n, lateral.abs())
}

/// The seed-000 turn: quarter arc, straight (or merge), quarter arc.
///
/// `p1` is the end of the current line, `dir1` its unit travel direction; `p2` is the start of
/// the next line. The lines must be at least `2·r_min` apart (within 1 mm).
pub fn pi_turn(
    p1: Vec2,
    dir1: Vec2,
    p2: Vec2,
    params: &TurnParams,
    out: &mut Vec<PathPoint>,
) -> Result<(), PlanError> {
    params.validate()?;
    let r = params.r_min;
    let (n, d) = toward_next(&p1, &dir1, &p2);
    if d + 1e-3 < 2.0 * r {
        return Err(PlanError::Turn {
            reason: "lines closer than 2·r_min need a bulb or fishtail turn",
            distance: d,
        });
    }
    let c1 = p1 + n * r;
    let rv1 = p1 - c1;
    // Seed: positive cross(direction, radius vector 1) turns clockwise, else counter-clockwise.
    let ccw = cross(&dir1, &rv1) <= 0.0;
    let e1 = c1 + dir1 * r;
    let c2 = p2 - n * r;
    let s2 = c2 + dir1 * r;
    arc_points(c1, p1, e1, ccw, params.arc_step, true, out);
    if (s2 - e1).norm() >= params.merge_distance {
        straight_points(e1, s2, params.point_spacing, params.max_points, out);
    }
    arc_points(c2, s2, p2, ccw, params.arc_step, false, out);
    Ok(())
}

/// A forward-only bulb turn between lines closer than `2·r_min`: an arc away from the next
/// line, a large arc toward it, and an arc away again, all of radius `r_min` and tangent.
pub fn bulb_turn(
    p1: Vec2,
    dir1: Vec2,
    p2: Vec2,
    params: &TurnParams,
    out: &mut Vec<PathPoint>,
) -> Result<(), PlanError> {
    params.validate()?;
    let r = params.r_min;
    let (n, d) = toward_next(&p1, &dir1, &p2);
    if d > 2.0 * r + 1e-3 {
        return Err(PlanError::Turn {
            reason: "lines 2·r_min or more apart take a pi turn",
            distance: d,
        });
    }
    // Centres: c1 beside the current line away from the next one, c3 beside the next line on
    // the far side, c2 ahead in the headland tangent to both.
    let c1 = p1 - n * r;
    let c3 = p2 + n * r;
    let m = (c1 + c3) / 2.0;
    let half = (c3 - c1).norm() / 2.0;
    let h = ((2.0 * r).powi(2) - half * half).max(0.0).sqrt();
    let c2 = m + dir1 * h;
    let t1 = (c1 + c2) / 2.0;
    let t2 = (c2 + c3) / 2.0;
    // Turning toward the next line is counter-clockwise when it lies to the left.
    let toward_ccw = cross(&dir1, &n) > 0.0;
    arc_points(c1, p1, t1, !toward_ccw, params.arc_step, true, out);
    arc_points(c2, t1, t2, toward_ccw, params.arc_step, false, out);
    arc_points(c3, t2, p2, !toward_ccw, params.arc_step, false, out);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::heading_vec;

    fn params(r: f64) -> TurnParams {
        TurnParams {
            r_min: r,
            arc_step: 5f64.to_radians(),
            merge_distance: 0.05,
            point_spacing: 1.0,
            max_points: 500,
        }
    }

    /// Centre of the circle through three points.
    fn circumcentre(a: Vec2, b: Vec2, c: Vec2) -> Option<Vec2> {
        let d = 2.0 * (a.x * (b.y - c.y) + b.x * (c.y - a.y) + c.x * (a.y - b.y));
        if d.abs() < 1e-12 {
            return None;
        }
        let (a2, b2, c2) = (a.norm_squared(), b.norm_squared(), c.norm_squared());
        Some(v2(
            (a2 * (b.y - c.y) + b2 * (c.y - a.y) + c2 * (a.y - b.y)) / d,
            (a2 * (c.x - b.x) + b2 * (a.x - c.x) + c2 * (b.x - a.x)) / d,
        ))
    }

    /// Heading (unit tangent in the direction of travel) at the first point of `pts`,
    /// from the circle through the first three points.
    fn tangent_at_start(pts: &[Vec2]) -> Vec2 {
        let chord = (pts[1] - pts[0]).normalize();
        match circumcentre(pts[0], pts[1], pts[2]) {
            None => chord,
            Some(c) => {
                let t = left_normal(&(pts[0] - c)).normalize();
                if t.dot(&chord) >= 0.0 {
                    t
                } else {
                    -t
                }
            }
        }
    }

    fn angle_between(a: &Vec2, b: &Vec2) -> f64 {
        cross(a, b).atan2(a.dot(b)).abs()
    }

    /// Check a turn: exact ends, tangent joins, radius ≥ r everywhere.
    fn check_turn(pts: &[Vec2], p1: Vec2, dir1: Vec2, p2: Vec2, dir2: Vec2, r: f64) {
        assert!((pts[0] - p1).norm() < 1e-3, "start {:?}", pts[0]);
        assert!((pts[pts.len() - 1] - p2).norm() < 1e-3, "end");
        let t0 = tangent_at_start(pts);
        assert!(
            angle_between(&t0, &dir1).to_degrees() < 1.0,
            "start heading"
        );
        let rev: Vec<Vec2> = pts.iter().rev().copied().collect();
        let t1 = -tangent_at_start(&rev);
        assert!(angle_between(&t1, &dir2).to_degrees() < 1.0, "end heading");
        for w in pts.windows(3) {
            if let Some(c) = circumcentre(w[0], w[1], w[2]) {
                let rad = (w[1] - c).norm();
                assert!(rad >= r - 1e-6, "radius {rad} < {r}");
            }
        }
        // No kink anywhere: consecutive chords turn by at most the arc step.
        for w in pts.windows(3) {
            let a = w[1] - w[0];
            let b = w[2] - w[1];
            if a.norm() > 1e-9 && b.norm() > 1e-9 {
                assert!(angle_between(&a, &b) <= 5f64.to_radians() + 1e-6);
            }
        }
    }

    #[test]
    fn pi_turn_geometry_both_sides_with_and_without_straight() {
        for &(r, d) in &[(5.0, 10.0), (5.0, 12.0), (5.0, 31.0), (3.0, 6.0)] {
            for &left in &[true, false] {
                for &h in &[0.0, 0.7, -2.0] {
                    let dir1 = heading_vec(h);
                    let n = if left {
                        left_normal(&dir1)
                    } else {
                        -left_normal(&dir1)
                    };
                    let p1 = v2(10.0, -3.0);
                    let p2 = p1 + n * d;
                    let mut out = Vec::new();
                    pi_turn(p1, dir1, p2, &params(r), &mut out).unwrap();
                    let pts: Vec<Vec2> = out.iter().map(|p| p.pos).collect();
                    check_turn(&pts, p1, dir1, p2, -dir1, r);
                    assert!(out.iter().all(|p| p.tag == crate::geo::Tag::Turn));
                    if d == 2.0 * r {
                        // Merged: one semicircle, no straight and no duplicate point.
                        for w in pts.windows(2) {
                            assert!((w[1] - w[0]).norm() > 1e-6);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn straight_part_is_capped() {
        let mut p = params(5.0);
        p.max_points = 3;
        let mut out = Vec::new();
        pi_turn(v2(0.0, 0.0), v2(1.0, 0.0), v2(0.0, 100.0), &p, &mut out).unwrap();
        let ccount = out
            .windows(2)
            .filter(|w| (w[1].pos - w[0].pos).norm() > 5.0)
            .count();
        assert_eq!(ccount, 4, "90 m straight in 4 pieces");
    }

    #[test]
    fn bulb_turn_geometry() {
        for &d in &[0.5, 3.0, 6.0, 9.99] {
            for &left in &[true, false] {
                let dir1 = heading_vec(1.1);
                let n = if left {
                    left_normal(&dir1)
                } else {
                    -left_normal(&dir1)
                };
                let p1 = v2(-4.0, 7.0);
                let p2 = p1 + n * d;
                let mut out = Vec::new();
                bulb_turn(p1, dir1, p2, &params(5.0), &mut out).unwrap();
                let pts: Vec<Vec2> = out.iter().map(|p| p.pos).collect();
                check_turn(&pts, p1, dir1, p2, -dir1, 5.0);
            }
        }
    }

    #[test]
    fn wrong_turn_kind_is_an_error() {
        let mut out = Vec::new();
        assert!(pi_turn(
            v2(0.0, 0.0),
            v2(1.0, 0.0),
            v2(0.0, 3.0),
            &params(5.0),
            &mut out
        )
        .is_err());
        assert!(bulb_turn(
            v2(0.0, 0.0),
            v2(1.0, 0.0),
            v2(0.0, 30.0),
            &params(5.0),
            &mut out
        )
        .is_err());
        let mut bad = params(5.0);
        bad.r_min = f64::NAN;
        assert!(pi_turn(v2(0.0, 0.0), v2(1.0, 0.0), v2(0.0, 30.0), &bad, &mut out).is_err());
    }
}
