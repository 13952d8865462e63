//! Transits between cells, runs and headland passes: the shortest Dubins curve-straight-curve
//! (LSL, RSR, LSR, RSL) with radius r_min whose points keep clear of the field edge and the
//! obstacles, so every transit is driveable forward (curvature ≤ 1/r_min).

use crate::geo::{heading_vec, left_normal, wrap_angle, Vec2};
use std::f64::consts::TAU;

/// Points of the Dubins CSC path from (`p1`, heading `h1`) to (`p2`, heading `h2`) with turn
/// senses `s1`, `s2` (+1 left, −1 right), about `step` m apart (none unless `points`); `None`
/// when the word has no solution. Returns (length m, points).
#[allow(clippy::too_many_arguments)]
fn csc(
    p1: Vec2,
    h1: f64,
    p2: Vec2,
    h2: f64,
    s1: f64,
    s2: f64,
    r: f64,
    step: f64,
    points: bool,
) -> Option<(f64, Vec<Vec2>)> {
    let c1 = p1 + left_normal(&heading_vec(h1)) * (s1 * r);
    let c2 = p2 + left_normal(&heading_vec(h2)) * (s2 * r);
    let d = c2 - c1;
    let dist = d.norm();
    // Tangent direction of the straight.
    let theta = if s1 == s2 {
        if dist < 1e-9 {
            return None;
        }
        d.y.atan2(d.x)
    } else {
        if dist < 2.0 * r {
            return None;
        }
        let alpha = (2.0 * r / dist).asin();
        d.y.atan2(d.x) + s1 * alpha
    };
    let sweep = |from: f64, to: f64, s: f64| {
        let a = wrap_angle(to - from) * s;
        if a < -1e-9 {
            a + TAU
        } else {
            a.max(0.0)
        }
    };
    let a1 = sweep(h1, theta, s1);
    let a2 = sweep(theta, h2, s2);
    // Tangent points.
    let t1 = c1 - left_normal(&heading_vec(theta)) * (s1 * r);
    let t2 = c2 - left_normal(&heading_vec(theta)) * (s2 * r);
    let straight = (t2 - t1).norm();
    if (t2 - t1).dot(&heading_vec(theta)) < -1e-6 {
        return None;
    }
    let length = r * (a1 + a2) + straight;
    if !points {
        return Some((length, Vec::new()));
    }
    // Points evenly spaced along the exact curve (arc, straight, arc): every point lies on
    // the curve and the chords are all alike, so three-point curvature never reads more than
    // 1/r, even across the joins of the pieces.
    let n = (length / step).ceil().max(1.0) as usize;
    let (l1, l2) = (r * a1, r * a1 + straight);
    let on_arc = |c: Vec2, h0: f64, s: f64, along: f64| {
        c - left_normal(&heading_vec(h0 + s * along / r)) * (s * r)
    };
    let mut pts: Vec<Vec2> = (0..=n)
        .map(|k| {
            let at = length * k as f64 / n as f64;
            if at <= l1 {
                on_arc(c1, h1, s1, at)
            } else if at <= l2 {
                t1 + heading_vec(theta) * (at - l1)
            } else {
                on_arc(c2, theta, s2, at - l2)
            }
        })
        .collect();
    if let Some(last) = pts.last_mut() {
        *last = p2;
    }
    Some((length, pts))
}

/// Length of the shortest CSC curve from (`p1`, `h1`) to (`p2`, `h2`) with radius `r`, m.
pub fn csc_length(p1: Vec2, h1: f64, p2: Vec2, h2: f64, r: f64) -> Option<f64> {
    const WORDS: [(f64, f64); 4] = [(1.0, 1.0), (-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0)];
    WORDS
        .iter()
        .filter_map(|&(a, b)| csc(p1, h1, p2, h2, a, b, r, 1.0, false).map(|c| c.0))
        .min_by(f64::total_cmp)
}

/// The shortest CSC transit for which `clear` holds at every point, else the shortest one
/// (`false` second element).
pub fn transit(
    p1: Vec2,
    h1: f64,
    p2: Vec2,
    h2: f64,
    r: f64,
    step: f64,
    clear: &dyn Fn(&Vec2) -> bool,
) -> Option<(Vec<Vec2>, bool)> {
    const WORDS: [(f64, f64); 4] = [(1.0, 1.0), (-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0)];
    // Lengths first; points only for the words tried, shortest first.
    let mut words: Vec<(f64, (f64, f64))> = WORDS
        .iter()
        .filter_map(|&(a, b)| csc(p1, h1, p2, h2, a, b, r, step, false).map(|c| (c.0, (a, b))))
        .collect();
    words.sort_by(|a, b| a.0.total_cmp(&b.0));
    let points = |(a, b): (f64, f64)| csc(p1, h1, p2, h2, a, b, r, step, true).map(|c| c.1);
    for &(_, word) in &words {
        let pts = points(word)?;
        if pts.iter().all(clear) {
            return Some((pts, true));
        }
    }
    Some((points(words.first()?.1)?, false))
}

/// Clear waypoints on a square grid: the nodes of [`route_graph`].
#[derive(Debug, Clone)]
pub struct WaypointGrid {
    /// Position of node (0, 0), m.
    pub origin: Vec2,
    /// Node spacing, m.
    pub step: f64,
    pub nx: usize,
    pub ny: usize,
    /// Node (i, j) at `j * nx + i` is usable.
    pub usable: Vec<bool>,
}

impl WaypointGrid {
    /// Nodes every `step` m over the box `lo`–`hi` where `usable` holds; at most `max_nodes`
    /// (the step grows to fit).
    pub fn new(
        lo: Vec2,
        hi: Vec2,
        step: f64,
        max_nodes: usize,
        usable: &dyn Fn(&Vec2) -> bool,
    ) -> Self {
        let span = hi - lo;
        let step = step.max((span.x.max(0.0) * span.y.max(0.0) / max_nodes.max(1) as f64).sqrt());
        let nx = (span.x / step).floor().max(0.0) as usize + 1;
        let ny = (span.y / step).floor().max(0.0) as usize + 1;
        let mut grid = WaypointGrid {
            origin: lo,
            step,
            nx,
            ny,
            usable: vec![false; nx * ny],
        };
        for j in 0..ny {
            for i in 0..nx {
                grid.usable[j * nx + i] = usable(&grid.node(i, j));
            }
        }
        grid
    }

    /// Distance from every node to `goal` through usable nodes (8-neighbour moves), m;
    /// infinite where the goal cannot be reached. Nodes within `radius` of the goal start at
    /// their straight distance.
    fn distances_to(&self, goal: &Vec2, radius: f64) -> Vec<f64> {
        use std::cmp::Reverse;
        let mut dist = vec![f64::INFINITY; self.usable.len()];
        let mut heap = std::collections::BinaryHeap::new();
        let key = |d: f64| Reverse((d * 1000.0) as u64);
        for (k, q) in self.near(goal, radius) {
            dist[k] = (q - goal).norm();
            heap.push((key(dist[k]), k));
        }
        while let Some((Reverse(d), k)) = heap.pop() {
            if (d as f64) > dist[k] * 1000.0 + 1.0 {
                continue;
            }
            let (i, j) = ((k % self.nx) as i64, (k / self.nx) as i64);
            for (di, dj) in [
                (-1, -1),
                (-1, 0),
                (-1, 1),
                (0, -1),
                (0, 1),
                (1, -1),
                (1, 0),
                (1, 1),
            ] {
                let (a, b) = (i + di, j + dj);
                if a < 0 || b < 0 || a >= self.nx as i64 || b >= self.ny as i64 {
                    continue;
                }
                let n = b as usize * self.nx + a as usize;
                if !self.usable[n] {
                    continue;
                }
                let nd = dist[k] + self.step * ((di * di + dj * dj) as f64).sqrt();
                if nd < dist[n] {
                    dist[n] = nd;
                    heap.push((key(nd), n));
                }
            }
        }
        dist
    }

    fn node(&self, i: usize, j: usize) -> Vec2 {
        self.origin + Vec2::new(i as f64 * self.step, j as f64 * self.step)
    }

    /// Usable nodes within `radius` m of `p`: (index, position).
    fn near(&self, p: &Vec2, radius: f64) -> Vec<(usize, Vec2)> {
        let rel = (p - self.origin) / self.step;
        let reach = (radius / self.step).ceil() as i64;
        let (ci, cj) = (rel.x.round() as i64, rel.y.round() as i64);
        let mut out = Vec::new();
        for j in (cj - reach).max(0)..=(cj + reach).min(self.ny as i64 - 1) {
            for i in (ci - reach).max(0)..=(ci + reach).min(self.nx as i64 - 1) {
                let k = j as usize * self.nx + i as usize;
                let q = self.node(i as usize, j as usize);
                if self.usable[k] && (q - p).norm() <= radius {
                    out.push((k, q));
                }
            }
        }
        out
    }
}

/// Weight of the distance to go (through the grid) in the search's priority (> 1: fewer
/// states expanded, a transit at most about this factor longer than the best).
const HEURISTIC_WEIGHT: f64 = 1.5;

/// Headings tried at every waypoint.
const GRAPH_HEADINGS: usize = 8;

/// A clear transit through several waypoints: A* over (waypoint, heading) states joined by
/// clear CSC curves to the waypoints within two grid steps, from the start pose to the goal
/// pose; at most `max_expansions` states are expanded. `None` when no clear way was found.
#[allow(clippy::too_many_arguments)]
pub fn route_graph(
    p1: Vec2,
    h1: f64,
    p2: Vec2,
    h2: f64,
    r: f64,
    step: f64,
    clear: &dyn Fn(&Vec2) -> bool,
    grid: &WaypointGrid,
    max_expansions: usize,
) -> Option<Vec<Vec2>> {
    use std::cmp::Reverse;
    use std::collections::{BinaryHeap, HashMap};
    let heading = |k: usize| k as f64 * TAU / GRAPH_HEADINGS as f64;
    let reach = 2.0 * grid.step * std::f64::consts::SQRT_2 + 1e-6;
    // The heuristic: the distance to go through the grid (it knows the way around bays).
    let to_goal = grid.distances_to(&p2, 3.0 * grid.step);
    let pose = |s: usize| {
        (
            grid.node(s / GRAPH_HEADINGS % grid.nx, s / GRAPH_HEADINGS / grid.nx),
            heading(s % GRAPH_HEADINGS),
        )
    };
    let edge = |a: (Vec2, f64), b: (Vec2, f64)| -> Option<(f64, Vec<Vec2>)> {
        match transit(a.0, a.1, b.0, b.1, r, step, clear) {
            Some((pts, true)) => Some((crate::geo::polygon::polyline_length(&pts), pts)),
            _ => None,
        }
    };
    // States: waypoint index · GRAPH_HEADINGS + heading index; START is the start pose.
    const START: usize = usize::MAX;
    let key = |f: f64| Reverse((f * 1000.0) as u64);
    let mut best: HashMap<usize, (f64, usize)> = HashMap::new();
    let mut heap: BinaryHeap<(Reverse<u64>, usize)> = BinaryHeap::new();
    let relax = |from: usize,
                 from_cost: f64,
                 at: (Vec2, f64),
                 best: &mut HashMap<usize, (f64, usize)>,
                 heap: &mut BinaryHeap<(Reverse<u64>, usize)>| {
        for (k, q) in grid.near(&at.0, reach) {
            let dir = q - at.0;
            for hk in 0..GRAPH_HEADINGS {
                let h = heading(hk);
                // Only headings roughly along the way there.
                if dir.norm() > 1e-9 && wrap_angle(h - dir.y.atan2(dir.x)).abs() > 0.8 {
                    continue;
                }
                let s = k * GRAPH_HEADINGS + hk;
                if s == from {
                    continue;
                }
                let Some((len, _)) = edge(at, (q, h)) else {
                    continue;
                };
                let g = from_cost + len;
                if best.get(&s).is_none_or(|b| g < b.0) {
                    best.insert(s, (g, from));
                    let to_go = to_goal[k];
                    if to_go.is_finite() {
                        heap.push((key(g + HEURISTIC_WEIGHT * to_go), s));
                    }
                }
            }
        }
    };
    relax(START, 0.0, (p1, h1), &mut best, &mut heap);
    let mut done: HashMap<usize, ()> = HashMap::new();
    let mut expansions = 0;
    while let Some((_, s)) = heap.pop() {
        if done.insert(s, ()).is_some() {
            continue;
        }
        expansions += 1;
        if expansions > max_expansions {
            tracing::debug!(expansions, "no clear transit found through the waypoints");
            return None;
        }
        let g = best.get(&s).map(|b| b.0)?;
        let at = pose(s);
        if (p2 - at.0).norm() <= 3.0 * grid.step {
            if let Some((_, last)) = edge(at, (p2, h2)) {
                // Rebuild the chain of poses back to the start, then its curves.
                let mut chain = vec![s];
                while let Some(&(_, parent)) = best.get(chain.last()?) {
                    if parent == START {
                        break;
                    }
                    chain.push(parent);
                }
                chain.reverse();
                let mut pts = vec![p1];
                let mut from = (p1, h1);
                for &c in &chain {
                    let to = pose(c);
                    let (_, piece) = edge(from, to)?;
                    pts.extend(piece.into_iter().skip(1));
                    from = to;
                }
                pts.extend(last.into_iter().skip(1));
                tracing::debug!(
                    expansions,
                    waypoints = chain.len(),
                    "transit through waypoints"
                );
                return Some(pts);
            }
        }
        relax(s, g, at, &mut best, &mut heap);
    }
    None
}

/// A straight from `a` to `b` as points about `step` m apart.
pub fn straight(a: Vec2, b: Vec2, step: f64) -> Vec<Vec2> {
    let n = ((b - a).norm() / step).ceil().max(1.0) as usize;
    (0..=n)
        .map(|i| a + (b - a) * (i as f64 / n as f64))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;

    #[test]
    fn csc_ends_at_the_goal_with_bounded_curvature() {
        let (pts, ok) =
            transit(v2(0.0, 0.0), 0.0, v2(30.0, 20.0), 3.0, 6.0, 0.5, &|_| true).unwrap();
        assert!(ok);
        assert!((pts.last().unwrap() - v2(30.0, 20.0)).norm() < 1e-9);
        for w in pts.windows(3) {
            let (a, b, c) = (w[0], w[1], w[2]);
            let k = 2.0 * crate::geo::cross(&(b - a), &(c - b)).abs()
                / ((b - a).norm() * (c - b).norm() * (c - a).norm()).max(1e-12);
            assert!(k <= 1.0 / 6.0 * 1.02, "curvature {k}");
        }
        let end_dir = pts[pts.len() - 1] - pts[pts.len() - 2];
        assert!((end_dir.y.atan2(end_dir.x) - 3.0).abs() < 0.1);
    }
}
