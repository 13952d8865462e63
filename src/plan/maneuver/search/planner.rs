//! The hybrid-A* search itself: motion primitives precomputed once (samples and footprint
//! rectangles relative to their start), nodes on a duplicate-detection grid, the open list, the
//! analytic connection to the goal and the goal patterns. [`super::plan_maneuver`] drives it.

use super::ManeuverParams;
use crate::geo::{v2, wrap_angle, Direction, Pose, Vec2};
use crate::plan::maneuver::collision::CollisionMap;
use crate::plan::maneuver::path::{CurvePath, CurveSegment};
use crate::plan::maneuver::steering::Steering;
use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap, HashSet};

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

pub(super) struct Planner<'a, S: Steering> {
    map: &'a CollisionMap,
    steer: &'a S,
    p: &'a ManeuverParams,
    pub(super) spacing: f64,
    /// Largest distance of the footprint from the rear axle, m.
    radius: f64,
    prims: Vec<Primitive>,
    pub(super) expansions: usize,
}

impl<'a, S: Steering> Planner<'a, S> {
    pub(super) fn new(map: &'a CollisionMap, steer: &'a S, p: &'a ManeuverParams) -> Self {
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
    pub(super) fn path_clear(&self, path: &CurvePath) -> bool {
        self.map.path_clear(&self.p.footprint, path, self.spacing)
    }

    /// Cost of segments driven after a segment in `prev` direction.
    pub(super) fn cost(&self, segments: &[CurveSegment], mut prev: Option<Direction>) -> f64 {
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

    pub(super) fn key(&self, pose: &Pose) -> (i64, i64, i64) {
        let r = self.p.xy_resolution_m;
        let h = self.p.heading_resolution_rad;
        (
            (pose.pos.x / r).floor() as i64,
            (pose.pos.y / r).floor() as i64,
            ((wrap_angle(pose.heading) + std::f64::consts::PI) / h).round() as i64
                % ((std::f64::consts::TAU / h).round() as i64).max(1),
        )
    }

    pub(super) fn heuristic(&self, pose: &Pose, goal: &Pose) -> f64 {
        self.steer.distance(pose, goal)
    }

    pub(super) fn budget_left(&self) -> usize {
        self.p.max_expansions.saturating_sub(self.expansions)
    }

    /// Hybrid A* from `from` to `to`. Returns the path and its cost when one cheaper than
    /// `bound` is found.
    pub(super) fn search(
        &mut self,
        from: &Pose,
        to: &Pose,
        first_direction: Option<Direction>,
        bound: f64,
    ) -> Option<(CurvePath, f64)> {
        self.search_limited(from, to, first_direction, bound, usize::MAX)
    }

    /// [`Self::search`] that also stops when the expansion count reaches `stop_at`.
    pub(super) fn search_limited(
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
    pub(super) fn goal_pattern(
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
