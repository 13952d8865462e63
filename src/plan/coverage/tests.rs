use super::*;

pub(crate) fn params(w: f64, r: f64, passes: usize) -> CoverageParams {
    CoverageParams {
        line_width: w,
        r_min: r,
        headland_passes: passes,
        point_spacing: 1.0,
        swath_angle: SwathAngle::MinTurns,
        route: RouteOrder::Auto,
        small_obstacle_max_m: 0.0,
        max_curvature_rate: 0.0,
        headland_order: Default::default(),
        sections: 1,
        overlap: 0.0,
    }
}

fn curvature(w: &[Vec2]) -> f64 {
    let (a, b, c) = (w[0], w[1], w[2]);
    2.0 * crate::geo::cross(&(b - a), &(c - b)).abs()
        / ((b - a).norm() * (c - b).norm() * (c - a).norm()).max(1e-12)
}

/// Every point clear of the edge and obstacles by w/2, curvature ≤ 1/r_min (3-point, 2 %
/// for discretisation), consecutive segments joined.
pub(crate) fn check(field: &Field, p: &CoverageParams) -> FieldPlan {
    let plan = plan_field(field, p).unwrap();
    assert!(plan.swaths > 0);
    for s in &plan.segments {
        for q in &s.points {
            assert!(
                implement_clear(field, p.line_width / 2.0, q),
                "{:?} {} at {q:?}",
                s.kind,
                s.index
            );
        }
        for w in s.points.windows(3) {
            if (w[1] - w[0]).norm() > 0.05 && (w[2] - w[1]).norm() > 0.05 {
                let k = curvature(w);
                assert!(
                    k <= 1.02 / p.r_min,
                    "{:?} {}: curvature {k}",
                    s.kind,
                    s.index
                );
            }
        }
    }
    for pair in plan.segments.windows(2) {
        let gap = (pair[1].points[0] - *pair[0].points.last().unwrap()).norm();
        assert!(
            gap < 1e-6,
            "segments {} → {} apart by {gap}",
            pair[0].index,
            pair[1].index
        );
    }
    plan
}

#[test]
fn small_obstacles_are_passed_on_detours_large_ones_split_the_swaths() {
    let pole = vec![
        v2(140.0, 70.0),
        v2(148.0, 70.0),
        v2(148.0, 78.0),
        v2(140.0, 78.0),
    ];
    let field = Field {
        boundary: vec![
            v2(0.0, 0.0),
            v2(300.0, 0.0),
            v2(300.0, 150.0),
            v2(0.0, 150.0),
        ],
        obstacles: vec![pole],
    };
    let mut p = params(6.0, 5.0, 2);
    p.small_obstacle_max_m = 15.0;
    let plan = check(&field, &p);
    let detours: Vec<&PlanSegment> = plan
        .segments
        .iter()
        .filter(|s| s.kind == SegmentKind::Detour)
        .collect();
    assert!(!detours.is_empty(), "the 8 m pole is passed on detours");
    // Each detour leaves its swath and comes back to it: same line, same heading.
    for d in &detours {
        let (a, b) = (d.points[0], *d.points.last().unwrap());
        assert!(
            (a.y - b.y).abs() < 1e-6,
            "detour {} ends on its line",
            d.index
        );
    }
    // Below the threshold, the same pole gets headland passes and no detour.
    p.small_obstacle_max_m = 5.0;
    let plan = check(&field, &p);
    assert!(plan.segments.iter().all(|s| s.kind != SegmentKind::Detour));
    assert!(
        plan.segments
            .iter()
            .filter(|s| s.kind == SegmentKind::Headland)
            .count()
            > 2,
        "field passes and obstacle passes"
    );
}

#[test]
fn rectangle_l_and_obstacle_fields_plan_clear_and_driveable() {
    let rect = Field {
        boundary: vec![
            v2(0.0, 0.0),
            v2(300.0, 0.0),
            v2(300.0, 150.0),
            v2(0.0, 150.0),
        ],
        obstacles: vec![],
    };
    let plan = check(&rect, &params(12.0, 6.0, 2));
    assert_eq!(plan.cells, 1);
    let l = Field {
        boundary: vec![
            v2(0.0, 0.0),
            v2(220.0, 0.0),
            v2(220.0, 110.0),
            v2(110.0, 110.0),
            v2(110.0, 220.0),
            v2(0.0, 220.0),
        ],
        obstacles: vec![vec![
            v2(150.0, 45.0),
            v2(162.0, 45.0),
            v2(162.0, 57.0),
            v2(150.0, 57.0),
        ]],
    };
    check(&l, &params(12.0, 6.0, 2));
    // The bench's 100 ha field: a convex 12-gon with an obstacle, w = r_min = 6 m.
    let radii = [
        1.00, 0.93, 1.08, 0.97, 1.05, 0.9, 1.02, 0.95, 1.1, 0.92, 1.0, 0.96,
    ];
    let pts: Vec<Vec2> = radii
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let a = i as f64 * std::f64::consts::TAU / 12.0 + 0.1 * (i % 3) as f64;
            v2(r * a.cos() * 1.4, r * a.sin())
        })
        .collect();
    let hull = geometry::convex_hull(&pts);
    let k = (1e6 / crate::geo::polygon::signed_area(&hull)).sqrt();
    let c = v2(0.2 * k, 0.1 * k);
    let gon = Field {
        boundary: hull.iter().map(|q| q * k).collect(),
        obstacles: vec![vec![
            c + v2(-10.0, -7.0),
            c + v2(10.0, -7.0),
            c + v2(10.0, 7.0),
            c + v2(-10.0, 7.0),
        ]],
    };
    let t = std::time::Instant::now();
    let plan = check(&gon, &params(6.0, 6.0, 3));
    eprintln!(
        "12-gon: {} segments, {} swaths, {} cells in {:?}",
        plan.segments.len(),
        plan.swaths,
        plan.cells,
        t.elapsed()
    );
    // Narrow lines (w < 2·r_min): the skip order.
    let plan = check(&rect, &params(6.0, 6.0, 3));
    assert!(plan
        .segments
        .iter()
        .all(|s| s.direction == Direction::Forward));
}

#[test]
fn headland_order_last_works_the_swaths_first_and_the_headland_from_the_inside_out() {
    let field = Field {
        boundary: vec![
            v2(0.0, 0.0),
            v2(200.0, 0.0),
            v2(200.0, 120.0),
            v2(0.0, 120.0),
        ],
        obstacles: vec![],
    };
    let mut p = params(6.0, 5.0, 3);
    let first = check(&field, &p);
    p.headland_order = HeadlandOrder::Last;
    let last = check(&field, &p);
    let kinds = |plan: &FieldPlan| -> Vec<SegmentKind> {
        plan.segments
            .iter()
            .map(|s| s.kind)
            .filter(|k| matches!(k, SegmentKind::Work | SegmentKind::Headland))
            .collect()
    };
    let (kf, kl) = (kinds(&first), kinds(&last));
    assert_eq!(kf[0], SegmentKind::Headland);
    assert_eq!(kl[0], SegmentKind::Work);
    let last_work = kl.iter().rposition(|k| *k == SegmentKind::Work).unwrap();
    let first_headland = kl.iter().position(|k| *k == SegmentKind::Headland).unwrap();
    assert!(
        last_work < first_headland,
        "every swath before the headland"
    );
    assert_eq!(first.swaths, last.swaths);
    // Innermost pass first: the first headland pass of "last" keeps farther from the edge
    // than its last one.
    let edge = |q: &Vec2| q.x.min(200.0 - q.x).min(q.y).min(120.0 - q.y);
    let passes: Vec<&PlanSegment> = last
        .segments
        .iter()
        .filter(|s| s.kind == SegmentKind::Headland)
        .collect();
    assert_eq!(passes.len(), 3);
    let mean_edge =
        |s: &PlanSegment| s.points.iter().map(edge).sum::<f64>() / s.points.len() as f64;
    assert!(mean_edge(passes[0]) > mean_edge(passes[2]) + 6.0);
    // Both orders cover the field alike.
    let mf = metrics::plan_metrics(&field, &first, 6.0);
    let ml = metrics::plan_metrics(&field, &last, 6.0);
    assert!((mf.covered_fraction - ml.covered_fraction).abs() < 0.005);
}

/// A block with an arm 24 m wide (w 3 m, r_min 8 m, 4 passes): only the outermost pass fits
/// in the arm (pass k is opened at r_min), and the ground inside it, 18 m wide, was never
/// worked (no working area there: the field shrunk by 4·w); 78.5 % of the field was worked.
/// Now swaths work it, with reversing transits where no turn fits, the plan within the
/// guarantees and joined. (Turned by 0.3 rad; the same field on the axes is
/// `metrics::tests::footprints_of_a_plan_on_the_axes`.)
#[test]
fn an_arm_narrower_than_the_inner_passes_is_worked() {
    let (sin, cos) = 0.3f64.sin_cos();
    let turned = |x: f64, y: f64| v2(x * cos - y * sin, x * sin + y * cos);
    let field = Field {
        boundary: vec![
            turned(0.0, 0.0),
            turned(100.0, 0.0),
            turned(100.0, 100.0),
            turned(24.0, 100.0),
            turned(24.0, 250.0),
            turned(0.0, 250.0),
        ],
        obstacles: vec![],
    };
    let p = params(3.0, 8.0, 4);
    let plan = plan_field(&field, &p).unwrap();
    // The guarantees (turns and transits keep the tractor in the field; the implement is
    // raised there) and one path throughout.
    let violations = metrics::checks::check_plan(&field, &plan, p.line_width, p.r_min);
    assert!(violations.is_empty(), "{violations:?}");
    for pair in plan.segments.windows(2) {
        assert!((pair[1].points[0] - *pair[0].points.last().unwrap()).norm() < 1e-6);
    }
    let m = metrics::plan_metrics(&field, &plan, p.line_width);
    // Work whose middle is in the arm (beyond y' = 110 m in the field's own frame).
    let in_arm = |q: &Vec2| -q.x * sin + q.y * cos > 110.0;
    let arm_work: f64 = plan
        .segments
        .iter()
        .filter(|s| s.kind == SegmentKind::Work && in_arm(&s.points[s.points.len() / 2]))
        .map(|s| crate::geo::polygon::polyline_length(&s.points))
        .sum();
    assert!(arm_work > 500.0, "arm work {arm_work} m");
    assert!(m.covered_fraction > 0.85, "covered {}", m.covered_fraction);
    assert_eq!(plan.transit_gaps, 0);
}

/// The plan of `field`, asserted to hold the guarantees (`metrics::checks::check_plan`).
fn plan_within_guarantees(field: &Field, p: &CoverageParams) -> FieldPlan {
    let plan = plan_field(field, p).unwrap();
    let violations = metrics::checks::check_plan(field, &plan, p.line_width, p.r_min);
    assert!(violations.is_empty(), "{violations:?}");
    plan
}

/// An L, 120 × 100 m with an arm 34 m wide up to `arm_top` m, planned at w 12 m, r_min 8 m,
/// 2 passes and swaths East; the plan holds the guarantees and is one path throughout.
fn l_field_plan(arm_top: f64) -> (FieldPlan, CoverageParams) {
    let field = Field {
        boundary: vec![
            v2(0.0, 0.0),
            v2(120.0, 0.0),
            v2(120.0, 100.0),
            v2(34.0, 100.0),
            v2(34.0, arm_top),
            v2(0.0, arm_top),
        ],
        obstacles: vec![],
    };
    let p = CoverageParams {
        swath_angle: SwathAngle::Fixed { angle: 0.0 },
        ..params(12.0, 8.0, 2)
    };
    let plan = plan_within_guarantees(&field, &p);
    for pair in plan.segments.windows(2) {
        assert!((pair[1].points[0] - *pair[0].points.last().unwrap()).norm() < 1e-6);
    }
    (plan, p)
}

/// An L whose arm (34 m wide) holds the outer pass at w 12 m but not the inner one: between the
/// outer pass's footprints a strip 10 m wide is left, too narrow for a disc an implement wide,
/// and swaths at the field's angle (East) cross it for a few metres at most. Worked along its
/// length (`leftover::Worked::own`): a swath runs North up the arm over the strip's middle,
/// within the guarantees. Before, the strip was left (10 × 90 m unworked).
#[test]
fn a_strip_narrower_than_the_implement_is_worked_along_its_length() {
    let (plan, p) = l_field_plan(220.0);
    // Work up the arm, along it, whose footprint holds the strip's middle.
    let middle = v2(17.0, 165.0);
    let up_the_arm = work_over(&plan, &middle, p.line_width / 2.0).any(|s| {
        let (a, b) = (s.points[0], s.points[s.points.len() - 1]);
        (b - a).y.abs() > 10.0 * (b - a).x.abs() && (b - a).norm() > 40.0
    });
    assert!(up_the_arm, "no swath up the arm over {middle:?}");
}

/// The same L with an arm of 40 m: the strip between the outer pass's footprints is 10 m by
/// about 45 (some 440 m², under 4·w²). A pocket a farmer would work, and worked: some work's
/// footprint holds its middle, within the guarantees and with no gap. Before, leftover ground
/// under 4·w² was left.
#[test]
fn a_short_strip_between_the_outer_pass_footprints_is_worked() {
    let (plan, p) = l_field_plan(140.0);
    assert_worked_without_a_gap(&plan, &v2(17.0, 110.0), p.line_width / 2.0);
}

/// `plan` has no place without a transit and some work whose footprint (`half` m either side)
/// holds `q`.
fn assert_worked_without_a_gap(plan: &FieldPlan, q: &Vec2, half: f64) {
    assert_eq!(plan.transit_gaps, 0, "{:?}", plan.warnings);
    let over = work_over(plan, q, half).next().is_some();
    assert!(over, "no work over {q:?}");
}

/// The work segments of `plan` whose footprint (`half` m either side) holds `q`.
fn work_over<'a>(
    plan: &'a FieldPlan,
    q: &'a Vec2,
    half: f64,
) -> impl Iterator<Item = &'a PlanSegment> + 'a {
    plan.segments
        .iter()
        .filter(|s| s.kind == SegmentKind::Work)
        .filter(move |s| {
            s.points
                .windows(2)
                .any(|w| crate::geo::polygon::point_segment_distance(q, &w[0], &w[1]) < half)
        })
}

/// Two blocks joined by a neck 22 m wide and 60 m long (w 6 m, r_min 8 m): the outermost
/// pass, opened at r_min, cannot run through the neck and splits into a ring round each block,
/// leaving the neck's ground outside both. Worked as a cell of its own (`leftover::Worked::own`):
/// some work's footprint holds the neck's middle, within the guarantees and with no gap.
#[test]
fn the_ground_a_neck_leaves_outside_the_outer_pass_is_worked() {
    let field = Field {
        boundary: vec![
            v2(0.0, 0.0),
            v2(80.0, 0.0),
            v2(80.0, 29.0),
            v2(140.0, 29.0),
            v2(140.0, 0.0),
            v2(220.0, 0.0),
            v2(220.0, 80.0),
            v2(140.0, 80.0),
            v2(140.0, 51.0),
            v2(80.0, 51.0),
            v2(80.0, 80.0),
            v2(0.0, 80.0),
        ],
        obstacles: vec![],
    };
    let p = CoverageParams {
        swath_angle: SwathAngle::MinSpan,
        ..params(6.0, 8.0, 2)
    };
    let plan = plan_within_guarantees(&field, &p);
    assert_worked_without_a_gap(&plan, &v2(110.0, 40.0), p.line_width / 2.0);
}

/// Two blocks joined by a neck 12 m wide (w 3 m, r_min 8 m, 3 passes): the outermost pass's
/// area is two pieces, one per block, and the neck is tight to drive through. Each block is
/// worked whole (its headland passes and swaths) before the other: the work crosses the neck
/// once. Before, the headland passes alternated between the blocks, pass by pass.
#[test]
fn a_field_of_two_blocks_is_worked_block_by_block() {
    let (sin, cos) = 0.2f64.sin_cos();
    let turned = |x: f64, y: f64| v2(x * cos - y * sin, x * sin + y * cos);
    let field = Field {
        boundary: [
            (0.0, 0.0),
            (120.0, 0.0),
            (120.0, 80.0),
            (66.0, 80.0),
            (66.0, 100.0),
            (120.0, 100.0),
            (120.0, 180.0),
            (0.0, 180.0),
            (0.0, 100.0),
            (54.0, 100.0),
            (54.0, 80.0),
            (0.0, 80.0),
        ]
        .into_iter()
        .map(|(x, y)| turned(x, y))
        .collect(),
        obstacles: vec![],
    };
    let p = params(3.0, 8.0, 3);
    let plan = plan_within_guarantees(&field, &p);
    // The block of each worked segment (by its middle point, in the field's own frame).
    let upper = |q: &Vec2| -q.x * sin + q.y * cos > 90.0;
    let blocks: Vec<bool> = plan
        .segments
        .iter()
        .filter(|s| matches!(s.kind, SegmentKind::Work | SegmentKind::Headland))
        .map(|s| upper(&s.points[s.points.len() / 2]))
        .collect();
    let crossings = blocks.windows(2).filter(|b| b[0] != b[1]).count();
    assert!(blocks.contains(&true) && blocks.contains(&false));
    assert_eq!(crossings, 1, "blocks in order {blocks:?}");
    let m = metrics::plan_metrics(&field, &plan, p.line_width);
    assert!(m.covered_fraction > 0.95, "covered {}", m.covered_fraction);
}

/// A parallelogram with 45° ends (w 3 m, r_min 8 m, 3 passes): where the swaths meet a slanted
/// end, no forward turn fits in the headland without pulling the swaths back. A K-turn (backing
/// up, the implement clear throughout) at the full ends is tried before the pull-back: 94.5 % of
/// the field was worked with pull-backs alone; now more than 95.5 %, with the guarantees held.
#[test]
fn a_swath_end_where_no_forward_turn_fits_turns_backing_up() {
    let field = Field {
        boundary: vec![
            v2(0.0, 0.0),
            v2(120.0, 0.0),
            v2(200.0, 80.0),
            v2(80.0, 80.0),
        ],
        obstacles: vec![],
    };
    let p = params(3.0, 8.0, 3);
    let plan = plan_within_guarantees(&field, &p);
    for pair in plan.segments.windows(2) {
        assert!((pair[1].points[0] - *pair[0].points.last().unwrap()).norm() < 1e-6);
    }
    let backing = plan
        .segments
        .iter()
        .filter(|s| s.kind == SegmentKind::Turn && s.direction == crate::geo::Direction::Reverse)
        .count();
    assert!(backing > 0);
    let m = metrics::plan_metrics(&field, &plan, p.line_width);
    assert!(m.covered_fraction > 0.955, "covered {}", m.covered_fraction);
}

/// A parallelogram field whose short edges slant 40° to the swaths (w 12 m): without section
/// control a swath end either leaves a corner or lays it twice (the middle half of its band
/// is run on to the edge); with sections the swaths run on over their whole band and the
/// sections switch off over the headland passes' ground: more of the field worked, less laid
/// twice.
#[test]
fn with_sections_the_swaths_reach_the_slanted_headland_and_lay_less_twice() {
    let slant = 40f64.to_radians().tan();
    let field = Field {
        boundary: vec![
            v2(0.0, 0.0),
            v2(300.0, 0.0),
            v2(300.0 + 150.0 / slant, 150.0),
            v2(150.0 / slant, 150.0),
        ],
        obstacles: Vec::new(),
    };
    let mut p = params(12.0, 6.0, 2);
    p.swath_angle = SwathAngle::Fixed { angle: 0.0 };
    let whole = check(&field, &p);
    p.sections = 8;
    let sectioned = check(&field, &p);
    assert_eq!(sectioned.sections, 8);
    let (mw, ms) = (
        metrics::plan_metrics(&field, &whole, 12.0),
        metrics::plan_metrics(&field, &sectioned, 12.0),
    );
    assert!(
        ms.covered_fraction > mw.covered_fraction + 0.001,
        "worked {} → {}",
        mw.covered_fraction,
        ms.covered_fraction
    );
    assert!(
        ms.overlap_fraction < mw.overlap_fraction - 0.01,
        "overlap {} → {}",
        mw.overlap_fraction,
        ms.overlap_fraction
    );
}

/// A `width` × `height` m rectangle from the origin, no obstacles.
fn rectangle(width: f64, height: f64) -> Field {
    Field {
        boundary: vec![
            v2(0.0, 0.0),
            v2(width, 0.0),
            v2(width, height),
            v2(0.0, height),
        ],
        obstacles: Vec::new(),
    }
}

/// [`params`] with the swaths along East.
fn along_east(w: f64, r: f64, passes: usize) -> CoverageParams {
    CoverageParams {
        swath_angle: SwathAngle::Fixed { angle: 0.0 },
        ..params(w, r, passes)
    }
}

/// The lowest y of every segment of `kind` (on a rectangle along East: where a swath runs,
/// and the bottom side of a headland pass), sorted.
fn lowest_ys(plan: &FieldPlan, kind: SegmentKind) -> Vec<f64> {
    let mut ys: Vec<f64> = plan
        .segments
        .iter()
        .filter(|s| s.kind == kind)
        .map(|s| s.points.iter().map(|q| q.y).fold(f64::INFINITY, f64::min))
        .collect();
    ys.sort_by(f64::total_cmp);
    ys
}

#[test]
fn with_sections_the_swaths_are_w_apart_and_the_overlap_is_switched_off_over_the_headland() {
    // 97 m across with two 12 m passes: 49 m of working area, 5 swaths for 60 m of footprint.
    // Spread, 11 m lie twice in 2.75 m slivers between the swaths; exact, the 11 m lie over a
    // headland pass where 7 of the 8 sections switch off.
    let field = rectangle(200.0, 97.0);
    let mut p = along_east(12.0, 6.0, 2);
    let whole = check(&field, &p);
    p.sections = 8;
    let sectioned = check(&field, &p);
    // Configured with no headland passes, the turns still need them (`headland::passes`), and
    // the swaths run on over them as over configured ones.
    let fewest = CoverageParams {
        headland_passes: 0,
        ..p.clone()
    };
    assert!(headland::passes(&fewest) > 0);
    let fewest = check(&field, &fewest);
    for (plan, swaths) in [(&sectioned, 5..=5), (&fewest, 5..=usize::MAX)] {
        let ys = lowest_ys(plan, SegmentKind::Work);
        assert!(swaths.contains(&ys.len()), "{ys:?}");
        assert!(
            ys.windows(2).all(|y| (y[1] - y[0] - 12.0).abs() < 0.05),
            "{ys:?}"
        );
    }
    let (mw, ms) = (
        metrics::plan_metrics(&field, &whole, 12.0),
        metrics::plan_metrics(&field, &sectioned, 12.0),
    );
    assert!(ms.covered_fraction >= mw.covered_fraction - 1e-4);
    assert!(
        ms.overlap_fraction < 0.25 * mw.overlap_fraction,
        "overlap {} → {}",
        mw.overlap_fraction,
        ms.overlap_fraction
    );
}

#[test]
fn an_overlap_brings_every_pass_that_much_closer_to_its_neighbour() {
    // 200 × 96 m at w 6 m with two headland passes; each pass lies 0.25 m closer to the one
    // before than without overlap: headland passes, swaths and the outermost swaths against
    // the inner pass. Without overlap the 72 m between the passes take 12 swaths exactly.
    let field = rectangle(200.0, 96.0);
    let mut p = along_east(6.0, 5.0, 2);
    let exact = check(&field, &p);
    p.overlap = 0.25;
    let overlapped = check(&field, &p);
    let margin = headland::chord_margin(&p);
    for (plan, s) in [(&exact, 6.0), (&overlapped, 5.75)] {
        let rings = lowest_ys(plan, SegmentKind::Headland);
        assert_eq!(rings.len(), 2, "{rings:?}");
        for (k, y) in rings.iter().enumerate() {
            let want = 3.0 + k as f64 * s + margin;
            assert!((y - want).abs() < 0.02, "pass {k} at {y}, want {want}");
        }
        let swaths = lowest_ys(plan, SegmentKind::Work);
        assert!(
            swaths.windows(2).all(|y| y[1] - y[0] <= s + 1e-6),
            "{swaths:?}"
        );
        // The first swath's centre at most s from the inner pass's: footprints overlap by at
        // least w − s.
        assert!(swaths[0] - rings[1] <= s + 1e-6, "{swaths:?} {rings:?}");
    }
    // The closer passes show: more swaths, or the first one nearer the edge.
    let (exact_swaths, overlapped_swaths) = (
        lowest_ys(&exact, SegmentKind::Work),
        lowest_ys(&overlapped, SegmentKind::Work),
    );
    assert!(
        overlapped_swaths.len() > exact_swaths.len() || overlapped_swaths[0] < exact_swaths[0],
        "{exact_swaths:?} {overlapped_swaths:?}"
    );
    let (me, mo) = (
        metrics::plan_metrics(&field, &exact, 6.0),
        metrics::plan_metrics(&field, &overlapped, 6.0),
    );
    assert!(mo.covered_fraction >= me.covered_fraction - 1e-4);
    assert!(
        mo.overlap_fraction > me.overlap_fraction + 0.01,
        "overlap {} → {}",
        me.overlap_fraction,
        mo.overlap_fraction
    );
    // Half the implement or more is refused.
    p.overlap = 3.0;
    assert!(plan_field(&field, &p).is_err());
}
