//! The seed-004 manoeuvre planner (SPEC §4): endpoint checks, straight-line expansion to a
//! rough route, a reversing pattern at the goal chosen from the side the route arrives from,
//! and a hybrid-A* search with curve primitives and analytic connection for the rest.
//!
//! Stages, in order (each later one only when the earlier ones found nothing):
//! 1. **Endpoints.** The footprint at the start and at the goal must be clear; otherwise
//!    [`ManeuverError::Endpoint`] names the endpoint and why.
//! 2. **Direct.** The analytic connection start → goal, when it is clear.
//! 3. **Rough route** ([`rough_route`]), used by 4 and 6.
//! 4. **Goal pattern** (seed ¶51–60). The first two legs of the route at the goal say whether it
//!    arrives from the goal's left or right, and by how much it must turn (the angle between
//!    the second leg's direction of travel and the goal heading). Each configured pattern
//!    (written for an arrival from the left, e.g. `lrlr_pnpn`; mirrored l ↔ r for the right)
//!    splits that turn evenly over its curves; the pattern is laid back from the goal to its
//!    other end, and when its sweep is clear the search (5) runs from the start to that end.
//!    The pattern's curves are the same continuous-curvature turns as the primitives.
//! 5. **Hybrid A\*** from the start to the goal (Dolgov et al., "Practical search techniques in
//!    path planning for autonomous driving", 2008; primitives as in seed ¶34–36): from every node
//!    the primitive turns whose heading change steps by `heading_step` up to `primitive_max`
//!    either way, forward and reverse (a change of 0 is a straight of `straight_step_m`); cost =
//!    forward length + `reverse_penalty` × reverse length + `cusp_penalty_m` per change of
//!    direction; heuristic max(Euclidean, Reeds-Shepp length); duplicates merged on a coarse
//!    (x, y, heading) grid; every `analytic_every` expansions the analytic connection to the
//!    target is tried and, when clear, kept if it is the cheapest so far; the search goes on for
//!    `extra_expansions` more expansions (or until no open node can beat it) and returns the
//!    cheapest. When the pattern stage found a path, this search runs with that cost as a bound
//!    and replaces it only with a cheaper one, so a pattern's reversals are kept only when they
//!    pay (the seed takes the pattern unconditionally; a farmer would not want needless
//!    reversals in open ground).
//! 6. **Fallback** (seed ¶81–82): the search is retried between points along the route's first
//!    leg and points along its last leg (reached from the endpoints by straight driving along
//!    their headings).
//!
//! Budgets: every search counts towards `max_expansions`; a pattern's search stops after
//! `pattern_max_expansions`, the search of stage 5 after `search_max_expansions`, and the
//! fallback searches share what is left. Collision checks of primitives use rectangles
//! precomputed in the primitive's own frame (one rotation per node) and test the end first.
//!
//! Pure: no I/O, no clock. All limits are in [`ManeuverParams`] (the `[maneuver]` section).

use super::collision::{Blocked, CollisionMap, Footprint};
use super::expansion::{leg_clear, rough_route, ExpansionParams, RoughRoute};
use super::path::{CurvePath, CurveSegment};
use super::steering::Steering;
use crate::geo::{cross, heading_vec, v2, vec_heading, wrap_angle, Direction, Pose, Vec2};
use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap, HashSet};

/// Finest collision sample spacing along the rough route's legs, m. The legs are straight and
/// only a guide (everything the planner returns is checked at the full spacing), so a tiny
/// `sample_tolerance_m` does not make the rough route finer (and slower) than this.
const ROUGH_ROUTE_MIN_SPACING_M: f64 = 0.05;

/// Every tunable of the planner, SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct ManeuverParams {
    /// Vehicle (and implement) rectangle with the clearance margin.
    pub footprint: Footprint,
    /// Largest distance any footprint point moves between collision samples, m.
    pub sample_tolerance_m: f64,
    /// Cell of the collision map's broad-phase grid, m (for whoever builds the map).
    pub grid_cell_m: f64,
    /// Straight-line expansion limits.
    pub expansion: ExpansionParams,
    /// Goal-side reversing patterns for an arrival from the left (mirrored for the right),
    /// e.g. `lrlr_pnpn`; empty = no pattern stage.
    pub goal_patterns: Vec<String>,
    /// Heading-change step of the primitives, rad.
    pub heading_step_rad: f64,
    /// Largest heading change of a primitive, rad (≤ π).
    pub primitive_max_rad: f64,
    /// Length of the straight primitive, m.
    pub straight_step_m: f64,
    /// Reverse length is multiplied by this in the cost (≥ 1).
    pub reverse_penalty: f64,
    /// Cost of each change of driving direction, m.
    pub cusp_penalty_m: f64,
    /// Duplicate-detection grid: position cell, m, and heading cell, rad.
    pub xy_resolution_m: f64,
    pub heading_resolution_rad: f64,
    /// Most node expansions over all searches of one plan.
    pub max_expansions: usize,
    /// Most expansions of the search to one goal pattern's start.
    pub pattern_max_expansions: usize,
    /// Most expansions of the search straight to the goal (the rest of `max_expansions` is
    /// left for the fallback).
    pub search_max_expansions: usize,
    /// Try the analytic connection every this many expansions (1 = every one).
    pub analytic_every: usize,
    /// Expansions after the first solution spent looking for a cheaper one.
    pub extra_expansions: usize,
    /// Points per leg tried in the fallback stage.
    pub fallback_points: usize,
}

/// How a path was found.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// The analytic connection start → goal.
    Direct,
    /// Search to a goal pattern, then the pattern (its name as applied, e.g. `rlrl_pnpn`).
    Pattern(String),
    /// Hybrid-A* search straight to the goal.
    Search,
    /// Search between points on the rough route's first and last legs.
    Fallback,
}

/// The planner's answer.
#[derive(Debug, Clone, PartialEq)]
pub struct ManeuverResult {
    /// The path from the start pose, when found.
    pub path: Option<CurvePath>,
    pub method: Option<Method>,
    /// Node expansions over all searches.
    pub expansions: usize,
    /// The rough route of the straight-line expansion (empty when not needed or not found).
    pub rough_route: Vec<Vec2>,
    /// Why no path was found (`None` when found).
    pub failure: Option<String>,
    /// What each stage did, in order (for logs and the CLI's JSON).
    pub stages: Vec<String>,
}

/// Which endpoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Endpoint {
    Start,
    Goal,
}

impl std::fmt::Display for Endpoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Endpoint::Start => "start",
            Endpoint::Goal => "goal",
        })
    }
}

/// Why planning could not start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ManeuverError {
    #[error("{endpoint} pose is invalid: {reason}")]
    Endpoint { endpoint: Endpoint, reason: Blocked },
    #[error("{endpoint} pose is not finite")]
    NotFinite { endpoint: Endpoint },
    #[error("goal pattern `{0}`: expected curves of l/r, `_`, and as many directions p/n (e.g. lrlr_pnpn)")]
    BadPattern(String),
}

/// Parse a pattern like `lrlr_pnpn` into (curvature sign, direction) per curve.
pub fn parse_pattern(s: &str) -> Result<Vec<(f64, Direction)>, ManeuverError> {
    let bad = || ManeuverError::BadPattern(s.to_string());
    let (curves, dirs) = s.split_once('_').ok_or_else(bad)?;
    if curves.is_empty() || curves.len() != dirs.len() {
        return Err(bad());
    }
    curves
        .chars()
        .zip(dirs.chars())
        .map(|(c, d)| {
            let side = match c {
                'l' => 1.0,
                'r' => -1.0,
                _ => return Err(bad()),
            };
            let dir = match d {
                'p' => Direction::Forward,
                'n' => Direction::Reverse,
                _ => return Err(bad()),
            };
            Ok((side, dir))
        })
        .collect()
}

fn dir_sign(d: Direction) -> f64 {
    match d {
        Direction::Forward => 1.0,
        Direction::Reverse => -1.0,
    }
}

/// `local` (relative to the origin pose) placed at `at`.
fn compose(at: &Pose, local: &Pose) -> Pose {
    let (s, c) = at.heading.sin_cos();
    Pose::new(
        at.pos.x + c * local.pos.x - s * local.pos.y,
        at.pos.y + s * local.pos.x + c * local.pos.y,
        at.heading + local.heading,
    )
}

/// A precomputed primitive: its segments and its samples relative to the origin pose.
struct Primitive {
    segments: Vec<CurveSegment>,
    direction: Direction,
    length: f64,
    end: Pose,
    /// Per sample: the rear-axle position and the footprint's rectangles, relative to the
    /// primitive's start pose (placing them only needs one rotation per node).
    samples: Vec<(Vec2, Vec<[Vec2; 4]>)>,
}

#[derive(Debug, Clone, Copy)]
struct Node {
    pose: Pose,
    g: f64,
    parent: Option<usize>,
    primitive: usize,
    direction: Option<Direction>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Open {
    f: f64,
    node: usize,
    /// Whether `f` already uses the Reeds-Shepp heuristic (else only the Euclidean bound).
    refined: bool,
}
impl Eq for Open {}
impl Ord for Open {
    fn cmp(&self, o: &Self) -> Ordering {
        o.f.total_cmp(&self.f).then(o.node.cmp(&self.node))
    }
}
impl PartialOrd for Open {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

struct Planner<'a, S: Steering> {
    map: &'a CollisionMap,
    steer: &'a S,
    p: &'a ManeuverParams,
    spacing: f64,
    /// Largest distance of the footprint from the rear axle, m.
    radius: f64,
    prims: Vec<Primitive>,
    expansions: usize,
}

impl<'a, S: Steering> Planner<'a, S> {
    fn new(map: &'a CollisionMap, steer: &'a S, p: &'a ManeuverParams) -> Self {
        let spacing = p
            .footprint
            .sample_spacing_m(p.sample_tolerance_m, steer.kappa_max());
        let mut prims = Vec::new();
        let mut buf = Vec::new();
        let step = p.heading_step_rad.max(1e-3);
        let n = (p.primitive_max_rad / step + 1e-9).floor() as i64;
        for direction in [Direction::Forward, Direction::Reverse] {
            for k in -n..=n {
                let delta = k as f64 * step;
                let segments = steer.turn(delta, direction, p.straight_step_m);
                let path = CurvePath {
                    start: Pose::new(0.0, 0.0, 0.0),
                    segments,
                };
                path.sample(spacing, &mut buf);
                prims.push(Primitive {
                    length: path.length(),
                    end: path.end_pose(),
                    samples: buf
                        .iter()
                        .skip(1)
                        .map(|s| (s.pose.pos, p.footprint.rectangles(&s.pose)))
                        .collect(),
                    segments: path.segments,
                    direction,
                });
            }
        }
        Planner {
            map,
            steer,
            p,
            spacing,
            radius: p.footprint.max_corner_radius_m(),
            prims,
            expansions: 0,
        }
    }

    /// Whether the footprint stays clear along `path`, sampled every `spacing` (at most);
    /// stops at the first blocked sample ([`CollisionMap::path_clear`]).
    fn path_clear(&self, path: &CurvePath) -> bool {
        self.map.path_clear(&self.p.footprint, path, self.spacing)
    }

    /// Cost of segments driven after a segment in `prev` direction.
    fn cost(&self, segments: &[CurveSegment], mut prev: Option<Direction>) -> f64 {
        let mut c = 0.0;
        for s in segments.iter().filter(|s| s.length > 1e-9) {
            c += match s.direction {
                Direction::Forward => s.length,
                Direction::Reverse => self.p.reverse_penalty * s.length,
            };
            if prev.is_some_and(|d| d != s.direction) {
                c += self.p.cusp_penalty_m;
            }
            prev = Some(s.direction);
        }
        c
    }

    fn key(&self, pose: &Pose) -> (i64, i64, i64) {
        let r = self.p.xy_resolution_m;
        let h = self.p.heading_resolution_rad;
        (
            (pose.pos.x / r).floor() as i64,
            (pose.pos.y / r).floor() as i64,
            ((wrap_angle(pose.heading) + std::f64::consts::PI) / h).round() as i64
                % ((std::f64::consts::TAU / h).round() as i64).max(1),
        )
    }

    fn heuristic(&self, pose: &Pose, goal: &Pose) -> f64 {
        self.steer.distance(pose, goal)
    }

    fn budget_left(&self) -> usize {
        self.p.max_expansions.saturating_sub(self.expansions)
    }

    /// Hybrid A* from `from` to `to`. Returns the path and its cost when one cheaper than
    /// `bound` is found.
    fn search(
        &mut self,
        from: &Pose,
        to: &Pose,
        first_direction: Option<Direction>,
        bound: f64,
    ) -> Option<(CurvePath, f64)> {
        self.search_limited(from, to, first_direction, bound, usize::MAX)
    }

    /// [`Self::search`] that also stops when the expansion count reaches `stop_at`.
    fn search_limited(
        &mut self,
        from: &Pose,
        to: &Pose,
        first_direction: Option<Direction>,
        bound: f64,
        stop_at: usize,
    ) -> Option<(CurvePath, f64)> {
        let mut nodes = vec![Node {
            pose: *from,
            g: 0.0,
            parent: None,
            primitive: usize::MAX,
            direction: first_direction,
        }];
        let mut open = BinaryHeap::new();
        open.push(Open {
            f: self.heuristic(from, to),
            node: 0,
            refined: true,
        });
        let mut best_g: HashMap<(i64, i64, i64), f64> = HashMap::new();
        best_g.insert(self.key(from), 0.0);
        let mut closed: HashSet<(i64, i64, i64)> = HashSet::new();
        let mut best: Option<(usize, CurvePath, f64)> = None;
        let mut bound = bound;
        let mut since_found = 0usize;
        let mut placed: Vec<[Vec2; 4]> = Vec::with_capacity(2);
        let mut local = 0usize;
        while let Some(Open { f, node, refined }) = open.pop() {
            if f >= bound {
                break;
            }
            if !refined {
                // Lazy heuristic: children are queued with the Euclidean distance and get the
                // (dearer) Reeds-Shepp distance only when they reach the top; a larger value
                // sends them back into the queue.
                let g = nodes[node].g;
                let f2 = g + self.heuristic(&nodes[node].pose, to);
                if f2 > f + 1e-9 {
                    open.push(Open {
                        f: f2,
                        node,
                        refined: true,
                    });
                    continue;
                }
            }
            let n = nodes[node];
            let key = self.key(&n.pose);
            if !closed.insert(key) && node != 0 {
                continue;
            }
            if self.budget_left() == 0 || self.expansions >= stop_at {
                break;
            }
            self.expansions += 1;
            local += 1;
            if best.is_some() {
                since_found += 1;
                if since_found > self.p.extra_expansions {
                    break;
                }
            }
            if (local - 1) % self.p.analytic_every.max(1) == 0 {
                if let Some(conn) = self.steer.connect(&n.pose, to) {
                    let c = n.g + self.cost(&conn.segments, n.direction);
                    if c < bound && self.path_clear(&conn) {
                        bound = c;
                        best = Some((node, conn, c));
                    }
                }
            }
            let (sin, cos) = n.pose.heading.sin_cos();
            for (pi, prim) in self.prims.iter().enumerate() {
                let end = compose(&n.pose, &prim.end);
                let mut g = n.g + prim.length;
                if prim.direction == Direction::Reverse {
                    g += (self.p.reverse_penalty - 1.0) * prim.length;
                }
                if n.direction.is_some_and(|d| d != prim.direction) {
                    g += self.p.cusp_penalty_m;
                }
                let k = self.key(&end);
                if closed.contains(&k) || best_g.get(&k).is_some_and(|&b| b <= g) {
                    continue;
                }
                let h = (to.pos - end.pos).norm();
                if g + h >= bound {
                    continue;
                }
                let clear = prim.samples.iter().rev().all(|(pos, rects)| {
                    let at =
                        |v: &Vec2| n.pose.pos + v2(cos * v.x - sin * v.y, sin * v.x + cos * v.y);
                    placed.clear();
                    placed.extend(
                        rects
                            .iter()
                            .map(|r| [at(&r[0]), at(&r[1]), at(&r[2]), at(&r[3])]),
                    );
                    self.map
                        .placed_clear(&at(pos), self.radius, &placed)
                        .is_ok()
                });
                if !clear {
                    continue;
                }
                best_g.insert(k, g);
                nodes.push(Node {
                    pose: end,
                    g,
                    parent: Some(node),
                    primitive: pi,
                    direction: Some(prim.direction),
                });
                open.push(Open {
                    f: g + h,
                    node: nodes.len() - 1,
                    refined: false,
                });
            }
        }
        let (node, conn, cost) = best?;
        let mut chain = Vec::new();
        let mut k = Some(node);
        while let Some(i) = k {
            if nodes[i].parent.is_some() {
                chain.push(nodes[i].primitive);
            }
            k = nodes[i].parent;
        }
        chain.reverse();
        let mut segments: Vec<CurveSegment> = chain
            .iter()
            .flat_map(|&pi| self.prims[pi].segments.iter().copied())
            .collect();
        segments.extend(conn.segments);
        Some((
            CurvePath {
                start: *from,
                segments,
            },
            cost,
        ))
    }

    /// The goal pattern laid back from `goal`: its start pose and path, when clear.
    fn goal_pattern(
        &mut self,
        pattern: &[(f64, Direction)],
        mirror: bool,
        turn: f64,
        goal: &Pose,
    ) -> Option<CurvePath> {
        let delta = turn.abs() / pattern.len() as f64;
        let mut segments = Vec::new();
        for &(side, dir) in pattern {
            let side = if mirror { -side } else { side };
            // Heading change = curvature sign × driving-direction sign.
            let d = side * dir_sign(dir) * delta;
            segments.extend(self.steer.turn(d, dir, 0.0));
        }
        let rel = CurvePath {
            start: Pose::new(0.0, 0.0, 0.0),
            segments: segments.clone(),
        }
        .end_pose();
        // start ∘ rel = goal.
        let h = goal.heading - rel.heading;
        let (s, c) = h.sin_cos();
        let start = Pose::new(
            goal.pos.x - (c * rel.pos.x - s * rel.pos.y),
            goal.pos.y - (s * rel.pos.x + c * rel.pos.y),
            h,
        );
        let path = CurvePath { start, segments };
        self.path_clear(&path).then_some(path)
    }
}

/// The side the rough route arrives from at the goal and the heading change it implies: the
/// goal heading minus the direction of travel along the route's second leg from the goal
/// (+ = arriving from the goal's left, turning left into it). `None` when the route has a
/// single leg at the goal and the start lies on the goal's line.
pub fn approach_turn(route: &RoughRoute, goal: &Pose) -> Option<f64> {
    let n = route.points.len();
    let from = if n >= 3 {
        route.points[n - 3]
    } else {
        *route.points.first()?
    };
    let side = cross(&heading_vec(goal.heading), &(from - goal.pos));
    if side.abs() < 1e-6 {
        return None;
    }
    let mut turn = std::f64::consts::FRAC_PI_2;
    if n >= 3 {
        let travel = vec_heading(&(route.points[n - 2] - from));
        // The first leg may be driven forward or in reverse: fold into [0, π/2].
        let t = wrap_angle(goal.heading - travel).abs();
        let t = t.min(std::f64::consts::PI - t);
        if t > 1e-6 {
            turn = t;
        }
    }
    Some(side.signum() * turn)
}

/// Plan a manoeuvre from `start` to `goal` on `map` with `steer` (see the module docs).
pub fn plan_maneuver<S: Steering>(
    map: &CollisionMap,
    steer: &S,
    p: &ManeuverParams,
    start: &Pose,
    goal: &Pose,
) -> Result<ManeuverResult, ManeuverError> {
    for (endpoint, pose) in [(Endpoint::Start, start), (Endpoint::Goal, goal)] {
        if !(pose.pos.x.is_finite() && pose.pos.y.is_finite() && pose.heading.is_finite()) {
            return Err(ManeuverError::NotFinite { endpoint });
        }
        map.pose_clear(&p.footprint, pose)
            .map_err(|reason| ManeuverError::Endpoint { endpoint, reason })?;
    }
    let patterns = p
        .goal_patterns
        .iter()
        .map(|s| parse_pattern(s).map(|pat| (s.clone(), pat)))
        .collect::<Result<Vec<_>, _>>()?;
    let mut pl = Planner::new(map, steer, p);
    let mut stages = Vec::new();
    let found = |path: CurvePath,
                 method: Method,
                 pl: &Planner<S>,
                 route: Vec<Vec2>,
                 stages: Vec<String>| {
        tracing::debug!(
            ?method,
            expansions = pl.expansions,
            ?stages,
            "manoeuvre found"
        );
        ManeuverResult {
            path: Some(path),
            method: Some(method),
            expansions: pl.expansions,
            rough_route: route,
            failure: None,
            stages,
        }
    };
    // 2. Direct connection.
    match steer.connect(start, goal) {
        Some(direct) if pl.path_clear(&direct) => {
            stages.push("direct: clear".into());
            return Ok(found(direct, Method::Direct, &pl, Vec::new(), stages));
        }
        Some(_) => stages.push("direct: blocked".into()),
        None => stages.push("direct: no connection".into()),
    }
    // 3. Rough route.
    let route = rough_route(
        map,
        &p.footprint,
        start,
        goal,
        &p.expansion,
        pl.spacing.max(ROUGH_ROUTE_MIN_SPACING_M),
    );
    let route_pts = route.as_ref().map(|r| r.points.clone()).unwrap_or_default();
    stages.push(match &route {
        Some(r) => format!("rough route: {} legs", r.points.len().saturating_sub(1)),
        None => "rough route: none".into(),
    });
    // 4. Goal pattern, then 5. the plain search with the pattern's cost as a bound.
    let mut best: Option<(CurvePath, f64, Method)> = None;
    if let Some(turn) = route.as_ref().and_then(|r| approach_turn(r, goal)) {
        if turn.abs() > p.heading_step_rad * 0.5 {
            for (name, pat) in &patterns {
                let mirror = turn < 0.0;
                let applied: String = if mirror {
                    name.chars()
                        .map(|ch| match ch {
                            'l' => 'r',
                            'r' => 'l',
                            other => other,
                        })
                        .collect()
                } else {
                    name.clone()
                };
                let Some(tail) = pl.goal_pattern(pat, mirror, turn, goal) else {
                    stages.push(format!(
                        "pattern {applied} ({:.0}°): blocked",
                        turn.to_degrees()
                    ));
                    continue;
                };
                let before = pl.expansions;
                let budget = before.saturating_add(p.pattern_max_expansions);
                match pl.search_limited(start, &tail.start, None, f64::INFINITY, budget) {
                    Some((head, c)) => {
                        let last = head.segments.iter().rev().find(|s| s.length > 1e-9);
                        let total = c + pl.cost(&tail.segments, last.map(|s| s.direction));
                        stages.push(format!(
                            "pattern {applied} ({:.0}°): found, cost {total:.1} m, {} expansions",
                            turn.to_degrees(),
                            pl.expansions - before
                        ));
                        best = Some((head.then(tail), total, Method::Pattern(applied)));
                        break;
                    }
                    None => stages.push(format!(
                        "pattern {applied} ({:.0}°): no search to its start in {} expansions",
                        turn.to_degrees(),
                        pl.expansions - before
                    )),
                }
            }
        } else {
            stages.push("pattern: the route arrives straight".into());
        }
    }
    let bound = best.as_ref().map_or(f64::INFINITY, |b| b.1);
    let before = pl.expansions;
    let stop_at = before.saturating_add(p.search_max_expansions);
    match pl.search_limited(start, goal, None, bound, stop_at) {
        Some((path, c)) if c < bound => {
            stages.push(format!(
                "search: found, cost {c:.1} m, {} expansions",
                pl.expansions - before
            ));
            best = Some((path, c, Method::Search));
        }
        _ => stages.push(format!(
            "search: nothing{} in {} expansions",
            if bound.is_finite() { " cheaper" } else { "" },
            pl.expansions - before
        )),
    }
    if let Some((path, _, method)) = best {
        return Ok(found(path, method, &pl, route_pts, stages));
    }
    // 6. Fallback along the first and last legs.
    if let Some(r) = &route {
        if let (Some((s0, s1)), Some((g0, g1))) = (r.first_leg(), r.last_leg()) {
            let k = p.fallback_points.max(1);
            let along = |a: Vec2, b: Vec2, i: usize| a + (b - a) * (i as f64 / k as f64);
            'outer: for i in 1..=k {
                let ps = along(s0, s1, i);
                for j in 0..k {
                    if pl.budget_left() == 0 {
                        break 'outer;
                    }
                    let pg = along(g0, g1, j);
                    let from = Pose::new(ps.x, ps.y, start.heading);
                    let to = Pose::new(pg.x, pg.y, goal.heading);
                    let lead = straight(start, &from);
                    let trail = straight(&to, goal);
                    if !leg_clear(map, &p.footprint, start.pos, ps, pl.spacing)
                        || !pl.path_clear(&lead)
                        || !pl.path_clear(&trail)
                    {
                        continue;
                    }
                    let first_dir = lead.segments.first().map(|s| s.direction);
                    if let Some((mid, _)) = pl.search(&from, &to, first_dir, f64::INFINITY) {
                        let path = lead.then(mid).then(trail);
                        stages.push(format!("fallback: found from leg point {i} to {j}"));
                        return Ok(found(path, Method::Fallback, &pl, route_pts, stages));
                    }
                }
            }
        }
    }
    let mut failure = if pl.budget_left() == 0 {
        format!("search budget of {} expansions used up", p.max_expansions)
    } else {
        format!(
            "no collision-free path found ({} expansions)",
            pl.expansions
        )
    };
    if route.is_none() {
        failure.push_str("; the straight-line expansion found no route either");
    }
    stages.push("fallback: nothing".into());
    Ok(ManeuverResult {
        path: None,
        method: None,
        expansions: pl.expansions,
        rough_route: route_pts,
        failure: Some(failure),
        stages,
    })
}

/// A straight drive from `a` to `b` (same heading): forward when `b` lies ahead.
fn straight(a: &Pose, b: &Pose) -> CurvePath {
    let d = b.pos - a.pos;
    let ahead = d.dot(&heading_vec(a.heading));
    let direction = if ahead >= 0.0 {
        Direction::Forward
    } else {
        Direction::Reverse
    };
    let length = d.norm();
    CurvePath {
        start: *a,
        segments: if length > 1e-9 {
            vec![CurveSegment::line(direction, length)]
        } else {
            Vec::new()
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::geo::rect;
    use crate::geo::v2;
    use crate::plan::maneuver::steering::RsSteering;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn params() -> ManeuverParams {
        Config::default().maneuver_params()
    }

    const RS: RsSteering = RsSteering { r_min_m: 5.0 };

    fn assert_clear(map: &CollisionMap, p: &ManeuverParams, path: &CurvePath) {
        let mut s = Vec::new();
        path.sample(0.02, &mut s);
        let mut bare = p.footprint;
        bare.margin_m = 0.0;
        for smp in &s {
            assert_eq!(map.pose_clear(&bare, &smp.pose), Ok(()), "at s = {}", smp.s);
        }
    }

    #[test]
    fn free_space_is_one_direct_connection() {
        let r = plan_maneuver(
            &CollisionMap::free(),
            &RS,
            &params(),
            &Pose::new(0.0, 0.0, 0.0),
            &Pose::new(30.0, 10.0, FRAC_PI_2),
        )
        .unwrap();
        assert_eq!(r.method, Some(Method::Direct));
        assert_eq!(r.expansions, 0);
        let end = r.path.unwrap().end_pose();
        assert!((end.pos - v2(30.0, 10.0)).norm() < 1e-6);
    }

    #[test]
    fn invalid_endpoints_are_named() {
        let map = CollisionMap::new(
            Some(rect(0.0, 0.0, 50.0, 20.0)),
            vec![rect(30.0, 5.0, 35.0, 15.0)],
            2.0,
        )
        .unwrap();
        let p = params();
        let ok = Pose::new(5.0, 10.0, 0.0);
        let e = plan_maneuver(&map, &RS, &p, &Pose::new(49.0, 10.0, 0.0), &ok).unwrap_err();
        assert_eq!(
            e,
            ManeuverError::Endpoint {
                endpoint: Endpoint::Start,
                reason: Blocked::OutsideBoundary
            }
        );
        let e = plan_maneuver(&map, &RS, &p, &ok, &Pose::new(31.0, 10.0, 0.0)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "goal pose is invalid: the vehicle touches obstacle 0"
        );
        let e = plan_maneuver(&map, &RS, &p, &ok, &Pose::new(f64::NAN, 1.0, 0.0)).unwrap_err();
        assert_eq!(
            e,
            ManeuverError::NotFinite {
                endpoint: Endpoint::Goal
            }
        );
    }

    #[test]
    fn corridor_u_turn_needs_reversing_and_stays_clear() {
        let map = CollisionMap::new(Some(rect(0.0, 0.0, 60.0, 12.0)), vec![], 2.0).unwrap();
        let p = params();
        let (start, goal) = (Pose::new(20.0, 3.5, 0.0), Pose::new(20.0, 8.5, PI));
        let r = plan_maneuver(&map, &RS, &p, &start, &goal).unwrap();
        let path = r.path.expect("found");
        assert!(path.cusps() >= 1, "a forward U-turn does not fit");
        let end = path.end_pose();
        assert!((end.pos - goal.pos).norm() < 1e-6);
        assert!(wrap_angle(end.heading - goal.heading).abs() < 1e-6);
        assert_clear(&map, &p, &path);
        // The same turn in an open yard needs no search at all.
        let open = CollisionMap::new(Some(rect(0.0, -30.0, 60.0, 42.0)), vec![], 2.0).unwrap();
        let r2 = plan_maneuver(&open, &RS, &p, &start, &goal).unwrap();
        assert_eq!(r2.method, Some(Method::Direct));
    }

    #[test]
    fn walled_off_goal_is_not_found_and_says_why() {
        let map = CollisionMap::new(
            Some(rect(0.0, 0.0, 60.0, 20.0)),
            vec![rect(29.0, -1.0, 31.0, 21.0)],
            2.0,
        )
        .unwrap();
        let mut p = params();
        p.max_expansions = 300;
        let r = plan_maneuver(
            &map,
            &RS,
            &p,
            &Pose::new(10.0, 10.0, 0.0),
            &Pose::new(50.0, 10.0, 0.0),
        )
        .unwrap();
        assert!(r.path.is_none());
        assert!(r.expansions > 0 && r.expansions <= 300);
        let why = r.failure.unwrap();
        assert!(why.contains("expansions"), "{why}");
    }

    #[test]
    fn fallback_searches_between_the_first_and_last_legs() {
        // The bay of tools/maneuvers with the direct search cut to one expansion and no
        // patterns: only the fallback can find the way, and its path is clear and exact.
        let mut boundary = vec![
            v2(0.0, 0.0),
            v2(50.0, 0.0),
            v2(50.0, 9.0),
            v2(26.6, 9.0),
            v2(26.6, 16.0),
            v2(23.0, 16.0),
            v2(23.0, 9.0),
            v2(0.0, 9.0),
        ];
        crate::geo::polygon::make_ccw(&mut boundary);
        let map = CollisionMap::new(Some(boundary), vec![], 2.0).unwrap();
        let mut p = params();
        p.goal_patterns.clear();
        p.search_max_expansions = 1;
        let (start, goal) = (Pose::new(5.0, 4.5, 0.0), Pose::new(24.8, 13.8, -FRAC_PI_2));
        let r = plan_maneuver(&map, &RS, &p, &start, &goal).unwrap();
        assert_eq!(r.method, Some(Method::Fallback), "{:?}", r.stages);
        let path = r.path.unwrap();
        let end = path.end_pose();
        assert!((end.pos - goal.pos).norm() < 1e-6);
        assert!(wrap_angle(end.heading - goal.heading).abs() < 1e-6);
        assert!((path.start.pos - start.pos).norm() < 1e-12);
        assert_clear(&map, &p, &path);
        assert!(r.stages.iter().any(|s| s.starts_with("fallback: found")));
    }

    #[test]
    fn patterns_parse_and_are_laid_back_onto_the_goal() {
        assert_eq!(
            parse_pattern("lrlr_pnpn").unwrap(),
            vec![
                (1.0, Direction::Forward),
                (-1.0, Direction::Reverse),
                (1.0, Direction::Forward),
                (-1.0, Direction::Reverse)
            ]
        );
        for bad in ["lrl_pn", "lsl_pnp", "lr", "_", "lr_px"] {
            assert!(parse_pattern(bad).is_err(), "{bad}");
        }
        let map = CollisionMap::free();
        let p = params();
        let mut pl = Planner::new(&map, &RS, &p);
        let goal = Pose::new(3.0, -2.0, 0.4);
        let pat = parse_pattern("lrlr_pnpn").unwrap();
        for (mirror, sign) in [(false, 1.0), (true, -1.0)] {
            let path = pl
                .goal_pattern(&pat, mirror, sign * FRAC_PI_2, &goal)
                .unwrap();
            let end = path.end_pose();
            assert!((end.pos - goal.pos).norm() < 1e-6, "{end:?}");
            assert!(wrap_angle(end.heading - goal.heading).abs() < 1e-9);
            // lrlr_pnpn turns the vehicle left (CCW) by the whole turn; mirrored, right.
            assert!(
                (wrap_angle(goal.heading - path.start.heading) - sign * FRAC_PI_2).abs() < 1e-9
            );
            assert_eq!(path.cusps(), 3);
        }
    }

    #[test]
    fn approach_side_from_the_route() {
        let goal = Pose::new(0.0, 0.0, FRAC_PI_2);
        // Route comes from the west (the goal's left when heading north), then runs north.
        let left = RoughRoute {
            points: vec![v2(-20.0, -5.0), v2(0.0, -5.0), v2(0.0, 0.0)],
        };
        assert!((approach_turn(&left, &goal).unwrap() - FRAC_PI_2).abs() < 1e-9);
        let right = RoughRoute {
            points: vec![v2(20.0, -5.0), v2(0.0, -5.0), v2(0.0, 0.0)],
        };
        assert!((approach_turn(&right, &goal).unwrap() + FRAC_PI_2).abs() < 1e-9);
        let straight = RoughRoute {
            points: vec![v2(0.0, -9.0), v2(0.0, 0.0)],
        };
        assert_eq!(approach_turn(&straight, &goal), None);
    }
}
