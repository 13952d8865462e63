//! The distance to go of the waypoint search of [`super::transit::route_graph`]: the shortest
//! way from each grid node to the goal through the usable nodes, as the crow flies between
//! neighbours.
//!
//! Two such distances are kept. The open one joins every two neighbouring usable nodes: it
//! tells which nodes can reach the goal at all (a node it cannot is never used, and the
//! failed searches' closed sets are built on it, see [`super::closed`]). The one the search
//! steers by joins two neighbours only when the straight between them is clear: the open one
//! steps across a boundary notch or a strip narrower than the grid's step as if it were not
//! there, so a goal 20 m away across a slot looked 20 m away from every state on the near side,
//! and the search expanded every state cheaper than the 800 m way round the slot's end
//! (de_bb_concave, dk_marker_strip) before it went that way.

use super::transit::WaypointGrid;
use crate::geo::Vec2;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// The neighbour steps (di, dj) of the distance to steer by: the eight neighbours and the
/// eight a knight's move away; step `d` and step `15 - d` are opposite.
const STEPS: [(i64, i64); 16] = [
    (-2, -1),
    (-2, 1),
    (-1, -2),
    (-1, -1),
    (-1, 0),
    (-1, 1),
    (-1, 2),
    (0, -1),
    (0, 1),
    (1, -2),
    (1, -1),
    (1, 0),
    (1, 1),
    (1, 2),
    (2, -1),
    (2, 1),
];

/// The eight neighbours of the open distance (indices into [`STEPS`]).
const EIGHT: [usize; 8] = [3, 4, 5, 7, 8, 10, 11, 12];
const ALL: [usize; 16] = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15];

/// Per node and step ([`STEPS`]): the length of the way to the neighbour the distance to
/// steer by takes (see [`WaypointGrid::link`]); NaN until asked, infinite when there is none.
pub(super) type Links = Vec<[f32; 16]>;

/// Where a link whose straight is not clear may bend: at these fractions of its length off
/// its midpoint, to either side.
const BENDS: [f64; 3] = [0.15, 0.3, 0.5];

impl WaypointGrid<'_> {
    /// The way from node `k` to its neighbour `n` (step `d`) by clear straights: the straight
    /// when it is clear, else the shortest of two straights through a point off its midpoint
    /// (a neck the straight clips, round a corner the curves bend round); `None` when neither
    /// is. Found once per grid (both ways).
    fn link(&self, k: usize, n: usize, d: usize) -> Option<f64> {
        let known = self.links.borrow().get(k).map_or(f32::NAN, |l| l[d]);
        if !known.is_nan() {
            return known.is_finite().then_some(f64::from(known));
        }
        let (a, b) = (self.node_at(k), self.node_at(n));
        let length = if self.segment_clear(a, b) {
            Some((b - a).norm())
        } else {
            let mid = (a + b) * 0.5;
            let across = crate::geo::left_normal(&(b - a));
            BENDS
                .iter()
                .flat_map(|&f| [f, -f])
                .map(|f| mid + across * f)
                .find(|m| (self.clear)(m) && self.segment_clear(a, *m) && self.segment_clear(*m, b))
                .map(|m| (m - a).norm() + (b - m).norm())
        };
        let value = length.map_or(f32::INFINITY, |l| l as f32);
        let mut links = self.links.borrow_mut();
        if let Some(l) = links.get_mut(k) {
            l[d] = value;
        }
        if let Some(l) = links.get_mut(n) {
            l[15 - d] = value;
        }
        length
    }

    /// Is the straight from `a` to `b` clear at points at most the probe spacing apart (the
    /// ends not checked)?
    fn segment_clear(&self, a: Vec2, b: Vec2) -> bool {
        let m = ((b - a).norm() / self.probe).ceil().max(1.0) as usize;
        (1..m).all(|t| (self.clear)(&(a + (b - a) * (t as f64 / m as f64))))
    }

    fn node_at(&self, k: usize) -> Vec2 {
        self.node(k % self.nx, k / self.nx)
    }

    /// The open distances to `goal` through usable nodes (every two neighbours joined), m;
    /// infinite where the goal cannot be reached. Nodes within `radius` of the goal start at
    /// their straight distance.
    pub(super) fn open_distances(&self, goal: &Vec2, radius: f64) -> Vec<f64> {
        let mut open = Dijkstra::new(self, &self.near(goal, radius), goal, false);
        while open.step(self) {}
        open.dist
    }

    /// The distances to steer by ([`Self::open_distances`] through clear straights only):
    /// the nodes within `radius` of the goal whose straight to it is clear start at their
    /// straight distance (all of them when none is clear). Found as far as asked
    /// ([`Steer::at`]): a short detour's search asks only the nodes near it.
    pub(super) fn steer_distances(&self, goal: &Vec2, radius: f64) -> Steer {
        let near = self.near(goal, radius);
        let seen: Vec<(usize, Vec2)> = near
            .iter()
            .copied()
            .filter(|(_, q)| self.segment_clear(*q, *goal))
            .collect();
        let seeds = if seen.is_empty() { &near } else { &seen };
        Steer(Dijkstra::new(self, seeds, goal, true))
    }
}

/// The distances to steer by of one search ([`WaypointGrid::steer_distances`]).
pub(super) struct Steer(Dijkstra);

impl Steer {
    /// The distance to steer by from node `k`, m; where it finds no way, `open` (the node's
    /// open distance).
    pub(super) fn at(&mut self, grid: &WaypointGrid, k: usize, open: f64) -> f64 {
        let d = self.0.settled(grid, k);
        if d.is_finite() {
            d
        } else {
            open
        }
    }
}

/// A Dijkstra search from the goal's nodes over the usable nodes, run as far as asked.
struct Dijkstra {
    dist: Vec<f64>,
    heap: BinaryHeap<(Reverse<u64>, usize)>,
    /// Through the neighbours whose straight is clear (else through every neighbour).
    straight: bool,
}

/// The queue's key of a distance (mm).
fn key(d: f64) -> Reverse<u64> {
    Reverse((d * 1000.0) as u64)
}

impl Dijkstra {
    /// From `seeds` at their straight distances to `goal`.
    fn new(grid: &WaypointGrid, seeds: &[(usize, Vec2)], goal: &Vec2, straight: bool) -> Self {
        let mut dist = vec![f64::INFINITY; grid.node_count()];
        let mut heap = BinaryHeap::new();
        for &(k, q) in seeds {
            dist[k] = (q - goal).norm();
            heap.push((key(dist[k]), k));
        }
        Dijkstra {
            dist,
            heap,
            straight,
        }
    }

    /// The distance of node `k`, the search run until no node left in its queue can shorten
    /// it (every move is at least a grid step); infinite when none reaches it.
    fn settled(&mut self, grid: &WaypointGrid, k: usize) -> f64 {
        loop {
            let d = self.dist.get(k).copied().unwrap_or(f64::INFINITY);
            let next = self.heap.peek().map(|e| e.0 .0);
            match next {
                Some(q) if d.is_infinite() || (q as f64) < (d - grid.step) * 1000.0 + 1.0 => {
                    self.step(grid);
                }
                _ => return d,
            }
        }
    }

    /// Settle the next node of the queue; `false` when the queue is empty.
    fn step(&mut self, grid: &WaypointGrid) -> bool {
        let Some((Reverse(d), k)) = self.heap.pop() else {
            return false;
        };
        let dist = &mut self.dist;
        if (d as f64) > dist[k] * 1000.0 + 1.0 {
            return true;
        }
        let (i, j) = ((k % grid.nx) as i64, (k / grid.nx) as i64);
        let dirs: &[usize] = if self.straight { &ALL } else { &EIGHT };
        for &dir in dirs {
            let (di, dj) = STEPS[dir];
            let Some(n) = grid.index(i + di, j + dj) else {
                continue;
            };
            if !grid.usable(n) {
                continue;
            }
            let step = grid.step * ((di * di + dj * dj) as f64).sqrt();
            if dist[k] + step >= dist[n] {
                continue;
            }
            let length = if self.straight {
                match grid.link(k, n, dir) {
                    Some(l) => l,
                    None => continue,
                }
            } else {
                step
            };
            let nd = dist[k] + length;
            if nd < dist[n] {
                dist[n] = nd;
                self.heap.push((key(nd), n));
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use crate::geo::polygon::{contains_point, point_segment_distance};
    use crate::geo::{v2, Vec2};
    use crate::plan::coverage::transit::WaypointGrid;

    /// A 200 × 100 m field with a slot 2 m wide cut 80 m up from its bottom edge between the
    /// grid's columns at x 90 and 100 m, clear 1.5 m from the edges: from the node left of the
    /// slot the goal just right of it is 7 m away for the open distance and round the slot's
    /// end for the one to steer by.
    #[test]
    fn the_distance_to_steer_by_goes_round_a_slot() {
        let boundary = [
            v2(0.0, 0.0),
            v2(92.0, 0.0),
            v2(92.0, 80.0),
            v2(94.0, 80.0),
            v2(94.0, 0.0),
            v2(200.0, 0.0),
            v2(200.0, 100.0),
            v2(0.0, 100.0),
        ];
        let half = 1.5;
        let clear = |q: &Vec2| {
            let n = boundary.len();
            contains_point(&boundary, q)
                && (0..n).all(|i| {
                    point_segment_distance(q, &boundary[i], &boundary[(i + 1) % n]) >= half
                })
        };
        let grid = WaypointGrid::new(
            v2(0.0, 0.0),
            v2(200.0, 100.0),
            10.0,
            20_000,
            &clear,
            (half, None),
        );
        // Goal just right of the slot, 20 m up; the node left of it at (90, 20).
        let goal = v2(97.0, 20.0);
        let open = grid.open_distances(&goal, 30.0);
        let mut steer = grid.steer_distances(&goal, 30.0);
        let k = 2 * grid.nx + 9;
        assert!((grid.node(9, 2) - v2(90.0, 20.0)).norm() < 1e-9);
        assert!((open[k] - 7.0).abs() < 1e-9, "open {}", open[k]);
        // Round the slot's end (y ≥ 81.5): about 2 × 62 m up and down.
        let round = steer.at(&grid, k, open[k]);
        assert!(round > 120.0 && round < 170.0, "steer {round}");
        // Nodes on the goal's side see it straight.
        let right = 2 * grid.nx + 10;
        assert!((steer.at(&grid, right, open[right]) - open[right]).abs() < 1e-9);
    }
}
