//! Continuous-curvature Reeds-Shepp paths: zero curvature at the start, the goal and every
//! cusp, |κ| ≤ κ_max, |dκ/ds| ≤ σ_max (docs/METHODS.md, Curves; Fraichard & Scheuer, "From Reeds
//! and Shepp's to continuous-curvature paths", IEEE T-RO 2004; the CC00-RS families of Banzhaf et
//! al., `steering_functions`, were used to learn the circle geometry — own formulation and code).
//!
//! # Geometry
//!
//! Every CC turn ([`super::cc_turn`]) starting at a κ = 0 configuration q lies on a *CC
//! circle*: centre Ω, radius R = R_Ω, the heading at q at angle μ from the circle tangent, and
//! ends on the same circle at angle μ again. In the frame of a configuration (x forward, y
//! left), with l = +1 for left steering / −1 right and s = +1 forward / −1 reverse:
//!
//! * q *enters* the circle (l, s) with centre  Ω = q + R·(s·sin μ,  l·cos μ),
//! * q *leaves* the circle (l, s) with centre  Ω = q + R·(−s·sin μ, l·cos μ),
//!
//! and a turn from an entering heading θa to a leaving heading θb has deflection
//! δ = (l·s·(θb − θa)) mod 2π, length [`CcCircle::circle_turn_length`]`(δ)`. A junction q between a
//! turn on circle 1 and one on circle 2 (a cusp when s1 ≠ s2) therefore fixes
//! Ω2 − Ω1 = R·rot(θ_q)·((s1 + s2)·sin μ, (l2 − l1)·cos μ); a straight piece between them adds
//! its signed length along θ_q. This gives closed forms for the families built here:
//!
//! * **TST** with any driving directions of the three pieces (Banzhaf's TST, TcST, TScT,
//!   TcScT): 4 start circles × 4 goal circles × 2 line directions, two roots each;
//! * **TTT** with any directions (TTT, TcTT, TTcT, TcTcT, and TT/TcT in the limit): the middle
//!   circle centre is an intersection of two circles around the start and goal centres;
//!   4 × 4 × 4 circle types, two intersections each;
//! * **TcTST, TSTcT, TcTSTcT** (Reeds-Shepp's C|CSC, CSC|C, C|CSC|C): intermediate turns of
//!   fixed deflection (Reeds & Shepp's optimal π/2 for plain paths; 0.4π and 0.6π as well change the mean length by < 0.1 %); then the offset
//!   between the start and goal centres is linear in the signed straight length, which comes
//!   from a quadratic (`Solver::chain`);
//! * **TTcTT, TcTTcT** (C C|C C, C|C C|C): the two intermediate circles placed mirror- or
//!   point-symmetrically about the middle of the start and goal centres (as Banzhaf does).
//!
//! The chain and four-turn constructions fix one degree of freedom heuristically (as
//! Reeds-Shepp's optimal families do for plain paths and Banzhaf does for CC paths), so the
//! result is the shortest of these candidates, not a proven optimum.
//!
//! The shortest candidate is built into segments and its end is checked against the goal.

use super::cc_turn::CcCircle;
use super::path::{CurveParams, CurvePath, CurveSegment};
use crate::geo::{v2, wrap_angle, Direction, Pose, Vec2};
use std::f64::consts::{PI, TAU};

/// One piece of a candidate.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Piece {
    /// CC turn: deflection δ ≥ 0 (rad), steering sense l = ±1, direction s = ±1.
    Turn { delta: f64, l: f64, s: f64 },
    /// Straight: length ≥ 0 (m), direction s = ±1.
    Line { len: f64, s: f64 },
}

impl Piece {
    fn turn(delta: f64, l: f64, s: f64) -> Piece {
        Piece::Turn { delta, l, s }
    }
}

#[derive(Debug, Clone, Copy)]
struct Candidate {
    len: f64,
    n: usize,
    pieces: [Piece; 6],
}

const NO_PIECE: Piece = Piece::Line { len: 0.0, s: 1.0 };

impl Candidate {
    fn new(len: f64, p: &[Piece]) -> Self {
        let mut pieces = [NO_PIECE; 6];
        pieces[..p.len()].copy_from_slice(p);
        Candidate {
            len,
            n: p.len(),
            pieces,
        }
    }
}

/// Candidates offered in order, kept only when shorter than every earlier one (so the list
/// is by decreasing length and its last entry is the shortest).
struct Cands {
    best: f64,
    list: Vec<Candidate>,
}

impl Cands {
    fn new() -> Self {
        Cands {
            best: f64::INFINITY,
            list: Vec::with_capacity(16),
        }
    }

    #[inline]
    fn offer(&mut self, c: Candidate) {
        if c.len < self.best {
            self.best = c.len;
            self.list.push(c);
        }
    }
}

/// An intermediate turn of fixed deflection in a chain.
#[derive(Debug, Clone, Copy)]
struct Mid {
    /// Steering sense ±1.
    l: f64,
    /// Direction ±1.
    s: f64,
    /// Deflection, rad, with its sine and cosine.
    delta: f64,
    sin: f64,
    cos: f64,
    /// Turn length, m.
    len: f64,
}

/// A CC circle placed in the plane.
#[derive(Debug, Clone, Copy)]
struct Circ {
    c: Vec2,
    l: f64,
    s: f64,
}

/// Fixed deflections (rad) tried for the intermediate turns of the chain families.
const MID_DEFLECTIONS: [f64; 1] = [0.5 * PI];

const TYPES: [(f64, f64); 4] = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)];

#[inline]
fn deflection(l: f64, s: f64, from: f64, to: f64) -> f64 {
    let mut d = l * s * (to - from);
    if !d.is_finite() {
        return f64::INFINITY;
    }
    if d.abs() > 8.0 * TAU {
        d = d.rem_euclid(TAU);
    }
    while d < 0.0 {
        d += TAU;
    }
    while d >= TAU {
        d -= TAU;
    }
    if d > TAU - 1e-10 {
        0.0
    } else {
        d
    }
}

#[inline]
fn dir(s: f64) -> Direction {
    if s > 0.0 {
        Direction::Forward
    } else {
        Direction::Reverse
    }
}

struct Solver<'a> {
    g: &'a CcCircle,
    start: Pose,
    goal: Pose,
    starts: [Circ; 4],
    goals: [Circ; 4],
    /// Direction angle of each junction offset, by type index (see [`tidx`]).
    jang: [[f64; 4]; 4],
    /// Junction point as a complex factor of the centre offset: q = Ω_a + f·(Ω_b − Ω_a)
    /// (independent of the junction heading), by type index; used for chord lower bounds.
    jq: [[Vec2; 4]; 4],
    /// Length of the shortest CC turn (δ = 0: 2·R·sin μ), m; a lower bound for every turn
    /// (turn length is non-decreasing in δ), used to prune candidates early.
    tl0: f64,
}

/// Index of a circle type in [`TYPES`].
#[inline]
fn tidx(l: f64, s: f64) -> usize {
    (if l < 0.0 { 2 } else { 0 }) + usize::from(s < 0.0)
}

impl<'a> Solver<'a> {
    fn new(g: &'a CcCircle, start: &Pose, goal: &Pose) -> Self {
        let r = g.radius;
        let mk = |q: &Pose, entering: bool| {
            let (sn, cs) = q.heading.sin_cos();
            TYPES.map(|(l, s)| {
                let fx = if entering { s } else { -s };
                let (x, y) = (r * fx * g.sin_mu, r * l * g.cos_mu);
                Circ {
                    c: q.pos + v2(cs * x - sn * y, sn * x + cs * y),
                    l,
                    s,
                }
            })
        };
        let mut jang = [[0.0; 4]; 4];
        let mut jq = [[v2(0.0, 0.0); 4]; 4];
        for (i, &(l1, s1)) in TYPES.iter().enumerate() {
            for (j, &(l2, s2)) in TYPES.iter().enumerate() {
                let v = v2(r * (s1 + s2) * g.sin_mu, r * (l2 - l1) * g.cos_mu);
                jang[i][j] = v.y.atan2(v.x);
                // (q − Ω_a) = R·rot(θ)·(s_a sin μ, −l_a cos μ); divide by v as complex numbers.
                let w = v2(r * s1 * g.sin_mu, -r * l1 * g.cos_mu);
                let n2 = v.norm_squared();
                jq[i][j] = if n2 > 0.0 {
                    v2((w.x * v.x + w.y * v.y) / n2, (w.y * v.x - w.x * v.y) / n2)
                } else {
                    v2(0.0, 0.0)
                };
            }
        }
        Solver {
            g,
            start: *start,
            goal: *goal,
            starts: mk(start, true),
            goals: mk(goal, false),
            jang,
            jq,
            tl0: g.circle_turn_length(0.0),
        }
    }

    /// Junction point between circles `a` (type ia, centre ca) and `b`.
    #[inline]
    fn jpoint(&self, ia: usize, ca: Vec2, ib: usize, cb: Vec2) -> Vec2 {
        let f = self.jq[ia][ib];
        let d = cb - ca;
        ca + v2(f.x * d.x - f.y * d.y, f.x * d.y + f.y * d.x)
    }

    /// Offset Ω2 − Ω1 of a junction between circle types (l1, s1) → (l2, s2), in the frame of
    /// the junction heading.
    #[inline]
    fn junction(&self, l1: f64, s1: f64, l2: f64, s2: f64) -> Vec2 {
        v2(
            self.g.radius * (s1 + s2) * self.g.sin_mu,
            self.g.radius * (l2 - l1) * self.g.cos_mu,
        )
    }

    fn tst(&self, out: &mut Cands) {
        let (th0, thg) = (self.start.heading, self.goal.heading);
        for c1 in &self.starts {
            for c2 in &self.goals {
                let v = self.junction(c1.l, c1.s, c2.l, c2.s);
                let (a, b) = (v.x, v.y);
                let d = c2.c - c1.c;
                let d2 = d.norm_squared();
                if d2 < b * b {
                    continue;
                }
                let root = (d2 - b * b).sqrt();
                let mut ang = None;
                for x in [root, -root] {
                    for sl in [1.0, -1.0] {
                        let len = sl * (x - a);
                        if len < -1e-12 || len + 2.0 * self.tl0 >= out.best {
                            continue;
                        }
                        let ang = *ang.get_or_insert_with(|| d.y.atan2(d.x));
                        let th = ang - b.atan2(x);
                        let d1 = deflection(c1.l, c1.s, th0, th);
                        let d2 = deflection(c2.l, c2.s, th, thg);
                        let len = len.max(0.0);
                        out.offer(Candidate::new(
                            self.g.circle_turn_length(d1) + len + self.g.circle_turn_length(d2),
                            &[
                                Piece::turn(d1, c1.l, c1.s),
                                Piece::Line { len, s: sl },
                                Piece::turn(d2, c2.l, c2.s),
                            ],
                        ));
                    }
                }
            }
        }
    }

    fn ttt(&self, out: &mut Cands) {
        if 3.0 * self.tl0 >= out.best {
            return;
        }
        let (th0, thg) = (self.start.heading, self.goal.heading);
        for c1 in &self.starts {
            for c3 in &self.goals {
                let dv = c3.c - c1.c;
                let d = dv.norm();
                if d < 1e-12 {
                    continue;
                }
                let u = dv / d;
                for (l2, s2) in TYPES {
                    let v12 = self.junction(c1.l, c1.s, l2, s2);
                    let v23 = self.junction(l2, s2, c3.l, c3.s);
                    let (r1, r2) = (v12.norm(), v23.norm());
                    if r1 < 1e-9 || r2 < 1e-9 || d > r1 + r2 || d < (r1 - r2).abs() {
                        continue;
                    }
                    let a = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d);
                    let h = (r1 * r1 - a * a).max(0.0).sqrt();
                    let p = c1.c + u * a;
                    for sg in [1.0, -1.0] {
                        let o2 = p + v2(-u.y, u.x) * (sg * h);
                        let (i1, i2, i3) = (tidx(c1.l, c1.s), tidx(l2, s2), tidx(c3.l, c3.s));
                        let q1 = self.jpoint(i1, c1.c, i2, o2);
                        let q2 = self.jpoint(i2, o2, i3, c3.c);
                        let chord = (q1 - self.start.pos).norm()
                            + (q2 - q1).norm()
                            + (self.goal.pos - q2).norm();
                        if chord >= out.best {
                            if h == 0.0 {
                                break;
                            }
                            continue;
                        }
                        let e12 = o2 - c1.c;
                        let e23 = c3.c - o2;
                        let th1 = e12.y.atan2(e12.x) - self.jang[tidx(c1.l, c1.s)][tidx(l2, s2)];
                        let th2 = e23.y.atan2(e23.x) - self.jang[tidx(l2, s2)][tidx(c3.l, c3.s)];
                        let d1 = deflection(c1.l, c1.s, th0, th1);
                        let t1 = self.g.circle_turn_length(d1);
                        if t1 + 2.0 * self.tl0 >= out.best {
                            continue;
                        }
                        let d2 = deflection(l2, s2, th1, th2);
                        let t12 = t1 + self.g.circle_turn_length(d2);
                        if t12 + self.tl0 >= out.best {
                            continue;
                        }
                        let d3 = deflection(c3.l, c3.s, th2, thg);
                        out.offer(Candidate::new(
                            t12 + self.g.circle_turn_length(d3),
                            &[
                                Piece::turn(d1, c1.l, c1.s),
                                Piece::turn(d2, l2, s2),
                                Piece::turn(d3, c3.l, c3.s),
                            ],
                        ));
                        if h == 0.0 {
                            break;
                        }
                    }
                }
            }
        }
    }

    /// A chain start circle → intermediate circles of fixed deflection → goal circle with
    /// one straight piece (direction `sl`) at junction `line_at` (0 = right after the start
    /// circle). With the intermediate deflections fixed, the offset Ω_goal − Ω_start in the
    /// frame of the first junction heading is P + X·e (X the signed line length), so
    /// |Ω_goal − Ω_start| gives X from a quadratic and the direction of Ω_goal − Ω_start the
    /// first junction heading.
    fn chain(&self, c1: &Circ, cn: &Circ, mids: &[Mid], line_at: usize, sl: f64, out: &mut Cands) {
        let k = mids.len();
        let mid_len: f64 = mids.iter().map(|m| m.len).sum();
        if mid_len + 2.0 * self.tl0 >= out.best {
            return;
        }
        let ty = |i: usize| -> (f64, f64) {
            if i == 0 {
                (c1.l, c1.s)
            } else if i == k + 1 {
                (cn.l, cn.s)
            } else {
                (mids[i - 1].l, mids[i - 1].s)
            }
        };
        let mut phi = 0.0;
        let (mut sn, mut cs) = (0.0, 1.0);
        let mut p = v2(0.0, 0.0);
        let mut e = v2(1.0, 0.0);
        for j in 0..=k {
            if j > 0 {
                let m = &mids[j - 1];
                phi += m.l * m.s * m.delta;
                // Rotate by l·s·δ using the precomputed sin δ, cos δ.
                let (ms, mc) = (m.l * m.s * m.sin, m.cos);
                (sn, cs) = (sn * mc + cs * ms, cs * mc - sn * ms);
            }
            let (l1, s1) = ty(j);
            let (l2, s2) = ty(j + 1);
            let v = self.junction(l1, s1, l2, s2);
            p += v2(cs * v.x - sn * v.y, sn * v.x + cs * v.y);
            if j == line_at {
                e = v2(cs, sn);
            }
        }
        let w = cn.c - c1.c;
        let pe = p.dot(&e);
        let disc = pe * pe - p.norm_squared() + w.norm_squared();
        if disc < 0.0 {
            return;
        }
        let root = disc.sqrt();
        let mut wa = None;
        for x in [-pe + root, -pe - root] {
            let len = sl * x;
            if len < -1e-12 || len + mid_len + 2.0 * self.tl0 >= out.best {
                continue;
            }
            let wa = *wa.get_or_insert_with(|| w.y.atan2(w.x));
            let len = len.max(0.0);
            let q = p + e * x;
            let th0 = wa - q.y.atan2(q.x);
            let d1 = deflection(c1.l, c1.s, self.start.heading, th0);
            let dn = deflection(cn.l, cn.s, th0 + phi, self.goal.heading);
            let mut pieces = [NO_PIECE; 6];
            let mut n = 0;
            pieces[n] = Piece::turn(d1, c1.l, c1.s);
            n += 1;
            for j in 0..=k {
                if j > 0 {
                    let m = &mids[j - 1];
                    pieces[n] = Piece::turn(m.delta, m.l, m.s);
                    n += 1;
                }
                if j == line_at {
                    pieces[n] = Piece::Line { len, s: sl };
                    n += 1;
                }
            }
            pieces[n] = Piece::turn(dn, cn.l, cn.s);
            n += 1;
            out.offer(Candidate {
                len: self.g.circle_turn_length(d1) + mid_len + len + self.g.circle_turn_length(dn),
                n,
                pieces,
            });
        }
    }

    /// TcTST, TSTcT and TcTSTcT (Reeds-Shepp's C|CSC, CSC|C, C|CSC|C) with the intermediate
    /// turns at fixed deflections (Reeds & Shepp's optimal value π/2 and a few around it).
    fn chains(&self, out: &mut Cands) {
        for &dm in &MID_DEFLECTIONS {
            let len = self.g.circle_turn_length(dm);
            let (sin, cos) = dm.sin_cos();
            let mid = |l: f64, s: f64| Mid {
                l,
                s,
                delta: dm,
                len,
                sin,
                cos,
            };
            for c1 in &self.starts {
                for cn in &self.goals {
                    if cn.s == -c1.s {
                        // TcTST: start, cusp, middle (−l1, −s1), straight −s1, goal (·, −s1).
                        self.chain(c1, cn, &[mid(-c1.l, -c1.s)], 1, -c1.s, out);
                        // TSTcT: start, straight s1, middle (−ln, s1), cusp, goal (ln, −s1).
                        self.chain(c1, cn, &[mid(-cn.l, c1.s)], 0, c1.s, out);
                    } else if cn.l == -c1.l {
                        // TcTSTcT: start, cusp, (−l1, −s1), straight, (l1, −s1), cusp, goal.
                        let mids = [mid(-c1.l, -c1.s), mid(c1.l, -c1.s)];
                        self.chain(c1, cn, &mids, 1, -c1.s, out);
                    }
                }
            }
        }
    }

    /// Four turns with the two intermediate circles placed symmetrically (mirror or point
    /// symmetry about the middle of the start and goal centres): TTcTT (C C|C C) and TcTTcT
    /// (C|C C|C).
    fn four_turns(&self, out: &mut Cands) {
        if 4.0 * self.tl0 >= out.best {
            return;
        }
        for c1 in &self.starts {
            for cn in &self.goals {
                if cn.l != -c1.l {
                    continue;
                }
                let (l1, s1) = (c1.l, c1.s);
                let (m1, m2) = if cn.s == -s1 {
                    ((-l1, s1), (l1, -s1)) // TTcTT
                } else {
                    ((-l1, -s1), (l1, -s1)) // TcTTcT
                };
                self.sym4(c1, m1, m2, cn, out);
            }
        }
    }

    fn sym4(&self, c1: &Circ, m1: (f64, f64), m2: (f64, f64), cn: &Circ, out: &mut Cands) {
        let v = [
            self.junction(c1.l, c1.s, m1.0, m1.1),
            self.junction(m1.0, m1.1, m2.0, m2.1),
            self.junction(m2.0, m2.1, cn.l, cn.s),
        ];
        let (d12, d23) = (v[0].norm(), v[1].norm());
        let w = cn.c - c1.c;
        let dd = w.norm();
        if dd < 1e-12 || (d12 - v[2].norm()).abs() > 1e-9 {
            return;
        }
        let u = w / dd;
        let nrm = v2(-u.y, u.x);
        // (Δx, mirror?) options.
        let opts = [
            (0.5 * (dd - d23), true),
            (0.5 * (dd + d23), true),
            ((dd * dd + 4.0 * d12 * d12 - d23 * d23) / (4.0 * dd), false),
        ];
        for (dx, mirror) in opts {
            let h2 = d12 * d12 - dx * dx;
            if h2 < 0.0 {
                continue;
            }
            let dy0 = h2.sqrt();
            for dy in [dy0, -dy0] {
                let o2 = c1.c + u * dx + nrm * dy;
                let o3 = if mirror {
                    cn.c - u * dx + nrm * dy
                } else {
                    cn.c - u * dx - nrm * dy
                };
                let cs = [c1.c, o2, o3, cn.c];
                let ids = [
                    tidx(c1.l, c1.s),
                    tidx(m1.0, m1.1),
                    tidx(m2.0, m2.1),
                    tidx(cn.l, cn.s),
                ];
                let mut chord = 0.0;
                let mut last = self.start.pos;
                for j in 0..3 {
                    let q = self.jpoint(ids[j], cs[j], ids[j + 1], cs[j + 1]);
                    chord += (q - last).norm();
                    last = q;
                }
                chord += (self.goal.pos - last).norm();
                if chord >= out.best {
                    if dy0 == 0.0 {
                        break;
                    }
                    continue;
                }
                let mut th = [0.0; 3];
                for j in 0..3 {
                    let e = cs[j + 1] - cs[j];
                    th[j] = e.y.atan2(e.x) - v[j].y.atan2(v[j].x);
                }
                let d1 = deflection(c1.l, c1.s, self.start.heading, th[0]);
                let d2 = deflection(m1.0, m1.1, th[0], th[1]);
                let d3 = deflection(m2.0, m2.1, th[1], th[2]);
                let d4 = deflection(cn.l, cn.s, th[2], self.goal.heading);
                let g = self.g;
                out.offer(Candidate::new(
                    g.circle_turn_length(d1)
                        + g.circle_turn_length(d2)
                        + g.circle_turn_length(d3)
                        + g.circle_turn_length(d4),
                    &[
                        Piece::turn(d1, c1.l, c1.s),
                        Piece::turn(d2, m1.0, m1.1),
                        Piece::turn(d3, m2.0, m2.1),
                        Piece::turn(d4, cn.l, cn.s),
                    ],
                ));
                if dy0 == 0.0 {
                    break;
                }
            }
        }
    }

    fn all(&self, out: &mut Cands) {
        self.tst(out);
        self.ttt(out);
        self.chains(out);
        self.four_turns(out);
    }

    fn build(&self, cand: &Candidate) -> CurvePath {
        let mut segments = Vec::with_capacity(9);
        for p in &cand.pieces[..cand.n] {
            match *p {
                Piece::Turn { delta, l, s } => {
                    self.g.turn_segments(delta, l > 0.0, dir(s), &mut segments)
                }
                Piece::Line { len, s } => {
                    if len > 0.0 {
                        segments.push(CurveSegment::line(dir(s), len));
                    }
                }
            }
        }
        CurvePath {
            start: self.start,
            segments,
        }
    }
}

fn valid_params(p: &CurveParams) -> bool {
    p.kappa_max > 0.0 && p.sigma_max > 0.0 && p.kappa_max.is_finite() && p.sigma_max.is_finite()
}

/// Start and goal equal (1 µm, 1 µrad): the empty path.
fn same_pose(a: &Pose, b: &Pose) -> bool {
    (a.pos - b.pos).norm() < 1e-6 && wrap_angle(a.heading - b.heading).abs() < 1e-6
}

fn finite(p: &Pose) -> bool {
    p.pos.x.is_finite() && p.pos.y.is_finite() && p.heading.is_finite()
}

/// Shortest continuous-curvature Reeds-Shepp path among the families of the module doc (TST,
/// TcST, TScT, TcScT, TTT, TcTT, TTcT, TcTcT, TcTST, TSTcT, TcTSTcT, TTcTT, TcTTcT).
/// Curvature is 0 at the start, the goal and every cusp. `None` only for invalid parameters
/// or non-finite poses (the TST family with both turns on the same side always has a
/// solution).
pub fn cc_reeds_shepp_shortest(
    start: &Pose,
    goal: &Pose,
    params: &CurveParams,
) -> Option<CurvePath> {
    if !valid_params(params) || !finite(start) || !finite(goal) {
        return None;
    }
    if same_pose(start, goal) {
        return Some(CurvePath {
            start: *start,
            segments: Vec::new(),
        });
    }
    let g = CcCircle::new(params);
    let solver = Solver::new(&g, start, goal);
    let mut cands = Cands::new();
    solver.all(&mut cands);
    // Build the shortest candidate whose end reaches the goal (a guard against numerically
    // degenerate junctions; in practice the first one tried).
    let tol = 1e-6 * (1.0 + (goal.pos - start.pos).norm());
    for c in cands.list.iter().rev().take(8) {
        let path = solver.build(c);
        let end = path.end_pose();
        if (end.pos - goal.pos).norm() < tol && wrap_angle(end.heading - goal.heading).abs() < 1e-7
        {
            return Some(path);
        }
        tracing::debug!(?c, ?end, "CC-RS candidate does not reach the goal");
    }
    None
}

/// Length (m) of [`cc_reeds_shepp_shortest`] without building segments (the end check of the
/// full builder is skipped).
pub fn cc_reeds_shepp_length(start: &Pose, goal: &Pose, params: &CurveParams) -> Option<f64> {
    if !valid_params(params) || !finite(start) || !finite(goal) {
        return None;
    }
    if same_pose(start, goal) {
        return Some(0.0);
    }
    let g = CcCircle::new(params);
    let solver = Solver::new(&g, start, goal);
    let mut cands = Cands::new();
    solver.all(&mut cands);
    cands.list.last().map(|c| c.len)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    const P: CurveParams = CurveParams {
        kappa_max: 0.2,
        sigma_max: 0.1,
    };

    #[test]
    fn straight_ahead_is_a_straight_line() {
        let a = Pose::new(0.0, 0.0, 0.3);
        let b = Pose::new(20.0 * 0.3f64.cos(), 20.0 * 0.3f64.sin(), 0.3);
        let path = cc_reeds_shepp_shortest(&a, &b, &P).expect("path");
        assert!((path.length() - 20.0).abs() < 1e-9, "{}", path.length());
        assert_eq!(path.cusps(), 0);
        assert!(path.max_curvature() < 1e-12);
    }

    #[test]
    fn same_length_both_ways_and_never_shorter_than_rs() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..300 {
            let mut p = || {
                Pose::new(
                    rng.gen_range(-15.0..15.0),
                    rng.gen_range(-15.0..15.0),
                    rng.gen_range(-PI..PI),
                )
            };
            let (a, b) = (p(), p());
            let ab = cc_reeds_shepp_length(&a, &b, &P).expect("length");
            let ba = cc_reeds_shepp_length(&b, &a, &P).expect("length");
            assert!((ab - ba).abs() < 1e-6 * ab.max(1.0), "{ab} vs {ba}");
            let rs = super::super::reeds_shepp::reeds_shepp_length(&a, &b, 1.0 / P.kappa_max)
                .expect("rs");
            assert!(ab >= rs - 1e-9);
        }
    }

    #[test]
    fn same_pose_is_the_empty_path() {
        let a = Pose::new(3.0, 4.0, 1.0);
        let path = cc_reeds_shepp_shortest(&a, &a, &P).expect("path");
        assert!(path.segments.is_empty());
        assert_eq!(cc_reeds_shepp_length(&a, &a, &P), Some(0.0));
        // Nearly the same pose still gets a real (valid) path.
        let b = Pose::new(3.001, 4.0, 1.0);
        let path = cc_reeds_shepp_shortest(&a, &b, &P).expect("path");
        assert!((path.end_pose().pos - b.pos).norm() < 1e-6);
    }

    #[test]
    fn rejects_bad_input() {
        let a = Pose::new(0.0, 0.0, 0.0);
        let bad = CurveParams {
            kappa_max: 0.0,
            sigma_max: 1.0,
        };
        assert!(cc_reeds_shepp_shortest(&a, &a, &bad).is_none());
        let nan = Pose {
            pos: v2(f64::NAN, 0.0),
            heading: 0.0,
        };
        assert!(cc_reeds_shepp_length(&a, &nan, &P).is_none());
    }
}
