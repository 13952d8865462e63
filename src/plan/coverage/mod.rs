//! Coverage of a polygon field (docs/METHODS.md, Coverage of a field; seeds 003 and 001), as a
//! pipeline of pure stages in the manner of Fields2Cover: headland → swath angle → decomposition →
//! swaths → obstacles → route → turns → one ordered list of [`PlanSegment`]s.
//!
//! Input is a [`Field`] in the local ENU frame (see [`crate::field`] for reading GeoJSON and
//! ISO 11783-10 TASKDATA into one). Every stage is a pure function of its inputs.

mod apart;
mod attempts;
pub mod bypass;
mod chains;
mod clear_map;
mod closed;
pub mod decompose;
mod disc_caps;
mod edges;
pub mod geometry;
pub mod headland;
pub mod leftover;
pub mod metrics;
pub mod narrow;
mod params;
mod regions;
mod reverse;
mod ring_start;
pub mod rings;
mod runs;
mod stub;
pub mod swath_angle;
pub mod swaths;
mod to_goal;
pub mod transit;

pub use crate::plan::types::{Field, PlanSegment, SegmentKind};
pub use clear_map::{implement_clear, TRANSIT_CLEARANCE_M};
pub use params::{CoverageParams, FieldPlan, HeadlandOrder, RouteOrder, SwathAngle};
pub use runs::obstacle_size;

use clear_map::{ClearMap, Tests};
use runs::drive_run;

use crate::geo::{v2, vec_heading, wrap_angle, Direction, Vec2};
use crate::plan::types::PlanError;

/// States a transit's waypoint search may expand before giving up.
const ROUTE_MAX_EXPANSIONS: usize = 20_000;

/// States a detour's waypoint search may expand before giving up: the bypass of arcs
/// ([`bypass::bypass`]) is tried first and passes nearly every small obstacle; a search that
/// fails expands all it may, and 20 000 states took seconds per blocked stretch.
const DETOUR_MAX_EXPANSIONS: usize = 2_000;

/// Clearance added to the bypass circle beyond the implement's half width and the chord
/// margin, m.
const BYPASS_SLACK_M: f64 = 0.05;

/// Where a plan stood before a run: its segment count, its last segment, the vehicle's pose
/// and the warnings' count (a run put back restores them).
type UndoPoint = (usize, Option<PlanSegment>, Option<(Vec2, f64)>, usize);

/// Plan the whole field: headland passes (outermost first), then the cells in a short order,
/// each swept by its runs of swaths with turns, joined by transits; with
/// [`HeadlandOrder::Last`] the cells first, then the headland passes innermost first.
///
/// When no swath fits inside the configured headland, the field is planned with the fewest
/// passes the turns need, or else worked by headland passes alone as far in as they go
/// ([`narrow`]); each says so in [`FieldPlan::warnings`]. A plan with no working pass at all is
/// the caller's to refuse ([`headland::no_swath_fits`] gives the numbers). With sections, a
/// plan that goes on somewhere without a transit is tried again with the swaths stopped where
/// an implement without sections stops them, and that plan is kept if it has fewer such
/// places (said in the warnings).
pub fn plan_field(field: &Field, p: &CoverageParams) -> Result<FieldPlan, PlanError> {
    p.validate()?;
    // The clearance tests and waypoint grids depend on the field, the width, r_min and the
    // point spacing, not on the headland passes: one set for the plans of every pass count
    // tried (their checks, and the edges the searches checked, kept from one to the next).
    let half = p.line_width / 2.0;
    let strict_half = half + headland::chord_margin(p) - headland::CHORD_MARGIN;
    let loose_half =
        half.min(TRANSIT_CLEARANCE_M) + headland::chord_margin(p) - headland::CHORD_MARGIN;
    let clear_map = ClearMap::new(field, strict_half);
    let one_test = loose_half == strict_half;
    let loose_map = (!one_test).then(|| ClearMap::new(field, loose_half));
    let clear = |q: &Vec2| clear_map.clear(q);
    let loose = |q: &Vec2| loose_map.as_ref().unwrap_or(&clear_map).clear(q);
    let margin = |q: &Vec2| clear_map.blocked_margin(q);
    let loose_margin = |q: &Vec2| loose_map.as_ref().unwrap_or(&clear_map).blocked_margin(q);
    let (grid, loose_grid) = (std::cell::OnceCell::new(), std::cell::OnceCell::new());
    let tests = Tests {
        field,
        clear: &clear,
        loose: &loose,
        clearance: (strict_half, loose_half),
        margins: (&margin, &loose_margin),
        one_test,
        grid: &grid,
        loose_grid: &loose_grid,
    };
    let plan_with =
        |widening| narrow::plan_field(field, p, |f, q| plan_once(f, q, &tests, widening));
    let plan = plan_with(swaths::band_widening(p.sections))?;
    if p.sections > 1 && plan.transit_gaps > 0 {
        // Swaths run on over their whole band can end too deep in a corner for any way on:
        // stopped where an implement without sections stops, they may leave room.
        let mut shorter = plan_with(swaths::BAND_WIDENING)?;
        if shorter.transit_gaps < plan.transit_gaps {
            shorter.warnings.push(format!(
                "the swaths stop where an implement without sections would ({} place(s) had no way on with them run on to the headland)",
                plan.transit_gaps
            ));
            return Ok(shorter);
        }
    }
    Ok(plan)
}

/// [`plan_field`] with the configured headland passes as they are, with the field's `tests`, the
/// swaths run on over the share `widening` of their band ([`swaths::band_widening`]).
fn plan_once(
    field: &Field,
    p: &CoverageParams,
    tests: &Tests,
    widening: f64,
) -> Result<FieldPlan, PlanError> {
    p.validate()?;
    if field.boundary.len() < 3 || crate::geo::polygon::signed_area(&field.boundary) <= 0.0 {
        return Err(PlanError::Invalid {
            name: "boundary",
            value: field.boundary.len() as f64,
            rule: "must be a counter-clockwise polygon of at least 3 points",
        });
    }
    let w = p.line_width;
    let half = w / 2.0;
    let margin = half + headland::CHORD_MARGIN;
    // Small obstacles (seed 001) stay in the working area: the swaths run through them and
    // each blocked stretch becomes a detour. Large ones get a headland and split the swaths.
    // Small ones within reach of a headland pass get a headland too (the passes bend round).
    let (small, large) = headland::split_obstacles(&field.boundary, &field.obstacles, p);
    // Each small obstacle as a disc (centre, radius + w/2 + 1 m), to find the swaths that pass
    // near one without checking every point of every swath.
    let small_discs: Vec<(Vec2, f64)> = small
        .iter()
        .map(|o| {
            let c = o.iter().fold(v2(0.0, 0.0), |a, q| a + q) / o.len().max(1) as f64;
            let r = o.iter().map(|q| (q - c).norm()).fold(0.0, f64::max);
            (c, r + half + 1.0)
        })
        .collect();
    tracing::debug!(
        small = small.len(),
        large = large.len(),
        "obstacles: small ones are passed on detours, large ones split the swaths"
    );
    let safe = headland::subtract_obstacles(
        &geometry::offset(&[(field.boundary.clone(), vec![])], -margin),
        &large,
        margin,
    );
    let passes = headland::passes_around(&field.boundary, &large, p);
    let leftover::Worked { working, own } = leftover::with_leftover(
        headland::working_area(&field.boundary, &large, p),
        (&field.boundary, &large),
        &passes,
        p,
    );
    // Points are checked; the chords between them may cut a little inside the arcs
    // (`tests.clear`). Transits that find no way with the implement clear of the edge keep the
    // tractor inside the field and off the obstacles (`tests.loose`; the guarantee for
    // paths that do not work). With an implement no wider than the tractor's clearance the two
    // tests are one (w ≤ 3 m): one map then, and the relaxed attempts that would repeat the
    // strict ones are skipped.
    let (clear, loose, one_test) = (tests.clear, tests.loose, tests.one_test);
    // Waypoints for detours and transits that cannot go direct: grids of clear points over
    // the field, each with the test of its curves.
    let (grid_lo, grid_hi) =
        crate::geo::polygon::bbox(field.boundary.iter()).unwrap_or((v2(0.0, 0.0), v2(1.0, 1.0)));
    let grid_of = |test, c| {
        let c = (c, Some(tests.field));
        transit::WaypointGrid::new(grid_lo, grid_hi, 2.0 * p.r_min, 20_000, test, c)
    };
    let waypoint_grid = || tests.grid.get_or_init(|| grid_of(clear, tests.clearance.0));
    let loose_grid = || {
        if one_test {
            return waypoint_grid();
        }
        tests
            .loose_grid
            .get_or_init(|| grid_of(loose, tests.clearance.1))
    };
    let warnings = std::cell::RefCell::new(Vec::<String>::new());
    let warnings_len = || warnings.borrow().len();
    let transit_gaps = std::cell::Cell::new(0);

    // Cells and their swath directions; the pieces worked on their own after the others.
    let mut cells = decompose::cells(&working, &own, p);
    let (mut working, worked_cells) = (working, cells.len() - own.len());

    // The pieces of the outermost pass's area, worked one after the other.
    let regions = regions::Regions::new(passes.areas.first());
    // Headland passes: the field's (outermost first), then the obstacles' (nearest first),
    // those that keep clear of the field edge and the other obstacles.
    let headland::Passes {
        field: field_passes,
        obstacles: obstacle_passes,
        ..
    } = passes;
    // Transits may follow the headland passes (field and obstacles) where they are clear and
    // turn no tighter than r_min (the passes themselves are cut where they turn tighter than
    // the checks allow: `clear_stretches`). The rings' own limit leaves the checks' absolute
    // slack to the joins, which bend a little more than the ring where a curve meets it (a
    // ring at 0.0697 /m, a join at 0.06987 against 0.06985 at r_min 14.8 m).
    let rings = rings::Rings::new(
        &field_passes
            .iter()
            .chain(obstacle_passes.iter())
            .cloned()
            .collect::<Vec<_>>(),
        &clear,
        metrics::checks::curvature_limit(p.r_min) - metrics::checks::CURVATURE_SLACK_ABS,
    );
    // Pieces of the field that no transit with the implement clear joins (see `apart`).
    let gap = p.point_spacing.max(rings.max_gap());
    let pieces = apart::Apart::new(field, tests.clearance.0, gap);
    // A pass is worked only where its implement is clear and it turns no tighter than r_min
    // (the guarantees): a pass that is not so throughout is cut into its stretches that are,
    // and the cut is reported.
    let mut field_tracks: std::collections::VecDeque<Vec<Vec2>> =
        headland::clear_stretches(field_passes, &clear, p.r_min, &warnings).into();
    if p.headland_order == HeadlandOrder::Last {
        // Worked last, from the inside out: the outermost pass along the edge ends the job.
        field_tracks.make_contiguous().reverse();
    }
    let mut obstacle_tracks =
        headland::clear_stretches(obstacle_passes, &clear, p.r_min, &warnings);

    let tp = p.turn_params();
    let mut cache = crate::plan::turns::TurnCache::default();
    let mut block_orders = crate::plan::skip_order::BlockOrders::default();
    let mut segments: Vec<PlanSegment> = Vec::new();
    let push = |segments: &mut Vec<PlanSegment>, kind, direction, cell, points: Vec<Vec2>| {
        if points.len() >= 2 {
            let index = segments.len();
            segments.push(PlanSegment {
                kind,
                direction,
                index,
                cell,
                points,
            });
        }
    };
    // Where the vehicle is: (position, heading).
    let mut at: Option<(Vec2, f64)> = None;
    // A transit from the vehicle to the start of `target`: direct if clear; else with the
    // previous work segment's end and the target's start pulled back together (a swath that
    // ends at an obstacle leaves no room to turn), metre by metre; else through a waypoint.
    // Returns how many points were cut from the start of `target`.
    // Has a relaxed headland attempt found no way (see `loose_headland` below)?
    let loose_failed = &mut false;
    // The curves on and off the rings of the headland attempts (strict, relaxed), kept from
    // one transit to the next asked from the same pose (the starts of a ring tried in turn,
    // see `ring_start`; each transit's answer is the one it finds with new ones, see
    // `rings::Ends`), dropped when the vehicle has moved on.
    let mut kept_ends: Option<((Vec2, f64), [rings::Ends; 2])> = None;
    let mut go_to = |segments: &mut Vec<PlanSegment>,
                     at: &mut Option<(Vec2, f64)>,
                     target: &[Vec2],
                     cell: usize|
     -> usize {
        let heading_at = |pts: &[Vec2], i: usize| vec_heading(&(pts[i + 1] - pts[i]));
        let Some((from, h0)) = *at else {
            return 0;
        };
        let to = target[0];
        let h = heading_at(target, 0);
        if (to - from).norm() < 1e-6 && wrap_angle(h - h0).abs() < 1e-6 {
            return 0;
        }
        let prev_work = segments
            .last()
            .filter(|s| s.kind == SegmentKind::Work && s.direction == Direction::Forward)
            .map(|s| s.points.clone());
        let max_cut = ((3.0 * p.r_min + p.line_width) / p.point_spacing).ceil() as usize;
        // (cut from the previous work end, cut from the target start) → the two poses.
        let poses = |t: usize| {
            let cut_prev = prev_work
                .as_ref()
                .map_or(0, |pts| t.min(pts.len().saturating_sub(3)));
            let cut_next = t.min(target.len().saturating_sub(3));
            let (f, hf) = match &prev_work {
                Some(pts) if cut_prev > 0 => {
                    let i = pts.len() - 1 - cut_prev;
                    (pts[i], heading_at(pts, i - 1))
                }
                _ => (from, h0),
            };
            (
                cut_prev,
                cut_next,
                f,
                hf,
                target[cut_next],
                heading_at(target, cut_next),
            )
        };
        use attempts::Way;
        let attempts = attempts::order(p, max_cut, cell >= worked_cells);
        let mut found = None;
        // The relaxed headland attempt without shortening, made first (once) where the tests
        // differ and one of this plan's relaxed headland attempts found no way before: its
        // test passes every point the strict one passes, on the same rings, candidates and
        // joins, so when it finds no way the strict attempt finds none either. (Made first in
        // every plan, it cost the plans whose strict attempts succeed as much as it saved the
        // narrow fields whose attempts all fail.)
        let mut loose_headland: Option<Option<Vec<Vec2>>> = None;
        if kept_ends.as_ref().is_some_and(|k| k.0 != (from, h0)) {
            kept_ends = None;
        }
        let ends = &mut kept_ends
            .get_or_insert_with(|| {
                let margins = &tests.margins;
                let ends = [
                    rings::Ends::with_margin(margins.0),
                    rings::Ends::with_margin(margins.1),
                ];
                ((from, h0), ends)
            })
            .1;
        for (t, way, relaxed) in attempts {
            let (cp, cn, f, hf, q, hq) = poses(t);
            if t > 0 && cp == 0 && cn == 0 {
                continue;
            }
            if relaxed && one_test && t == 0 && matches!(way, Way::Direct | Way::Headland) {
                // The strict attempt with the same poses and test found nothing.
                continue;
            }
            let (r, step) = (p.r_min, p.point_spacing);
            let ok: &dyn Fn(&Vec2) -> bool = if relaxed { &loose } else { &clear };
            // No strict headland attempt between pieces no clear transit joins (once a relaxed one
            // found no way: finding the pieces costs a clip).
            let apart = |failed: bool| !one_test && failed && pieces.apart(&f, &q);
            let pts = match way {
                Way::Direct => transit::clear_transit(f, hf, q, hq, r, step, ok),
                Way::Headland if t == 0 && !one_test && (relaxed || *loose_failed) => {
                    let loose_way = loose_headland.get_or_insert_with(|| {
                        rings.transit_with(f, hf, q, hq, r, step, &loose, &mut ends[1])
                    });
                    *loose_failed |= loose_way.is_none();
                    if relaxed {
                        loose_way.take()
                    } else if loose_way.is_none() || apart(*loose_failed) {
                        None
                    } else {
                        rings.transit_with(f, hf, q, hq, r, step, ok, &mut ends[0])
                    }
                }
                Way::Headland if !relaxed && apart(*loose_failed) => None,
                Way::Headland => {
                    rings.transit_with(f, hf, q, hq, r, step, ok, &mut ends[usize::from(relaxed)])
                }
                // (Only relaxed: the loose grid's test is `ok`.)
                Way::Waypoints => {
                    transit::route_graph(f, hf, q, hq, r, step, loose_grid(), ROUTE_MAX_EXPANSIONS)
                }
                Way::Reverse => None,
            };
            let pts = match way {
                Way::Reverse => {
                    reverse::transit((f, hf), (q, hq), r, p.max_curvature_rate, step, &loose, 0.0)
                }
                _ => pts.map(|pts| vec![(Direction::Forward, pts)]),
            };
            if let Some(pts) = pts {
                tracing::trace!(t, ?way, relaxed, "transit found");
                found = Some((pts, cp, cn));
                break;
            }
        }
        // No way inside the field, forward or backing out (parts joined only by a neck, or a
        // pocket, narrower than the turns need): the plan goes on from the target without a
        // transit, so each part is worked on its own and the warning names the gap. (A curve
        // out of the field would break a guarantee; dropping the target would leave the rest
        // of the field unworked.)
        let Some((pts, cut_prev, cut_next)) = found else {
            transit_gaps.set(transit_gaps.get() + 1);
            warnings.borrow_mut().push(format!(
                "no transit inside the field from ({:.1}, {:.1}) to ({:.1}, {:.1}): the plan goes on there without one (no path forward or backing out at r_min stays inside the field between them: a neck or a pocket too narrow to turn in; drive there by hand)",
                from.x, from.y, to.x, to.y
            ));
            return 0;
        };
        if let Some(last) = segments.last_mut().filter(|_| cut_prev > 0) {
            last.points.truncate(last.points.len() - cut_prev);
        }
        for (direction, pts) in pts {
            push(segments, SegmentKind::Transit, direction, cell, pts);
        }
        cut_next
    };

    // A clear way from one pose on a swath to another past a small obstacle: A* over the
    // clear waypoints, every edge a Dubins curve of radius r_min.
    // First a single waypoint beside the obstacle (a smooth swerve), on either side, further
    // out step by step; then the waypoint grid.
    let detour = |from: Vec2, h0: f64, to: Vec2, h1: f64| -> Option<Vec<Vec2>> {
        // First a bypass of arcs round a circle holding the small obstacles near the line
        // (the implement's half width and the chord margin beyond them), the gentlest first:
        // leaving the line on 3·r_min, 2·r_min, then r_min, on the side away from the
        // obstacles' centre first.
        let near: Vec<&Vec<Vec2>> = small
            .iter()
            .zip(&small_discs)
            .filter(|(_, (c, r))| crate::geo::polygon::point_segment_distance(c, &from, &to) <= *r)
            .map(|(o, _)| o)
            .collect();
        if !near.is_empty() {
            let (centre, reach) = bypass::enclosing_circle(near.iter().copied());
            let radius = (reach + half + headland::chord_margin(p) + BYPASS_SLACK_M).max(p.r_min);
            let across =
                (centre - from).dot(&crate::geo::left_normal(&crate::geo::heading_vec(h0)));
            let away = if across > 0.0 { -1.0 } else { 1.0 };
            for r_leave in [3.0 * p.r_min, 2.0 * p.r_min, p.r_min] {
                for side in [away, -away] {
                    if let Some(pts) =
                        bypass::bypass(from, h0, to, centre, radius, r_leave, side, p.point_spacing)
                    {
                        if pts.iter().all(&clear) {
                            return Some(pts);
                        }
                    }
                }
            }
        }
        let mid = 0.5 * (from + to);
        let side = crate::geo::left_normal(&crate::geo::heading_vec(h0));
        for k in 1..=8 {
            for sign in [1.0, -1.0] {
                let via = mid + side * (sign * k as f64 * 0.5 * p.line_width);
                if !clear(&via) {
                    continue;
                }
                let a = transit::clear_transit(from, h0, via, h0, p.r_min, p.point_spacing, &clear);
                let b =
                    || transit::clear_transit(via, h0, to, h1, p.r_min, p.point_spacing, &clear);
                if let Some((mut a, b)) = a.and_then(|a| Some((a, b()?))) {
                    a.extend(b.into_iter().skip(1));
                    return Some(a);
                }
            }
        }
        transit::route_graph(
            from,
            h0,
            to,
            h1,
            p.r_min,
            p.point_spacing,
            waypoint_grid(),
            DETOUR_MAX_EXPANSIONS,
        )
    };

    // Runs of every cell, visited greedily nearest first.
    let mut pending: Vec<(usize, f64, Vec<swaths::RunSwath>, swaths::SwathLines)> = Vec::new();
    let mut swath_total = 0;
    let mut overlap_m2 = 0.0;
    // With sections and a headland to run on over (configured or the turns' own), the lines are
    // exactly w apart (see `swath_lines`).
    let exact = p.sections > 1 && headland::passes(p) > 0;
    for (ci, (cell, angle)) in cells.iter().enumerate() {
        if ci == worked_cells && swath_total == 0 {
            // Strips alone are no plan: `narrow::plan_field` tries fewer passes first.
            break;
        }
        let lines = swaths::swath_lines(cell, &safe, *angle, p.pass_spacing(), widening, exact);
        // The lines' n·s − span plus the overlap each of the n footprints lays beyond s.
        overlap_m2 += (lines.overlap_m + lines.ys.len() as f64 * p.overlap)
            * lines
                .intervals
                .iter()
                .flatten()
                .map(|(a, b)| b - a)
                .sum::<f64>()
            / lines.ys.len().max(1) as f64;
        for run in swaths::runs(&lines) {
            swath_total += run.len();
            pending.push((ci, *angle, run, lines.clone()));
        }
    }
    if swath_total == 0 {
        cells.truncate(worked_cells);
    }
    working.extend(cells[worked_cells..].iter().map(|c| c.0.clone()));
    // A field in parts a tractor cannot drive between inside the boundary: the largest part
    // is planned, the others are dropped and named (each can be planned as a field of its own).
    let parts = narrow::parts(field);
    if parts.len() > 1 {
        let mut dropped = vec![(0usize, 0usize); parts.len()];
        let mut keep = |q: &Vec2, swaths: usize| match narrow::part_of(&parts, q) {
            0 => true,
            k => {
                dropped[k].0 += usize::from(swaths == 0);
                dropped[k].1 += swaths;
                false
            }
        };
        field_tracks.retain(|t| keep(&t[0], 0));
        obstacle_tracks.retain(|t| keep(&t[0], 0));
        pending.retain(|(_, angle, run, lines)| {
            let (line, (x0, _)) = run[0];
            keep(&swaths::unrotate(v2(x0, lines.ys[line]), *angle), run.len())
        });
        for (k, &(passes, runs)) in dropped.iter().enumerate().skip(1) {
            swath_total -= runs;
            if passes + runs > 0 {
                warnings
                    .borrow_mut()
                    .push(narrow::dropped_part(&parts[k], passes, runs));
            }
        }
    }
    // The headland passes before or after the swaths.
    let phases = match p.headland_order {
        HeadlandOrder::First => [true, false],
        HeadlandOrder::Last => [false, true],
    };
    // Each region's work in the order of the phases, then the nearest region's left (see
    // `regions`): the first region is that of the first headland pass or swath run. Each
    // pass's and run's region (by where it starts) is found once.
    let region_of = |t: &Vec<Vec2>| t.first().map_or(0, |q| regions.of(q));
    let mut field_tracks: std::collections::VecDeque<(usize, Vec<Vec2>)> = field_tracks
        .into_iter()
        .map(|t| (region_of(&t), t))
        .collect();
    let mut obstacle_tracks: Vec<(usize, Vec<Vec2>)> = obstacle_tracks
        .into_iter()
        .map(|t| (region_of(&t), t))
        .collect();
    let mut pending: Vec<(usize, Vec2, _)> = pending
        .into_iter()
        .map(|run| {
            let q = runs::run_start(&run.2, &run.3, run.1);
            (regions.of(&q), q, run)
        })
        .collect();
    let first = field_tracks.front().map(|t| t.0);
    let mut region = first.or_else(|| pending.first().map(|r| r.0)).unwrap_or(0);
    // What to put back of the run kept last when the next run of the working area finds no
    // transit from its end: the plan's length after that run, the state to return to, the
    // swaths taken off.
    let mut last_kept: Option<(usize, UndoPoint, usize)> = None;
    loop {
        for headland_phase in phases {
            if headland_phase {
                loop {
                    let next = field_tracks.iter().position(|t| t.0 == region);
                    let ring = match next.and_then(|k| field_tracks.remove(k)) {
                        Some(r) => r.1,
                        None if obstacle_tracks.iter().any(|t| t.0 == region) => {
                            let here = at.map(|a| a.0).unwrap_or(field.boundary[0]);
                            let dist = |t: &Vec<Vec2>| {
                                t.iter()
                                    .map(|q| (q - here).norm())
                                    .fold(f64::INFINITY, f64::min)
                            };
                            let k = (0..obstacle_tracks.len())
                                .filter(|&i| obstacle_tracks[i].0 == region)
                                .min_by(|&i, &j| {
                                    dist(&obstacle_tracks[i].1)
                                        .total_cmp(&dist(&obstacle_tracks[j].1))
                                })
                                .unwrap_or(0);
                            obstacle_tracks.swap_remove(k).1
                        }
                        None => break,
                    };
                    let n = ring.len();
                    if n < 4 {
                        continue;
                    }
                    if (ring[n - 1] - ring[0]).norm() > 1e-9 {
                        // An open stretch of a cut pass: driven from its end nearer the vehicle
                        // (from the other where no transit reaches that one).
                        let here = at.map(|a| a.0).unwrap_or(ring[0]);
                        let mut near_end = ring;
                        if (near_end[n - 1] - here).norm() < (near_end[0] - here).norm() {
                            near_end.reverse();
                        }
                        let far_end: Vec<Vec2> = near_end.iter().rev().copied().collect();
                        let ends = [near_end, far_end].into_iter();
                        let (track, cut) = ring_start::first_reached(
                            ends,
                            || None,
                            &transit_gaps,
                            &warnings,
                            |t| go_to(&mut segments, &mut at, t, 0),
                        )
                        .unwrap_or_default();
                        let track = track[cut..].to_vec();
                        let n = track.len();
                        if n >= 2 {
                            let end = (track[n - 1], vec_heading(&(track[n - 1] - track[n - 2])));
                            push(
                                &mut segments,
                                SegmentKind::Headland,
                                Direction::Forward,
                                0,
                                track,
                            );
                            at = Some(end);
                        }
                        continue;
                    }
                    // Start the closed track a little ahead of the vehicle where a transit
                    // reaches it; where none does, at another point of it (see `ring_start`).
                    let open = &ring[..n - 1];
                    let m = open.len();
                    let first = ring_start::first_start(open, at, &field.boundary, p, &clear);
                    let starts = std::iter::once(first).chain(ring_start::other_starts(m, first));
                    // With no way to it, the pass starts on a straight near the first start.
                    let straight = || Some(ring_start::straight_start(open, first, p));
                    let (start, cut) = ring_start::first_reached(
                        starts,
                        straight,
                        &transit_gaps,
                        &warnings,
                        |&s| go_to(&mut segments, &mut at, &ring_start::track_from(open, s), 0),
                    )
                    .unwrap_or((first, 0));
                    let track = ring_start::track_from(open, start);
                    // A start pulled back (no way to it): the pass goes on past its start over the
                    // stretch cut, so the whole ring is still worked once.
                    let mut track = track[cut..].to_vec();
                    track.extend((1..=cut).map(|k| open[(start + k) % m]));
                    let n = track.len();
                    let hl = vec_heading(&(track[n - 1] - track[n - 2]));
                    push(
                        &mut segments,
                        SegmentKind::Headland,
                        Direction::Forward,
                        0,
                        track.clone(),
                    );
                    at = Some((track[n - 1], hl));
                }
            } else {
                loop {
                    let here = at.map(|a| a.0).unwrap_or(field.boundary[0]);
                    let nearest = pending
                        .iter()
                        .enumerate()
                        .filter(|(_, (r, _, _))| *r == region)
                        .map(|(k, (_, q, _))| (k, (q - here).norm()))
                        .fold(None, |b: Option<(usize, f64)>, c| match b {
                            Some(b) if b.1 <= c.1 => Some(b),
                            _ => Some(c),
                        });
                    let Some((k, _)) = nearest else {
                        break;
                    };
                    let (_, _, (ci, angle, run, lines)) = pending.swap_remove(k);
                    // A run of those cells that no transit reaches is put back (not driven to
                    // by hand); so is the last one kept (of the working area's, its last swath)
                    // when the next run of the others finds no transit from its end (that run is
                    // then driven again from where the vehicle entered the other).
                    let gaps = transit_gaps.get();
                    let own = ci >= worked_cells;
                    let mut before = (segments.len(), segments.last().cloned(), at, warnings_len());
                    let mut put_back = false;
                    // What undoing the last own run took off, put back on if the run of the
                    // others finds no transit from where that one was entered either.
                    let mut redo = None;
                    for attempt in 0..2 {
                        drive_run(
                            &run,
                            &lines,
                            angle,
                            ci,
                            p,
                            &tp,
                            &mut cache,
                            &mut block_orders,
                            &clear,
                            field,
                            &mut segments,
                            &mut at,
                            &mut go_to,
                            &detour,
                            &small_discs,
                            (&transit_gaps, &warnings),
                        )?;
                        let undo = if transit_gaps.get() == gaps || attempt > 0 {
                            None
                        } else if own {
                            Some((before.clone(), run.len()))
                        } else {
                            let kept = last_kept.take().filter(|(end, _, _)| *end == before.0);
                            kept.map(|(_, state, taken)| (state, taken))
                        };
                        let Some(((len, last, pose, warned), taken)) = undo else {
                            if let Some((tail, state, all_warned, gaps_then)) = redo.take() {
                                if transit_gaps.get() >= gaps_then {
                                    segments.truncate(before.0.saturating_sub(1));
                                    segments.extend(tail);
                                    (at, swath_total) = state;
                                    *warnings.borrow_mut() = all_warned;
                                    transit_gaps.set(gaps_then);
                                }
                            }
                            break;
                        };
                        if !own {
                            let from = len.saturating_sub(1);
                            let tail = segments[from.min(segments.len())..].to_vec();
                            let all_warned = warnings.borrow().clone();
                            let gaps_then = transit_gaps.get();
                            redo = Some((tail, (at, swath_total), all_warned, gaps_then));
                        }
                        segments.truncate(len);
                        if let (Some(l), Some(kept)) = (segments.last_mut(), last) {
                            *l = kept;
                        }
                        (at, swath_total) = (pose, swath_total - taken);
                        warnings.borrow_mut().truncate(warned);
                        transit_gaps.set(gaps);
                        if own {
                            put_back = true;
                            break;
                        }
                        before = (segments.len(), segments.last().cloned(), at, warnings_len());
                    }
                    // Kept whole (an own run put back leaves the one before it the last kept):
                    // of a cell of its own, the whole run is what to put back; of the working
                    // area's, only its last swath (a short piece in a pocket).
                    if !put_back && transit_gaps.get() == gaps {
                        let last_swath = if own {
                            None
                        } else {
                            runs::before_last_swath(&segments, before.0)
                        };
                        let (state, taken) = match last_swath {
                            Some((k, pose)) => {
                                let last = segments.get(k).cloned();
                                ((k + 1, last, Some(pose), warnings_len()), 1)
                            }
                            None => (before, run.len()),
                        };
                        last_kept = Some((segments.len(), state, taken));
                    } else if !own {
                        last_kept = None;
                    }
                }
            }
        }
        let here = at.map(|a| a.0).unwrap_or(field.boundary[0]);
        let starts = field_tracks
            .iter()
            .chain(&obstacle_tracks)
            .filter_map(|(r, t)| Some((*r, *t.first()?)))
            .chain(pending.iter().map(|(r, q, _)| (*r, *q)));
        match regions::nearest(here, starts) {
            Some(next) => region = next,
            None => break,
        }
    }

    // Where the plan has gaps, the chain that works the most ground first (see `chains`).
    let segments = chains::most_work_first(segments, |q| regions.of(q));
    Ok(FieldPlan {
        segments,
        working_area: working,
        cells: cells.len(),
        swath_angles: cells.iter().map(|c| c.1).collect(),
        swaths: swath_total,
        overlap_m2,
        turn_shapes_solved: cache.solved,
        warnings: warnings.into_inner(),
        transit_gaps: transit_gaps.get(),
        sections: p.sections,
        pass_overlap_m: p.overlap,
    })
}

#[cfg(test)]
mod tests;
