//! What a plan's reader must be told beyond its metrics: every violation of the hard
//! guarantees (checked from the plan's geometry alone), the ground left unworked and the
//! ground the vehicle cannot reach, and every warning of reading the field. Shown on the
//! summary line of `agsteer plan`, in `metrics.json` and in `plan.svg`.

use super::LoadedField;
use crate::plan::coverage::metrics::checks::{check_plan, Violation, ViolationKind};
use crate::plan::coverage::metrics::{
    area_and_pieces, unreachable_ground, unworked_ground, PlanMetrics,
};
use crate::plan::coverage::{Field, FieldPlan};
use geo::MultiPolygon;
use serde::Serialize;

/// The whole-field worked fraction below which the unworked ground is a warning (issue 17's
/// target for every test field).
pub const WORKED_TARGET: f64 = 0.995;
/// Pieces of unworked or unreachable ground smaller than this are not counted (slivers
/// between footprints from the polygon operations' rounding), m².
pub const MIN_PIECE_M2: f64 = 1.0;

/// Unworked and unreachable ground narrower than twice this is dropped from the drawing and
/// the count of pieces (rounding slivers along footprint edges and re-grown edges that meet
/// the boundary exactly; they would join the pieces into one and paint the boundary), m.
pub const SLIVER_M: f64 = 0.05;

/// `mp` opened by `d`: shrunk by `d` then grown back, so parts narrower than `2·d` vanish.
fn opened(mp: &MultiPolygon<f64>, d: f64) -> MultiPolygon<f64> {
    use geo::algorithm::buffer::{BufferStyle, LineJoin};
    use geo::Buffer;
    let style = |d: f64| BufferStyle::new(d).line_join(LineJoin::Round(0.1));
    mp.buffer_with_style(style(-d)).buffer_with_style(style(d))
}

/// Ground of `field` the implement cannot reach (`metrics::unreachable_ground`) without
/// slivers narrower than `2·SLIVER_M`.
pub fn unreachable(field: &Field, line_width: f64, r_min: f64) -> MultiPolygon<f64> {
    opened(&unreachable_ground(field, line_width, r_min), SLIVER_M)
}

/// Number of violations of each kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct ViolationCounts {
    pub outside_boundary: usize,
    pub inside_obstacle: usize,
    pub footprint_not_clear: usize,
    pub curvature: usize,
}

impl ViolationCounts {
    pub fn of(violations: &[Violation]) -> ViolationCounts {
        let count = |k: ViolationKind| violations.iter().filter(|v| v.kind == k).count();
        ViolationCounts {
            outside_boundary: count(ViolationKind::OutsideBoundary),
            inside_obstacle: count(ViolationKind::InsideObstacle),
            footprint_not_clear: count(ViolationKind::FootprintNotClear),
            curvature: count(ViolationKind::Curvature),
        }
    }

    pub fn total(&self) -> usize {
        self.outside_boundary + self.inside_obstacle + self.footprint_not_clear + self.curvature
    }
}

/// The findings of one plan (serialised into `metrics.json`). Areas m², lengths m.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct PlanFindings {
    /// Implement width and turning radius the plan was checked with, m.
    pub line_width_m: f64,
    pub r_min_m: f64,
    /// Pieces of unworked ground at least `2·SLIVER_M` wide and [`MIN_PIECE_M2`] in area (the
    /// whole unworked area is the metrics' `unworked_area_m2`).
    pub unworked_pieces: usize,
    /// Ground the implement cannot reach driving forward and turning no tighter than r_min
    /// (corners sharper than the vehicle turns, necks narrower than its turn;
    /// `metrics::unreachable_ground` without slivers), m².
    pub unreachable_area_m2: f64,
    /// Pieces of unreachable ground of at least [`MIN_PIECE_M2`].
    pub unreachable_pieces: usize,
    pub violation_counts: ViolationCounts,
    /// Every violation of the hard guarantees, in plan order.
    pub violations: Vec<Violation>,
    /// Every warning, one sentence each: reading the field, the planner's own, unworked and
    /// unreachable ground.
    pub warnings: Vec<String>,
}

/// The ground to draw: unworked (red, without slivers narrower than `2·SLIVER_M`) and
/// unreachable (hatched), local metres.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanGround {
    pub unworked: MultiPolygon<f64>,
    pub unreachable: MultiPolygon<f64>,
}

/// Check `plan` of `loaded` (implement `line_width`, turning radius `r_min`, m) and collect
/// the findings; `planner_warnings` are the planner's own notes.
pub fn plan_findings(
    loaded: &LoadedField,
    plan: &FieldPlan,
    metrics: &PlanMetrics,
    line_width: f64,
    r_min: f64,
    planner_warnings: &[String],
) -> (PlanFindings, PlanGround) {
    let field = &loaded.field;
    let violations = check_plan(field, plan, line_width, r_min);
    let unworked = opened(&unworked_ground(field, plan, line_width), SLIVER_M);
    let unreachable = unreachable(field, line_width, r_min);
    let (_, unworked_pieces) = area_and_pieces(&unworked, MIN_PIECE_M2);
    let (unreachable_area_m2, unreachable_pieces) = area_and_pieces(&unreachable, MIN_PIECE_M2);
    let mut warnings = loaded.warnings.clone();
    warnings.extend(planner_warnings.iter().cloned());
    if metrics.covered_fraction < WORKED_TARGET {
        warnings.push(format!(
            "field worked {:.2} % (< {:.1} %): {:.0} m² unworked in {unworked_pieces} piece{} (red in plan.svg)",
            100.0 * metrics.covered_fraction,
            100.0 * WORKED_TARGET,
            metrics.unworked_area_m2,
            if unworked_pieces == 1 { "" } else { "s" }
        ));
    }
    if unreachable_pieces > 0 {
        warnings.push(format!(
            "{unreachable_area_m2:.0} m² in {unreachable_pieces} place{} cannot be reached turning at r_min {r_min} m with a {line_width} m implement (hatched in plan.svg; by hand or reversing)",
            if unreachable_pieces == 1 { "" } else { "s" }
        ));
    }
    let findings = PlanFindings {
        line_width_m: line_width,
        r_min_m: r_min,
        unworked_pieces,
        unreachable_area_m2,
        unreachable_pieces,
        violation_counts: ViolationCounts::of(&violations),
        violations,
        warnings,
    };
    (
        findings,
        PlanGround {
            unworked,
            unreachable,
        },
    )
}

/// One phrase per kind of violation: how many stretches, their length, the worst value and
/// the first place (segment and local position), e.g. "3 outside the boundary (214.0 m,
/// worst 4.20 m; first Transit segment 12 at (10.0, -3.5))".
pub fn violation_phrases(violations: &[Violation]) -> Vec<String> {
    let kinds = [
        (ViolationKind::OutsideBoundary, "outside the boundary", "m"),
        (ViolationKind::InsideObstacle, "inside an obstacle", "m"),
        (
            ViolationKind::FootprintNotClear,
            "implement over the edge or an obstacle",
            "m",
        ),
        (ViolationKind::Curvature, "curvature above 1/r_min", "/m"),
    ];
    kinds
        .iter()
        .filter_map(|(kind, what, unit)| {
            let of: Vec<&Violation> = violations.iter().filter(|v| v.kind == *kind).collect();
            let first = of.first()?;
            let length: f64 = of.iter().map(|v| v.length_m).sum();
            let worst = of.iter().map(|v| v.worst).fold(0.0, f64::max);
            Some(format!(
                "{} {what} ({length:.1} m, worst {worst:.3} {unit}; first {:?} segment {} at ({:.1}, {:.1}))",
                of.len(),
                first.segment_kind,
                first.segment,
                first.at[0],
                first.at[1]
            ))
        })
        .collect()
}

impl PlanFindings {
    /// The end of the summary line: "violations: none" or each kind with its count, then
    /// "warnings: none" or every warning.
    pub fn summary(&self) -> String {
        let violations = if self.violations.is_empty() {
            "violations: none".to_string()
        } else {
            format!(
                "VIOLATIONS {}: {}",
                self.violations.len(),
                violation_phrases(&self.violations).join("; ")
            )
        };
        let warnings = if self.warnings.is_empty() {
            "warnings: none".to_string()
        } else {
            format!(
                "warnings {}: {}",
                self.warnings.len(),
                self.warnings.join("; ")
            )
        };
        format!("{violations}; {warnings}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::{load_field, LoadOptions};
    use crate::geo::{rect, v2, Direction};
    use crate::plan::coverage::metrics::plan_metrics;
    use crate::plan::coverage::{PlanSegment, SegmentKind};

    fn rectangle() -> LoadedField {
        let text = r#"{"type":"Polygon","coordinates":[[[5.0,52.0],[5.003,52.0],[5.003,52.001],[5.0,52.001],[5.0,52.0]]]}"#;
        load_field(text, &LoadOptions::default()).unwrap()
    }

    fn segment(kind: SegmentKind, index: usize, points: Vec<crate::geo::Vec2>) -> PlanSegment {
        PlanSegment {
            kind,
            direction: Direction::Forward,
            index,
            cell: 0,
            points,
        }
    }

    #[test]
    fn a_plan_with_a_stray_turn_names_it_and_the_unworked_and_unreachable_ground() {
        let loaded = rectangle();
        let (lo, hi) = crate::geo::polygon::bbox(loaded.field.boundary.iter()).unwrap();
        // One swath along the middle (6 m), and a turn 10 m out of the field at the east end.
        let y = 0.5 * (lo.y + hi.y);
        let plan = FieldPlan {
            segments: vec![
                segment(
                    SegmentKind::Work,
                    0,
                    vec![v2(lo.x + 10.0, y), v2(hi.x - 10.0, y)],
                ),
                segment(
                    SegmentKind::Turn,
                    1,
                    (0..=20).map(|k| v2(hi.x - 10.0 + k as f64, y)).collect(),
                ),
            ],
            working_area: vec![(rect(lo.x, lo.y, hi.x, hi.y), vec![])],
            swaths: 1,
            ..FieldPlan::default()
        };
        let m = plan_metrics(&loaded.field, &plan, 6.0);
        let (f, ground) = plan_findings(&loaded, &plan, &m, 6.0, 5.0, &["planner note".into()]);
        assert_eq!(f.violation_counts.outside_boundary, 1, "{:?}", f.violations);
        assert_eq!(f.violation_counts.total(), f.violations.len());
        let line = f.summary();
        assert!(
            line.contains("VIOLATIONS 1: 1 outside the boundary (10.0 m"),
            "{line}"
        );
        assert!(line.contains("planner note"), "{line}");
        assert!(line.contains("unworked in 1 piece (red"), "{line}");
        // Four right-angle corners at r_min 5 m + 3 m: 4·(1 − π/4)·8² = 55 m².
        assert_eq!(f.unreachable_pieces, 4);
        assert!(
            (f.unreachable_area_m2 - 55.0).abs() < 1.0,
            "{}",
            f.unreachable_area_m2
        );
        assert!(
            line.contains("55 m² in 4 places cannot be reached"),
            "{line}"
        );
        use geo::Area;
        assert!((ground.unworked.unsigned_area() - m.unworked_area_m2).abs() < 1.0);
        // A clean plan says so.
        let clean = PlanFindings::default();
        assert_eq!(clean.summary(), "violations: none; warnings: none");
    }
}
