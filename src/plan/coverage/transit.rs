//! Transits between cells, runs and headland passes: the shortest Dubins curve-straight-curve
//! (LSL, RSR, LSR, RSL) with radius r_min whose points keep clear of the field edge and the
//! obstacles, so every transit is driveable forward (curvature ≤ 1/r_min).

use super::closed::{CheckedEdges, ClosedSets};
use super::edges::{
    arrival_headings, graph_heading, EdgeTable, EdgeWord, EDGE_REACH, EDGE_SPAN, GRAPH_HEADINGS,
};
use crate::geo::{heading_vec, left_normal, wrap_angle, Vec2};
use std::cell::RefCell;
use std::f64::consts::TAU;
use std::rc::Rc;

#[path = "finish.rs"]
mod finish;
#[path = "free.rs"]
mod free;

/// One Dubins CSC curve: arc about `c1`, straight from `t1` along `theta`, arc about `c2`.
pub(super) struct Csc {
    c1: Vec2,
    c2: Vec2,
    h1: f64,
    s1: f64,
    s2: f64,
    theta: f64,
    /// Direction of the straight (heading `theta`).
    dir: Vec2,
    t1: Vec2,
    /// Lengths of the first arc and of the straight, and the whole length, m.
    l1: f64,
    straight: f64,
    pub(super) length: f64,
    r: f64,
    /// The goal (the last point, exactly).
    p2: Vec2,
}

impl Csc {
    /// The Dubins CSC curve from (`p1`, heading `h1`, left normal `n1`) to (`p2`, `h2`, `n2`)
    /// with turn senses `s1`, `s2` (+1 left, −1 right) and radius `r`; `None` when the word
    /// has no solution. (The normals are shared by the four words of two poses.)
    fn with_normals(
        (p1, h1, n1): (Vec2, f64, Vec2),
        (p2, h2, n2): (Vec2, f64, Vec2),
        s1: f64,
        s2: f64,
        r: f64,
    ) -> Option<Self> {
        let c1 = p1 + n1 * (s1 * r);
        let c2 = p2 + n2 * (s2 * r);
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
        let dir = heading_vec(theta);
        let t1 = c1 - left_normal(&dir) * (s1 * r);
        let t2 = c2 - left_normal(&dir) * (s2 * r);
        let straight = (t2 - t1).norm();
        if (t2 - t1).dot(&dir) < -1e-6 {
            return None;
        }
        Some(Csc {
            c1,
            c2,
            h1,
            s1,
            s2,
            theta,
            dir,
            t1,
            l1: r * a1,
            straight,
            length: r * (a1 + a2) + straight,
            r,
            p2,
        })
    }

    /// Point `k` of `n` + 1 evenly spaced along the exact curve (arc, straight, arc); point
    /// `n` is the goal.
    fn point_at(&self, k: usize, n: usize) -> Vec2 {
        let l2 = self.l1 + self.straight;
        let r = self.r;
        let on_arc = |c: Vec2, h0: f64, s: f64, along: f64| {
            c - left_normal(&heading_vec(h0 + s * along / r)) * (s * r)
        };
        let at = self.length * k as f64 / n as f64;
        if k == n {
            self.p2
        } else if at <= self.l1 {
            on_arc(self.c1, self.h1, self.s1, at)
        } else if at <= l2 {
            self.t1 + self.dir * (at - self.l1)
        } else {
            on_arc(self.c2, self.theta, self.s2, at - l2)
        }
    }

    /// Points evenly spaced along the exact curve (arc, straight, arc), about `step` m apart,
    /// the last one the goal: every point lies on the curve and the chords are all alike, so
    /// three-point curvature never reads more than 1/r, even across the joins of the pieces.
    /// `None` when `clear` fails at a point: every [`CHECK_STRIDE`]th point is checked first
    /// (a blocked curve is blocked along a stretch, found after a few checks), in halving
    /// order ([`halving`]: a long curve through a blocked stretch in its middle is found out
    /// after a few checks too), then the rest.
    pub(super) fn points(&self, step: f64, clear: &dyn Fn(&Vec2) -> bool) -> Option<Vec<Vec2>> {
        let n = (self.length / step).ceil().max(1.0) as usize;
        let coarse = |k: usize| k % CHECK_STRIDE == CHECK_STRIDE / 2;
        let strides = if n >= CHECK_STRIDE / 2 {
            (n - CHECK_STRIDE / 2) / CHECK_STRIDE + 1
        } else {
            0
        };
        if !halving(strides).all(|m| clear(&self.point_at(CHECK_STRIDE / 2 + m * CHECK_STRIDE, n)))
        {
            return None;
        }
        let mut pts = Vec::with_capacity(n + 1);
        for k in 0..=n {
            let q = self.point_at(k, n);
            if !coarse(k) && !clear(&q) {
                return None;
            }
            pts.push(q);
        }
        Some(pts)
    }
}

/// Points of a curve checked first (every this many, then the rest): the same answer as
/// checking them in order, with fewer checks of a curve that is not clear.
const CHECK_STRIDE: usize = 8;

/// `0..n` in halving order: 0, then the multiples of the largest power of two below `n` not
/// yet given, then of the next smaller one, and so on (0, 8, 4, 12, 2, 6, 10, 14, 1, … for
/// n = 16): each index once, the points checked spread along the curve from the start.
fn halving(n: usize) -> impl Iterator<Item = usize> {
    let top = usize::BITS - n.max(1).leading_zeros();
    (0..top).rev().flat_map(move |level| {
        let s = 1usize << level;
        (0..n)
            .step_by(s)
            .filter(move |&m| level + 1 == top || m % (2 * s) != 0)
    })
}

/// Is `clear` true at every point of `pts` (each moved by `base`)? Every
/// [`CHECK_STRIDE`]th point first, then the rest.
fn all_clear(pts: &[Vec2], base: Vec2, clear: &dyn Fn(&Vec2) -> bool) -> bool {
    (0..CHECK_STRIDE).all(|o| {
        let o = (o + CHECK_STRIDE / 2) % CHECK_STRIDE;
        pts.iter()
            .skip(o)
            .step_by(CHECK_STRIDE)
            .all(|q| clear(&(base + q)))
    })
}

/// The turn senses of the CSC words: LSL, RSR, LSR, RSL.
const WORDS: [(f64, f64); 4] = [(1.0, 1.0), (-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0)];

/// The CSC curves from (`p1`, `h1`) to (`p2`, `h2`) with radius `r`, one per word that has a
/// solution, in [`WORDS`] order.
fn words(p1: Vec2, h1: f64, p2: Vec2, h2: f64, r: f64) -> impl Iterator<Item = Csc> {
    let a = (p1, h1, left_normal(&heading_vec(h1)));
    let b = (p2, h2, left_normal(&heading_vec(h2)));
    WORDS
        .into_iter()
        .filter_map(move |(s1, s2)| Csc::with_normals(a, b, s1, s2, r))
}

/// The CSC curves from (`p1`, `h1`) to (`p2`, `h2`) with radius `r` that have a solution,
/// shortest first.
pub(super) fn words_by_length(p1: Vec2, h1: f64, p2: Vec2, h2: f64, r: f64) -> Vec<Csc> {
    let mut words: Vec<Csc> = words(p1, h1, p2, h2, r).collect();
    words.sort_by(|a, b| a.length.total_cmp(&b.length));
    words
}

/// Length of the shortest CSC curve from (`p1`, `h1`) to (`p2`, `h2`) with radius `r`, m.
pub fn csc_length(p1: Vec2, h1: f64, p2: Vec2, h2: f64, r: f64) -> Option<f64> {
    words(p1, h1, p2, h2, r)
        .map(|c| c.length)
        .min_by(f64::total_cmp)
}

/// The shortest CSC transit for which `clear` holds at every point; `None` when none does.
/// ([`transit`] without the points of the shortest curve when no curve is clear, which its
/// callers that want a clear one only threw away.)
pub fn clear_transit(
    p1: Vec2,
    h1: f64,
    p2: Vec2,
    h2: f64,
    r: f64,
    step: f64,
    clear: &dyn Fn(&Vec2) -> bool,
) -> Option<Vec<Vec2>> {
    // Lengths first; points only for the words tried, shortest first, each given up at its
    // first point that is not clear.
    words_by_length(p1, h1, p2, h2, r)
        .iter()
        .find_map(|curve| curve.points(step, clear))
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
    if let Some(pts) = clear_transit(p1, h1, p2, h2, r, step, clear) {
        return Some((pts, true));
    }
    let shortest = words_by_length(p1, h1, p2, h2, r).into_iter().next()?;
    Some((shortest.points(step, &|_| true)?, false))
}

/// Clear waypoints on a square grid: the nodes of [`route_graph`], with the test of the points
/// of its curves (the one its nodes were chosen by).
#[derive(Clone)]
pub struct WaypointGrid<'a> {
    /// Position of node (0, 0), m.
    pub origin: Vec2,
    /// Node spacing, m.
    pub step: f64,
    pub nx: usize,
    pub ny: usize,
    /// Node (i, j) at `j * nx + i` is usable: 1, not: 2, not yet asked: 0 (a search's
    /// distances reach only the nodes of its goal's part of the field: asking every node
    /// cost a plan whose searches fail at once, as between parts joined by a neck too narrow
    /// to turn through, more than its searches).
    usable: RefCell<Vec<u8>>,
    /// Is a point of a curve clear?
    pub(super) clear: &'a dyn Fn(&Vec2) -> bool,
    /// Spacing of the points checked on the straights between neighbouring nodes, m: the
    /// clearance, half the thickness of the thinnest ground that is not clear.
    pub(super) probe: f64,
    /// The ways between neighbouring nodes by clear straights (see [`super::to_goal`]).
    pub(super) links: RefCell<super::to_goal::Links>,
    /// The curves between nodes, solved once (see [`EdgeTable`]).
    edges: RefCell<EdgeTable>,
    /// The states of the searches that failed with nothing left to expand.
    closed: RefCell<ClosedSets>,
    /// The answers of the searches made, by their poses, radius, spacing and budget (the
    /// plans of a field with several headland pass counts ask the same ones).
    answers: RefCell<std::collections::HashMap<[u64; 9], Option<Vec<Vec2>>>>,
    /// The nodes' distances to the field's edges: the edges known clear unchecked.
    free: free::Free<'a>,
}

impl<'a> WaypointGrid<'a> {
    /// Nodes every `step` m over the box `lo`–`hi` where `clear` holds; at most `max_nodes`
    /// (the step grows to fit). The curves of every search on the grid keep `clear` at every
    /// point. `clearance`: the distance from the field's edges and obstacles `clear` keeps, m
    /// (the ground that is not clear is at least twice that thick), and the field when `clear`
    /// is [`super::implement_clear`] of it with that distance (its edges far from a node then
    /// tell the curves from the node that are clear without checking their points; `None`:
    /// every curve checked point by point).
    pub fn new(
        lo: Vec2,
        hi: Vec2,
        step: f64,
        max_nodes: usize,
        clear: &'a dyn Fn(&Vec2) -> bool,
        (clearance, field): (f64, Option<&'a super::Field>),
    ) -> Self {
        let span = hi - lo;
        let step = step.max((span.x.max(0.0) * span.y.max(0.0) / max_nodes.max(1) as f64).sqrt());
        let nx = (span.x / step).floor().max(0.0) as usize + 1;
        let ny = (span.y / step).floor().max(0.0) as usize + 1;
        WaypointGrid {
            origin: lo,
            step,
            nx,
            ny,
            usable: RefCell::new(vec![0; nx * ny]),
            clear,
            probe: clearance.max(0.05),
            links: RefCell::new(vec![[f32::NAN; 16]; nx * ny]),
            edges: RefCell::default(),
            closed: RefCell::default(),
            answers: RefCell::default(),
            free: free::Free::new(field, clearance, nx * ny),
        }
    }

    /// The number of nodes.
    pub fn node_count(&self) -> usize {
        self.nx * self.ny
    }

    /// Is node `k` (at `j * nx + i`) usable: `clear` at it? Asked once.
    pub fn usable(&self, k: usize) -> bool {
        let known = self.usable.borrow().get(k).copied().unwrap_or(2);
        if known != 0 {
            return known == 1;
        }
        let ok = (self.clear)(&self.node(k % self.nx, k / self.nx));
        if let Some(x) = self.usable.borrow_mut().get_mut(k) {
            *x = if ok { 1 } else { 2 };
        }
        ok
    }

    /// The words of the edge from a node with heading index `ha` to the node (`di`, `dj`)
    /// steps away with heading index `hb`, shortest first, points `step` m apart.
    fn edge_words(&self, d: (i64, i64), ha: usize, hb: usize, r: f64, step: f64) -> Rc<[EdgeWord]> {
        let mut table = self.edges.borrow_mut();
        table.prepare(r, step, self.step);
        let slot = EdgeTable::slot(d, ha, hb);
        if let Some(words) = &table.slots[slot] {
            return words.clone();
        }
        let to = Vec2::new(d.0 as f64 * self.step, d.1 as f64 * self.step);
        let (h1, h2) = (graph_heading(ha), graph_heading(hb));
        let origin = Vec2::new(0.0, 0.0);
        let words: Rc<[EdgeWord]> = words_by_length(origin, h1, to, h2, r)
            .into_iter()
            .filter_map(|c| EdgeWord::of(&c, step))
            .collect();
        table.slots[slot] = Some(words.clone());
        words
    }

    pub(super) fn node(&self, i: usize, j: usize) -> Vec2 {
        self.origin + Vec2::new(i as f64 * self.step, j as f64 * self.step)
    }

    /// Index of node (`i`, `j`), if on the grid.
    pub(super) fn index(&self, i: i64, j: i64) -> Option<usize> {
        (i >= 0 && j >= 0 && (i as usize) < self.nx && (j as usize) < self.ny)
            .then(|| j as usize * self.nx + i as usize)
    }

    /// Usable nodes within `radius` m of `p`: (index, position).
    pub(super) fn near(&self, p: &Vec2, radius: f64) -> Vec<(usize, Vec2)> {
        let rel = (p - self.origin) / self.step;
        let reach = (radius / self.step).ceil() as i64;
        let (ci, cj) = (rel.x.round() as i64, rel.y.round() as i64);
        let mut out = Vec::new();
        for j in (cj - reach).max(0)..=(cj + reach).min(self.ny as i64 - 1) {
            for i in (ci - reach).max(0)..=(ci + reach).min(self.nx as i64 - 1) {
                let k = j as usize * self.nx + i as usize;
                let q = self.node(i as usize, j as usize);
                if (q - p).norm() <= radius && self.usable(k) {
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

/// A clear transit through several waypoints: A* over (waypoint, heading) states joined by
/// clear CSC curves to the waypoints within two grid steps, from the start pose to the goal
/// pose, every point clear by the grid's test; at most `max_expansions` states are expanded.
/// `None` when no clear way was found.
///
/// The search is lazy: a state is queued with the length of its edge's shortest word, and the
/// edge's points are checked only when the state comes off the queue (then it is queued again
/// with a longer word's length, or dropped when no word is clear), so each expansion checks
/// one curve instead of the sixty it could reach. The edges between nodes come from the grid's
/// [`EdgeTable`], their checks kept there for the grid's later searches.
#[allow(clippy::too_many_arguments)]
pub fn route_graph(
    p1: Vec2,
    h1: f64,
    p2: Vec2,
    h2: f64,
    r: f64,
    step: f64,
    grid: &WaypointGrid,
    max_expansions: usize,
) -> Option<Vec<Vec2>> {
    let bits = f64::to_bits;
    let key = [
        bits(p1.x),
        bits(p1.y),
        bits(h1),
        bits(p2.x),
        bits(p2.y),
        bits(h2),
        bits(r),
        bits(step),
        max_expansions as u64,
    ];
    if let Some(answer) = grid.answers.borrow().get(&key) {
        return answer.clone();
    }
    let answer = search(p1, h1, p2, h2, r, step, grid, max_expansions);
    grid.answers.borrow_mut().insert(key, answer.clone());
    answer
}

/// [`route_graph`]'s search.
#[allow(clippy::too_many_arguments)]
fn search(
    p1: Vec2,
    h1: f64,
    p2: Vec2,
    h2: f64,
    r: f64,
    step: f64,
    grid: &WaypointGrid,
    max_expansions: usize,
) -> Option<Vec<Vec2>> {
    let clear = grid.clear;
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    const H: usize = GRAPH_HEADINGS;
    /// The parent of the states joined to the start pose.
    const START: u32 = u32::MAX;
    let reach = 2.0 * grid.step * std::f64::consts::SQRT_2 + 1e-6;
    // Which nodes can reach the goal (`to_goal`): none near the start, no way.
    let to_goal = grid.open_distances(&p2, 3.0 * grid.step);
    let start_nodes = grid.near(&p1, reach);
    if start_nodes.iter().all(|(k, _)| !to_goal[*k].is_finite()) {
        return None;
    }
    // The heuristic: the distance to go through the grid by clear straights (it knows the
    // way round bays and slots).
    let mut steer = grid.steer_distances(&p2, 3.0 * grid.step);
    let states = grid.node_count() * H;
    let cell = |s: usize| (s / H % grid.nx, s / H / grid.nx);
    let pose = |s: usize| {
        let (i, j) = cell(s);
        (grid.node(i, j), graph_heading(s % H))
    };
    // States of earlier searches that failed with nothing left to expand, from which this
    // search cannot reach its goal either (see [`super::closed`]): left out.
    let closed_key = (r.to_bits(), step.to_bits());
    let goal_nodes: Vec<usize> = grid
        .near(&p2, 3.0 * grid.step)
        .iter()
        .map(|e| e.0)
        .collect();
    let finishes = |s: usize| {
        let (q, h) = pose(s);
        clear_transit(q, h, p2, h2, r, step, clear).is_some()
    };
    let dead = grid
        .closed
        .borrow()
        .dead(closed_key, &to_goal, &goal_nodes, H, &finishes);
    let is_dead = |s: usize| dead.as_ref().is_some_and(|d| d.has(s));
    // The words of the edge parent → s, shortest first, with the point they are placed at.
    let words_of = |parent: u32, s: usize| -> (Vec2, Rc<[EdgeWord]>) {
        let (q, h) = pose(s);
        if parent == START {
            let words: Rc<[EdgeWord]> = words_by_length(p1, h1, q, h, r)
                .into_iter()
                .filter_map(|c| EdgeWord::of(&c, step))
                .collect();
            return (Vec2::new(0.0, 0.0), words);
        }
        let p = parent as usize;
        let ((pi, pj), (si, sj)) = (cell(p), cell(s));
        let d = (si as i64 - pi as i64, sj as i64 - pj as i64);
        (pose(p).0, grid.edge_words(d, p % H, s % H, r, step))
    };
    let key = |f: f64| (f * 1000.0) as u64;
    let mut done = vec![false; states];
    let mut cost = vec![f64::INFINITY; states];
    let mut parent = vec![START; states];
    let mut word = vec![0u8; states];
    // The smallest priority queued for each state since its last failed offer: an offer that
    // is not smaller is not queued. (With every offer queued, 95 % of what came off the queue
    // was a state already expanded: 330 000 pops for 11 000 expansions on de_bb_concave.)
    let mut best = vec![u64::MAX; states];
    // Edges whose points were checked: (parent, state) → (word, length); `None` when no word
    // is clear. When a state's best offer turns out blocked or longer than queued, the offers
    // of its expanded neighbours that were not queued are queued then, at their known lengths.
    // (The start's edges here; the others in the grid's map, marked with this search.)
    let mut checked = CheckedEdges::default();
    let mut from_start = vec![false; states];
    // Per node: its expanded headings (bit per heading index).
    let mut done_at = vec![0u8; grid.node_count()];
    let mut heap: BinaryHeap<(Reverse<u64>, u32, u32)> = BinaryHeap::new();
    // Queue the start's neighbours with their shortest words' lengths.
    for (k, q) in start_nodes {
        if !to_goal[k].is_finite() {
            continue;
        }
        for hk in arrival_headings(q - p1, None) {
            if let Some(len) = csc_length(p1, h1, q, graph_heading(hk), r) {
                let s = k * H + hk;
                if is_dead(s) {
                    continue;
                }
                from_start[s] = true;
                let f = key(len + HEURISTIC_WEIGHT * steer.at(grid, k, to_goal[k]));
                if f < best[s] {
                    best[s] = f;
                    heap.push((Reverse(f), s as u32, START));
                }
            }
        }
    }
    // The shortest word of every edge and the masks of those with a word (copies: the words
    // are solved on first need meanwhile), and this search's number.
    let (table, to_mask, from_mask, search) = {
        let mut t = grid.edges.borrow_mut();
        t.prepare(r, step, grid.step);
        t.searches = t.searches.wrapping_add(1);
        let masks = (t.to_mask.clone(), t.from_mask.clone());
        (t.shortest.clone(), masks.0, masks.1, t.searches)
    };
    // The cell of a displacement (di, dj) in the table's layout.
    let span_cell =
        |di: i64, dj: i64| (di + EDGE_REACH) as usize * EDGE_SPAN + (dj + EDGE_REACH) as usize;
    let (mut expansions, mut pops) = (0, 0);
    while let Some((Reverse(queued), s, from)) = heap.pop() {
        let s = s as usize;
        // (Once, after some states off the queue: can any state finish? See `finish`.)
        pops += 1;
        let mark = search.wrapping_sub(1);
        let ends = ((p1, h1), (p2, h2));
        if pops == finish::ASK_AFTER
            && finish::out_of_reach(grid, ends.0, ends.1, r, step, &to_goal, mark)
        {
            return None;
        }
        if done[s] {
            continue;
        }
        // The edge's first clear word, checked once (`fresh`: first in this search).
        let edge = (from, s as u32);
        let (known, fresh) = if from == START {
            match checked.get(&edge) {
                Some(k) => (k.0, false),
                None => {
                    // The start's curves, solved here: each word's points made only as far as
                    // its first one that is not clear (the same points and test as its word).
                    let (q, h) = pose(s);
                    let k = words_by_length(p1, h1, q, h, r)
                        .iter()
                        .enumerate()
                        .find(|(_, c)| c.points(step, clear).is_some())
                        .map(|(w, c)| (w as u8, c.length));
                    checked.insert(edge, (k, search));
                    (k, true)
                }
            }
        } else {
            let earlier = match grid.edges.borrow_mut().checked.get_mut(&edge) {
                Some((k, n)) if *n == search => Some((*k, false)),
                Some((k, n)) => {
                    *n = search;
                    Some((*k, true))
                }
                None => None,
            };
            earlier.unwrap_or_else(|| {
                let (base, words) = words_of(from, s);
                // (The shortest word clear unchecked where the edges are far: see `free`.)
                let far = |w: &EdgeWord| grid.free.covers(from as usize / H, &base, w.length);
                let k = words
                    .iter()
                    .enumerate()
                    .find(|(w, word)| (*w == 0 && far(word)) || all_clear(&word.pts, base, clear))
                    .map(|(w, found)| (w as u8, found.length));
                grid.edges.borrow_mut().checked.insert(edge, (k, search));
                (k, true)
            })
        };
        let h_s = HEURISTIC_WEIGHT * steer.at(grid, s / H, to_goal[s / H]);
        let g_from = if from == START {
            0.0
        } else {
            cost[from as usize]
        };
        let mut requeue = None;
        if let Some((w, length)) = known {
            let f = key(g_from + length + h_s);
            if f > queued + 1 {
                // A longer word than queued: back in the queue at its true cost.
                requeue = Some(f);
            } else {
                done[s] = true;
                done_at[s / H] |= 1 << (s % H);
                cost[s] = g_from + length;
                parent[s] = from;
                word[s] = w;
                expansions += 1;
            }
        }
        if !done[s] {
            if !fresh {
                // A second offer of an edge already checked (queued at its true cost then).
                continue;
            }
            if let Some(f) = requeue {
                heap.push((Reverse(f), s as u32, from));
            }
            // The offers of the expanded neighbours (and of the start) that this one kept out
            // of the queue: queued now, at their known lengths where their edges were checked.
            best[s] = requeue.unwrap_or(u64::MAX);
            let mut offer = |q: u32, length: f64, heap: &mut BinaryHeap<_>| {
                let g = if q == START { 0.0 } else { cost[q as usize] };
                let f = key(g + length + h_s);
                if f < best[s] {
                    best[s] = f;
                    heap.push((Reverse(f), s as u32, q));
                }
            };
            if from_start[s] && from != START {
                match checked.get(&(START, s as u32)) {
                    Some((Some((_, l)), _)) => offer(START, *l, &mut heap),
                    Some((None, _)) => {}
                    None => {
                        let (q, h) = pose(s);
                        if let Some(l) = csc_length(p1, h1, q, h, r) {
                            offer(START, l, &mut heap);
                        }
                    }
                }
            }
            let (si, sj) = cell(s);
            let edges = grid.edges.borrow();
            for di in -EDGE_REACH..=EDGE_REACH {
                for dj in -EDGE_REACH..=EDGE_REACH {
                    let Some(k) = grid.index(si as i64 - di, sj as i64 - dj) else {
                        continue;
                    };
                    // The expanded headings there with an edge (with a word) to this state,
                    // in heading order. (An edge with no word was never queued, so never
                    // checked.)
                    let mut has = done_at[k] & from_mask[span_cell(di, dj) * H + s % H];
                    while has != 0 {
                        let ha = has.trailing_zeros() as usize;
                        has &= has - 1;
                        let q = k * H + ha;
                        if q as u32 == from {
                            continue;
                        }
                        let shortest = table[EdgeTable::slot((di, dj), ha, s % H)];
                        let length = match edges.checked.get(&(q as u32, s as u32)) {
                            Some((Some((_, l)), n)) if *n == search => *l,
                            Some((None, n)) if *n == search => continue,
                            _ => shortest,
                        };
                        if length.is_finite() {
                            offer(q as u32, length, &mut heap);
                        }
                    }
                }
            }
            continue;
        }
        let g = cost[s];
        if expansions > max_expansions {
            tracing::debug!(expansions, "no clear transit found through the waypoints");
            return None;
        }
        let at = pose(s);
        if (p2 - at.0).norm() <= 3.0 * grid.step {
            if let Some(last) = clear_transit(at.0, at.1, p2, h2, r, step, clear) {
                // The chain of states back to the start, then its curves.
                let mut chain = vec![s];
                while let Some(&c) = chain.last() {
                    if parent[c] == START {
                        break;
                    }
                    chain.push(parent[c] as usize);
                }
                chain.reverse();
                let mut pts = vec![p1];
                let mut from = START;
                for &c in &chain {
                    let (base, words) = words_of(from, c);
                    let piece = words.get(word[c] as usize)?;
                    pts.extend(piece.pts.iter().skip(1).map(|q| base + q));
                    from = c as u32;
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
        // Queue the neighbours with their shortest words' lengths.
        let (i, j) = cell(s);
        for di in -EDGE_REACH..=EDGE_REACH {
            for dj in -EDGE_REACH..=EDGE_REACH {
                let Some(k) = grid.index(i as i64 + di, j as i64 + dj) else {
                    continue;
                };
                if !to_goal[k].is_finite() || !grid.usable(k) {
                    continue;
                }
                let h_to_go = HEURISTIC_WEIGHT * steer.at(grid, k, to_goal[k]);
                // The headings there with an edge (with a word) from this state, in order.
                let mut has = to_mask[span_cell(di, dj) * H + s % H];
                while has != 0 {
                    let hk = has.trailing_zeros() as usize;
                    has &= has - 1;
                    let next = k * H + hk;
                    let length = table[EdgeTable::slot((di, dj), s % H, hk)];
                    if !done[next] && !is_dead(next) {
                        let f = key(g + length + h_to_go);
                        if f < best[next] {
                            best[next] = f;
                            heap.push((Reverse(f), next as u32, s as u32));
                        }
                    }
                }
            }
        }
    }
    // Nothing left to expand: the expanded states (with those left out) are closed.
    if expansions > 0 {
        let mut closed = grid.closed.borrow_mut();
        closed.record(closed_key, &done, dead.as_ref(), H, &to_goal);
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

    /// The halving order gives every index once.
    #[test]
    fn halving_gives_every_index_once() {
        for n in 0..70 {
            let mut all: Vec<usize> = halving(n).collect();
            assert_eq!(all.first().copied(), (n > 0).then_some(0));
            all.sort_unstable();
            assert_eq!(all, (0..n).collect::<Vec<_>>(), "n {n}");
        }
        assert_eq!(
            halving(16).collect::<Vec<_>>(),
            [0, 8, 4, 12, 2, 6, 10, 14, 1, 3, 5, 7, 9, 11, 13, 15]
        );
    }

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
