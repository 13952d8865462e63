//! Turns between parallel lines, as pure functions, and the one turn selector.
//!
//! [`turn_shape`] chooses the turn from the lateral gap between the lines and `r_min`:
//! * a pi turn ([`pi_turn`], the seed-000 turn) when the lines are at least `2·r_min` apart
//!   (within [`GAP_TOLERANCE`]): a quarter arc off the current line, a straight across the
//!   headland (or nothing, when the arcs meet), a quarter arc onto the next line;
//! * closer lines take a forward-only bulb (omega) turn ([`bulb_turn`]: an arc away from the
//!   next line, a large arc the other way and an arc back, all of radius `r_min`) where the
//!   job may not reverse ([`ShortTurn::Bulb`]: AB block jobs, arcs), else a fishtail with a
//!   reversal ([`ShortTurn::Fishtail`]: fields, sequential AB lines).
//!
//! The curvature-rate limit (`TurnParams::max_curvature_rate` > 0) makes pi turns and
//! fishtails continuous-curvature (clothoid + arc + clothoid; a pi turn falls back to arcs
//! when its lines are not level or too close for the clothoids).
//!
//! [`forward_turn`] writes a pi or bulb turn straight into a caller's buffer (the AB plan's
//! turns, generated while driving, and the arcs job). [`TurnCache`] solves each turn once in
//! a canonical frame and moves it onto every alike pair of line ends (fields, sequential AB
//! lines).
//!
//! Every point carries [`Tag::Turn`](crate::geo::Tag); the first point is exactly the end of the
//! current line and the last exactly the start of the next one.
//!
//! Contract: pure; uses `plan::types`, `plan::maneuver` (clothoid turns, cusp splitting) and
//! [`crate::geo`] only.

pub mod cache;
mod cc;

pub use cache::{canonical_turn, TurnCache, TurnPart};
pub(crate) use cc::cc_quarter_turn;
use cc::{cc_bulb_turn, cc_pi_turn};

use super::types::PlanError;
use crate::geo::{cross, left_normal, v2, PathPoint, Vec2};
use std::f64::consts::TAU;

/// Lines closer than `2·r_min` by less than this still take a pi turn (the rounding of gaps
/// computed from coordinates), m. The skip order counts line gaps with the same tolerance.
pub const GAP_TOLERANCE: f64 = 1e-3;

/// How a job joins lines closer than `2·r_min`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShortTurn {
    /// Forward only: a bulb (omega) turn (AB block jobs, arcs).
    Bulb,
    /// With a reversal: a fishtail (fields, sequential AB lines).
    Fishtail,
}

/// The kind of a turn between two parallel lines.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TurnShape {
    Pi,
    Bulb,
    Fishtail,
}

/// The one turn selector: a pi turn for lines `gap` (m) apart when `gap + ε ≥ 2·r_min`
/// (ε = [`GAP_TOLERANCE`]), else the job's turn for close lines.
pub fn turn_shape(gap: f64, r_min: f64, short: ShortTurn) -> TurnShape {
    if gap + GAP_TOLERANCE >= 2.0 * r_min {
        TurnShape::Pi
    } else {
        match short {
            ShortTurn::Bulb => TurnShape::Bulb,
            ShortTurn::Fishtail => TurnShape::Fishtail,
        }
    }
}

/// Append the forward-only turn from the end `p1` (travel direction `dir1`, unit) of a line to
/// the start `p2` of the next one, `gap` m to the side: a pi turn or a bulb turn, as
/// [`turn_shape`] chooses.
pub fn forward_turn(
    p1: Vec2,
    dir1: Vec2,
    p2: Vec2,
    gap: f64,
    params: &TurnParams,
    out: &mut Vec<PathPoint>,
) -> Result<(), PlanError> {
    match turn_shape(gap, params.r_min, ShortTurn::Bulb) {
        TurnShape::Pi => pi_turn(p1, dir1, p2, params, out),
        TurnShape::Bulb | TurnShape::Fishtail => bulb_turn(p1, dir1, p2, params, out),
    }
}

/// Arc sweeps below this are treated as zero, rad.
const ZERO_SWEEP: f64 = 1e-6;

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
    /// Largest curvature rate per metre driven for continuous-curvature turns, 1/m²; 0 =
    /// turns made of arcs only (curvature steps at their ends).
    pub max_curvature_rate: f64,
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
        PlanError::check(
            "max_curvature_rate",
            self.max_curvature_rate,
            self.max_curvature_rate >= 0.0,
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

/// Append the points of an arc about `centre` from `from` to `to` (positions, m), turning
/// counter-clockwise when `ccw`, with steps of at most `step` rad. `from` itself is appended
/// only when `include_start`; `to` is appended exactly. An arc of (numerically) zero sweep adds
/// no point beyond `from` (when asked for), so touching arcs never duplicate a point.
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
    // A sweep within a micro-radian of zero or of a full turn is a zero arc (rounding of
    // touching arcs); no turn arc legitimately sweeps a full circle.
    if sweep > TAU - ZERO_SWEEP {
        sweep = 0.0;
    }
    if include_start {
        out.push(PathPoint::turn(from));
    }
    if sweep < ZERO_SWEEP {
        // `to` is `from` up to rounding. When the caller put `from` down already, make that
        // point exactly `to` (so a turn still ends exactly on its target).
        if !include_start {
            match out.last_mut() {
                Some(last) => last.pos = to,
                None => out.push(PathPoint::turn(to)),
            }
        }
        return;
    }
    let sign = if ccw { 1.0 } else { -1.0 };
    // At least two steps, so every arc has an interior point and a well-defined tangent.
    let n = ((sweep / step).ceil() as usize).max(2);
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
/// `p1` is the end of the current line (m), `dir1` its unit travel direction; `p2` is the
/// start of the next line (m), on either side. Circle 1 (radius `r_min`) touches the current
/// line at `p1`, circle 2 the next line at `p2`, both toward the other line; the turning sense
/// follows the seed: positive `cross(dir1, p1 − c1)` turns clockwise, else counter-clockwise.
/// Arc points are at most `arc_step` apart; the straight between the arc ends is interpolated
/// to `point_spacing` (at most `max_points` interior points) unless the ends are closer than
/// `merge_distance`, in which case the two arcs merge into one semicircle. The lines must be
/// at least `2·r_min` apart (within 1 mm), else [`PlanError::Turn`].
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
    if d + GAP_TOLERANCE < 2.0 * r {
        return Err(PlanError::Turn {
            reason: "lines closer than 2·r_min need a bulb or fishtail turn",
            distance: d,
        });
    }
    if params.max_curvature_rate > 0.0
        && (cc_pi_turn(p1, dir1, p2, n, d, params, out)
            || cc_bulb_turn(p1, dir1, p2, n, d, params, out))
    {
        return Ok(());
    }
    let c1 = p1 + n * r;
    let rv1 = p1 - c1;
    // Seed: positive cross(direction, radius vector 1) turns clockwise, else counter-clockwise.
    let ccw = cross(&dir1, &rv1) <= 0.0;
    let e1 = c1 + dir1 * r;
    let c2 = p2 - n * r;
    let s2 = c2 + dir1 * r;
    let gap = s2 - e1;
    if gap.norm() >= params.merge_distance {
        arc_points(c1, p1, e1, ccw, params.arc_step, true, out);
        straight_points(e1, s2, params.point_spacing, params.max_points, out);
        arc_points(c2, s2, p2, ccw, params.arc_step, false, out);
    } else if gap.dot(&dir1).abs() < 1e-3 {
        // Merge, next line level with this one: one semicircle through p1 and p2 (radius
        // d/2 ≥ r_min up to the 1 mm tolerance), tangent to both lines, evenly stepped.
        arc_points((p1 + p2) / 2.0, p1, p2, ccw, params.arc_step, true, out);
    } else {
        // Merge with a small longitudinal offset: the two quarter arcs back to back (the
        // skipped straight is shorter than `merge_distance`).
        arc_points(c1, p1, e1, ccw, params.arc_step, true, out);
        arc_points(c2, s2, p2, ccw, params.arc_step, false, out);
    }
    Ok(())
}

/// A forward-only bulb (omega) turn between lines closer than `2·r_min`: an arc away from the
/// next line by β, a large arc the other way by π + 2β, and an arc away again by β, all of
/// radius `r_min` (m) and tangent to each other, ending exactly at `p2` heading along `−dir1`.
///
/// `p1` is the end of the current line (m), `dir1` its unit travel direction, `p2` the start
/// of the next line (m), `0 ≤ d ≤ 2·r_min` apart sideways (within 1 mm). `d = 0` (the same
/// line back) gives the symmetric omega with β = 60°; `d = 2·r_min` degenerates to the merged
/// pi turn (β = 0, one semicircle). Errors when the lines are farther apart, or `p2` lies so
/// far along the current line that the middle circle cannot touch both others.
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
    if d > 2.0 * r + GAP_TOLERANCE {
        return Err(PlanError::Turn {
            reason: "lines 2·r_min or more apart take a pi turn",
            distance: d,
        });
    }
    if params.max_curvature_rate > 0.0 && cc_bulb_turn(p1, dir1, p2, n, d, params, out) {
        return Ok(());
    }
    // Centres: c1 beside the current line away from the next one, c3 beside the next line on
    // the far side, c2 ahead in the headland tangent to both.
    let c1 = p1 - n * r;
    let c3 = p2 + n * r;
    // |c3 − c1| ≥ d + 2r − (rounding) > 0 whatever the longitudinal offset of p2.
    let span = c3 - c1;
    let half = span.norm() / 2.0;
    if half > 2.0 * r + 1e-3 {
        return Err(PlanError::Turn {
            reason: "next line starts too far along the current one for a bulb turn",
            distance: d,
        });
    }
    // c2 on the perpendicular bisector of c1–c3, on the headland side, 2r from both.
    let mut bisector = left_normal(&(span / (2.0 * half)));
    if bisector.dot(&dir1) < 0.0 {
        bisector = -bisector;
    }
    let h = ((2.0 * r).powi(2) - half * half).max(0.0).sqrt();
    let c2 = (c1 + c3) / 2.0 + bisector * h;
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
            max_curvature_rate: 0.0,
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
    fn cc_pi_turns_end_on_the_next_line_and_fall_back_to_arcs_when_too_close() {
        let mut p = params(5.0);
        p.max_curvature_rate = 0.1;
        let (p1, dir) = (v2(0.0, 100.0), v2(0.0, 1.0));
        // 15 m apart (≥ two CC quarter-turn reaches of a little over 6 m): CC, either side.
        for side in [1.0, -1.0] {
            let p2 = v2(15.0 * side, 100.0);
            let mut out = Vec::new();
            pi_turn(p1, dir, p2, &p, &mut out).unwrap();
            assert_eq!(out[0].pos, p1);
            assert_eq!(out.last().unwrap().pos, p2);
            // The last step heads back along −dir, and the path bulges beyond the line ends
            // by more than r_min (clothoids reach further than arcs).
            let n = out.len();
            let d = (out[n - 1].pos - out[n - 2].pos).normalize();
            assert!((d + dir).norm() < 0.02, "{d:?}");
            let top = out.iter().map(|q| q.pos.y).fold(f64::MIN, f64::max);
            assert!(top > 105.5 && top < 107.5, "{top}");
            // Curvature from three points never above 1/r_min (plus sampling slack).
            for w in out.windows(3) {
                if let Some(c) = circumcentre(w[0].pos, w[1].pos, w[2].pos) {
                    assert!((w[1].pos - c).norm() > 5.0 * 0.97);
                }
            }
        }
        // 12 m apart (≥ 2·r_min, below two CC reaches): the CC bulb, reaching further than
        // the arcs' r_min.
        let mut out = Vec::new();
        pi_turn(p1, dir, v2(12.0, 100.0), &p, &mut out).unwrap();
        let top = out.iter().map(|q| q.pos.y).fold(f64::MIN, f64::max);
        assert!(top > 105.5, "{top}");
        assert_eq!(out.last().unwrap().pos, v2(12.0, 100.0));
        // Not level: the arcs, top exactly r_min.
        let mut out = Vec::new();
        pi_turn(p1, dir, v2(12.0, 101.0), &p, &mut out).unwrap();
        let top = out.iter().map(|q| q.pos.y).fold(f64::MIN, f64::max);
        assert!((top - 106.0).abs() < 1e-9, "{top}");
    }

    /// Curvature from three points (1/m, positive left), or 0 on a straight.
    fn three_point_curvature(a: Vec2, b: Vec2, c: Vec2) -> f64 {
        let (u, w) = (b - a, c - b);
        let chord = (c - a).norm();
        if chord < 1e-9 {
            return 0.0;
        }
        2.0 * cross(&u, &w) / (u.norm() * w.norm() * chord)
    }

    /// A slow curvature rate (a 10°/s motor at 10 km/h on a 3 m wheelbase: 0.021 /m²) makes
    /// the CC quarter turn reach far more than r_min: the AB demo's gaps (12, 15 m) and any
    /// gap up to wider than the CC pi turn's still get a continuous-curvature turn, forward
    /// only, ending exactly on the next line heading back, within κ_max and σ_max. Closer
    /// lines, whose CC bulb would cross itself, keep the arcs (ends exact all the same).
    #[test]
    fn close_lines_get_a_continuous_curvature_bulb_at_a_slow_curvature_rate() {
        let sigma = 0.021;
        let mut p = params(5.0);
        p.max_curvature_rate = sigma;
        p.point_spacing = 0.25;
        for &d in &[0.0, 3.0, 6.0, 10.0, 12.0, 15.0, 24.0] {
            for side in [1.0, -1.0] {
                let (p1, dir) = (v2(2.0, 50.0), heading_vec(0.4));
                let p2 = p1 + left_normal(&dir) * (d * side);
                let mut out = Vec::new();
                forward_turn(p1, dir, p2, d, &p, &mut out).unwrap();
                let pts: Vec<Vec2> = out.iter().map(|q| q.pos).collect();
                assert_eq!(pts[0], p1);
                assert_eq!(*pts.last().unwrap(), p2);
                assert_no_duplicates(&pts);
                let n = pts.len();
                assert!((pts[1] - pts[0]).normalize().dot(&dir) > 0.999, "d {d}");
                assert!(
                    (pts[n - 1] - pts[n - 2]).normalize().dot(&-dir) > 0.999,
                    "d {d}"
                );
                if d < 10.0 {
                    continue;
                }
                let kappa: Vec<f64> = pts
                    .windows(3)
                    .map(|w| three_point_curvature(w[0], w[1], w[2]))
                    .collect();
                assert!(kappa[0].abs() < 0.02 && kappa[kappa.len() - 1].abs() < 0.02);
                for k in &kappa {
                    assert!(k.abs() <= 0.2 * 1.02, "d {d}: κ {k}");
                }
                // Continuous: κ changes by no more than σ_max over the sample spacing (with
                // slack for the sampling), never by a step.
                for w in kappa.windows(2) {
                    assert!((w[1] - w[0]).abs() < 3.0 * sigma * 0.5, "d {d}: {w:?}");
                }
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

    fn assert_no_duplicates(pts: &[Vec2]) {
        for w in pts.windows(2) {
            assert!((w[1] - w[0]).norm() > 1e-6, "duplicate point {:?}", w[0]);
        }
    }

    #[test]
    fn bulb_turn_geometry() {
        // d = 0 (same line back), up to d = 2r (degenerates into the merged pi turn).
        for &d in &[0.0, 0.5, 3.0, 6.0, 9.99, 10.0] {
            for &left in &[true, false] {
                // Next line starting level with the current end, or a little along/behind it.
                for &along in &[0.0, 1.5, -2.0] {
                    // Near d = 2r the middle circle cannot reach an offset start.
                    if along != 0.0 && d > 6.0 {
                        continue;
                    }
                    let dir1 = heading_vec(1.1);
                    let n = if left {
                        left_normal(&dir1)
                    } else {
                        -left_normal(&dir1)
                    };
                    let p1 = v2(-4.0, 7.0);
                    let p2 = p1 + n * d + dir1 * along;
                    let mut out = Vec::new();
                    bulb_turn(p1, dir1, p2, &params(5.0), &mut out).unwrap();
                    let pts: Vec<Vec2> = out.iter().map(|p| p.pos).collect();
                    check_turn(&pts, p1, dir1, p2, -dir1, 5.0);
                    assert_no_duplicates(&pts);
                    assert!(out.iter().all(|p| p.tag == crate::geo::Tag::Turn));
                    assert!(out
                        .iter()
                        .all(|p| p.direction == crate::geo::Direction::Forward));
                    // The middle arc reaches r (d = 2r) to (1 + √3)·r (d = 0) beyond the line
                    // end.
                    let reach = pts
                        .iter()
                        .map(|q| (q - p1).dot(&dir1))
                        .fold(f64::MIN, f64::max);
                    let top = (1.0 + 3f64.sqrt()) * 5.0 + along.abs();
                    assert!(reach >= 5.0 - 1e-6 && reach <= top, "reach {reach}");
                    // Going away from the next line first (for d > 0).
                    if d > 0.0 && d <= 6.0 {
                        let side = |q: &Vec2| (q - p1).dot(&n);
                        assert!(pts.iter().take(4).skip(1).all(|q| side(q) < 0.0));
                    }
                }
            }
        }
        // The middle circle cannot touch both when the next line starts far ahead.
        let mut out = Vec::new();
        assert!(bulb_turn(
            v2(0.0, 0.0),
            v2(1.0, 0.0),
            v2(30.0, 2.0),
            &params(5.0),
            &mut out
        )
        .is_err());
    }

    #[test]
    fn pi_turn_merges_nearly_touching_arcs_without_a_kink() {
        // d slightly above 2r: arc ends 3 cm apart, below the 5 cm merge distance.
        let (r, d) = (5.0, 10.03);
        for &left in &[true, false] {
            let dir1 = heading_vec(-2.5);
            let n = if left {
                left_normal(&dir1)
            } else {
                -left_normal(&dir1)
            };
            let p1 = v2(1.0, 2.0);
            let p2 = p1 + n * d;
            let mut merged = Vec::new();
            pi_turn(p1, dir1, p2, &params(r), &mut merged).unwrap();
            let pts: Vec<Vec2> = merged.iter().map(|p| p.pos).collect();
            check_turn(&pts, p1, dir1, p2, -dir1, r);
            assert_no_duplicates(&pts);
            // With a zero merge distance the 3 cm straight is kept as its own point pair.
            let mut p = params(r);
            p.merge_distance = 0.0;
            let mut joined = Vec::new();
            pi_turn(p1, dir1, p2, &p, &mut joined).unwrap();
            // Merged: every point on the one semicircle about the midpoint.
            let centre = (p1 + p2) / 2.0;
            assert!(pts
                .iter()
                .all(|q| ((q - centre).norm() - d / 2.0).abs() < 1e-9));
            // Joined: two quarter arcs of radius r with the 3 cm straight between them.
            let straight = joined
                .windows(2)
                .filter(|w| ((w[1].pos - w[0].pos).norm() - (d - 2.0 * r)).abs() < 1e-9)
                .count();
            assert_eq!(straight, 1);
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
