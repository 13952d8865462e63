//! Issue 17 point 2: the hard guarantees of a field plan, over random fields (convex,
//! concave, with holes, thin) and random implement widths and turning radii.
//!
//! The checks here are written again with the `geo` crate (not `metrics::checks`), so they
//! check the planner and the tool's own checks at once:
//! - every path point inside the boundary and outside every hole;
//! - every point of a working pass (work, detour, headland) at least w/2 from the boundary and
//!   from every hole (its implement clear), less 1 cm of rounding;
//! - every three-point curvature ≤ 1.02/r_min + 0.001 /m (three-point curvature over chords
//!   reads up to ~1 % high on an arc; the same slack as `metrics::checks`).
//!
//! `agsteer plan` exits 0 only when `check_plan` finds nothing, so
//! [`a_violation_is_never_exit_0`] asserts that whatever these checks find, `check_plan` finds
//! too. [`every_plan_keeps_the_guarantees`] asserts the planner's side: a plan it returns
//! (`Ok`) passes these checks; "no plan" (`Err`) is an honest answer.
//!
//! Both run 48 fields each (a few seconds in release on the loaded shared host; 400 random more
//! with `--ignored many`); failing cases are kept in
//! `tests/proptest-regressions/plan_guarantees.txt` (where proptest reads and writes them since
//! the tests became modules of one test binary; the cases saved before that were moved there)
//! and run first. A case is kept as its random seed, drawn again through today's strategy: the
//! two saved before `Case` gained `sections` and `overlap` now draw other fields than the ones
//! their comments show.
//! [`a_violation_is_never_exit_0`] draws new fields every run. [`every_plan_keeps_the_guarantees`]
//! draws from a fixed seed, so CI is reproducible; `many` keeps drawing fresh fields. Until
//! session 5 the planner broke a guarantee on about 1 random field in 2 000 (2 of 10 runs of
//! `--ignored many`: transits that found no way inside the field were planned as the shortest
//! curve, 34 points outside the boundary, 9 inside a hole). Now the plan goes on from the target
//! without a transit and names the gap. Measured 2026-12-02 with `many` on fresh fields: 4 000
//! (10 runs) without a failure; 10 000 more with an earlier variant that dropped the unreached
//! work instead: no transit out of the field or through a hole, one plan breaking a guarantee
//! (a headland pass with a kink, three-point curvature 1.47 /m at r_min ≈ 9.2 m, a field with
//! holes at w ≈ 30 m; the pass layout's, not a transit).

use agsteer::config::Config;
use agsteer::geo::Vec2;
use agsteer::plan::coverage::metrics::checks::check_plan;
use agsteer::plan::coverage::{
    plan_field, CoverageParams, Field, FieldPlan, HeadlandOrder, SegmentKind,
};
use geo::{Contains, Coord, Distance, Euclidean, LineString, Point, Polygon};
use proptest::prelude::*;
use std::f64::consts::PI;

/// Random fields: the shapes of issue 17's property test.
#[derive(Debug, Clone)]
enum Shape {
    /// Points on an ellipse (a convex polygon).
    Convex { aspect: f64, angles: Vec<f64> },
    /// A star-shaped polygon with radii 0.4–1 of the size (concave).
    Concave { points: Vec<(f64, f64)> },
    /// A star-shaped polygon with radii 0.7–1 and one or two square holes near the middle.
    Holes {
        points: Vec<(f64, f64)>,
        holes: Vec<(f64, f64, f64)>,
    },
    /// A rotated strip `width_of_w` implement widths wide.
    Thin {
        width_of_w: f64,
        length: f64,
        angle: f64,
    },
}

#[derive(Debug, Clone)]
struct Case {
    shape: Shape,
    /// Size (largest radius) of the field, m.
    size: f64,
    line_width: f64,
    r_min: f64,
    /// Implement sections (`field.sections`; above 1 the swaths run on over their whole band).
    sections: usize,
    /// Overlap of neighbouring passes (`field.overlap_m`), m.
    overlap: f64,
    /// Headland passes (`field.headland_passes`) and whether they are worked last
    /// (`field.headland_order`).
    headland: (usize, bool),
}

fn star(points: &[(f64, f64)], size: f64) -> Vec<Vec2> {
    let n = points.len() as f64;
    points
        .iter()
        .enumerate()
        .map(|(i, (u, r))| {
            // Angles strictly increasing: each point in its own sector.
            let a = 2.0 * PI * (i as f64 + 0.05 + 0.9 * u) / n;
            Vec2::new(size * r * a.cos(), size * r * a.sin())
        })
        .collect()
}

fn square(cx: f64, cy: f64, half: f64) -> Vec<Vec2> {
    vec![
        Vec2::new(cx - half, cy - half),
        Vec2::new(cx + half, cy - half),
        Vec2::new(cx + half, cy + half),
        Vec2::new(cx - half, cy + half),
    ]
}

impl Case {
    fn field(&self) -> Field {
        let s = self.size;
        match &self.shape {
            Shape::Convex { aspect, angles } => {
                let mut a: Vec<f64> = angles.iter().map(|u| 2.0 * PI * u).collect();
                a.sort_by(f64::total_cmp);
                a.dedup_by(|x, y| (*x - *y).abs() < 0.05);
                Field {
                    boundary: a
                        .iter()
                        .map(|t| Vec2::new(s * t.cos(), s * aspect * t.sin()))
                        .collect(),
                    obstacles: vec![],
                }
            }
            Shape::Concave { points } => Field {
                boundary: star(points, s),
                obstacles: vec![],
            },
            Shape::Holes { points, holes } => {
                // Radii ≥ 0.7 and sectors ≤ 120° keep the outline ≥ 0.35·size from the
                // middle; the holes stay within 0.2·size + 0.05·size·√2 of it, on opposite
                // sides, so they neither touch the outline nor each other.
                let obstacles = holes
                    .iter()
                    .enumerate()
                    .map(|(k, (phi, d, half))| {
                        let a = 2.0 * PI * phi + PI * k as f64;
                        square(s * d * a.cos(), s * d * a.sin(), s * half)
                    })
                    .collect();
                Field {
                    boundary: star(points, s),
                    obstacles,
                }
            }
            Shape::Thin {
                width_of_w,
                length,
                angle,
            } => {
                let (c, si) = (angle.cos(), angle.sin());
                let (l, t) = (0.5 * length, 0.5 * width_of_w * self.line_width);
                Field {
                    boundary: [(-l, -t), (l, -t), (l, t), (-l, t)]
                        .iter()
                        .map(|(x, y)| Vec2::new(c * x - si * y, si * x + c * y))
                        .collect(),
                    obstacles: vec![],
                }
            }
        }
    }

    fn params(&self) -> CoverageParams {
        let mut p = Config::default().coverage_params();
        p.line_width = self.line_width;
        p.r_min = self.r_min;
        p.sections = self.sections;
        p.overlap = self.overlap;
        (p.headland_passes, p.headland_order) = match self.headland {
            (passes, true) => (passes, HeadlandOrder::Last),
            (passes, false) => (passes, HeadlandOrder::First),
        };
        p
    }
}

fn shape() -> impl Strategy<Value = Shape> {
    let sector = (0.0..1.0f64, 0.4..1.0f64);
    prop_oneof![
        (0.3..1.0f64, prop::collection::vec(0.0..1.0f64, 3..10))
            .prop_map(|(aspect, angles)| Shape::Convex { aspect, angles }),
        prop::collection::vec(sector, 5..14).prop_map(|points| Shape::Concave { points }),
        (
            prop::collection::vec((0.0..1.0f64, 0.7..1.0f64), 6..12),
            prop::collection::vec((0.0..1.0f64, 0.12..0.2f64, 0.01..0.05f64), 1..3),
        )
            .prop_map(|(points, holes)| Shape::Holes { points, holes }),
        (0.5..6.0f64, 80.0..400.0f64, 0.0..PI).prop_map(|(width_of_w, length, angle)| {
            Shape::Thin {
                width_of_w,
                length,
                angle,
            }
        }),
    ]
}

fn case() -> impl Strategy<Value = Case> {
    (
        shape(),
        50.0..220.0f64,
        3.0..36.0f64,
        4.0..20.0f64,
        prop::sample::select(vec![1usize, 1, 8]),
        prop::sample::select(vec![0.0, 0.0, 0.3]),
        (
            prop::sample::select(vec![2usize, 2, 0, 1, 3, 4]),
            prop::bool::weighted(0.3),
        ),
    )
        .prop_map(
            |(shape, size, line_width, r_min, sections, overlap, headland)| Case {
                shape,
                size,
                line_width,
                r_min,
                sections,
                overlap,
                headland,
            },
        )
}

fn ring(pts: &[Vec2]) -> LineString<f64> {
    let mut c: Vec<Coord<f64>> = pts.iter().map(|p| Coord { x: p.x, y: p.y }).collect();
    c.extend(c.first().copied());
    LineString::new(c)
}

/// Every breach of the guarantees in `plan`, one line each (at most a few per segment).
fn independent_violations(field: &Field, plan: &FieldPlan, w: f64, r_min: f64) -> Vec<String> {
    let boundary = Polygon::new(ring(&field.boundary), vec![]);
    let holes: Vec<Polygon<f64>> = field
        .obstacles
        .iter()
        .map(|o| Polygon::new(ring(o), vec![]))
        .collect();
    let edges: Vec<LineString<f64>> = std::iter::once(&field.boundary)
        .chain(field.obstacles.iter())
        .map(|r| ring(r))
        .collect();
    let limit = 1.02 / r_min + 1e-3;
    let mut out = Vec::new();
    for s in &plan.segments {
        let working = matches!(
            s.kind,
            SegmentKind::Work | SegmentKind::Detour | SegmentKind::Headland
        );
        let mut pts: Vec<Vec2> = Vec::new();
        for p in &s.points {
            if pts.last().is_none_or(|q: &Vec2| (p - q).norm() > 1e-6) {
                pts.push(*p);
            }
        }
        let (mut outside, mut inside, mut unclear, mut curved) = (0, 0, 0.0f64, 0.0f64);
        for p in &pts {
            let q = Point::new(p.x, p.y);
            if !boundary.contains(&q) {
                outside += 1;
            }
            if holes.iter().any(|h| h.contains(&q)) {
                inside += 1;
            }
            if working {
                let d = edges
                    .iter()
                    .map(|e| Euclidean.distance(&q, e))
                    .fold(f64::INFINITY, f64::min);
                unclear = unclear.max(0.5 * w - 0.01 - d);
            }
        }
        for t in pts.windows(3) {
            let (a, b, c) = (t[0], t[1], t[2]);
            let (ab, bc, ca) = ((b - a).norm(), (c - b).norm(), (a - c).norm());
            let cross = (b - a).x * (c - b).y - (b - a).y * (c - b).x;
            let k = 2.0 * cross.abs() / (ab * bc * ca);
            curved = curved.max(k);
        }
        let name = format!("{:?} segment {}", s.kind, s.index);
        if outside > 0 {
            out.push(format!("{name}: {outside} points outside the boundary"));
        }
        if inside > 0 {
            out.push(format!("{name}: {inside} points inside a hole"));
        }
        if unclear > 0.0 {
            out.push(format!("{name}: implement {unclear:.3} m over the edge"));
        }
        if curved > limit {
            out.push(format!("{name}: curvature {curved:.4} > {limit:.4} /m"));
        }
    }
    out
}

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 48,
        max_shrink_iters: 32,
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config())]

    /// What these checks find, `check_plan` finds: `agsteer plan` exits 4, never 0.
    #[test]
    fn a_violation_is_never_exit_0(c in case()) {
        let field = c.field();
        if let Ok(plan) = plan_field(&field, &c.params()) {
            let found = independent_violations(&field, &plan, c.line_width, c.r_min);
            let checked = check_plan(&field, &plan, c.line_width, c.r_min);
            prop_assert!(
                found.is_empty() || !checked.is_empty(),
                "check_plan misses: {}",
                found.join("; ")
            );
        }
    }

}

proptest! {
    #![proptest_config(ProptestConfig {
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x17_0002),
        ..config()
    })]

    /// A plan the planner returns keeps every guarantee (fixed seed: see the module's docs).
    #[test]
    fn every_plan_keeps_the_guarantees(c in case()) {
        keeps_the_guarantees(&c)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..config() })]

    /// [`every_plan_keeps_the_guarantees`] over 400 fields: `cargo test --release --test
    /// plan_guarantees -- --ignored many` (about 5 s of CPU).
    #[test]
    #[ignore = "more cases of every_plan_keeps_the_guarantees; run with --ignored"]
    fn many_plans_keep_the_guarantees(c in case()) {
        keeps_the_guarantees(&c)?;
    }
}

fn keeps_the_guarantees(c: &Case) -> Result<(), TestCaseError> {
    let field = c.field();
    if let Ok(plan) = plan_field(&field, &c.params()) {
        let found = independent_violations(&field, &plan, c.line_width, c.r_min);
        prop_assert!(found.is_empty(), "{}", found.join("; "));
    }
    Ok(())
}

#[test]
fn the_checks_catch_what_they_check() {
    use agsteer::geo::Direction;
    use agsteer::plan::coverage::PlanSegment;
    let field = Field {
        boundary: square(0.0, 0.0, 50.0),
        obstacles: vec![square(10.0, 10.0, 5.0)],
    };
    let plan = |kind, points: Vec<Vec2>| FieldPlan {
        segments: vec![PlanSegment {
            kind,
            direction: Direction::Forward,
            index: 0,
            cell: 0,
            points,
        }],
        ..FieldPlan::default()
    };
    let line = |y: f64, x0: f64, x1: f64| -> Vec<Vec2> {
        (0..=20)
            .map(|k| Vec2::new(x0 + (x1 - x0) * k as f64 / 20.0, y))
            .collect()
    };
    let check = |p: &FieldPlan| independent_violations(&field, p, 6.0, 5.0);
    assert!(check(&plan(SegmentKind::Work, line(-20.0, -40.0, 40.0))).is_empty());
    let v = check(&plan(SegmentKind::Transit, line(-20.0, 40.0, 60.0)));
    assert!(
        v.len() == 1 && v[0].contains("outside the boundary"),
        "{v:?}"
    );
    let v = check(&plan(SegmentKind::Transit, line(10.0, -10.0, 30.0)));
    assert!(v.len() == 1 && v[0].contains("inside a hole"), "{v:?}");
    let v = check(&plan(SegmentKind::Work, line(-48.0, -40.0, 40.0)));
    assert!(v.len() == 1 && v[0].contains("over the edge"), "{v:?}");
    assert!(check(&plan(SegmentKind::Turn, line(-48.0, -40.0, 40.0))).is_empty());
    let arc: Vec<Vec2> = (0..=30)
        .map(|k| {
            let a = k as f64 * 0.1;
            Vec2::new(-20.0 + 4.0 * a.cos(), -20.0 + 4.0 * a.sin())
        })
        .collect();
    let v = check(&plan(SegmentKind::Turn, arc));
    assert!(v.len() == 1 && v[0].contains("curvature"), "{v:?}");
    // The random fields are what they claim: simple, counter-clockwise, holes inside.
    let runner_cases = [
        Shape::Concave {
            points: vec![(0.0, 0.4), (1.0, 1.0), (0.5, 0.4), (0.0, 1.0), (1.0, 0.4)],
        },
        Shape::Holes {
            points: vec![(0.99, 0.7); 6],
            holes: vec![(0.3, 0.2, 0.05), (0.3, 0.12, 0.05)],
        },
    ];
    for shape in runner_cases {
        let f = Case {
            shape,
            size: 100.0,
            line_width: 6.0,
            r_min: 5.0,
            sections: 1,
            overlap: 0.0,
            headland: (2, false),
        }
        .field();
        assert!(agsteer::geo::polygon::signed_area(&f.boundary) > 0.0);
        let outer = Polygon::new(ring(&f.boundary), vec![]);
        for h in &f.obstacles {
            assert!(agsteer::geo::polygon::signed_area(h) > 0.0);
            assert!(outer.contains(&Polygon::new(ring(h), vec![])));
        }
    }
}

/// The planner over 400 random fields (the same generator, a fixed seed), by shape: cases,
/// "no plan" answers, plans breaking a guarantee, and of those any `check_plan` misses. A
/// measurement, not a check: `cargo test --release --test plan -- --ignored
/// plan_guarantees::tally --nocapture` (about 10 s of CPU). Session 4 before the passes bent
/// round the holes: concave
/// 85/0/0/0, convex 85/2/0/0, holes 124/0/28/0 (16 headland passes and 12 swaths through or
/// over a hole), thin 106/0/0/0; after: holes 124/0/0/0, the others unchanged.
#[test]
#[ignore = "a measurement; prints the tally"]
fn tally() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let mut tally = std::collections::BTreeMap::<String, [usize; 4]>::new();
    for _ in 0..400 {
        let Ok(tree) = case().new_tree(&mut runner) else {
            continue;
        };
        let c = tree.current();
        let kind = format!("{:?}", c.shape);
        let kind = kind.split([' ', '{']).next().unwrap_or("").to_string();
        let field = c.field();
        let e = tally.entry(kind.clone()).or_default();
        e[0] += 1;
        match plan_field(&field, &c.params()) {
            Err(_) => e[1] += 1,
            Ok(plan) => {
                let found = independent_violations(&field, &plan, c.line_width, c.r_min);
                if !found.is_empty() {
                    e[2] += 1;
                    if check_plan(&field, &plan, c.line_width, c.r_min).is_empty() {
                        e[3] += 1;
                    }
                    eprintln!(
                        "{kind} size {:.0} m, w {:.1} m, r_min {:.1} m: {}",
                        c.size,
                        c.line_width,
                        c.r_min,
                        found.join("; ")
                    );
                }
            }
        }
    }
    eprintln!("by shape: [cases, no plan, violating, missed by check_plan] {tally:?}");
}

/// The real field `name` of tools/fields/real/, read as `agsteer plan` reads it, planned with
/// the default configuration at width `w` and turning radius `r_min` (m).
fn real_plan(name: &str, w: f64, r_min: f64) -> (Field, CoverageParams, FieldPlan) {
    let path = format!(
        "{}/tools/fields/real/{name}.geojson",
        env!("CARGO_MANIFEST_DIR")
    );
    let (field, p, plan) = plan_file(std::path::Path::new(&path), w, r_min, 1);
    (field, p, plan.expect("a plan"))
}

/// The field of the GeoJSON file at `path`, read as `agsteer plan` reads it, and its plan with
/// the default configuration at width `w` and turning radius `r_min` (m), the implement in
/// `sections`.
fn plan_file(
    path: &std::path::Path,
    w: f64,
    r_min: f64,
    sections: usize,
) -> (
    Field,
    CoverageParams,
    Result<FieldPlan, agsteer::plan::PlanError>,
) {
    let cfg = Config::default();
    let text = std::fs::read_to_string(path).expect("the field is in the repository");
    let loaded = agsteer::field::load_field(&text, &cfg.field_load_options()).expect("loads");
    let mut p = cfg.coverage_params();
    p.line_width = w;
    p.r_min = r_min;
    p.sections = sections;
    let plan = plan_field(&loaded.field, &p);
    (loaded.field, p, plan)
}

/// The parcels of tools/fields/holdout/, which the planner was not developed on, at every
/// width and turning radius of `agsteer plan --sweep` (3, 6, 12, 36 m; 5, 8 m), without
/// sections and with 8 (the swaths then run on to the cell's extent): every plan keeps the
/// guarantees (by these checks and by `check_plan`). Only the guarantees: the
/// coverage figures of this set are measured and reported (README, Real fields: where the
/// planner stands; docs/coverage-history.md, Session 30: a hold-out set of parcels; runs that
/// strand the vehicle put back), not asserted.
#[test]
fn every_hold_out_parcel_keeps_the_guarantees() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/fields/holdout");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("tools/fields/holdout is in the repository")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|f| f.extension().is_some_and(|x| x == "geojson"))
        .collect();
    files.sort();
    assert!(files.len() >= 12, "{files:?}");
    let mut broken = Vec::new();
    for f in &files {
        let name = f.file_name().unwrap_or_default().to_string_lossy();
        for (w, r_min, sections) in [3.0, 6.0, 12.0, 36.0]
            .into_iter()
            .flat_map(|w| [5.0, 8.0].map(|r| (w, r)))
            .flat_map(|(w, r)| [1, 8].map(|n| (w, r, n)))
        {
            let case = format!("{name} w {w} r_min {r_min} sections {sections}");
            let (field, p, plan) = plan_file(f, w, r_min, sections);
            let Ok(plan) = plan else {
                broken.push(format!("{case}: no plan: {plan:?}"));
                continue;
            };
            let mut found = independent_violations(&field, &plan, p.line_width, p.r_min);
            let checked = check_plan(&field, &plan, p.line_width, p.r_min);
            found.extend(checked.iter().map(|v| format!("check_plan: {v:?}")));
            if !found.is_empty() {
                broken.push(format!("{case}: {}", found.join("; ")));
            }
        }
    }
    assert!(broken.is_empty(), "{}", broken.join("\n"));
}

/// A transit follows a headland pass only where the pass turns no tighter than r_min, as the
/// pass itself is worked only there (`clear_stretches`): `bg_27_large_concave_152v` (second
/// hold-out set) at w 2.06 m, r_min 19.59 m, 5 passes worked last had three transits along a
/// pass's kinks, 0.0535 /m against 0.0510, and `agsteer plan` exited 4 (found by a random
/// sweep of the configuration, session 40).
#[test]
fn a_transit_follows_a_headland_pass_only_where_it_turns_no_tighter_than_r_min() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tools/fields/holdout2/bg_27_large_concave_152v.geojson");
    let cfg = Config::default();
    let text = std::fs::read_to_string(path).expect("the field is in the repository");
    let loaded = agsteer::field::load_field(&text, &cfg.field_load_options()).expect("loads");
    let mut p = cfg.coverage_params();
    p.line_width = 2.06;
    p.r_min = 19.59;
    p.headland_passes = 5;
    p.headland_order = HeadlandOrder::Last;
    let plan = plan_field(&loaded.field, &p).expect("a plan");
    let checked = check_plan(&loaded.field, &plan, p.line_width, p.r_min);
    assert!(checked.is_empty(), "{checked:?}");
    assert!(plan.swaths > 0);
}

/// A cell of its own (leftover ground) whose run strands the vehicle is put back, also when
/// the run tried after it was another cell of its own, itself put back (`de_bb_holes_irregular`
/// at w 12 m, r_min 8 m): before session 30 the put-back run took the stranding one's place
/// as the last kept, so the next run of the working area undid nothing and drove on from the
/// pocket with no transit (three places without a transit, now two; an 82 m strip is left
/// unworked instead, red in plan.svg). The plan keeps its guarantees either way.
#[test]
fn a_leftover_run_that_strands_the_vehicle_is_put_back() {
    let (field, p, plan) = real_plan("de_bb_holes_irregular", 12.0, 8.0);
    assert!(check_plan(&field, &plan, p.line_width, p.r_min).is_empty());
    let gaps = gap_warnings(&plan);
    assert!(
        gaps <= 2,
        "{gaps} places without a transit: {:?}",
        plan.warnings
    );
    assert!(plan.swaths > 0);
}

/// A plan with gaps starts with the chain of joined segments that works the most ground
/// (`de_bb_holes_irregular`, three blocks joined by necks no transit crosses, at every width):
/// the steering is given back at the first gap after that chain, not after the smallest block,
/// a tenth of the work, as before session 39. The gaps are the planner's: as many as it warns
/// of, and no chain works more ground than the first.
#[test]
fn a_plan_with_gaps_starts_with_the_chain_that_works_most() {
    for w in [3.0, 12.0, 36.0] {
        let (field, p, plan) = real_plan("de_bb_holes_irregular", w, 8.0);
        assert!(check_plan(&field, &plan, p.line_width, p.r_min).is_empty());
        let worked = |s: &agsteer::plan::coverage::PlanSegment| {
            use agsteer::plan::coverage::SegmentKind::*;
            matches!(s.kind, Work | Headland | Detour)
        };
        let mut chains = vec![0.0];
        for (k, s) in plan.segments.iter().enumerate() {
            assert_eq!(s.index, k);
            if k > 0 && (s.points[0] - *plan.segments[k - 1].points.last().unwrap()).norm() > 1e-3 {
                chains.push(0.0);
            }
            if worked(s) {
                *chains.last_mut().unwrap() += s.length();
            }
        }
        assert_eq!(
            chains.len() - 1,
            gap_warnings(&plan),
            "w {w}: {:?}",
            plan.warnings
        );
        assert!(chains.len() >= 2, "w {w}: the blocks are no longer apart");
        let total: f64 = chains.iter().sum();
        assert!(
            chains[1..].iter().all(|&c| c <= chains[0]) && chains[0] >= 0.4 * total,
            "w {w}: worked per chain {chains:?}"
        );
    }
}

/// How many warnings of `plan` name a place it goes on from without a transit.
fn gap_warnings(plan: &FieldPlan) -> usize {
    plan.warnings
        .iter()
        .filter(|w| w.contains("no transit inside the field from ("))
        .count()
}

/// A run of the working area that ends with a short swath in a pocket no transit leads out of
/// (`es_cat_many_vertices` at w 3 m, r_min 8 m): the last swath is put back and the next run
/// is driven from the swath before it, where before session 30 the plan went on from the
/// pocket without a transit (one place; now none, for 0.04 % of the field left unworked).
#[test]
fn a_runs_last_swath_in_a_pocket_is_put_back_for_a_transit() {
    let (field, p, plan) = real_plan("es_cat_many_vertices", 3.0, 8.0);
    assert!(check_plan(&field, &plan, p.line_width, p.r_min).is_empty());
    assert_eq!(plan.transit_gaps, 0, "{:?}", plan.warnings);
    assert_eq!(gap_warnings(&plan), 0, "{:?}", plan.warnings);
}

/// A real parcel whose parts join only by necks a few metres wide (`de_bb_concave` at w 12 m,
/// r_min 8 m): before session 5 five transits found no way inside the field and were planned
/// as the shortest curve, out of it (exit 4). The plan now goes on from the target without a
/// transit and names each gap, so it keeps every guarantee and says where the parts part.
#[test]
fn a_gap_no_transit_crosses_is_named_not_driven_outside() {
    let (field, p, plan) = real_plan("de_bb_concave", 12.0, 8.0);
    let found = independent_violations(&field, &plan, p.line_width, p.r_min);
    assert!(found.is_empty(), "{}", found.join("; "));
    assert!(check_plan(&field, &plan, p.line_width, p.r_min).is_empty());
    assert!(gap_warnings(&plan) > 0, "{:?}", plan.warnings);
    assert!(plan.swaths > 0);
}

/// A real parcel in three blocks (`at_invekos_hole` at w 12 m, r_min 8 m), each worked whole
/// before the next: the transit to a block's next headland pass finds no way to the pass's
/// first choice of start and pulls it back. The pass then goes on past its start over the
/// stretch pulled back, so every pass is still a whole ring (none is cut into stretches here:
/// no warning says so), where before the stretch was left unworked.
#[test]
fn a_headland_pass_whose_start_is_pulled_back_is_still_worked_round() {
    let (field, p, plan) = real_plan("at_invekos_hole", 12.0, 8.0);
    assert!(check_plan(&field, &plan, p.line_width, p.r_min).is_empty());
    assert!(
        !plan.warnings.iter().any(|w| w.contains("stretches")),
        "{:?}",
        plan.warnings
    );
    let passes: Vec<_> = plan
        .segments
        .iter()
        .filter(|s| s.kind == SegmentKind::Headland)
        .collect();
    assert!(passes.len() >= 6, "{} passes", passes.len());
    for s in passes {
        let (a, b) = (s.points[0], s.points[s.points.len() - 1]);
        assert!(
            (a - b).norm() < 1e-6,
            "pass {} ends {:.1} m from its start",
            s.index,
            (a - b).norm()
        );
    }
}

/// A star-shaped field with a hole (w 26.5 m, r_min 5.7 m) that a fresh draw of
/// `many_plans_keep_the_guarantees` found: the opened area of its outer pass kept two kinks
/// (1.16 and 1.22 /m against 1/r_min = 0.18 /m) and the planner returned the pass with them
/// (refused by the checks, exit 4). The pass is now cut where it turns tighter than r_min.
#[test]
fn a_kinked_headland_pass_found_at_random_keeps_the_guarantees() {
    let c = Case {
        shape: Shape::Holes {
            points: vec![
                (0.6104748219070809, 0.7),
                (0.0, 0.7),
                (0.5877787946485098, 0.7620806342169772),
                (0.5123331797164642, 0.9081334361119455),
                (0.22407924493505527, 0.8120824347898419),
                (0.0, 0.7),
            ],
            holes: vec![(0.5319255796219482, 0.1706934542303401, 0.037490071511938)],
        },
        size: 73.97763748868036,
        line_width: 26.45078928775462,
        r_min: 5.659127914805385,
        sections: 1,
        overlap: 0.0,
        headland: (2, false),
    };
    keeps_the_guarantees(&c).unwrap();
}

/// A field with two holes (w 17.4 m, r_min 14.8 m, one headland pass, 8 sections) that a
/// draw of `many_plans_keep_the_guarantees` found once its r_min reached 20 m and its
/// headland passes varied (session 40): a transit turned off an obstacle's ring where the
/// ring itself read 0.0697 /m, and its join read 0.06987 against the checks' 0.06985. The
/// rings are now followed only where they leave the checks' absolute slack to the joins.
#[test]
fn a_join_off_a_ring_found_at_random_keeps_the_guarantees() {
    let c = Case {
        shape: Shape::Holes {
            points: [0.0, 0.0, 0.0, 0.0, 0.6421689761035235, 0.0]
                .map(|angle| (angle, 0.7))
                .to_vec(),
            holes: vec![
                (
                    0.09155634247420429,
                    0.12169950473779971,
                    0.03641421742579115,
                ),
                (
                    0.7375991001801837,
                    0.16054800252197893,
                    0.030719386149878826,
                ),
            ],
        },
        size: 216.4720287526256,
        line_width: 17.376492169388733,
        r_min: 14.813839124104545,
        sections: 8,
        overlap: 0.0,
        headland: (1, false),
    };
    let field = c.field();
    let plan = plan_field(&field, &c.params()).expect("a plan");
    let checked = check_plan(&field, &plan, c.line_width, c.r_min);
    assert!(checked.is_empty(), "{checked:?}");
    keeps_the_guarantees(&c).unwrap();
}
