//! Transits along the headland: the headland passes are closed, driveable tracks (curvature
//! ≤ 1/r_min, clear of the edge by w/2), so a transit that cannot go direct can turn onto a
//! pass, follow it and turn off it near its goal, as a driver does on the headland. Fields2Cover
//! routes the same way (its route planner joins the swaths through the headland rings); this
//! is a search over a few entry and exit points per ring, not over the whole field, so it costs
//! a few Dubins curves where the waypoint search of [`super::transit::route_graph`] costs
//! thousands.

use super::closed::EdgeHasher;
#[cfg(test)]
use super::transit::transit;
use super::transit::{words_by_length, Csc};
use crate::geo::{heading_vec, left_normal, vec_heading, Vec2};
use std::hash::BuildHasherDefault;

/// Points of a ring tried as the place to turn onto it (or off it), at most.
const CANDIDATES_PER_END: usize = 24;

/// Joins (entry, exit) verified point by point before giving up on a ring direction.
const MAX_VERIFIED: usize = 48;

/// One closed track: points (the first not repeated), the length along it, which points are
/// clear.
#[derive(Debug, Clone)]
struct Ring {
    pts: Vec<Vec2>,
    /// `cum[i]`: length from `pts[0]` to `pts[i]`; `cum[n]` the whole ring, m.
    cum: Vec<f64>,
    /// `blocked[i]`: points among `pts[..i]` that are not clear (prefix counts).
    blocked: Vec<u32>,
    /// Per run of [`CHUNK`] points (the last may be shorter): a disc holding them (centre,
    /// radius), to pass over the runs far from a point ([`Ring::near`]).
    chunks: Vec<(Vec2, f64)>,
    /// A disc holding every point (centre, radius): no point is nearer a position than its
    /// distance less the radius.
    disc: (Vec2, f64),
}

/// Points of a ring per disc of [`Ring::chunks`].
const CHUNK: usize = 16;

impl Ring {
    fn new(track: &[Vec2], clear: &dyn Fn(&Vec2) -> bool, max_curvature: f64) -> Option<Self> {
        let mut pts: Vec<Vec2> = track.to_vec();
        if pts.len() >= 2 && (pts[pts.len() - 1] - pts[0]).norm() < 1e-9 {
            pts.pop();
        }
        if pts.len() < 4 {
            return None;
        }
        let n = pts.len();
        // A point where the ring turns tighter than allowed is not followed, as one that is
        // not clear: a transit along it would break the curvature guarantee there.
        let ok = |i: usize| {
            clear(&pts[i])
                && crate::plan::coverage::metrics::ring_curvature(&pts, i) <= max_curvature
        };
        let mut cum = Vec::with_capacity(n + 1);
        let mut blocked = Vec::with_capacity(n + 1);
        let (mut len, mut b) = (0.0, 0u32);
        for i in 0..n {
            cum.push(len);
            blocked.push(b);
            len += (pts[(i + 1) % n] - pts[i]).norm();
            b += u32::from(!ok(i));
        }
        cum.push(len);
        blocked.push(b);
        if b as usize == n {
            return None;
        }
        // A disc holding `run` (not empty): its centroid and the farthest point's distance.
        let disc = |run: &[Vec2]| {
            let c = run.iter().fold(Vec2::new(0.0, 0.0), |a, p| a + p) / run.len() as f64;
            (c, run.iter().map(|p| (p - c).norm()).fold(0.0, f64::max))
        };
        let chunks = pts.chunks(CHUNK).map(disc).collect();
        let disc = disc(&pts);
        Some(Ring {
            pts,
            cum,
            blocked,
            chunks,
            disc,
        })
    }

    /// No point of the ring is nearer `q` than this, m (a micrometre allowed for rounding).
    fn least_distance(&self, q: &Vec2) -> f64 {
        ((self.disc.0 - q).norm() - self.disc.1 - 1e-6).max(0.0)
    }

    fn len(&self) -> usize {
        self.pts.len()
    }

    /// Heading of travel at point `i` in direction `dir` (+1 along the indices, −1 against):
    /// the tangent, along the chord between the points either side. A curve joining the ring
    /// there then bends from its own last chord to the ring's next chord by half a chord angle
    /// of each; with the next chord's heading instead, a curve leaving the ring bent by the
    /// ring's whole chord angle on top of its own (three-point curvature read 0.26 /m at r 5).
    fn heading(&self, i: usize, dir: i32) -> f64 {
        let n = self.len();
        let (next, prev) = (self.pts[(i + 1) % n], self.pts[(i + n - 1) % n]);
        let d = if dir > 0 { next - prev } else { prev - next };
        vec_heading(&d)
    }

    /// Length along the ring from `i` to `j` in direction `dir`, m.
    fn along(&self, i: usize, j: usize, dir: i32) -> f64 {
        let total = self.cum[self.len()];
        let d = if dir > 0 {
            self.cum[j] - self.cum[i]
        } else {
            self.cum[i] - self.cum[j]
        };
        d.rem_euclid(total)
    }

    /// Are all points from `i` to `j` (inclusive) in direction `dir` clear?
    fn stretch_clear(&self, i: usize, j: usize, dir: i32) -> bool {
        let (a, b) = if dir > 0 { (i, j) } else { (j, i) };
        // Points a..=b going up the indices, wrapping past the end.
        let count = |from: usize, to_excl: usize| self.blocked[to_excl] - self.blocked[from];
        if a <= b {
            count(a, b + 1) == 0
        } else {
            count(a, self.len()) == 0 && count(0, b + 1) == 0
        }
    }

    /// Points from `i` to `j` in direction `dir`, both included.
    fn stretch(&self, i: usize, j: usize, dir: i32) -> Vec<Vec2> {
        let n = self.len();
        let mut out = vec![self.pts[i]];
        let mut k = i;
        while k != j {
            k = if dir > 0 {
                (k + 1) % n
            } else {
                (k + n - 1) % n
            };
            out.push(self.pts[k]);
        }
        out
    }

    /// Clear points near `q`: within `reach` m of the nearest, evenly thinned to at most
    /// [`CANDIDATES_PER_END`]. The distances are those of the points of the runs
    /// ([`Self::chunks`]) that could hold the nearest point, then of those that could hold a
    /// point within `reach` of it: a run whose disc is farther is passed over (its points are
    /// at least that far, a micrometre allowed for the rounding), with the same answer as
    /// from every point's distance.
    fn near(&self, q: &Vec2, reach: f64) -> Vec<usize> {
        let distance = |i: usize| (self.pts[i] - q).norm();
        let run = |k: usize| k * CHUNK..((k + 1) * CHUNK).min(self.len());
        // The distance of each run's disc (less its radius: its points are no nearer) and
        // the farthest the nearest point can be (the nearest disc's far side).
        let (mut least, mut most) = (Vec::with_capacity(self.chunks.len()), f64::INFINITY);
        for (c, radius) in &self.chunks {
            let d = (c - q).norm();
            least.push(d - radius - 1e-6);
            most = most.min(d + radius + 1e-6);
        }
        let nearest = (0..least.len())
            .filter(|&k| least[k] <= most)
            .flat_map(run)
            .map(distance)
            .fold(f64::INFINITY, f64::min);
        let all: Vec<usize> = (0..least.len())
            .filter(|&k| least[k] <= nearest + reach)
            .flat_map(run)
            .filter(|&i| distance(i) <= nearest + reach && self.blocked[i + 1] == self.blocked[i])
            .collect();
        let step = all.len().div_ceil(CANDIDATES_PER_END).max(1);
        all.into_iter().step_by(step).collect()
    }
}

/// The closed tracks a transit may follow.
#[derive(Debug, Clone, Default)]
pub struct Rings {
    rings: Vec<Ring>,
}

impl Rings {
    /// The tracks (closed: first point repeated last, or not) with their points that are
    /// clear and turn no tighter than `max_curvature` (three-point curvature, 1/m).
    pub fn new(tracks: &[Vec<Vec2>], clear: &dyn Fn(&Vec2) -> bool, max_curvature: f64) -> Self {
        Rings {
            rings: tracks
                .iter()
                .filter_map(|t| Ring::new(t, clear, max_curvature))
                .collect(),
        }
    }

    /// The largest distance between consecutive points of a ring (0 with no ring), m.
    pub fn max_gap(&self) -> f64 {
        self.rings
            .iter()
            .flat_map(|r| r.cum.windows(2).map(|w| w[1] - w[0]))
            .fold(0.0, f64::max)
    }

    /// A clear transit from (`p1`, heading `h1`) to (`p2`, `h2`): a Dubins curve of radius
    /// `r` onto a ring, the ring's clear points, a Dubins curve off it; the shortest such of
    /// the candidates tried, `None` when none is clear. Points about `step` m apart. The
    /// curves onto and off the rings are kept in `ends` for the next transit from or to the
    /// same pose: the same answer as with a fresh `Ends::default()`, with the curves of a
    /// pose that an earlier call solved and checked not solved or checked again. `ends` must
    /// only ever be used with one test `clear` (its checks are kept).
    #[allow(clippy::too_many_arguments)]
    pub fn transit_with(
        &self,
        p1: Vec2,
        h1: f64,
        p2: Vec2,
        h2: f64,
        r: f64,
        step: f64,
        clear: &dyn Fn(&Vec2) -> bool,
        ends: &mut Ends,
    ) -> Option<Vec<Vec2>> {
        let reach = 4.0 * r;
        let mut best: Option<(f64, Vec<Vec2>)> = None;
        // Every curve from the start pose at least `trap.0` m long is blocked, and every one
        // to the goal pose at least `trap.1` long (see [`trap_length`]): none onto a ring is
        // clear when every entry is that far, nor any off one when every exit is, and no join
        // is then clear; the others' words that long are not checked.
        let trap = (
            ends.trap_length((p1, h1, true), r, step),
            ends.trap_length((p2, h2, false), r, step),
        );
        // Every way through a ring is at least as long as the straight distances to its
        // nearest entry and from its nearest exit, and those at least the distances to the
        // ring's disc: the rings are taken by that least bound, each one's candidates found
        // only when it is taken, so the best way is found early and the rings that cannot
        // beat it (nor reach a trap's length) are passed over without looking at their points.
        let nearest = |ring: &Ring, q: &Vec2, pts: &[usize]| {
            pts.iter()
                .map(|&i| (ring.pts[i] - q).norm())
                .fold(f64::INFINITY, f64::min)
        };
        let mut order: Vec<(f64, usize)> = self
            .rings
            .iter()
            .enumerate()
            .filter_map(|(ri, ring)| {
                let (a, b) = (ring.least_distance(&p1), ring.least_distance(&p2));
                (a < trap.0 && b < trap.1).then_some((a + b, ri))
            })
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for (least, ri) in order {
            if best.as_ref().is_some_and(|b| b.0 <= least - 1e-6) {
                break;
            }
            let ring = &self.rings[ri];
            // The candidates of a ring with both (the others are passed over).
            let entries = ring.near(&p1, reach);
            if entries.is_empty() {
                continue;
            }
            let exits = ring.near(&p2, reach);
            if exits.is_empty() {
                continue;
            }
            let (onto, off) = (nearest(ring, &p1, &entries), nearest(ring, &p2, &exits));
            // No curve onto this ring is clear when every entry is as far as the start's trap
            // length, nor any off it when every exit is as far as the goal's: no join of it is
            // clear, and its curves are not solved (the others' answers are the same).
            if onto >= trap.0 || off >= trap.1 {
                continue;
            }
            // None beats the best so far when the bound does not (a micrometre of margin for
            // the rounding of the curves' lengths).
            let bound = onto + off - 1e-6;
            if best.as_ref().is_some_and(|b| b.0 <= bound) {
                continue;
            }
            for dir in [1, -1] {
                // The curves on at each entry (`onto`) or off at each exit, shortest first
                // (solved once, or found in `ends`: their lengths bound the joins, then the
                // joins verified check their points): (ring point, the end's index in `ends`,
                // its length). (Of the ring points `at` that `keep` passes.)
                let curves_at =
                    |ends: &mut Ends, at: &[usize], onto: bool, keep: &dyn Fn(usize) -> bool| {
                        let ((p, h), budget) = if onto {
                            ((p1, h1), trap.0)
                        } else {
                            ((p2, h2), trap.1)
                        };
                        at.iter()
                            .filter(|&&i| keep(i))
                            .filter_map(|&i| {
                                let pose = (ring.pts[i], ring.heading(i, dir));
                                let key = EndKey::new((p, h), (ri, i, dir, onto), r, step);
                                let e = ends.solve(key, budget, || {
                                    if onto {
                                        words_by_length(p, h, pose.0, pose.1, r)
                                    } else {
                                        words_by_length(pose.0, pose.1, p, h, r)
                                    }
                                });
                                Some((i, e, ends.length(e)?))
                            })
                            .collect::<Vec<(usize, usize, f64)>>()
                    };
                // Only an entry nearer than the start's trap length can have a clear curve
                // onto the ring: when none of those has, none has (nor any join), and the
                // curves to the others are not solved.
                if trap.0.is_finite() {
                    let maybe = curves_at(ends, &entries, true, &|i| {
                        (ring.pts[i] - p1).norm() < trap.0
                    });
                    if !ends.any_clear(&maybe, step, clear) {
                        continue;
                    }
                }
                let on = curves_at(ends, &entries, true, &|_| true);
                // Every join costs at least the shortest way on: none beats the best so far
                // when that does not (the bound below, with the ways off left out).
                let least =
                    |v: &[(usize, usize, f64)]| v.iter().map(|e| e.2).fold(f64::INFINITY, f64::min);
                if best.as_ref().is_some_and(|b| b.0 <= least(&on)) {
                    continue;
                }
                // No join of this direction is clear when no curve onto the ring is: the ways
                // off are then not solved, nor the joins made (see [`Ends::any_clear`]).
                if !ends.any_clear(&on, step, clear) {
                    continue;
                }
                // The same for the exits and the goal's trap length.
                if trap.1.is_finite() {
                    let maybe =
                        curves_at(ends, &exits, false, &|j| (ring.pts[j] - p2).norm() < trap.1);
                    if !ends.any_clear(&maybe, step, clear) {
                        continue;
                    }
                }
                let off = curves_at(ends, &exits, false, &|_| true);
                // Every join costs at least the shortest way on plus the shortest way off.
                if best
                    .as_ref()
                    .is_some_and(|b| b.0 <= least(&on) + least(&off))
                {
                    continue;
                }
                // Nor when no curve off it is.
                if !ends.any_clear(&off, step, clear) {
                    continue;
                }
                // (cost, entry, exit), the entry and exit as positions in `on` and `off`.
                let mut joins: Vec<(f64, usize, usize)> = on
                    .iter()
                    .enumerate()
                    .flat_map(|(a, &(i, _, li))| {
                        off.iter()
                            .enumerate()
                            .map(move |(b, &(j, _, lj))| (li + ring.along(i, j, dir) + lj, a, b))
                    })
                    .filter(|&(_, a, b)| ring.stretch_clear(on[a].0, off[b].0, dir))
                    .collect();
                // The cheapest MAX_VERIFIED in order of cost (ties in the order made, as a
                // stable sort of them all leaves them): a selection, then a sort of those few.
                let mut order: Vec<(f64, usize)> =
                    joins.iter().enumerate().map(|(k, j)| (j.0, k)).collect();
                let by_cost =
                    |a: &(f64, usize), b: &(f64, usize)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
                if order.len() > MAX_VERIFIED {
                    order.select_nth_unstable_by(MAX_VERIFIED, by_cost);
                    order.truncate(MAX_VERIFIED);
                }
                order.sort_unstable_by(by_cost);
                joins = order.iter().map(|&(_, k)| joins[k]).collect();
                for &(cost, a, b) in joins.iter().take(MAX_VERIFIED) {
                    if best.as_ref().is_some_and(|b| b.0 <= cost) {
                        break;
                    }
                    // A join with an end known not to be clear is passed over first (the
                    // other end's check, not needed for it, is left for a join that needs it).
                    let (ea, eb) = (on[a].1, off[b].1);
                    if ends.known_blocked(ea) || ends.known_blocked(eb) {
                        continue;
                    }
                    if !ends.check(ea, step, clear) || !ends.check(eb, step, clear) {
                        continue;
                    }
                    let (Some(pa), Some(pb)) = (ends.points(ea), ends.points(eb)) else {
                        continue;
                    };
                    let (i, j) = (on[a].0, off[b].0);
                    let mut pts = pa.to_vec();
                    pts.extend(ring.stretch(i, j, dir).into_iter().skip(1));
                    pts.extend(pb.iter().skip(1));
                    let len = crate::geo::polygon::polyline_length(&pts);
                    if best.as_ref().is_none_or(|b| len < b.0) {
                        best = Some((len, pts));
                    }
                    break;
                }
            }
        }
        best.map(|b| b.1)
    }
}

/// A length from which every curve of curvature at most 1/`r` from (`p`, heading `h`)
/// (`forward`; else every one arriving there with that heading) is blocked at one of its
/// points spaced evenly along it, at most `step` apart, the ends included (the points of
/// [`Csc::points`]), by the test whose [`super::clear_map::ClearMap::blocked_margin`] is
/// `margin`: every curve of [`Rings::transit_with`] that long from there onto a ring (or off
/// one to there) is blocked. Infinite when none is found (a budget of [`TRAP_BUDGET`]
/// margins).
///
/// Point `k` of such a curve of length L ≥ ℓ ≥ k·step (n = ⌈L/step⌉ ≥ `k` pieces) lies at arc
/// length σ = k·L/n from the pose, σ between k·step·ℓ/(ℓ + step) and k·step; its heading has
/// turned by at most σ/r, so it lies in the rectangle from r·sin(σ_lo/r) to σ_hi ahead
/// (behind, arriving) and within r·(1 − cos(σ_hi/r)) to either side (σ_hi ≤ r). When that
/// rectangle is blocked throughout, so is point `k` of every curve at least ℓ long; the pairs
/// (k, ℓ) are tried by ℓ. (Most failing headland attempts of narrow fields start facing the
/// edge a few metres ahead, too close to turn away: every curve onto every ring, about 2100,
/// was solved and checked to find that out.)
fn trap_length(
    margin: &dyn Fn(&Vec2) -> f64,
    (p, h, forward): (Vec2, f64, bool),
    r: f64,
    step: f64,
) -> f64 {
    let ahead = heading_vec(h) * if forward { 1.0 } else { -1.0 };
    let side = left_normal(&ahead);
    let most = (r / step).floor().max(0.0) as usize;
    let mut tries: Vec<(f64, usize)> = (1..=most)
        .flat_map(|k| TRAP_LENGTHS.map(|m| (k as f64 * step * m, k)))
        .collect();
    tries.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut budget = TRAP_BUDGET;
    tries
        .into_iter()
        .find(|&(length, k)| {
            let hi = k as f64 * step;
            let lo = hi * length / (length + step);
            let spread = r * (1.0 - (hi / r).cos());
            let rect = ((r * (lo / r).sin(), hi), (-spread, spread));
            let mut tries = TRAP_TRY_BUDGET.min(budget);
            let blocked = blocked_throughout(margin, (p, ahead, side), rect, &mut tries);
            budget -= TRAP_TRY_BUDGET.min(budget) - tries;
            blocked
        })
        .map_or(f64::INFINITY, |t| t.0)
}

/// The lengths tried by [`trap_length`] for point `k`, in k·step.
const TRAP_LENGTHS: [f64; 4] = [1.0, 2.0, 4.0, 16.0];

/// Most margins [`trap_length`] asks for one pose, and for one rectangle.
const TRAP_BUDGET: usize = 256;
const TRAP_TRY_BUDGET: usize = 32;

/// Is the rectangle `u` ahead from `u.0` to `u.1`, `v` to the side from `v.0` to `v.1`, of
/// the frame (`p`, `ahead`, `side`) blocked throughout: every point within the margin of the
/// middle of it, or of each half in turn (the longer side halved), as far as `budget` goes?
fn blocked_throughout(
    margin: &dyn Fn(&Vec2) -> f64,
    frame: (Vec2, Vec2, Vec2),
    (u, v): ((f64, f64), (f64, f64)),
    budget: &mut usize,
) -> bool {
    if *budget == 0 {
        return false;
    }
    *budget -= 1;
    let (p, ahead, side) = frame;
    let (um, vm) = (0.5 * (u.0 + u.1), 0.5 * (v.0 + v.1));
    let (du, dv) = (u.1 - u.0, v.1 - v.0);
    let m = margin(&(p + ahead * um + side * vm));
    if m <= 0.0 {
        return false;
    }
    // Half the diagonal, a millimetre more.
    if m >= 0.5 * (du * du + dv * dv).sqrt() + 1e-3 {
        return true;
    }
    let halves = if du >= dv {
        [((u.0, um), v), ((um, u.1), v)]
    } else {
        [(u, (v.0, vm)), (u, (vm, v.1))]
    };
    halves
        .into_iter()
        .all(|half| blocked_throughout(margin, frame, half, budget))
}

/// Which curve an end of [`Rings::transit_with`] is: the free pose (`p1` of a curve onto a
/// ring, `p2` of one off it), the ring, its point, the direction along it, onto or off, the
/// radius and the spacing of the points (as bits).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct EndKey([u64; 8]);

impl std::hash::Hash for EndKey {
    /// Word by word (the standard hash of an array feeds its bytes one at a time).
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        for w in self.0 {
            state.write_u64(w);
        }
    }
}

impl EndKey {
    fn new(
        (p, h): (Vec2, f64),
        (ring, point, dir, onto): (usize, usize, i32, bool),
        r: f64,
        step: f64,
    ) -> Self {
        let tag = (u64::from(dir > 0) << 1) | u64::from(onto);
        EndKey([
            p.x.to_bits(),
            p.y.to_bits(),
            h.to_bits(),
            ring as u64,
            point as u64,
            tag,
            r.to_bits(),
            step.to_bits(),
        ])
    }
}

/// One curve onto or off a ring: its words shortest first, and the points of its first clear
/// word once checked (`Some(None)`: none is clear).
struct End {
    words: Vec<Csc>,
    clear: Option<Option<Vec<Vec2>>>,
    /// The words at least this long are blocked ([`trap_length`] of its free pose).
    blocked_from: f64,
}

/// The curves onto and off the rings that [`Rings::transit_with`] solved and checked, for the
/// next transit from or to the same pose with the same test (a transit's attempt with its
/// target's start pulled back starts where the one before it did).
#[derive(Default)]
pub struct Ends<'a> {
    index: std::collections::HashMap<EndKey, usize, BuildHasherDefault<EdgeHasher>>,
    ends: Vec<End>,
    /// The test's [`super::clear_map::ClearMap::blocked_margin`], when known: poses no curve
    /// leaves or reaches are found without solving the curves ([`trap_length`]).
    margin: Option<&'a dyn Fn(&Vec2) -> f64>,
    /// [`trap_length`] of the poses asked: (position, heading, forward, radius, spacing).
    traps: std::collections::HashMap<[u64; 6], f64>,
}

impl<'a> Ends<'a> {
    /// No ends yet, with the blocked margin of the test they are used with.
    pub fn with_margin(margin: &'a dyn Fn(&Vec2) -> f64) -> Self {
        Ends {
            margin: Some(margin),
            ..Ends::default()
        }
    }

    /// [`trap_length`] of a pose with the test's margin (infinite without it), found once.
    fn trap_length(&mut self, (p, h, forward): (Vec2, f64, bool), r: f64, step: f64) -> f64 {
        let Some(margin) = self.margin else {
            return f64::INFINITY;
        };
        let key = [
            p.x.to_bits(),
            p.y.to_bits(),
            h.to_bits(),
            u64::from(forward),
            r.to_bits(),
            step.to_bits(),
        ];
        *self
            .traps
            .entry(key)
            .or_insert_with(|| trap_length(margin, (p, h, forward), r, step))
    }

    /// The index of the end `key`, its words solved by `solve` when first asked.
    /// Words at least `blocked_from` m long are known blocked.
    fn solve(&mut self, key: EndKey, blocked_from: f64, solve: impl FnOnce() -> Vec<Csc>) -> usize {
        if let Some(&e) = self.index.get(&key) {
            return e;
        }
        self.ends.push(End {
            words: solve(),
            clear: None,
            blocked_from,
        });
        self.index.insert(key, self.ends.len() - 1);
        self.ends.len() - 1
    }

    /// The length of end `e`'s shortest word; `None` when it has none.
    fn length(&self, e: usize) -> Option<f64> {
        self.ends.get(e)?.words.first().map(|c| c.length)
    }

    /// Is end `e` checked and none of its words clear?
    fn known_blocked(&self, e: usize) -> bool {
        self.ends
            .get(e)
            .is_some_and(|end| matches!(end.clear, Some(None)))
    }

    /// Is one of end `e`'s words clear (its first clear word's points, `step` m apart, kept)?
    /// Checked once.
    fn check(&mut self, e: usize, step: f64, clear: &dyn Fn(&Vec2) -> bool) -> bool {
        let Some(end) = self.ends.get_mut(e) else {
            return false;
        };
        let (words, from) = (&end.words, end.blocked_from);
        end.clear
            .get_or_insert_with(|| {
                words
                    .iter()
                    .find_map(|c| (c.length < from).then(|| c.points(step, clear)).flatten())
            })
            .is_some()
    }

    /// Is one of the ends `v` ((ring point, end, length) as [`Rings::transit_with`] lists
    /// them) clear? Checked shortest first, up to the first clear one; each end's check is
    /// kept, so a join made after this checks no end again. A direction of a ring with no
    /// clear end on one side has no clear join (a join needs a clear end on each side): most
    /// of the failing headland attempts of narrow fields (de_bb_holes_irregular, dk_marker_strip
    /// at w 3 m) found no clear curve onto the ring in three directions of four, after solving
    /// the curves off it and making and ordering the joins of every pair.
    fn any_clear(
        &mut self,
        v: &[(usize, usize, f64)],
        step: f64,
        clear: &dyn Fn(&Vec2) -> bool,
    ) -> bool {
        if v.iter().any(|e| self.points(e.1).is_some()) {
            return true;
        }
        let mut order: Vec<(f64, usize)> = v.iter().map(|e| (e.2, e.1)).collect();
        order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        order
            .into_iter()
            .any(|(_, e)| !self.known_blocked(e) && self.check(e, step, clear))
    }

    /// The points of end `e`'s first clear word, once checked.
    fn points(&self, e: usize) -> Option<&[Vec2]> {
        self.ends.get(e)?.clear.as_ref()?.as_deref()
    }
}

#[cfg(test)]
mod trap_tests;

#[cfg(test)]
mod tests;
