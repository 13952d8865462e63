//! A proof that a waypoint search of [`super::route_graph`] cannot reach its goal, found from
//! the goal's side. The search ends only at a state within three grid steps of the goal whose
//! curve to the goal is clear, at a usable node with a finite distance to the goal (every
//! state it expands is at one); it reaches such a state only from one with a clear edge to
//! it, and so on back to a state it starts at, with a clear curve from the start. When none of
//! the states found so from the goal has a clear curve from the start, it finds no way,
//! whatever it expands. A swath's start that no curve of radius r_min reaches from the
//! waypoints round it (facing into a corner, or just past a small obstacle with the swaths
//! either side close to it) has few such states or none: the search found that out by
//! expanding every state it could reach, or its budget of them, checking a curve to each
//! (dk_marker_strip at w 3 m, r_min 8 m: 12 and 15 ms, with no state and one state that
//! reach the goal; de_bb_holes_irregular: 5–11 ms, for a detour of 15 m, none).
//!
//! The states, edges and test are the search's own, the edges checked kept in the grid's map,
//! so the proof is exact: it says no way only where the search finds none.

use super::{all_clear, clear_transit, words_by_length, WaypointGrid};
use crate::geo::Vec2;
use crate::plan::coverage::edges::{
    arrival_headings, graph_heading, EDGE_REACH, EDGE_SPAN, GRAPH_HEADINGS,
};

/// States a search takes off its queue before it asks whether its goal can be reached (a
/// search that succeeds or fails sooner does not ask). Counted off the queue, not expanded:
/// where most curves are blocked (dk_marker_strip), 256 expansions took 4 400 states off the
/// queue, each a curve checked, 15 ms.
pub(super) const ASK_AFTER: usize = 256;

/// Curves checked at most to tell (a goal that many states reach is left to the search).
const BUDGET: usize = 768;

/// Is (`p2`, `h2`) out of reach of the search of [`super::route_graph`] on `grid` from
/// (`p1`, `h1`) with radius `r` and point spacing `step`, over the usable nodes with a finite
/// `to_goal` (per node)? `true` only when no state from which the goal can be reached has a
/// clear curve from the start, so that the search finds no way; `false` too when more than
/// [`BUDGET`] curves were needed to tell. The edges it checks are kept in the grid's map as
/// checked by search `mark`, which must not be the number of the search under way (they then
/// read as an earlier search's, which the search under way checks as if new).
#[allow(clippy::too_many_arguments)]
pub(super) fn out_of_reach(
    grid: &WaypointGrid,
    (p1, h1): (Vec2, f64),
    (p2, h2): (Vec2, f64),
    r: f64,
    step: f64,
    to_goal: &[f64],
    mark: u32,
) -> bool {
    const H: usize = GRAPH_HEADINGS;
    let clear = grid.clear;
    let open = |k: usize| to_goal.get(k).is_some_and(|d| d.is_finite()) && grid.usable(k);
    let pose = |s: usize| {
        let k = s / H;
        (grid.node(k % grid.nx, k / grid.nx), graph_heading(s % H))
    };
    let mut reaches = vec![false; grid.node_count() * H];
    let mut stack = Vec::new();
    let mut checks = 0;
    // The states the search finishes from: near the goal, with a clear curve to it.
    for (k, _) in grid.near(&p2, 3.0 * grid.step) {
        if !open(k) {
            continue;
        }
        for (h, state) in reaches[k * H..(k + 1) * H].iter_mut().enumerate() {
            checks += 1;
            if checks > BUDGET {
                return false;
            }
            let (q, hq) = pose(k * H + h);
            if clear_transit(q, hq, p2, h2, r, step, clear).is_some() {
                *state = true;
                stack.push(k * H + h);
            }
        }
    }
    let from_mask = {
        let mut t = grid.edges.borrow_mut();
        t.prepare(r, step, grid.step);
        t.from_mask.clone()
    };
    let span_cell =
        |di: i64, dj: i64| (di + EDGE_REACH) as usize * EDGE_SPAN + (dj + EDGE_REACH) as usize;
    // Every state with a clear edge to one that reaches the goal reaches it.
    while let Some(t) = stack.pop() {
        let (ti, tj) = ((t / H % grid.nx) as i64, (t / H / grid.nx) as i64);
        for di in -EDGE_REACH..=EDGE_REACH {
            for dj in -EDGE_REACH..=EDGE_REACH {
                let Some(k) = grid.index(ti - di, tj - dj).filter(|&k| open(k)) else {
                    continue;
                };
                // The headings there with an edge (with a word) to `t`.
                let mut has = from_mask[span_cell(di, dj) * H + t % H];
                while has != 0 {
                    let ha = has.trailing_zeros() as usize;
                    has &= has - 1;
                    let q = k * H + ha;
                    if reaches[q] {
                        continue;
                    }
                    let edge = (q as u32, t as u32);
                    let known = grid.edges.borrow().checked.get(&edge).map(|e| e.0);
                    let found = match known {
                        Some(found) => found,
                        None => {
                            checks += 1;
                            if checks > BUDGET {
                                return false;
                            }
                            let words = grid.edge_words((di, dj), ha, t % H, r, step);
                            let base = pose(q).0;
                            let found = words
                                .iter()
                                .enumerate()
                                .find(|(_, w)| all_clear(&w.pts, base, clear))
                                .map(|(w, word)| (w as u8, word.length));
                            grid.edges.borrow_mut().checked.insert(edge, (found, mark));
                            found
                        }
                    };
                    if found.is_some() {
                        reaches[q] = true;
                        stack.push(q);
                    }
                }
            }
        }
    }
    // The states the search starts at: usable nodes near the start, headed roughly away.
    let reach = 2.0 * grid.step * std::f64::consts::SQRT_2 + 1e-6;
    !grid.near(&p1, reach).into_iter().any(|(k, q)| {
        open(k)
            && arrival_headings(q - p1, None).any(|hk| {
                reaches[k * H + hk]
                    && words_by_length(p1, h1, q, graph_heading(hk), r)
                        .iter()
                        .any(|c| c.points(step, clear).is_some())
            })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;
    use crate::plan::coverage::Field;
    use rand::{Rng, SeedableRng};

    /// Sound against a brute-force search: over random start and goal poses (half the goals in
    /// the arm) in a field with an arm too narrow to turn in and an obstacle, whenever [`out_of_reach`] says the goal is out
    /// of reach, no state that a clear curve from the start and clear edges reach (every state
    /// of the graph the search could expand, found breadth first, with no heuristic and no
    /// budget) has a clear curve to the goal. It says so for some pairs; the brute force
    /// reaches the goal of others.
    #[test]
    fn out_of_reach_only_where_no_search_reaches_the_goal() {
        let field = Field {
            boundary: vec![
                v2(0.0, 0.0),
                v2(160.0, 0.0),
                v2(160.0, 60.0),
                v2(108.0, 60.0),
                v2(108.0, 120.0),
                v2(96.0, 120.0),
                v2(96.0, 60.0),
                v2(0.0, 60.0),
            ],
            obstacles: vec![vec![
                v2(30.0, 20.0),
                v2(50.0, 20.0),
                v2(50.0, 40.0),
                v2(30.0, 40.0),
            ]],
        };
        let (half, r, step) = (1.5, 6.0, 1.0);
        // (The map answers as `implement_clear` does, faster.)
        let map = crate::plan::coverage::clear_map::ClearMap::new(&field, half);
        let clear = |q: &Vec2| map.clear(q);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(23);
        let (mut proved, mut joined) = (0, 0);
        for n in 0..40 {
            // A fresh grid each time: no edge checked by an earlier pair.
            let grid = WaypointGrid::new(
                v2(0.0, 0.0),
                v2(160.0, 120.0),
                10.0,
                20_000,
                &clear,
                (half, None),
            );
            // Every other goal in the arm.
            let mut pose = |arm: bool| loop {
                let q = if arm {
                    v2(rng.gen_range(97.6..106.4), rng.gen_range(62.0..118.0))
                } else {
                    v2(rng.gen_range(0.0..160.0), rng.gen_range(0.0..60.0))
                };
                if clear(&q) {
                    break (q, rng.gen_range(-3.1..3.1));
                }
            };
            let (start, goal) = (pose(false), pose(n % 2 == 1));
            let to_goal = grid.open_distances(&goal.0, 3.0 * grid.step);
            let out = out_of_reach(&grid, start, goal, r, step, &to_goal, 0);
            // Brute force: every state reachable from the start, breadth first.
            const H: usize = GRAPH_HEADINGS;
            let open = |k: usize| to_goal[k].is_finite() && grid.usable(k);
            let pose_of = |s: usize| {
                let k = s / H;
                (grid.node(k % grid.nx, k / grid.nx), graph_heading(s % H))
            };
            let mut seen = vec![false; grid.node_count() * H];
            let mut queue = std::collections::VecDeque::new();
            let reach = 2.0 * grid.step * std::f64::consts::SQRT_2 + 1e-6;
            for (k, q) in grid.near(&start.0, reach) {
                for hk in arrival_headings(q - start.0, None) {
                    let s = k * H + hk;
                    let from = words_by_length(start.0, start.1, q, graph_heading(hk), r);
                    if open(k) && from.iter().any(|c| c.points(step, &clear).is_some()) {
                        seen[s] = true;
                        queue.push_back(s);
                    }
                }
            }
            let to_mask = {
                let mut t = grid.edges.borrow_mut();
                t.prepare(r, step, grid.step);
                t.to_mask.clone()
            };
            let mut finishes = false;
            while let Some(s) = queue.pop_front() {
                let (q, h) = pose_of(s);
                if (goal.0 - q).norm() <= 3.0 * grid.step
                    && clear_transit(q, h, goal.0, goal.1, r, step, &clear).is_some()
                {
                    finishes = true;
                    break;
                }
                let (i, j) = ((s / H % grid.nx) as i64, (s / H / grid.nx) as i64);
                for di in -EDGE_REACH..=EDGE_REACH {
                    for dj in -EDGE_REACH..=EDGE_REACH {
                        let Some(k) = grid.index(i + di, j + dj).filter(|&k| open(k)) else {
                            continue;
                        };
                        let cell =
                            (di + EDGE_REACH) as usize * EDGE_SPAN + (dj + EDGE_REACH) as usize;
                        for hb in (0..H).filter(|hb| to_mask[cell * H + s % H] >> hb & 1 == 1) {
                            let t = k * H + hb;
                            let words = grid.edge_words((di, dj), s % H, hb, r, step);
                            if !seen[t] && words.iter().any(|w| all_clear(&w.pts, q, &clear)) {
                                seen[t] = true;
                                queue.push_back(t);
                            }
                        }
                    }
                }
            }
            assert!(!(out && finishes), "start {start:?} goal {goal:?}");
            proved += usize::from(out);
            joined += usize::from(finishes);
        }
        assert!(proved >= 5, "{proved} pairs out of reach");
        assert!(joined >= 10, "{joined} pairs joined");
    }
}
