use super::*;
use crate::geo::{rect, v2, Direction};

fn seg(kind: SegmentKind, index: usize, points: Vec<Vec2>) -> PlanSegment {
    PlanSegment {
        kind,
        direction: Direction::Forward,
        index,
        cell: 0,
        points,
    }
}

/// 100 × 60 m field, 10 m swaths at y = 5, 15, …, 55 sampled every metre, no headland.
fn plan(swath_ys: &[f64]) -> (Field, FieldPlan) {
    let field = Field {
        boundary: rect(0.0, 0.0, 100.0, 60.0),
        obstacles: Vec::new(),
    };
    let segments = swath_ys
        .iter()
        .enumerate()
        .map(|(i, &y)| {
            let pts = (0..=100).map(|k| v2(k as f64, y)).collect();
            seg(SegmentKind::Work, i, pts)
        })
        .collect();
    let plan = FieldPlan {
        segments,
        working_area: vec![(field.boundary.clone(), Vec::new())],
        cells: 1,
        swath_angles: vec![0.0],
        swaths: swath_ys.len(),
        ..FieldPlan::default()
    };
    (field, plan)
}

const YS: [f64; 6] = [5.0, 15.0, 25.0, 35.0, 45.0, 55.0];

#[test]
fn exact_cover_has_full_coverage_no_overlap_nothing_outside() {
    let (field, p) = plan(&YS);
    let m = plan_metrics(&field, &p, 10.0);
    assert!(
        (m.covered_fraction - 1.0).abs() < 1e-9,
        "{}",
        m.covered_fraction
    );
    assert!((m.working_area_covered_fraction - 1.0).abs() < 1e-9);
    assert!(m.overlap_fraction.abs() < 1e-9, "{}", m.overlap_fraction);
    assert!(m.outside_area_m2 < 1e-6, "{}", m.outside_area_m2);
    assert!((m.work_length_m - 600.0).abs() < 1e-9);
    assert!(m.max_curvature < 1e-9);
    assert_eq!(m.turns, 0);
}

#[test]
fn missing_shifted_and_overlapping_swaths_are_measured() {
    let (field, p) = plan(&YS[..5]);
    let m = plan_metrics(&field, &p, 10.0);
    assert!((m.covered_fraction - 5.0 / 6.0).abs() < 1e-9);

    // Last swath moved to y = 60: half of it (100 × 5 m²) lies outside, 5 m strip uncovered.
    let (field, p) = plan(&[5.0, 15.0, 25.0, 35.0, 45.0, 60.0]);
    let m = plan_metrics(&field, &p, 10.0);
    assert!(
        (m.outside_area_m2 - 500.0).abs() < 1e-6,
        "{}",
        m.outside_area_m2
    );
    assert!((m.covered_fraction - 55.0 / 60.0).abs() < 1e-9);

    // Swath at y = 50 overlaps its neighbours at 45 and 55 by 5 m each over 100 m.
    let (field, p) = plan(&[5.0, 15.0, 25.0, 35.0, 45.0, 50.0, 55.0]);
    let m = plan_metrics(&field, &p, 10.0);
    assert!((m.covered_fraction - 1.0).abs() < 1e-9);
    let expected = 1000.0 / 6000.0;
    assert!(
        (m.overlap_fraction - expected).abs() < 1e-9,
        "{}",
        m.overlap_fraction
    );
}

#[test]
fn turns_curvature_containment_and_obstacles() {
    let (mut field, mut p) = plan(&YS);
    // A semicircular turn of radius 5 m from (100, 5) to (100, 15), bulging east (outside).
    let arc: Vec<Vec2> = (0..=36)
        .map(|k| {
            let a = -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * k as f64 / 36.0;
            v2(100.0 + 5.0 * a.cos(), 10.0 + 5.0 * a.sin())
        })
        .collect();
    p.segments.insert(1, seg(SegmentKind::Turn, 1, arc));
    let m = plan_metrics(&field, &p, 10.0);
    assert!((m.max_curvature - 0.2).abs() < 1e-6, "{}", m.max_curvature);
    assert_eq!(m.turns, 1);
    assert!(m.turn_points_outside >= 30, "{}", m.turn_points_outside);
    // The turn's footprint: a half annulus of radii 0..10 m east of x = 100, minus the
    // 16-gon shortfall: between 0.9 and 1.0 of π·10²/2.
    let half_disc = std::f64::consts::PI * 100.0 / 2.0;
    assert!(m.outside_area_m2 > 0.9 * half_disc && m.outside_area_m2 <= half_disc + 1e-6);

    // An obstacle on the swath at y = 25; the planner's working area ignores it.
    field.obstacles.push(rect(40.0, 28.0, 50.0, 32.0));
    let m = plan_metrics(&field, &p, 10.0);
    assert!(m.obstacle_intrusions > 0);
    // The obstacle is 40 m² of field and working area; covered fractions exclude it.
    assert!((m.working_area_m2 - (6000.0 - 40.0)).abs() < 1e-6);
    assert!((m.covered_fraction - 1.0).abs() < 1e-9);
    // Without the swath at y = 5, an obstacle at y 1..4 is ≥ 11 m from every path point.
    let (f2, p2) = plan(&YS[1..]);
    let f2 = Field {
        obstacles: vec![rect(40.0, 1.0, 50.0, 4.0)],
        ..f2
    };
    let m = plan_metrics(&f2, &p2, 10.0);
    assert_eq!(m.obstacle_intrusions, 0);
}

#[test]
fn reversals_count_direction_changes() {
    let (field, mut p) = plan(&YS);
    p.segments[2].direction = Direction::Reverse;
    let m = plan_metrics(&field, &p, 10.0);
    assert_eq!(m.reversals, 2);
}

#[test]
fn three_point_curvature_of_circle_points() {
    let r = 7.0;
    let pts: Vec<Vec2> = (0..3)
        .map(|k| {
            let a = 0.3 * k as f64;
            v2(r * a.cos(), r * a.sin())
        })
        .collect();
    assert!((three_point_curvature(&pts[0], &pts[1], &pts[2]) - 1.0 / r).abs() < 1e-12);
    assert_eq!(
        three_point_curvature(&v2(0.0, 0.0), &v2(1.0, 0.0), &v2(2.0, 0.0)),
        0.0
    );
}

/// A plan whose passes and swaths lie on the East and North axes (a block with an arm 24 m wide,
/// w 3 m, r_min 8 m): stroked in one buffer, its footprint ran out of memory; it is the same as
/// the footprint of the plan turned by 0.3 rad.
#[test]
fn footprints_of_a_plan_on_the_axes() {
    use crate::plan::coverage::{plan_field, tests::params};
    let field = Field {
        boundary: vec![
            v2(0.0, 0.0),
            v2(100.0, 0.0),
            v2(100.0, 100.0),
            v2(24.0, 100.0),
            v2(24.0, 250.0),
            v2(0.0, 250.0),
        ],
        obstacles: vec![],
    };
    let plan = plan_field(&field, &params(3.0, 8.0, 4)).unwrap();
    let area = footprint(&plan.segments, 3.0).unsigned_area();
    let (sin, cos) = 0.3f64.sin_cos();
    let turned: Vec<PlanSegment> = plan
        .segments
        .iter()
        .map(|s| PlanSegment {
            points: s
                .points
                .iter()
                .map(|q| v2(q.x * cos - q.y * sin, q.x * sin + q.y * cos))
                .collect(),
            ..s.clone()
        })
        .collect();
    let turned_area = footprint(&turned, 3.0).unsigned_area();
    assert!(area > 0.9 * 13_600.0, "footprint {area} m² of 13 600");
    assert!(
        (area - turned_area).abs() < 1e-6 * area,
        "{area} against {turned_area}"
    );
    let m = plan_metrics(&field, &plan, 3.0);
    assert!(m.covered_fraction > 0.0 && m.covered_fraction <= 1.0);
}

/// 101 points from `a` to `b`.
fn line(a: Vec2, b: Vec2) -> Vec<Vec2> {
    (0..=100)
        .map(|k| a + (b - a) * (k as f64 / 100.0))
        .collect()
}

/// A 10 m swath along y = 30 over a 100 × 60 m field whose 10 m headland pass runs from
/// (`x_bottom`, 0) to (`x_top`, 60); the plan made for `sections`.
fn swath_into_headland(x_bottom: f64, x_top: f64, sections: usize) -> (Field, FieldPlan) {
    let field = Field {
        boundary: rect(0.0, 0.0, 100.0, 60.0),
        obstacles: Vec::new(),
    };
    let plan = FieldPlan {
        segments: vec![
            seg(
                SegmentKind::Headland,
                0,
                line(v2(x_bottom, 0.0), v2(x_top, 60.0)),
            ),
            seg(SegmentKind::Work, 1, line(v2(0.0, 30.0), v2(100.0, 30.0))),
        ],
        working_area: vec![(rect(0.0, 0.0, 90.0, 60.0), Vec::new())],
        swaths: 1,
        sections,
        ..FieldPlan::default()
    };
    (field, plan)
}

#[test]
fn sections_switched_off_over_the_headland_lay_nothing_twice_and_leave_nothing() {
    // Square to the pass (x 90–100): the whole swath overlaps it by 10 × 10 m; with five
    // sections each switches off where the pass's footprint begins.
    let (field, whole) = swath_into_headland(95.0, 95.0, 1);
    let m = plan_metrics(&field, &whole, 10.0);
    let union = 600.0 + 900.0;
    assert!(
        (m.overlap_fraction - 100.0 / union).abs() < 1e-6,
        "{}",
        m.overlap_fraction
    );
    let (_, sectioned) = swath_into_headland(95.0, 95.0, 5);
    let s = plan_metrics(&field, &sectioned, 10.0);
    assert!(s.overlap_fraction.abs() < 1e-6, "{}", s.overlap_fraction);
    assert!((s.covered_fraction - m.covered_fraction).abs() < 1e-9);
    // Slanted 1 in 6: the whole width lays a 10 m-wide parallelogram's worth twice; five
    // sections at most a triangle per section beyond where each switches off.
    let (_, whole) = swath_into_headland(90.0, 100.0, 1);
    let (_, sectioned) = swath_into_headland(90.0, 100.0, 5);
    sections_lay_less_twice(&field, &whole, &sectioned, 0.3);
    let unworked = |p: &FieldPlan| unworked_ground(&field, p, 10.0).unsigned_area();
    assert!((unworked(&sectioned) - unworked(&whole)).abs() < 1e-6);
}

/// The metrics of `whole` (one section) and `sectioned` (the same paths, more sections) at
/// w 10 m, asserting that both lay ground twice, the sections under `at_most` of the whole
/// implement's overlap, and the same ground worked.
fn sections_lay_less_twice(
    field: &Field,
    whole: &FieldPlan,
    sectioned: &FieldPlan,
    at_most: f64,
) -> (PlanMetrics, PlanMetrics) {
    let (m, s) = (
        plan_metrics(field, whole, 10.0),
        plan_metrics(field, sectioned, 10.0),
    );
    assert!(m.overlap_fraction > 0.0 && s.overlap_fraction > 0.0);
    assert!(
        s.overlap_fraction < at_most * m.overlap_fraction,
        "sectioned {} whole {}",
        s.overlap_fraction,
        m.overlap_fraction
    );
    assert!((s.covered_fraction - m.covered_fraction).abs() < 1e-9);
    (m, s)
}

/// A 100 × 100 m field without headland, w 10 m: a swath along y = 50, then `second` (a
/// crossing swath or a bent path laid partly over the first), both worked by `sections`.
fn over_a_swath_before(
    second: Vec<Vec2>,
    kind: SegmentKind,
    sections: usize,
) -> (Field, FieldPlan) {
    let field = Field {
        boundary: rect(0.0, 0.0, 100.0, 100.0),
        obstacles: Vec::new(),
    };
    let plan = FieldPlan {
        segments: vec![
            seg(SegmentKind::Work, 0, line(v2(0.0, 50.0), v2(100.0, 50.0))),
            seg(kind, 1, second),
        ],
        working_area: vec![(field.boundary.clone(), Vec::new())],
        swaths: 2,
        sections,
        ..FieldPlan::default()
    };
    (field, plan)
}

#[test]
fn sections_switch_off_over_the_swaths_and_detours_driven_before() {
    // Crossing square: the whole implement lays the 10 × 10 m crossing twice; its sections
    // switch off over it.
    let crossing = line(v2(50.0, 0.0), v2(50.0, 100.0));
    let (field, whole) = over_a_swath_before(crossing.clone(), SegmentKind::Work, 1);
    let (_, sectioned) = over_a_swath_before(crossing, SegmentKind::Work, 5);
    let (m, s) = (
        plan_metrics(&field, &whole, 10.0),
        plan_metrics(&field, &sectioned, 10.0),
    );
    assert!(
        (m.overlap_fraction - 100.0 / 1900.0).abs() < 1e-6,
        "{}",
        m.overlap_fraction
    );
    assert!(s.overlap_fraction.abs() < 1e-6, "{}", s.overlap_fraction);
    // A bent path (a detour's shape: not straight) 7 m from the swath over its first half,
    // 3 m of its width over the swath's: two of five sections switch off there, one stays on
    // over its 1 m; beyond the bend it climbs away.
    let mut bent = line(v2(0.0, 57.0), v2(50.0, 57.0));
    bent.extend(line(v2(50.0, 57.0), v2(100.0, 70.0)).into_iter().skip(1));
    let (_, whole) = over_a_swath_before(bent.clone(), SegmentKind::Detour, 1);
    let (_, sectioned) = over_a_swath_before(bent, SegmentKind::Detour, 5);
    sections_lay_less_twice(&field, &whole, &sectioned, 0.5);
}

#[test]
fn a_headland_pass_switches_sections_off_over_the_pass_before() {
    // Two square passes round a 100 × 100 m field at w 10 m, 5 m apart: the inner one lays a
    // 5 m band over the outer one's footprint. With five 2 m sections the two outermost of the
    // inner pass switch off there and one stays on over its 1 m: about a fifth of the band.
    let field = Field {
        boundary: rect(0.0, 0.0, 100.0, 100.0),
        obstacles: Vec::new(),
    };
    let ring = |inset: f64| {
        let (lo, hi) = (inset, 100.0 - inset);
        let corners = [v2(lo, lo), v2(hi, lo), v2(hi, hi), v2(lo, hi), v2(lo, lo)];
        let mut pts = vec![corners[0]];
        for c in corners.windows(2) {
            pts.extend(line(c[0], c[1]).into_iter().skip(1));
        }
        pts
    };
    let plan = |sections| FieldPlan {
        segments: vec![
            seg(SegmentKind::Headland, 0, ring(5.0)),
            seg(SegmentKind::Headland, 1, ring(10.0)),
        ],
        working_area: vec![(rect(15.0, 15.0, 85.0, 85.0), Vec::new())],
        sections,
        ..FieldPlan::default()
    };
    sections_lay_less_twice(&field, &plan(1), &plan(5), 0.35);
}
