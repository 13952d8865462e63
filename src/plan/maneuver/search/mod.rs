//! The seed-004 manoeuvre planner (docs/METHODS.md, Search): endpoint checks, straight-line
//! expansion to a rough route, a reversing pattern at the goal chosen from the side the route
//! arrives from, and a hybrid-A* search with curve primitives and analytic connection for the rest.
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
//! The search machinery (primitives, nodes, open list, analytic connection, goal patterns) is
//! in `planner.rs`; this module runs the stages.
//!
//! Pure: no I/O, no clock. All limits are in [`ManeuverParams`] (the `[maneuver]` section).

mod planner;

use super::collision::{Blocked, CollisionMap, Footprint};
use super::expansion::{leg_clear, rough_route, ExpansionParams, RoughRoute};
use super::path::{CurvePath, CurveSegment};
use super::steering::Steering;
use crate::geo::{cross, heading_vec, vec_heading, wrap_angle, Direction, Pose, Vec2};
use planner::Planner;

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
mod tests;
