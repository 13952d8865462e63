//! Continuous-curvature Reeds-Shepp paths: zero curvature at the start, the goal and every
//! cusp, |κ| ≤ κ_max, |dκ/ds| ≤ σ_max (SPEC §4; Fraichard & Scheuer, "From Reeds and Shepp's to
//! continuous-curvature paths", IEEE T-RO 2004; the CC00-RS families of Banzhaf et al.,
//! `steering_functions`, were used to learn the circle geometry — own formulation and code).
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
//! δ = (l·s·(θb − θa)) mod 2π, length [`CcCircle::turn_length`]`(δ)`. A junction q between a
//! turn on circle 1 and one on circle 2 (a cusp when s1 ≠ s2) therefore fixes
//! Ω2 − Ω1 = R·rot(θ_q)·((s1 + s2)·sin μ, (l2 − l1)·cos μ); a straight piece between them adds
//! its signed length along θ_q. This gives closed forms for the families built here:
//!
//! * **TST** with any driving directions of the three pieces (Banzhaf's TST, TcST, TScT,
//!   TcScT): 4 start circles × 4 goal circles × 2 line directions, two roots each;
//! * **TTT** with any directions (TTT, TcTT, TTcT, TcTcT, and TT/TcT in the limit): the middle
//!   circle centre is an intersection of two circles around the start and goal centres;
//!   4 × 4 × 4 circle types, two intersections each;
//! * **TTST / TSTT** (TcTST, TSTcT with the middle turn of 90° deflection... see below) and the
//!   four-turn families are **not** built: see [`cc_reeds_shepp_shortest`].
//!
//! The shortest candidate is built into segments and its end is checked against the goal.

use super::cc_turn::CcCircle;
use super::path::{CurveParams, CurvePath, CurveSegment};
use crate::geo::{v2, wrap_angle, Direction, Pose, Vec2};
use std::f64::consts::TAU;

/// One piece of a candidate.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Piece {
    /// CC turn: deflection δ ≥ 0 (rad), steering sense l = ±1, direction s = ±1.
    Turn { delta: f64, l: f64, s: f64 },
    /// Straight: length ≥ 0 (m), direction s = ±1.
    Line { len: f64, s: f64 },
}

#[derive(Debug, Clone, Copy)]
struct Candidate {
    len: f64,
    pieces: [Piece; 3],
}

/// A CC circle placed in the plane.
#[derive(Debug, Clone, Copy)]
struct Circ {
    c: Vec2,
    l: f64,
    s: f64,
}

const TYPES: [(f64, f64); 4] = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)];

#[inline]
fn rot(th: f64, x: f64, y: f64) -> Vec2 {
    let (s, c) = th.sin_cos();
    v2(c * x - s * y, s * x + c * y)
}

#[inline]
fn deflection(l: f64, s: f64, from: f64, to: f64) -> f64 {
    let d = (l * s * (to - from)).rem_euclid(TAU);
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
}

impl<'a> Solver<'a> {
    fn new(g: &'a CcCircle, start: &Pose, goal: &Pose) -> Self {
        let r = g.radius;
        let mk = |q: &Pose, entering: bool| {
            TYPES.map(|(l, s)| {
                let fx = if entering { s } else { -s };
                Circ {
                    c: q.pos + rot(q.heading, r * fx * g.sin_mu, r * l * g.cos_mu),
                    l,
                    s,
                }
            })
        };
        Solver {
            g,
            start: *start,
            goal: *goal,
            starts: mk(start, true),
            goals: mk(goal, false),
        }
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

    fn tst(&self, out: &mut Vec<Candidate>) {
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
                let ang = d.y.atan2(d.x);
                for x in [root, -root] {
                    for sl in [1.0, -1.0] {
                        let len = sl * (x - a);
                        if len < -1e-12 {
                            continue;
                        }
                        let th = ang - b.atan2(x);
                        let d1 = deflection(c1.l, c1.s, th0, th);
                        let d2 = deflection(c2.l, c2.s, th, thg);
                        let len = len.max(0.0);
                        out.push(Candidate {
                            len: self.g.turn_length(d1) + len + self.g.turn_length(d2),
                            pieces: [
                                Piece::Turn {
                                    delta: d1,
                                    l: c1.l,
                                    s: c1.s,
                                },
                                Piece::Line { len, s: sl },
                                Piece::Turn {
                                    delta: d2,
                                    l: c2.l,
                                    s: c2.s,
                                },
                            ],
                        });
                    }
                }
            }
        }
    }

    fn ttt(&self, out: &mut Vec<Candidate>) {
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
                        let e12 = o2 - c1.c;
                        let e23 = c3.c - o2;
                        let th1 = e12.y.atan2(e12.x) - v12.y.atan2(v12.x);
                        let th2 = e23.y.atan2(e23.x) - v23.y.atan2(v23.x);
                        let d1 = deflection(c1.l, c1.s, th0, th1);
                        let d2 = deflection(l2, s2, th1, th2);
                        let d3 = deflection(c3.l, c3.s, th2, thg);
                        out.push(Candidate {
                            len: self.g.turn_length(d1)
                                + self.g.turn_length(d2)
                                + self.g.turn_length(d3),
                            pieces: [
                                Piece::Turn {
                                    delta: d1,
                                    l: c1.l,
                                    s: c1.s,
                                },
                                Piece::Turn {
                                    delta: d2,
                                    l: l2,
                                    s: s2,
                                },
                                Piece::Turn {
                                    delta: d3,
                                    l: c3.l,
                                    s: c3.s,
                                },
                            ],
                        });
                        if h == 0.0 {
                            break;
                        }
                    }
                }
            }
        }
    }

    fn build(&self, cand: &Candidate) -> CurvePath {
        let mut segments = Vec::with_capacity(9);
        for p in &cand.pieces {
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

fn finite(p: &Pose) -> bool {
    p.pos.x.is_finite() && p.pos.y.is_finite() && p.heading.is_finite()
}

/// Shortest continuous-curvature Reeds-Shepp path among the families built here (TST and TTT
/// with every choice of driving directions, i.e. TST, TcST, TScT, TcScT, TTT, TcTT, TTcT,
/// TcTcT). Curvature is 0 at the start, the goal and every cusp. `None` only for invalid
/// parameters or non-finite poses (the TST family with both turns on the same side always has
/// a solution).
///
/// Missing compared with Fraichard & Scheuer / Banzhaf's CC00-RS: the families with an
/// intermediate circle and a straight (TcTST, TSTcT, TcTSTcT) and the four-turn families
/// (TTcTT, TcTTcT). Their absence only makes some paths longer, never invalid.
pub fn cc_reeds_shepp_shortest(
    start: &Pose,
    goal: &Pose,
    params: &CurveParams,
) -> Option<CurvePath> {
    if !valid_params(params) || !finite(start) || !finite(goal) {
        return None;
    }
    let g = CcCircle::new(params);
    let solver = Solver::new(&g, start, goal);
    let mut cands = Vec::with_capacity(256);
    solver.tst(&mut cands);
    solver.ttt(&mut cands);
    cands.sort_by(|a, b| a.len.total_cmp(&b.len));
    // Build the shortest candidate whose end reaches the goal (a guard against numerically
    // degenerate junctions; in practice the first one).
    let tol = 1e-6 * (1.0 + (goal.pos - start.pos).norm());
    for c in cands.iter().take(8) {
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
    let g = CcCircle::new(params);
    let solver = Solver::new(&g, start, goal);
    let mut cands = Vec::with_capacity(256);
    solver.tst(&mut cands);
    solver.ttt(&mut cands);
    cands.iter().map(|c| c.len).min_by(f64::total_cmp)
}
