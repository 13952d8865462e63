//! Straight-line expansion trees (seed 004 ¶22–24, ¶44–49): a rough route between two poses
//! made of straight legs at right angles.
//!
//! From each endpoint a first leg runs along its heading (forward and backward, each kept when
//! the vehicle driving along it stays clear); from the end of every newest leg two legs run at
//! right angles to it, one to each side, kept when clear; beyond the seed, a third leg continues
//! straight on (with only right-angle children the legs alternate between two directions and
//! two trees on offset lattices often pass each other without meeting). The two trees grow a
//! level at a time
//! until a newest leg of one comes within `join_m` of a leg of the other (crossing legs are at
//! distance 0). Walking back from the two closest points to the roots gives the route.

use super::collision::{CollisionMap, Footprint};
use crate::geo::polygon::segment_distance;
use crate::geo::{cross, left_normal, v2, vec_heading, Pose, Vec2};
use std::collections::HashSet;

/// Limits of the expansion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExpansionParams {
    /// Length of every leg, m.
    pub step_m: f64,
    /// The trees are joined when legs of the two come this close, m.
    pub join_m: f64,
    /// Most levels grown per tree.
    pub max_depth: usize,
    /// Most legs per tree.
    pub max_legs: usize,
}

#[derive(Debug, Clone, Copy)]
struct Leg {
    a: Vec2,
    b: Vec2,
    parent: Option<usize>,
}

/// A rough route: the polyline from the start to the goal. `start_legs` of its legs belong to
/// the start's tree, the rest to the goal's.
#[derive(Debug, Clone, PartialEq)]
pub struct RoughRoute {
    pub points: Vec<Vec2>,
}

impl RoughRoute {
    /// The first leg (from the start), as (from, to).
    pub fn first_leg(&self) -> Option<(Vec2, Vec2)> {
        (self.points.len() >= 2).then(|| (self.points[0], self.points[1]))
    }
    /// The last leg (into the goal), as (from, to).
    pub fn last_leg(&self) -> Option<(Vec2, Vec2)> {
        let n = self.points.len();
        (n >= 2).then(|| (self.points[n - 2], self.points[n - 1]))
    }
}

/// Whether the vehicle driving straight from `a` to `b` (facing either way along the line)
/// stays clear, sampled every `spacing_m`.
pub fn leg_clear(map: &CollisionMap, fp: &Footprint, a: Vec2, b: Vec2, spacing_m: f64) -> bool {
    let d = b - a;
    let len = d.norm();
    if len < 1e-9 {
        return map.pose_clear(fp, &Pose::new(a.x, a.y, 0.0)).is_ok();
    }
    let n = (len / spacing_m).ceil().max(1.0) as usize;
    let h = vec_heading(&d);
    [h, h + std::f64::consts::PI].iter().any(|&heading| {
        (0..=n).all(|k| {
            let p = a + d * (k as f64 / n as f64);
            map.pose_clear(fp, &Pose::new(p.x, p.y, heading)).is_ok()
        })
    })
}

/// Drop route points where the route goes straight on, so each leg is a real change of
/// direction.
fn merge_collinear(points: Vec<Vec2>) -> Vec<Vec2> {
    let mut out: Vec<Vec2> = Vec::with_capacity(points.len());
    for p in points {
        if out.len() >= 2 {
            let (a, b) = (out[out.len() - 2], out[out.len() - 1]);
            let (u, v) = (b - a, p - b);
            if cross(&u, &v).abs() <= 1e-9 * u.norm() * v.norm() && u.dot(&v) > 0.0 {
                out.pop();
            }
        }
        out.push(p);
    }
    out
}

struct Tree {
    legs: Vec<Leg>,
    newest: Vec<usize>,
    /// Leg ends seen, with the leg's orientation (0 = mostly along x, 1 = along y).
    ends: HashSet<(i64, i64, bool)>,
}

impl Tree {
    fn new(root: &Pose, map: &CollisionMap, fp: &Footprint, p: &ExpansionParams, sp: f64) -> Self {
        let mut t = Tree {
            legs: Vec::new(),
            newest: Vec::new(),
            ends: HashSet::new(),
        };
        let dir = v2(root.heading.cos(), root.heading.sin());
        for s in [1.0, -1.0] {
            let b = root.pos + dir * (s * p.step_m);
            t.add(root.pos, b, None, map, fp, p, sp);
        }
        t
    }

    fn key(a: &Vec2, b: &Vec2, step: f64) -> (i64, i64, bool) {
        let c = 0.5 * step;
        let d = b - a;
        (
            (b.x / c).round() as i64,
            (b.y / c).round() as i64,
            d.x.abs() >= d.y.abs(),
        )
    }

    #[allow(clippy::too_many_arguments)]
    fn add(
        &mut self,
        a: Vec2,
        b: Vec2,
        parent: Option<usize>,
        map: &CollisionMap,
        fp: &Footprint,
        p: &ExpansionParams,
        sp: f64,
    ) {
        if self.legs.len() >= p.max_legs || !self.ends.insert(Self::key(&a, &b, p.step_m)) {
            return;
        }
        if leg_clear(map, fp, a, b, sp) {
            self.legs.push(Leg { a, b, parent });
            self.newest.push(self.legs.len() - 1);
        }
    }

    fn grow(&mut self, map: &CollisionMap, fp: &Footprint, p: &ExpansionParams, sp: f64) {
        let old = std::mem::take(&mut self.newest);
        for i in old {
            let leg = self.legs[i];
            let d = leg.b - leg.a;
            let n = left_normal(&d).normalize();
            for s in [1.0, -1.0] {
                self.add(leg.b, leg.b + n * (s * p.step_m), Some(i), map, fp, p, sp);
            }
            let on = d.normalize() * p.step_m;
            self.add(leg.b, leg.b + on, Some(i), map, fp, p, sp);
        }
    }

    /// Points from the root to `at` on leg `i`.
    fn route_to(&self, i: usize, at: Vec2) -> Vec<Vec2> {
        let mut pts = vec![at];
        let mut k = Some(i);
        while let Some(j) = k {
            pts.push(self.legs[j].a);
            k = self.legs[j].parent;
        }
        pts.reverse();
        pts
    }
}

/// Grow the two trees and return the rough route from `start` to `goal`, or `None` when they
/// do not meet within the limits. `spacing_m` is the collision sample spacing along legs.
pub fn rough_route(
    map: &CollisionMap,
    fp: &Footprint,
    start: &Pose,
    goal: &Pose,
    p: &ExpansionParams,
    spacing_m: f64,
) -> Option<RoughRoute> {
    let mut ts = Tree::new(start, map, fp, p, spacing_m);
    let mut tg = Tree::new(goal, map, fp, p, spacing_m);
    let mut fresh_s: Vec<usize> = ts.newest.clone();
    let mut fresh_g: Vec<usize> = tg.newest.clone();
    for _depth in 0..=p.max_depth {
        // Newest legs of each tree against every leg of the other.
        let mut best: Option<(f64, usize, usize, Vec2, Vec2)> = None;
        let mut consider = |i: usize, j: usize, ts: &Tree, tg: &Tree| {
            let (a, b) = (&ts.legs[i], &tg.legs[j]);
            let (d, pa, pb) = segment_distance(a.a, a.b, b.a, b.b);
            if d < p.join_m && best.as_ref().is_none_or(|x| d < x.0) {
                best = Some((d, i, j, pa, pb));
            }
        };
        for &i in &fresh_s {
            for j in 0..tg.legs.len() {
                consider(i, j, &ts, &tg);
            }
        }
        for &j in &fresh_g {
            for i in 0..ts.legs.len() {
                consider(i, j, &ts, &tg);
            }
        }
        if let Some((_, i, j, pa, pb)) = best {
            let mut points = ts.route_to(i, pa);
            let mut back = tg.route_to(j, pb);
            back.reverse();
            points.extend(back);
            points.dedup_by(|a, b| (*a - *b).norm() < 1e-9);
            return Some(RoughRoute {
                points: merge_collinear(points),
            });
        }
        if ts.newest.is_empty() && tg.newest.is_empty() {
            return None;
        }
        ts.grow(map, fp, p, spacing_m);
        tg.grow(map, fp, p, spacing_m);
        fresh_s = ts.newest.clone();
        fresh_g = tg.newest.clone();
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::maneuver::collision::tests::tractor_with_margin;

    fn fp() -> Footprint {
        tractor_with_margin(0.1)
    }

    fn params() -> ExpansionParams {
        ExpansionParams {
            step_m: 5.0,
            join_m: 0.5,
            max_depth: 8,
            max_legs: 400,
        }
    }

    #[test]
    fn route_goes_around_a_wall_with_right_angled_legs() {
        // A 40 × 30 yard with a wall from the south edge up to y = 20 between start and goal.
        let boundary = vec![v2(0.0, 0.0), v2(40.0, 0.0), v2(40.0, 30.0), v2(0.0, 30.0)];
        let wall = vec![v2(19.0, 0.0), v2(21.0, 0.0), v2(21.0, 20.0), v2(19.0, 20.0)];
        let map = CollisionMap::new(Some(boundary), vec![wall.clone()], 2.0).unwrap();
        let start = Pose::new(8.0, 5.0, std::f64::consts::FRAC_PI_2);
        let goal = Pose::new(32.0, 5.0, -std::f64::consts::FRAC_PI_2);
        let r = rough_route(&map, &fp(), &start, &goal, &params(), 0.3).expect("route");
        assert!((r.points[0] - start.pos).norm() < 1e-9);
        assert!((r.points[r.points.len() - 1] - goal.pos).norm() < 1e-9);
        // It must pass north of the wall, and every leg is clear.
        assert!(r.points.iter().any(|p| p.y > 21.0), "{:?}", r.points);
        for w in r.points.windows(2) {
            assert!(leg_clear(&map, &fp(), w[0], w[1], 0.3), "{w:?}");
        }
        // Legs at the goal: the first is along the goal heading.
        let (a, b) = r.last_leg().unwrap();
        assert!((b - goal.pos).norm() < 1e-9);
        assert!(
            (a.x - b.x).abs() < 1e-6,
            "last leg along the goal heading: {a:?}"
        );
    }

    #[test]
    fn collinear_points_merge_but_reversals_stay() {
        let pts = vec![
            v2(0.0, 0.0),
            v2(5.0, 0.0),
            v2(10.0, 0.0),
            v2(10.0, 5.0),
            v2(10.0, 2.0),
        ];
        assert_eq!(
            merge_collinear(pts),
            vec![v2(0.0, 0.0), v2(10.0, 0.0), v2(10.0, 5.0), v2(10.0, 2.0)]
        );
    }

    #[test]
    fn no_route_when_walled_off() {
        let boundary = vec![v2(0.0, 0.0), v2(40.0, 0.0), v2(40.0, 30.0), v2(0.0, 30.0)];
        let wall = vec![
            v2(19.0, -1.0),
            v2(21.0, -1.0),
            v2(21.0, 31.0),
            v2(19.0, 31.0),
        ];
        let map = CollisionMap::new(Some(boundary), vec![wall], 2.0).unwrap();
        let start = Pose::new(8.0, 5.0, 1.0);
        let goal = Pose::new(32.0, 5.0, -1.0);
        assert!(rough_route(&map, &fp(), &start, &goal, &params(), 0.3).is_none());
    }
}
