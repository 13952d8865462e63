//! Transits along the headland: the headland passes are closed, driveable tracks (curvature
//! ≤ 1/r_min, clear of the edge by w/2), so a transit that cannot go direct can turn onto a
//! pass, follow it and turn off it near its goal, as a driver does on the headland. Fields2Cover
//! routes the same way (its route planner joins the swaths through the headland rings); this
//! is a search over a few entry and exit points per ring, not over the whole field, so it costs
//! a few Dubins curves where the waypoint search of [`super::transit::route_graph`] costs
//! thousands.

#[cfg(test)]
use super::transit::transit;
use super::transit::{words_by_length, Csc};
use crate::geo::{vec_heading, Vec2};

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
}

impl Ring {
    fn new(track: &[Vec2], clear: &dyn Fn(&Vec2) -> bool) -> Option<Self> {
        let mut pts: Vec<Vec2> = track.to_vec();
        if pts.len() >= 2 && (pts[pts.len() - 1] - pts[0]).norm() < 1e-9 {
            pts.pop();
        }
        if pts.len() < 4 {
            return None;
        }
        let n = pts.len();
        let mut cum = Vec::with_capacity(n + 1);
        let mut blocked = Vec::with_capacity(n + 1);
        let (mut len, mut b) = (0.0, 0u32);
        for i in 0..n {
            cum.push(len);
            blocked.push(b);
            len += (pts[(i + 1) % n] - pts[i]).norm();
            b += u32::from(!clear(&pts[i]));
        }
        cum.push(len);
        blocked.push(b);
        if b as usize == n {
            return None;
        }
        Some(Ring { pts, cum, blocked })
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
    /// [`CANDIDATES_PER_END`].
    fn near(&self, q: &Vec2, reach: f64) -> Vec<usize> {
        let d: Vec<f64> = self.pts.iter().map(|p| (p - q).norm()).collect();
        let nearest = d.iter().copied().fold(f64::INFINITY, f64::min);
        let all: Vec<usize> = (0..self.len())
            .filter(|&i| d[i] <= nearest + reach && self.blocked[i + 1] == self.blocked[i])
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
    /// The tracks (closed: first point repeated last, or not) with their clear points.
    pub fn new(tracks: &[Vec<Vec2>], clear: &dyn Fn(&Vec2) -> bool) -> Self {
        Rings {
            rings: tracks.iter().filter_map(|t| Ring::new(t, clear)).collect(),
        }
    }

    /// A clear transit from (`p1`, heading `h1`) to (`p2`, `h2`): a Dubins curve of radius
    /// `r` onto a ring, the ring's clear points, a Dubins curve off it; the shortest such of
    /// the candidates tried, `None` when none is clear. Points about `step` m apart.
    #[allow(clippy::too_many_arguments)]
    pub fn transit(
        &self,
        p1: Vec2,
        h1: f64,
        p2: Vec2,
        h2: f64,
        r: f64,
        step: f64,
        clear: &dyn Fn(&Vec2) -> bool,
    ) -> Option<Vec<Vec2>> {
        let reach = 4.0 * r;
        let mut best: Option<(f64, Vec<Vec2>)> = None;
        for ring in &self.rings {
            let entries = ring.near(&p1, reach);
            let exits = ring.near(&p2, reach);
            if entries.is_empty() || exits.is_empty() {
                continue;
            }
            // Every way through this ring is at least as long as the straight distances to
            // its nearest entry and from its nearest exit: none beats the best so far when
            // those do not (a micrometre of margin for the rounding of the curves' lengths).
            let nearest = |q: &Vec2, pts: &[usize]| {
                pts.iter()
                    .map(|&i| (ring.pts[i] - q).norm())
                    .fold(f64::INFINITY, f64::min)
            };
            let bound = nearest(&p1, &entries) + nearest(&p2, &exits) - 1e-6;
            if best.as_ref().is_some_and(|b| b.0 <= bound) {
                continue;
            }
            for dir in [1, -1] {
                // The curves on at each entry and off at each exit, shortest first (solved once:
                // their lengths bound the joins, then the joins verified check their points).
                let curves = |a: (Vec2, f64), b: (Vec2, f64)| {
                    let words = words_by_length(a.0, a.1, b.0, b.1, r);
                    let length = words.first().map(|c| c.length);
                    length.map(|l| (l, words))
                };
                let on: Vec<(usize, (f64, Vec<Csc>))> = entries
                    .iter()
                    .filter_map(|&i| {
                        Some((i, curves((p1, h1), (ring.pts[i], ring.heading(i, dir)))?))
                    })
                    .collect();
                let off: Vec<(usize, (f64, Vec<Csc>))> = exits
                    .iter()
                    .filter_map(|&j| {
                        Some((j, curves((ring.pts[j], ring.heading(j, dir)), (p2, h2))?))
                    })
                    .collect();
                let ins: Vec<(usize, f64)> = on.iter().map(|(i, c)| (*i, c.0)).collect();
                let outs: Vec<(usize, f64)> = off.iter().map(|(j, c)| (*j, c.0)).collect();
                // The first curve whose points are all clear ([`transit`] of the same poses).
                let first_clear = |words: &[Csc]| words.iter().find_map(|c| c.points(step, clear));
                // Every join costs at least the shortest way on plus the shortest way off.
                let least =
                    |v: &[(usize, f64)]| v.iter().map(|e| e.1).fold(f64::INFINITY, f64::min);
                if best
                    .as_ref()
                    .is_some_and(|b| b.0 <= least(&ins) + least(&outs))
                {
                    continue;
                }
                let mut joins: Vec<(f64, usize, usize)> = ins
                    .iter()
                    .flat_map(|&(i, li)| {
                        outs.iter()
                            .map(move |&(j, lj)| (li + ring.along(i, j, dir) + lj, i, j))
                    })
                    .filter(|&(_, i, j)| ring.stretch_clear(i, j, dir))
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
                let mut curve_in = std::collections::HashMap::new();
                let mut curve_out = std::collections::HashMap::new();
                for &(cost, i, j) in joins.iter().take(MAX_VERIFIED) {
                    if best.as_ref().is_some_and(|b| b.0 <= cost) {
                        break;
                    }
                    let a = curve_in
                        .entry(i)
                        .or_insert_with(|| {
                            // (The entries and exits are in ring order.)
                            let k = on.binary_search_by_key(&i, |e| e.0).ok()?;
                            first_clear(&on[k].1 .1)
                        })
                        .clone();
                    let Some(a) = a else { continue };
                    let b = curve_out
                        .entry(j)
                        .or_insert_with(|| {
                            let k = off.binary_search_by_key(&j, |e| e.0).ok()?;
                            first_clear(&off[k].1 .1)
                        })
                        .clone();
                    let Some(b) = b else { continue };
                    let mut pts = a;
                    pts.extend(ring.stretch(i, j, dir).into_iter().skip(1));
                    pts.extend(b.into_iter().skip(1));
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;

    /// A U-shaped field's ring: the way from one arm's tip to the other's goes round the bay,
    /// where a direct curve would cross it.
    #[test]
    fn a_transit_follows_the_ring_round_a_bay() {
        // Track round a U (arms 20 m wide, bay 60 m wide and 80 m deep), 1 m apart.
        let corners = [
            v2(0.0, 0.0),
            v2(100.0, 0.0),
            v2(100.0, 100.0),
            v2(80.0, 100.0),
            v2(80.0, 20.0),
            v2(20.0, 20.0),
            v2(20.0, 100.0),
            v2(0.0, 100.0),
            v2(0.0, 0.0),
        ];
        let track = crate::geo::polygon::resample(&corners, 1.0);
        // Clear: within 10.5 m of the track (a corridor), sharp corners allowed for the test.
        let near_track = |q: &Vec2| {
            corners
                .windows(2)
                .any(|s| crate::geo::polygon::point_segment_distance(q, &s[0], &s[1]) <= 10.5)
        };
        let rings = Rings::new(&[track], &near_track);
        let from = v2(10.0, 90.0);
        let to = v2(90.0, 90.0);
        let pts = rings
            .transit(
                from,
                std::f64::consts::FRAC_PI_2,
                to,
                -std::f64::consts::FRAC_PI_2,
                3.0,
                0.5,
                &near_track,
            )
            .expect("a way round the bay");
        assert!(pts.iter().all(near_track));
        assert!((pts[0] - from).norm() < 1e-9);
        assert!((pts[pts.len() - 1] - to).norm() < 1e-9);
        // It went round the bottom of the U: it crosses the bay's middle (x = 50) only below
        // the bay's mouth of clear ground (the bottom strip, y 0–20, and 10.5 m beyond it).
        let crossings: Vec<f64> = pts
            .windows(2)
            .filter(|s| (s[0].x - 50.0) * (s[1].x - 50.0) <= 0.0)
            .map(|s| s[0].y)
            .collect();
        assert!(!crossings.is_empty());
        assert!(crossings.iter().all(|&y| y < 30.5), "{crossings:?}");
        // A direct curve would cross the bay.
        let (direct, ok) = transit(
            from,
            std::f64::consts::FRAC_PI_2,
            to,
            -std::f64::consts::FRAC_PI_2,
            3.0,
            0.5,
            &near_track,
        )
        .unwrap();
        assert!(!ok && !direct.is_empty());
    }
}
