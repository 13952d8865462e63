//! Concentric circular work lines (`job.kind = "arcs"`): the curved-line job of the accuracy
//! suite. Line i is an arc of radius `r_inner + i·width` about `centre`, sweeping `sweep` rad;
//! even lines run counter-clockwise from angle `start_angle`, odd lines clockwise back, and a
//! forward headland turn ([`forward_turn`]: a pi turn or, for lines closer than 2·r_min, a bulb
//! turn) joins the end of each line to the start of the next, as between AB lines.
//!
//! Contract: pure; returns planned segments ([`PlanSegment`]s), which the job layer turns into
//! the segment job the guidance drives.

use super::turns::{forward_turn, TurnParams};
use super::types::PlanError;
use crate::geo::{v2, Direction, PathPoint, Vec2};
use crate::plan::types::{PlanSegment, SegmentKind};

/// The shape of an arcs job.
#[derive(Debug, Clone, PartialEq)]
pub struct ArcsParams {
    /// Centre of the circles, local ENU m.
    pub centre: Vec2,
    /// Radius of the first (innermost) line, m.
    pub r_inner: f64,
    /// Spacing of the lines (implement width), m.
    pub width: f64,
    /// Number of lines, >= 1.
    pub lines: u64,
    /// Sweep of every line, rad, in (0, 2π).
    pub sweep: f64,
    /// Polar angle of the first line's start, rad (CCW from East).
    pub start_angle: f64,
    /// Largest distance between consecutive points of a line, m.
    pub point_spacing: f64,
    pub turn: TurnParams,
}

/// The points of line `i`, in driving order.
fn line_points(p: &ArcsParams, i: u64) -> Vec<Vec2> {
    let r = p.r_inner + i as f64 * p.width;
    let n = ((r * p.sweep / p.point_spacing).ceil() as usize).max(2);
    let ccw = i % 2 == 0;
    (0..=n)
        .map(|k| {
            let f = k as f64 / n as f64;
            let a = p.start_angle + if ccw { f } else { 1.0 - f } * p.sweep;
            p.centre + v2(a.cos(), a.sin()) * r
        })
        .collect()
}

/// The arcs job: lines and the turns between them, in driving order.
pub fn arcs_segments(p: &ArcsParams) -> Result<Vec<PlanSegment>, PlanError> {
    PlanError::check(
        "r_inner",
        p.r_inner,
        p.r_inner.is_finite() && p.r_inner > 0.0,
    )?;
    PlanError::check("width", p.width, p.width.is_finite() && p.width > 0.0)?;
    PlanError::check(
        "sweep",
        p.sweep,
        p.sweep > 0.0 && p.sweep < std::f64::consts::TAU,
    )?;
    PlanError::check(
        "point_spacing",
        p.point_spacing,
        p.point_spacing.is_finite() && p.point_spacing > 0.0,
    )?;
    PlanError::check(
        "centre",
        p.centre.x,
        p.centre.x.is_finite() && p.centre.y.is_finite() && p.start_angle.is_finite(),
    )?;
    if p.lines == 0 || p.lines > 1000 {
        return Err(PlanError::Invalid {
            name: "lines",
            value: p.lines as f64,
            rule: "an arcs job needs 1..=1000 lines",
        });
    }
    let mut segments = Vec::with_capacity(2 * p.lines as usize);
    let mut turn = Vec::new();
    for i in 0..p.lines {
        let points = line_points(p, i);
        if i > 0 {
            // The previous line's end and direction there (a line has at least 3 points).
            let Some(&[.., before, p1]) = segments.last().map(|s: &PlanSegment| &s.points[..])
            else {
                break;
            };
            // The arc's tangent at its end (the last chord turns half a step less).
            let radial = p1 - p.centre;
            let tangent = Vec2::new(-radial.y, radial.x).normalize();
            let dir1 = if tangent.dot(&(p1 - before)) >= 0.0 {
                tangent
            } else {
                -tangent
            };
            let p2 = points[0];
            turn.clear();
            forward_turn(p1, dir1, p2, (p2 - p1).norm(), &p.turn, &mut turn)?;
            segments.push(PlanSegment {
                kind: SegmentKind::Turn,
                direction: Direction::Forward,
                index: segments.len(),
                cell: 0,
                points: turn.iter().map(|q: &PathPoint| q.pos).collect(),
            });
        }
        segments.push(PlanSegment {
            kind: SegmentKind::Work,
            direction: Direction::Forward,
            index: segments.len(),
            cell: 0,
            points,
        });
    }
    Ok(segments)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::job::{JobSegment, SegmentJob};

    /// The segments as the job the guidance drives.
    fn arcs_job(p: &ArcsParams) -> Result<SegmentJob, PlanError> {
        SegmentJob::from_plan_segments(arcs_segments(p)?)
    }

    fn params() -> ArcsParams {
        ArcsParams {
            centre: v2(0.0, 0.0),
            r_inner: 15.0,
            width: 3.0,
            lines: 3,
            sweep: 270f64.to_radians(),
            start_angle: -90f64.to_radians(),
            point_spacing: 1.0,
            turn: TurnParams {
                r_min: 5.0,
                arc_step: 5f64.to_radians(),
                merge_distance: 0.5,
                point_spacing: 1.0,
                max_points: 100,
                max_curvature_rate: 0.0,
            },
        }
    }

    #[test]
    fn lines_are_concentric_arcs_joined_by_turns() {
        let job = arcs_job(&params()).expect("plans");
        let s = job.segments();
        assert_eq!(s.len(), 5, "3 lines, 2 turns");
        for (k, seg) in s.iter().enumerate() {
            if k % 2 == 0 {
                assert_eq!(seg.kind, SegmentKind::Work);
                let r = 15.0 + 3.0 * (k / 2) as f64;
                for q in &seg.points {
                    assert!((q.norm() - r).abs() < 1e-9, "line {k} off its circle");
                }
                assert!((seg.length() - r * 270f64.to_radians()).abs() < 0.05 * r);
            } else {
                assert_eq!(seg.kind, SegmentKind::Turn);
                // Each turn starts where the line before ends and ends where the next starts.
                let before = s[k - 1].points.last().copied().unwrap_or_default();
                let after = s[k + 1].points[0];
                assert!((seg.points[0] - before).norm() < 1e-6);
                assert!((seg.points.last().copied().unwrap_or_default() - after).norm() < 1e-6);
            }
        }
        // Adjacent lines run in opposite senses (the cross product of the start tangent with
        // the radius flips sign).
        let sense =
            |seg: &JobSegment| crate::geo::cross(&seg.points[0], &(seg.points[1] - seg.points[0]));
        assert!(sense(&s[0]) > 0.0 && sense(&s[2]) < 0.0 && sense(&s[4]) > 0.0);
    }

    #[test]
    fn bad_parameters_are_errors() {
        for f in [
            |p: &mut ArcsParams| p.r_inner = 0.0,
            |p: &mut ArcsParams| p.lines = 0,
            |p: &mut ArcsParams| p.sweep = 7.0,
            |p: &mut ArcsParams| p.width = f64::NAN,
        ] {
            let mut p = params();
            f(&mut p);
            assert!(arcs_job(&p).is_err());
        }
    }

    /// With a curvature rate, the turns between the arcs are continuous-curvature: their
    /// curvature changes by at most about σ per metre (the line's tangent at its end is the
    /// turn's start heading, so the lines are level and the CC bulb fits).
    #[test]
    fn turns_keep_the_curvature_rate() {
        // The suite's R 15 m arcs 3 m apart, and wider arcs 12 m apart started elsewhere.
        for (r_inner, width, start_deg, sigma) in
            [(15.0, 3.0, -90.0, 0.02), (40.0, 12.0, 30.0, 0.05)]
        {
            let mut p = params();
            p.r_inner = r_inner;
            p.width = width;
            p.start_angle = f64::to_radians(start_deg);
            p.point_spacing = 0.5;
            p.turn.point_spacing = 0.5;
            p.turn.max_points = 400;
            p.turn.max_curvature_rate = sigma;
            turns_of_arcs_keep(&p, sigma);
        }
    }

    fn turns_of_arcs_keep(p: &ArcsParams, sigma: f64) {
        let segments = arcs_segments(p).expect("plans");
        let curvature = |t: &[Vec2], i: usize| {
            crate::plan::coverage::metrics::three_point_curvature(&t[i - 1], &t[i], &t[i + 1])
        };
        for turn in segments.iter().filter(|s| s.kind == SegmentKind::Turn) {
            let t = &turn.points;
            assert!(t.len() > 10);
            assert!(curvature(t, 1).abs() < 0.05, "the turn starts straight");
            for i in 2..t.len() - 1 {
                let (k0, k1) = (curvature(t, i - 1), curvature(t, i));
                let ds = (t[i] - t[i - 1]).norm();
                assert!(
                    (k1 - k0).abs() <= sigma * ds * 1.5 + 1e-3,
                    "curvature step {k0:.3} → {k1:.3} over {ds:.2} m at point {i}"
                );
            }
        }
    }
}
