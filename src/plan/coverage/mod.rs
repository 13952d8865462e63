//! Coverage of a polygon field (SPEC §3, seeds 003 and 001), as a pipeline of pure stages in
//! the manner of Fields2Cover: headland → swath angle → decomposition → swaths → obstacles →
//! route → turns → one ordered list of [`PlanSegment`]s.
//!
//! Input is a [`Field`] in the local ENU frame (see [`crate::field`] for reading GeoJSON and
//! ISO 11783-10 TASKDATA into one). Every stage is a pure function of its inputs.

pub mod decompose;
pub mod geometry;
pub mod headland;
pub mod metrics;
pub mod swath_angle;
pub mod swaths;
pub mod transit;

pub use crate::plan::types::{Field, PlanSegment, SegmentKind};

use crate::geo::{v2, vec_heading, wrap_angle, Direction, Vec2};
use crate::plan::types::PlanError;
use serde::{Deserialize, Serialize};

/// How the swath direction is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "objective")]
pub enum SwathAngle {
    /// Minimum span of the convex hull (rotating calipers over the edge directions; seed 003).
    #[default]
    MinSpan,
    /// The least total number of turns across the cells after decomposition.
    MinTurns,
    /// A fixed direction, rad CCW from East (e.g. parallel to an AB line or the longest edge).
    Fixed { angle: f64 },
}

/// Order of the swaths inside a cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RouteOrder {
    /// Boustrophedon when `line_width ≥ 2·r_min`, else the seed-000 block skip order.
    #[default]
    Auto,
    /// Adjacent swaths in turn (fishtail turns when `line_width < 2·r_min`).
    Sequential,
    /// The seed-000 block/TSP skip order.
    Skip,
}

/// Everything the coverage planner needs besides the field. Units in the names' docs.
#[derive(Debug, Clone, PartialEq)]
pub struct CoverageParams {
    /// Implement working width = swath spacing, m.
    pub line_width: f64,
    /// Minimum turning radius, m.
    pub r_min: f64,
    /// Number of headland passes around the field (each `line_width` wide).
    pub headland_passes: usize,
    /// Spacing of plan points, m.
    pub point_spacing: f64,
    /// Swath direction objective.
    pub swath_angle: SwathAngle,
    /// Swath order inside each cell.
    pub route: RouteOrder,
    /// Obstacles whose largest dimension ([`obstacle_size`]) is at most this are passed on
    /// detours (the swaths run through them; each blocked stretch becomes a smooth path round
    /// the obstacle); larger ones get headland passes and split the swaths, m.
    pub small_obstacle_max_m: f64,
    /// Largest curvature rate per metre driven, 1/m², for continuous-curvature fishtail turns
    /// (clothoid + arc + clothoid); 0 = fishtails of arcs only.
    pub max_curvature_rate: f64,
}

/// A complete field plan: segments in driving order plus the areas they were made for.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FieldPlan {
    /// Every segment in driving order (headland passes, swaths, turns, detours, transits).
    pub segments: Vec<PlanSegment>,
    /// The working area (inside the headland) as polygons: (outer ring, holes), all CCW.
    pub working_area: Vec<(Vec<Vec2>, Vec<Vec<Vec2>>)>,
    /// Number of cells after decomposition.
    pub cells: usize,
    /// Swath direction of each cell, rad CCW from East.
    pub swath_angles: Vec<f64>,
    /// Number of work swaths.
    pub swaths: usize,
    /// Overlap of adjacent swath footprints from balancing, m² (estimate: the extra width
    /// times the mean swath length).
    pub overlap_m2: f64,
    /// Turn shapes solved in the canonical frame (each reused for every alike turn).
    pub turn_shapes_solved: usize,
}

/// A point of a path keeps the implement inside the field and off the obstacles: inside the
/// boundary and at least `half` m from every boundary edge and every obstacle.
pub fn implement_clear(field: &Field, half: f64, q: &Vec2) -> bool {
    use crate::geo::polygon::{contains_point, point_segment_distance};
    let far = |ring: &[Vec2]| {
        let n = ring.len();
        (0..n).all(|i| point_segment_distance(q, &ring[i], &ring[(i + 1) % n]) >= half - 1e-6)
    };
    contains_point(&field.boundary, q)
        && far(&field.boundary)
        && field
            .obstacles
            .iter()
            .all(|o| !contains_point(o, q) && far(o))
}

/// [`implement_clear`] with a lazily filled grid of cells known to be clear throughout (their
/// centre is clear by `half` plus half the cell's diagonal), so most checks are one lookup.
struct ClearMap<'a> {
    field: &'a Field,
    half: f64,
    origin: Vec2,
    cell: f64,
    nx: usize,
    ny: usize,
    /// 0 = not known yet, 1 = clear throughout, 2 = check each point.
    state: std::cell::RefCell<Vec<u8>>,
}

impl<'a> ClearMap<'a> {
    /// At most this many grid cells (a few MB).
    const MAX_CELLS: f64 = 4.0e6;

    fn new(field: &'a Field, half: f64) -> Self {
        let (lo, hi) = crate::geo::polygon::bbox(field.boundary.iter())
            .unwrap_or((v2(0.0, 0.0), v2(1.0, 1.0)));
        let span = hi - lo;
        let cell = (half.max(0.5)).max((span.x * span.y / Self::MAX_CELLS).sqrt());
        let nx = (span.x / cell).ceil() as usize + 1;
        let ny = (span.y / cell).ceil() as usize + 1;
        ClearMap {
            field,
            half,
            origin: lo,
            cell,
            nx,
            ny,
            state: std::cell::RefCell::new(vec![0; nx * ny]),
        }
    }

    fn clear(&self, q: &Vec2) -> bool {
        let i = ((q.x - self.origin.x) / self.cell).floor();
        let j = ((q.y - self.origin.y) / self.cell).floor();
        if i >= 0.0 && j >= 0.0 && (i as usize) < self.nx && (j as usize) < self.ny {
            let k = j as usize * self.nx + i as usize;
            let mut state = self.state.borrow_mut();
            if state[k] == 0 {
                let centre = self.origin + v2((i + 0.5) * self.cell, (j + 0.5) * self.cell);
                let deep = self.half + self.cell * std::f64::consts::FRAC_1_SQRT_2;
                state[k] = if implement_clear(self.field, deep, &centre) {
                    1
                } else {
                    2
                };
            }
            if state[k] == 1 {
                return true;
            }
        }
        implement_clear(self.field, self.half, q)
    }
}

impl CoverageParams {
    fn validate(&self) -> Result<(), PlanError> {
        PlanError::check("line_width", self.line_width, self.line_width > 0.0)?;
        PlanError::check("r_min", self.r_min, self.r_min > 0.0)?;
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
        PlanError::check(
            "small_obstacle_max_m",
            self.small_obstacle_max_m,
            self.small_obstacle_max_m >= 0.0,
        )?;
        Ok(())
    }

    fn turn_params(&self) -> crate::plan::turns::TurnParams {
        crate::plan::turns::TurnParams {
            r_min: self.r_min,
            arc_step: 2f64.to_radians(),
            merge_distance: 0.05,
            point_spacing: self.point_spacing,
            max_points: 100_000,
            max_curvature_rate: self.max_curvature_rate,
        }
    }
}

/// States a transit's waypoint search may expand before giving up.
const ROUTE_MAX_EXPANSIONS: usize = 20_000;

/// Plan the whole field: headland passes (outermost first), then the cells in a short order,
/// each swept by its runs of swaths with turns, joined by transits.
pub fn plan_field(field: &Field, p: &CoverageParams) -> Result<FieldPlan, PlanError> {
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
    let (small, large): (Vec<Vec<Vec2>>, Vec<Vec<Vec2>>) = field
        .obstacles
        .iter()
        .cloned()
        .partition(|o| obstacle_size(o) <= p.small_obstacle_max_m);
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
    let working = headland::working_area(&field.boundary, &large, p);
    // Points are checked; the chords between them may cut a little inside the arcs.
    let clear_map = ClearMap::new(
        field,
        half + headland::chord_margin(p) - headland::CHORD_MARGIN,
    );
    let clear = |q: &Vec2| clear_map.clear(q);
    // Waypoints for transits that cannot go direct: a grid of clear points over the field.
    // (Built on first need: most plans never need it.)
    let waypoint_grid = std::cell::OnceCell::new();
    let waypoint_grid = || {
        waypoint_grid.get_or_init(|| {
            let (lo, hi) = crate::geo::polygon::bbox(field.boundary.iter())
                .unwrap_or((v2(0.0, 0.0), v2(1.0, 1.0)));
            transit::WaypointGrid::new(lo, hi, 2.0 * p.r_min, 20_000, &clear)
        })
    };

    // Cells and their swath directions.
    let global_angle = match p.swath_angle {
        SwathAngle::Fixed { angle } => Some(angle),
        SwathAngle::MinSpan => {
            let pts: Vec<Vec2> = working.iter().flat_map(|a| a.0.iter().copied()).collect();
            swath_angle::min_span(&pts).map(|s| s.0)
        }
        SwathAngle::MinTurns => None,
    };
    let mut cells: Vec<(geometry::Area, f64)> = Vec::new();
    for area in &working {
        match global_angle {
            Some(a) => cells.push((area.clone(), a)),
            None => {
                let pieces: Vec<geometry::Area> = decompose::convex_cells(&area.0)
                    .into_iter()
                    .flat_map(|c| {
                        use geo::BooleanOps;
                        let g =
                            geometry::to_geo(&(c, vec![])).intersection(&geometry::to_geo(area));
                        geometry::from_geo(&g)
                    })
                    .collect();
                for c in decompose::merge_cells(pieces, w) {
                    let a = swath_angle::min_span(&c.0).map(|s| s.0).unwrap_or(0.0);
                    cells.push((c, a));
                }
            }
        }
    }

    let tp = p.turn_params();
    let mut cache = crate::plan::turns::TurnCache::default();
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
        // Without shortening any work first (direct, then through waypoints), then pulling
        // the ends back metre by metre, then the waypoints again.
        #[derive(Clone, Copy)]
        enum Way {
            Direct,
            Waypoints,
        }
        let mut attempts = vec![(0, Way::Direct), (0, Way::Waypoints)];
        attempts.extend((1..=max_cut).map(|t| (t, Way::Direct)));
        attempts.push((max_cut, Way::Waypoints));
        let mut found = None;
        for (t, way) in attempts {
            let (cp, cn, f, hf, q, hq) = poses(t);
            if t > 0 && cp == 0 && cn == 0 {
                continue;
            }
            let (r, step) = (p.r_min, p.point_spacing);
            let pts = match way {
                Way::Direct => transit::transit(f, hf, q, hq, r, step, &clear)
                    .and_then(|(pts, ok)| ok.then_some(pts)),
                Way::Waypoints => transit::route_graph(
                    f,
                    hf,
                    q,
                    hq,
                    r,
                    step,
                    &clear,
                    waypoint_grid(),
                    ROUTE_MAX_EXPANSIONS,
                ),
            };
            if let Some(pts) = pts {
                found = Some((pts, cp, cn));
                break;
            }
        }
        let (pts, cut_prev, cut_next) = match found {
            Some(x) => x,
            // Nothing clear: the shortest direct curve (the plan's metrics will show it).
            None => match transit::transit(from, h0, to, h, p.r_min, p.point_spacing, &clear) {
                Some((pts, _)) => (pts, 0, 0),
                None => return 0,
            },
        };
        if cut_prev > 0 {
            if let Some(last) = segments.last_mut() {
                let keep = last.points.len() - cut_prev;
                last.points.truncate(keep);
            }
        }
        push(
            segments,
            SegmentKind::Transit,
            Direction::Forward,
            cell,
            pts,
        );
        cut_next
    };

    // A clear way from one pose on a swath to another past a small obstacle: A* over the
    // clear waypoints, every edge a Dubins curve of radius r_min.
    // First a single waypoint beside the obstacle (a smooth swerve), on either side, further
    // out step by step; then the waypoint grid.
    let detour = |from: Vec2, h0: f64, to: Vec2, h1: f64| -> Option<Vec<Vec2>> {
        let mid = 0.5 * (from + to);
        let side = crate::geo::left_normal(&crate::geo::heading_vec(h0));
        for k in 1..=8 {
            for sign in [1.0, -1.0] {
                let via = mid + side * (sign * k as f64 * 0.5 * p.line_width);
                if !clear(&via) {
                    continue;
                }
                let a = transit::transit(from, h0, via, h0, p.r_min, p.point_spacing, &clear);
                let b = transit::transit(via, h0, to, h1, p.r_min, p.point_spacing, &clear);
                if let (Some((mut a, true)), Some((b, true))) = (a, b) {
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
            &clear,
            waypoint_grid(),
            ROUTE_MAX_EXPANSIONS,
        )
    };

    // Headland passes: the field's (outermost first), then the obstacles' (nearest first),
    // those that keep clear of the field edge and the other obstacles.
    let mut field_tracks: std::collections::VecDeque<Vec<Vec2>> =
        headland::headland_tracks(&field.boundary, p).into();
    let mut obstacle_tracks: Vec<Vec<Vec2>> = headland::obstacle_tracks(&large, p)
        .into_iter()
        .filter(|t| {
            let ok = t.iter().all(&clear);
            if !ok {
                tracing::debug!("an obstacle headland pass would leave the field; skipped");
            }
            ok
        })
        .collect();
    loop {
        let ring = match field_tracks.pop_front() {
            Some(r) => r,
            None if !obstacle_tracks.is_empty() => {
                let here = at.map(|a| a.0).unwrap_or(field.boundary[0]);
                let dist = |t: &Vec<Vec2>| {
                    t.iter()
                        .map(|q| (q - here).norm())
                        .fold(f64::INFINITY, f64::min)
                };
                let k = (0..obstacle_tracks.len())
                    .min_by(|&i, &j| {
                        dist(&obstacle_tracks[i]).total_cmp(&dist(&obstacle_tracks[j]))
                    })
                    .unwrap_or(0);
                obstacle_tracks.swap_remove(k)
            }
            None => break,
        };
        let n = ring.len();
        if n < 4 {
            continue;
        }
        // Start the closed track where the transit from the vehicle is clear: a little ahead
        // of it (the first pass: mid the longest boundary edge).
        let open = &ring[..n - 1];
        let target = match at {
            Some((q, h)) => q + crate::geo::heading_vec(h) * (2.5 * p.r_min),
            None => {
                let b = &field.boundary;
                let i = (0..b.len())
                    .max_by(|&i, &j| {
                        let li = (b[(i + 1) % b.len()] - b[i]).norm();
                        let lj = (b[(j + 1) % b.len()] - b[j]).norm();
                        li.total_cmp(&lj)
                    })
                    .unwrap_or(0);
                0.5 * (b[i] + b[(i + 1) % b.len()])
            }
        };
        let nearest = (0..open.len())
            .min_by(|&i, &j| {
                (open[i] - target)
                    .norm()
                    .total_cmp(&(open[j] - target).norm())
            })
            .unwrap_or(0);
        let m = open.len();
        let mut start = nearest;
        if let Some((q, h)) = at {
            // At most about 48 candidate starts around the track (each try is a whole curve).
            for k in (0..m).step_by((m / 48).max(1)) {
                let i = (nearest + k) % m;
                let hi = vec_heading(&(open[(i + 1) % m] - open[i]));
                if let Some((_, true)) =
                    transit::transit(q, h, open[i], hi, p.r_min, p.point_spacing, &clear)
                {
                    start = i;
                    break;
                }
            }
        }
        let mut track: Vec<Vec2> = (0..m).map(|k| open[(start + k) % m]).collect();
        track.push(open[start]);
        let n = track.len();
        let cut = go_to(&mut segments, &mut at, &track, 0);
        let track = track[cut..].to_vec();
        let n = n - cut;
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

    // Runs of every cell, visited greedily nearest first.
    let mut pending: Vec<(usize, f64, Vec<swaths::RunSwath>, swaths::SwathLines)> = Vec::new();
    let mut swath_total = 0;
    let mut overlap_m2 = 0.0;
    for (ci, (cell, angle)) in cells.iter().enumerate() {
        let lines = swaths::swath_lines(cell, &safe, *angle, w);
        overlap_m2 += lines.overlap_m
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
    while !pending.is_empty() {
        let here = at.map(|a| a.0).unwrap_or(field.boundary[0]);
        let (k, _) = pending
            .iter()
            .enumerate()
            .map(|(k, (_, angle, run, lines))| {
                let (line, (x0, _)) = run[0];
                let q = swaths::unrotate(v2(x0, lines.ys[line]), *angle);
                (k, (q - here).norm())
            })
            .fold((0, f64::INFINITY), |b, c| if c.1 < b.1 { c } else { b });
        let (ci, angle, run, lines) = pending.swap_remove(k);
        drive_run(
            &run,
            &lines,
            angle,
            ci,
            p,
            &tp,
            &mut cache,
            &clear,
            &mut segments,
            &mut at,
            &mut go_to,
            &detour,
            &small_discs,
        )?;
    }

    Ok(FieldPlan {
        segments,
        working_area: working,
        cells: cells.len(),
        swath_angles: cells.iter().map(|c| c.1).collect(),
        swaths: swath_total,
        overlap_m2,
        turn_shapes_solved: cache.solved,
    })
}

/// Appends a transit from the vehicle's pose to the start of a path: (segments, pose, path,
/// cell) → points cut from the path's start.
type GoTo<'a> =
    dyn FnMut(&mut Vec<PlanSegment>, &mut Option<(Vec2, f64)>, &[Vec2], usize) -> usize + 'a;

/// A clear path between two poses (position, heading) around a small obstacle.
type Detour<'a> = dyn Fn(Vec2, f64, Vec2, f64) -> Option<Vec<Vec2>> + 'a;

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
/// `lead` points after. Pieces that cannot be split are returned whole.
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
        // The shortest lead (a quarter of `lead` first, to leave least unworked) whose clear
        // detour has no loop (adds less than π·r_min to the straight it replaces); else the
        // detour that adds least.
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
            .position(|c| c.0 < std::f64::consts::PI * r_min);
        let best = no_loop.or_else(|| {
            (0..candidates.len()).min_by(|&i, &j| candidates[i].0.total_cmp(&candidates[j].0))
        });
        let found = best
            .and_then(|i| candidates.into_iter().nth(i))
            .map(|(_, a, b, way)| (a, b, way));
        let Some((a, b, way)) = found else {
            return vec![(SegmentKind::Work, pts)];
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
fn run_order(n: usize, spacing: f64, p: &CoverageParams) -> Vec<usize> {
    use crate::plan::skip_order::{min_gap_lines, skip_order};
    if p.route == RouteOrder::Sequential {
        return (0..n).collect();
    }
    skip_order(n, min_gap_lines(p.r_min, spacing), 1)
}

#[allow(clippy::too_many_arguments)]
fn drive_run(
    run: &[swaths::RunSwath],
    lines: &swaths::SwathLines,
    angle: f64,
    cell: usize,
    p: &CoverageParams,
    tp: &crate::plan::turns::TurnParams,
    cache: &mut crate::plan::turns::TurnCache,
    clear: &dyn Fn(&Vec2) -> bool,
    segments: &mut Vec<PlanSegment>,
    at: &mut Option<(Vec2, f64)>,
    go_to: &mut GoTo<'_>,
    detour: &Detour<'_>,
    small_discs: &[(Vec2, f64)],
) -> Result<(), PlanError> {
    let order = run_order(run.len(), lines.spacing, p);
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
            for t in 0..=tries {
                let apex = outer - dir * t as f64;
                let e_new = if forward { e.min(apex) } else { e.max(apex) };
                let start2 = if forward {
                    end2.min(apex)
                } else {
                    end2.max(apex)
                };
                let mut parts = cache.turn(world(apex, y), d, world(apex, y2), tp)?;
                let lead_in = world(e_new, y);
                if let Some(first) = parts.first_mut() {
                    let mut pts = transit::straight(lead_in, first.points[0], p.point_spacing);
                    pts.pop();
                    pts.extend(first.points.iter().copied());
                    first.points = pts;
                }
                if let Some(last) = parts.last_mut() {
                    let from = *last.points.last().unwrap_or(&lead_in);
                    let tail = transit::straight(from, world(start2, y2), p.point_spacing);
                    last.points.extend(tail.into_iter().skip(1));
                }
                let ok = parts.iter().all(|t| t.points.iter().all(clear));
                if ok || best.is_none() {
                    best = Some((parts, e_new, start2));
                }
                if ok {
                    break;
                }
            }
            let Some((parts, e_new, start2)) = best else {
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
    for (kind, direction, mut pts) in pieces {
        if pts.len() < 2 {
            continue;
        }
        if first {
            let cut = go_to(segments, at, &pts, cell);
            pts.drain(..cut);
            first = false;
        }
        let n = pts.len();
        let travel = vec_heading(&(pts[n - 1] - pts[n - 2]));
        let index = segments.len();
        segments.push(PlanSegment {
            kind,
            direction,
            index,
            cell,
            points: pts.clone(),
        });
        let heading = match direction {
            Direction::Forward => travel,
            Direction::Reverse => wrap_angle(travel + std::f64::consts::PI),
        };
        *at = Some((pts[n - 1], heading));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
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
}
