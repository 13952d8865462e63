//! The hard guarantees of a field plan, checked point by point from the plan's geometry alone:
//! no path point outside the boundary or inside an obstacle, the working passes' footprints
//! clear of the edge and the obstacles by w/2, and no curvature above 1/r_min.

use super::super::{Field, FieldPlan, SegmentKind};
use super::{merged, three_point_curvature};
use crate::geo::polygon::contains_point;
use crate::geo::Vec2;
use serde::Serialize;

/// Slack of the footprint clearance, m: the planner keeps w/2 plus a chord margin at every
/// point; this only absorbs rounding.
pub const CLEARANCE_SLACK_M: f64 = 0.01;
/// Relative slack of the curvature limit: three-point curvature over points about a metre
/// apart on an arc of radius r_min reads up to ~1 % high.
pub const CURVATURE_SLACK: f64 = 0.02;
/// Absolute slack of the curvature limit, 1/m.
pub const CURVATURE_SLACK_ABS: f64 = 1e-3;

/// The largest three-point curvature the guarantees allow at `r_min`, 1/m: 1/r_min with
/// [`CURVATURE_SLACK`] and [`CURVATURE_SLACK_ABS`].
pub fn curvature_limit(r_min: f64) -> f64 {
    (1.0 + CURVATURE_SLACK) / r_min + CURVATURE_SLACK_ABS
}

/// What a violation breaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ViolationKind {
    /// Path points outside the field boundary.
    OutsideBoundary,
    /// Path points inside an obstacle (a hole of the field).
    InsideObstacle,
    /// A working pass's implement (w/2 either side) over the field edge or an obstacle.
    FootprintNotClear,
    /// Curvature above 1/r_min.
    Curvature,
}

/// One stretch of one segment that breaks a guarantee.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Violation {
    pub kind: ViolationKind,
    /// Index of the segment in the plan.
    pub segment: usize,
    pub segment_kind: SegmentKind,
    /// First offending point, local ENU metres.
    pub at: [f64; 2],
    /// Length of the offending stretch along the path, m (0 for a single point).
    pub length_m: f64,
    /// Worst value on the stretch: distance outside / into the obstacle / short of the
    /// clearance (m), or curvature (1/m).
    pub worst: f64,
}

impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let what = match self.kind {
            ViolationKind::OutsideBoundary => "outside the boundary",
            ViolationKind::InsideObstacle => "inside an obstacle",
            ViolationKind::FootprintNotClear => "implement over the edge or an obstacle",
            ViolationKind::Curvature => "curvature above 1/r_min",
        };
        let worst = match self.kind {
            ViolationKind::Curvature => format!("{:.4} /m", self.worst),
            _ => format!("{:.2} m", self.worst),
        };
        write!(
            f,
            "{:?} segment {} {what}: {:.1} m from ({:.1}, {:.1}), worst {worst}",
            self.segment_kind, self.segment, self.length_m, self.at[0], self.at[1]
        )
    }
}

/// Collects runs of consecutive offending points of one segment into violations.
struct Runs<'a> {
    out: &'a mut Vec<Violation>,
    open: Option<Violation>,
    last: Option<Vec2>,
}

impl Runs<'_> {
    fn point(
        &mut self,
        bad: Option<f64>,
        q: &Vec2,
        kind: ViolationKind,
        seg: (usize, SegmentKind),
    ) {
        match (bad, self.open.as_mut()) {
            (Some(v), Some(open)) => {
                if let Some(last) = self.last {
                    open.length_m += (q - last).norm();
                }
                open.worst = open.worst.max(v);
            }
            (Some(v), None) => {
                self.open = Some(Violation {
                    kind,
                    segment: seg.0,
                    segment_kind: seg.1,
                    at: [q.x, q.y],
                    length_m: 0.0,
                    worst: v,
                })
            }
            (None, _) => self.close(),
        }
        self.last = Some(*q);
    }

    fn close(&mut self) {
        if let Some(v) = self.open.take() {
            self.out.push(v);
        }
    }
}

/// Every violation of the plan's guarantees, in plan order.
pub fn check_plan(field: &Field, plan: &FieldPlan, line_width: f64, r_min: f64) -> Vec<Violation> {
    use SegmentKind::*;
    let half = 0.5 * line_width;
    let limit = curvature_limit(r_min);
    let mut out = Vec::new();
    for s in &plan.segments {
        let seg = (s.index, s.kind);
        let working = matches!(s.kind, Work | Detour | Headland);
        let pts = merged(&s.points);
        let mut outside = Runs {
            out: &mut out,
            open: None,
            last: None,
        };
        for q in &pts {
            let bad = (!contains_point(&field.boundary, q)).then(|| field.distance_to_edges(q));
            outside.point(bad, q, ViolationKind::OutsideBoundary, seg);
        }
        outside.close();
        let mut inside = Runs {
            out: &mut out,
            open: None,
            last: None,
        };
        for q in &pts {
            let bad = field
                .obstacles
                .iter()
                .any(|o| contains_point(o, q))
                .then(|| field.distance_to_edges(q));
            inside.point(bad, q, ViolationKind::InsideObstacle, seg);
        }
        inside.close();
        if working {
            let mut clear = Runs {
                out: &mut out,
                open: None,
                last: None,
            };
            for q in &pts {
                let inside_field = field.contains(q);
                let d = field.distance_to_edges(q);
                let bad = (inside_field && d < half - CLEARANCE_SLACK_M).then_some(half - d);
                clear.point(bad, q, ViolationKind::FootprintNotClear, seg);
            }
            clear.close();
        }
        let mut curv = Runs {
            out: &mut out,
            open: None,
            last: None,
        };
        for w in pts.windows(3) {
            let k = three_point_curvature(&w[0], &w[1], &w[2]);
            curv.point(
                (k > limit).then_some(k),
                &w[1],
                ViolationKind::Curvature,
                seg,
            );
        }
        curv.close();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::{rect, v2, Direction};
    use crate::plan::coverage::PlanSegment;

    fn plan_of(kind: SegmentKind, points: Vec<Vec2>) -> FieldPlan {
        FieldPlan {
            segments: vec![PlanSegment {
                kind,
                direction: Direction::Forward,
                index: 0,
                cell: 0,
                points,
            }],
            ..FieldPlan::default()
        }
    }

    #[test]
    fn each_guarantee_is_caught_and_a_clear_plan_passes() {
        let field = Field {
            boundary: rect(0.0, 0.0, 100.0, 60.0),
            obstacles: vec![rect(40.0, 28.0, 50.0, 32.0)],
        };
        let line = |y: f64, x0: f64, x1: f64| -> Vec<Vec2> {
            (0..=((x1 - x0) as usize))
                .map(|k| v2(x0 + k as f64, y))
                .collect()
        };
        // Clear: a swath at y = 10 of a 6 m implement.
        assert!(check_plan(
            &field,
            &plan_of(SegmentKind::Work, line(10.0, 5.0, 95.0)),
            6.0,
            5.0
        )
        .is_empty());
        // A turn running out of the field over x 100..110 (the point on the edge counts as
        // outside): one run of 10 m.
        let v = check_plan(
            &field,
            &plan_of(SegmentKind::Turn, line(10.0, 90.0, 110.0)),
            6.0,
            5.0,
        );
        assert_eq!(v.len(), 1, "{v:?}");
        assert_eq!(v[0].kind, ViolationKind::OutsideBoundary);
        assert!((v[0].length_m - 10.0).abs() < 1e-9, "{}", v[0].length_m);
        // Through the obstacle.
        let v = check_plan(
            &field,
            &plan_of(SegmentKind::Transit, line(30.0, 30.0, 60.0)),
            6.0,
            5.0,
        );
        assert!(v.iter().any(|v| v.kind == ViolationKind::InsideObstacle));
        // A swath 2 m from the edge with a 6 m implement: not clear; a turn there is fine.
        let v = check_plan(
            &field,
            &plan_of(SegmentKind::Work, line(2.0, 5.0, 95.0)),
            6.0,
            5.0,
        );
        assert!(v.iter().all(|v| v.kind == ViolationKind::FootprintNotClear) && !v.is_empty());
        assert!(check_plan(
            &field,
            &plan_of(SegmentKind::Turn, line(2.0, 5.0, 95.0)),
            6.0,
            5.0
        )
        .is_empty());
        // A circle of radius 4 m driven at r_min 5 m.
        let circle: Vec<Vec2> = (0..=40)
            .map(|k| {
                let a = k as f64 * 0.1;
                v2(20.0 + 4.0 * a.cos(), 15.0 + 4.0 * a.sin())
            })
            .collect();
        let v = check_plan(
            &field,
            &plan_of(SegmentKind::Turn, circle.clone()),
            6.0,
            5.0,
        );
        assert_eq!(v.len(), 1);
        assert!((v[0].worst - 0.25).abs() < 1e-3, "{}", v[0].worst);
        assert!(check_plan(&field, &plan_of(SegmentKind::Turn, circle), 6.0, 4.0).is_empty());
    }
}
