//! Driving a cell's runs of swaths: the order of the swaths (adjacent ones in turn, or the
//! seed-000 block skip order of [`crate::plan::skip_order`]), the turns between them from the
//! canonical-frame turn cache (swath ends pulled back until the turn is clear), the detours
//! round small obstacles, and the segments in driving order. Called by [`super::plan_field`].

use super::{swaths, transit, CoverageParams, PlanSegment, RouteOrder, SegmentKind};
use crate::geo::{v2, vec_heading, wrap_angle, Direction, Vec2};
use crate::plan::skip_order::BlockOrders;
use crate::plan::types::PlanError;

/// Appends a transit from the vehicle's pose to the start of a path: (segments, pose, path,
/// cell) → points cut from the path's start.
pub(super) type GoTo<'a> =
    dyn FnMut(&mut Vec<PlanSegment>, &mut Option<(Vec2, f64)>, &[Vec2], usize) -> usize + 'a;

/// A clear path between two poses (position, heading) around a small obstacle.
pub(super) type Detour<'a> = dyn Fn(Vec2, f64, Vec2, f64) -> Option<Vec<Vec2>> + 'a;

/// An asymmetric (Dubins) turn between swath ends is taken when it is at most this many times
/// the length of a half circle plus the straight legs it replaces (no loops round the field).
const ASYMMETRIC_TURN_MAX_LENGTH: f64 = 1.5;

/// A straight between a turn and a swath shorter than this is not added: the turn's end point
/// moves onto the swath's instead, m.
const SNAP_M: f64 = 0.01;

/// Largest dimension of an obstacle (greatest distance between two of its vertices), m.
pub fn obstacle_size(ring: &[Vec2]) -> f64 {
    let mut size: f64 = 0.0;
    for (i, a) in ring.iter().enumerate() {
        for b in &ring[i + 1..] {
            size = size.max((b - a).norm());
        }
    }
    size
}

/// Split a straight work piece where the implement would touch a small obstacle: the work
/// stops `lead` points before the blocked stretch, a detour goes round it and the work resumes
/// `lead` points after. Where no detour is clear, the work stops before the blocked stretch and
/// resumes after it, with an empty `Transit` piece between: the caller joins them by a transit.
fn split_for_detours(
    pts: Vec<Vec2>,
    lead: usize,
    r_min: f64,
    clear: &dyn Fn(&Vec2) -> bool,
    detour: &Detour<'_>,
) -> Vec<(SegmentKind, Vec<Vec2>)> {
    let n = pts.len();
    let blocked: Vec<usize> = (0..n).filter(|&i| !clear(&pts[i])).collect();
    if blocked.is_empty() {
        return vec![(SegmentKind::Work, pts)];
    }
    // Blocked stretches, merged when their leads would overlap.
    let mut stretches: Vec<(usize, usize)> = Vec::new();
    for &i in &blocked {
        match stretches.last_mut() {
            Some(s) if i <= s.1 + 2 * lead + 1 => s.1 = i,
            _ => stretches.push((i, i)),
        }
    }
    let heading = vec_heading(&(pts[n - 1] - pts[0]));
    let mut out = Vec::new();
    let mut start = 0;
    for (b0, b1) in stretches {
        // The longest lead (`lead` first, then three, two and one quarter of it) whose clear
        // detour has no loop (adds less than π·r_min to the straight it replaces); else the
        // detour that adds least. The longest lead gives the gentlest swerve: a detour is
        // arcs at r_min joined without easement, and the wheels need distance to swing from
        // one lock to the other, so a short swerve is planned clear but driven wide of its
        // line (the demo field's pole: 0.77 m RMS on a 25 m swerve at a quarter lead).
        let candidates: Vec<(f64, usize, usize, Vec<Vec2>)> = (1..=4)
            .filter_map(|q| {
                let l = (lead * q).div_ceil(4);
                let (a, b) = (b0.checked_sub(l)?, b1 + l);
                if b >= n || a <= start {
                    return None;
                }
                let way = detour(pts[a], heading, pts[b], heading)?;
                let extra = crate::geo::polygon::polyline_length(&way) - (pts[b] - pts[a]).norm();
                Some((extra, a, b, way))
            })
            .collect();
        let no_loop = candidates
            .iter()
            .rposition(|c| c.0 < std::f64::consts::PI * r_min);
        let best = no_loop.or_else(|| {
            (0..candidates.len()).min_by(|&i, &j| candidates[i].0.total_cmp(&candidates[j].0))
        });
        let found = best
            .and_then(|i| candidates.into_iter().nth(i))
            .map(|(_, a, b, way)| (a, b, way));
        let Some((a, b, way)) = found else {
            // No clear detour: the blocked stretch is not worked (the implement would be over
            // the obstacle); a transit joins the two pieces (a piece of no points marks it).
            if b0 > start + 1 {
                out.push((SegmentKind::Work, pts[start..b0].to_vec()));
            }
            out.push((SegmentKind::Transit, Vec::new()));
            start = (b1 + 1).min(n - 1);
            continue;
        };
        out.push((SegmentKind::Work, pts[start..=a].to_vec()));
        out.push((SegmentKind::Detour, way));
        start = b;
    }
    out.push((SegmentKind::Work, pts[start..].to_vec()));
    out
}

/// The driving order of a run's swaths (indices into the run): adjacent ones in turn when the
/// spacing allows a U-turn (or the operator chose sequential lines, with fishtails); otherwise
/// the seed-000 block skip order ([`crate::plan::skip_order`], blocks of `2·min_gap + 1`), so no
/// turn is tighter than 2·r_min.
fn run_order(n: usize, spacing: f64, p: &CoverageParams, orders: &mut BlockOrders) -> Vec<usize> {
    use crate::plan::skip_order::{min_gap_lines, skip_order_with};
    if p.route == RouteOrder::Sequential {
        return (0..n).collect();
    }
    skip_order_with(n, min_gap_lines(p.r_min, spacing), 1, orders)
}

/// Where a swath run starts, in the field's frame.
pub(super) fn run_start(run: &[swaths::RunSwath], lines: &swaths::SwathLines, angle: f64) -> Vec2 {
    let (line, (x0, _)) = run[0];
    swaths::unrotate(v2(x0, lines.ys[line]), angle)
}

/// Undoing the last swath of a run driven into `segments` from index `from` on: the index of
/// the segment that then ends the plan (the swath before it, its turn onto the last one and
/// the last one's pieces taken off) and the vehicle's pose at its end; `None` when the run
/// holds a single swath (undo the whole run instead).
pub(super) fn before_last_swath(
    segments: &[PlanSegment],
    from: usize,
) -> Option<(usize, (Vec2, f64))> {
    use SegmentKind::{Detour, Work};
    let worked = |s: &PlanSegment| matches!(s.kind, Work | Detour);
    let tail = segments.iter().rposition(|s| !worked(s))?;
    let kept = segments[..tail].iter().rposition(worked)?;
    let s = segments.get(kept).filter(|_| kept >= from)?;
    Some((kept, end_pose(&s.points, s.direction)?))
}

/// The vehicle's pose at the end of a segment driven along `pts` in `direction`: the last
/// point, and the heading the vehicle faces there (against the travel when reversing); `None`
/// under two points.
fn end_pose(pts: &[Vec2], direction: Direction) -> Option<(Vec2, f64)> {
    let last = *pts.last()?;
    let travel = vec_heading(&(last - pts.get(pts.len().checked_sub(2)?)?));
    let heading = match direction {
        Direction::Forward => travel,
        Direction::Reverse => wrap_angle(travel + std::f64::consts::PI),
    };
    Some((last, heading))
}

#[allow(clippy::too_many_arguments)]
pub(super) fn drive_run(
    run: &[swaths::RunSwath],
    lines: &swaths::SwathLines,
    angle: f64,
    cell: usize,
    p: &CoverageParams,
    tp: &crate::plan::turns::TurnParams,
    cache: &mut crate::plan::turns::TurnCache,
    orders: &mut BlockOrders,
    clear: &dyn Fn(&Vec2) -> bool,
    field: &crate::plan::types::Field,
    segments: &mut Vec<PlanSegment>,
    at: &mut Option<(Vec2, f64)>,
    go_to: &mut GoTo<'_>,
    detour: &Detour<'_>,
    small_discs: &[(Vec2, f64)],
    (gaps, warnings): (&std::cell::Cell<usize>, &std::cell::RefCell<Vec<String>>),
) -> Result<(), PlanError> {
    let order = run_order(run.len(), lines.spacing, p, orders);
    let here = at.map(|a| a.0);
    // Start from the end of the first swath nearest the vehicle.
    let (l0, (a0, b0)) = run[order[0]];
    let start_left = match here {
        Some(h) => {
            let pa = swaths::unrotate(v2(a0, lines.ys[l0]), angle);
            let pb = swaths::unrotate(v2(b0, lines.ys[l0]), angle);
            (pa - h).norm() <= (pb - h).norm()
        }
        None => true,
    };
    // Swath ends in the rotated frame, possibly pulled back to make room for the turns.
    let mut ends: Vec<(f64, f64)> = order.iter().map(|&i| run[i].1).collect();
    let mut forward = start_left;
    let mut pieces: Vec<(SegmentKind, Direction, Vec<Vec2>)> = Vec::new();
    for (k, &i) in order.iter().enumerate() {
        let y = lines.ys[run[i].0];
        let (a, b) = ends[k];
        let (s, e) = if forward { (a, b) } else { (b, a) };
        let world = |x: f64, yy: f64| swaths::unrotate(v2(x, yy), angle);
        pieces.push((
            SegmentKind::Work,
            Direction::Forward,
            transit::straight(world(s, y), world(e, y), p.point_spacing),
        ));
        if let Some(&j) = order.get(k + 1) {
            let y2 = lines.ys[run[j].0];
            let (a2, b2) = ends[k + 1];
            let dir = if forward { 1.0 } else { -1.0 };
            let end2 = if forward { b2 } else { a2 };
            // Level the two ends at the outer one (the shorter swath runs on to it), then
            // pull the apex back, shortening the swaths, until the whole turn is clear.
            let outer = if forward { e.max(end2) } else { e.min(end2) };
            let inner = if forward { e.min(end2) } else { e.max(end2) };
            let tries = ((outer - inner).abs() + 4.0 * p.r_min + 2.0 * p.line_width) as usize;
            let d = swaths::unrotate(v2(dir, 0.0), angle);
            let mut best = None;
            // A turn that the swath ends cannot share (a headland edge slanted to the
            // swaths): the Dubins curve from this swath's end to the next one's start, each
            // pulled back as little as makes it clear, before the symmetric turn is pulled
            // back to the shorter end (which left a strip of the longer swath unworked).
            let far2 = if forward { a2 } else { b2 };
            // Out along this swath, back along the next; a turn longer than this bound is not
            // taken (ASYMMETRIC_TURN_MAX_LENGTH).
            let (h1, h2) = (vec_heading(&d), vec_heading(&(-d)));
            let max_length = ASYMMETRIC_TURN_MAX_LENGTH
                * (std::f64::consts::PI * p.r_min + (y2 - y).abs() + (end2 - e).abs());
            let dubins = |t: f64| {
                let (e_t, s2) = (e - dir * t, end2 - dir * t);
                if (e_t - s) * dir <= 0.0 || (s2 - far2) * dir <= 0.0 {
                    return None;
                }
                let (q1, q2) = (world(e_t, y), world(s2, y2));
                match transit::clear_transit(q1, h1, q2, h2, p.r_min, p.point_spacing, clear) {
                    Some(pts) if crate::geo::polygon::polyline_length(&pts) <= max_length => {
                        Some((
                            vec![crate::plan::turns::TurnPart {
                                direction: Direction::Forward,
                                points: pts,
                            }],
                            e_t,
                            s2,
                        ))
                    }
                    _ => None,
                }
            };
            // Backing up at the full ends (a K-turn, the implement clear throughout) where no
            // forward turn fits without pulling them back.
            let backing = || {
                let (q1, q2) = (world(e, y), world(end2, y2));
                let parts = super::reverse::transit(
                    (q1, h1),
                    (q2, h2),
                    p.r_min,
                    p.max_curvature_rate,
                    p.point_spacing,
                    clear,
                    super::reverse::turn_lead_in(p.r_min, p.max_curvature_rate),
                )?;
                let length: f64 = parts
                    .iter()
                    .map(|(_, pts)| crate::geo::polygon::polyline_length(pts))
                    .sum();
                (length <= max_length).then(|| {
                    let parts = parts
                        .into_iter()
                        .map(|(direction, points)| crate::plan::turns::TurnPart {
                            direction,
                            points,
                        })
                        .collect::<Vec<_>>();
                    (parts, e, end2)
                })
            };
            for t in 0..=tries {
                if t > 0 {
                    if let Some(found) = dubins((t - 1) as f64) {
                        best = Some(found);
                        break;
                    }
                }
                if t == 1 {
                    if let Some(found) = backing() {
                        best = Some(found);
                        break;
                    }
                }
                let apex = outer - dir * t as f64;
                let e_new = if forward { e.min(apex) } else { e.max(apex) };
                let start2 = if forward {
                    end2.min(apex)
                } else {
                    end2.max(apex)
                };
                if (e_new - s) * dir <= 0.0 || (start2 - far2) * dir <= 0.0 {
                    // Pulled back past a swath's other end: no swath is left to turn from.
                    break;
                }
                let mut parts = cache.turn(world(apex, y), d, world(apex, y2), tp)?;
                let lead_in = world(e_new, y);
                // A lead-in or tail shorter than SNAP_M moves the turn's end point instead:
                // a point that close to the next bends the path sharply in the checks.
                if let Some(first) = parts.first_mut() {
                    if (first.points[0] - lead_in).norm() < SNAP_M {
                        first.points[0] = lead_in;
                    } else {
                        let mut pts = transit::straight(lead_in, first.points[0], p.point_spacing);
                        pts.pop();
                        pts.extend(first.points.iter().copied());
                        first.points = pts;
                    }
                }
                if let Some(last) = parts.last_mut() {
                    let (from, to) = (*last.points.last().unwrap_or(&lead_in), world(start2, y2));
                    if (to - from).norm() < SNAP_M {
                        if let Some(q) = last.points.last_mut() {
                            *q = to;
                        }
                    } else {
                        let tail = transit::straight(from, to, p.point_spacing);
                        last.points.extend(tail.into_iter().skip(1));
                    }
                }
                let ok = parts.iter().all(|t| t.points.iter().all(clear));
                // With no clear turn, the least pulled-back one that keeps the tractor in the
                // field (the implement is raised).
                if ok
                    || (best.is_none()
                        && parts
                            .iter()
                            .all(|t| t.points.iter().all(|q| field.contains(q))))
                {
                    best = Some((parts, e_new, start2));
                }
                if ok {
                    break;
                }
            }
            let Some((parts, e_new, start2)) = best else {
                // No turn in the field: the next swath is reached by a transit.
                pieces.push((SegmentKind::Transit, Direction::Forward, Vec::new()));
                forward = !forward;
                continue;
            };
            // This swath ends where its turn begins.
            if let Some(last) = pieces.last_mut() {
                last.2 = transit::straight(world(s, y), world(e_new, y), p.point_spacing);
            }
            if forward {
                ends[k + 1].1 = start2;
            } else {
                ends[k + 1].0 = start2;
            }
            for t in parts {
                pieces.push((SegmentKind::Turn, t.direction, t.points));
            }
        }
        forward = !forward;
    }
    // Detours round the small obstacles on the swaths.
    let lead = ((2.0 * p.r_min + p.line_width) / p.point_spacing).ceil() as usize;
    let pieces: Vec<(SegmentKind, Direction, Vec<Vec2>)> = pieces
        .into_iter()
        .flat_map(|(kind, direction, pts)| match kind {
            SegmentKind::Work
                if pts.len() >= 2
                    && small_discs.iter().any(|(c, r)| {
                        crate::geo::polygon::point_segment_distance(c, &pts[0], &pts[pts.len() - 1])
                            <= *r
                    }) =>
            {
                split_for_detours(pts, lead, p.r_min, clear, detour)
                    .into_iter()
                    .map(|(k, pts)| (k, direction, pts))
                    .collect()
            }
            _ => vec![(kind, direction, pts)],
        })
        .collect();
    // Drive: transit to the first swath, then the pieces in order.
    let mut first = true;
    // Is the next transit past a blocked stretch (not the one onto the run)?
    let mut past_blocked = false;
    for (kind, direction, mut pts) in pieces {
        if kind == SegmentKind::Transit && pts.is_empty() {
            // A stretch left unworked: the next piece is reached by a transit.
            (first, past_blocked) = (true, true);
            continue;
        }
        if pts.len() < 2 {
            continue;
        }
        if first {
            let (g, w) = (gaps.get(), warnings.borrow().len());
            let mut cut = go_to(segments, at, &pts, cell);
            // No way on past a blocked stretch from a stub of a swath before it: from the swath
            // before the turn onto it, without the stub (see `stub`); kept where that finds none
            // either.
            let stub = (past_blocked && gaps.get() > g)
                .then(|| super::stub::stub_at_end(segments, lead as f64 * p.point_spacing))
                .flatten();
            if let Some(from) = stub {
                let kept = (
                    segments.split_off(from),
                    *at,
                    warnings.borrow().clone(),
                    gaps.get(),
                );
                let last = &segments[from - 1];
                *at = end_pose(&last.points, last.direction);
                gaps.set(g);
                warnings.borrow_mut().truncate(w);
                let c = go_to(segments, at, &pts, cell);
                if gaps.get() > g {
                    segments.truncate(from);
                    segments.extend(kept.0);
                    (*at, *warnings.borrow_mut()) = (kept.1, kept.2);
                    gaps.set(kept.3);
                } else {
                    cut = c;
                }
            }
            pts.drain(..cut.min(pts.len().saturating_sub(2)));
            (first, past_blocked) = (false, false);
        }
        *at = end_pose(&pts, direction);
        let index = segments.len();
        segments.push(PlanSegment {
            kind,
            direction,
            index,
            cell,
            points: pts.clone(),
        });
    }
    Ok(())
}
