//! TEMPORARY stand-in for the curve library being written in branch `curves` (CurvePath,
//! sampling, cc_turn). Deleted when that branch is merged; nothing else may depend on it.

use super::path::{CurveKind, CurveSegment};
use crate::geo::{wrap_angle, Direction, Pose};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveParams {
    pub kappa_max: f64,
    pub sigma_max: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct CurvePath {
    pub start: Pose,
    pub segments: Vec<CurveSegment>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathSample {
    pub pose: Pose,
    pub s: f64,
    pub kappa: f64,
    pub direction: Direction,
    pub segment: usize,
}

fn sgn(d: Direction) -> f64 {
    match d {
        Direction::Forward => 1.0,
        Direction::Reverse => -1.0,
    }
}

fn advance(p: &Pose, seg: &CurveSegment, s: f64) -> Pose {
    let n = ((s / 0.01).ceil() as usize).max(1);
    let h = s / n as f64;
    let d = sgn(seg.direction);
    let th = |u: f64| p.heading + d * (seg.kappa_start * u + 0.5 * seg.sharpness * u * u);
    let (mut x, mut y) = (p.pos.x, p.pos.y);
    for k in 0..n {
        let u0 = k as f64 * h;
        let (a, b, c) = (th(u0), th(u0 + 0.5 * h), th(u0 + h));
        x += d * h / 6.0 * (a.cos() + 4.0 * b.cos() + c.cos());
        y += d * h / 6.0 * (a.sin() + 4.0 * b.sin() + c.sin());
    }
    Pose::new(x, y, wrap_angle(th(s)))
}

impl CurvePath {
    pub fn length(&self) -> f64 {
        self.segments.iter().map(|s| s.length).sum()
    }
    pub fn reverse_length(&self) -> f64 {
        self.segments
            .iter()
            .filter(|s| s.direction == Direction::Reverse)
            .map(|s| s.length)
            .sum()
    }
    pub fn cusps(&self) -> usize {
        let dirs: Vec<Direction> = self
            .segments
            .iter()
            .filter(|s| s.length > 1e-9)
            .map(|s| s.direction)
            .collect();
        dirs.windows(2).filter(|w| w[0] != w[1]).count()
    }
    pub fn end_pose(&self) -> Pose {
        let mut p = self.start;
        for s in &self.segments {
            p = advance(&p, s, s.length);
        }
        p
    }
    pub fn max_curvature(&self) -> f64 {
        self.segments
            .iter()
            .map(|s| s.kappa_start.abs().max(s.kappa_end.abs()))
            .fold(0.0, f64::max)
    }
    pub fn max_curvature_rate(&self) -> f64 {
        self.segments
            .iter()
            .map(|s| s.sharpness.abs())
            .fold(0.0, f64::max)
    }
    pub fn sample(&self, spacing_m: f64, out: &mut Vec<PathSample>) {
        out.clear();
        let mut p = self.start;
        let mut s0 = 0.0;
        for (i, seg) in self.segments.iter().enumerate() {
            let n = ((seg.length / spacing_m).ceil() as usize).max(1);
            for k in 0..=n {
                if k == 0 && i > 0 {
                    continue;
                }
                let u = seg.length * k as f64 / n as f64;
                out.push(PathSample {
                    pose: advance(&p, seg, u),
                    s: s0 + u,
                    kappa: seg.kappa_start + seg.sharpness * u,
                    direction: seg.direction,
                    segment: i,
                });
            }
            p = advance(&p, seg, seg.length);
            s0 += seg.length;
        }
        if out.is_empty() {
            out.push(PathSample {
                pose: self.start,
                s: 0.0,
                kappa: 0.0,
                direction: Direction::Forward,
                segment: 0,
            });
        }
    }
    pub fn then(mut self, other: CurvePath) -> CurvePath {
        self.segments.extend(other.segments);
        self
    }
}

pub fn cc_turn(delta_rad: f64, direction: Direction, params: &CurveParams) -> Vec<CurveSegment> {
    let d = delta_rad.abs();
    let side = delta_rad.signum() * sgn(direction);
    let (k, s) = (params.kappa_max, params.sigma_max);
    let dmin = k * k / s;
    let seg = |kind, length: f64, k0: f64, k1: f64, sh: f64| CurveSegment {
        kind,
        direction,
        length,
        kappa_start: side * k0,
        kappa_end: side * k1,
        sharpness: side * sh,
    };
    if d < 1e-9 {
        return Vec::new();
    }
    if d > dmin {
        let lc = k / s;
        let la = (d - dmin) / k;
        vec![
            seg(CurveKind::Clothoid, lc, 0.0, k, s),
            seg(CurveKind::Arc, la, k, k, 0.0),
            seg(CurveKind::Clothoid, lc, k, 0.0, -s),
        ]
    } else {
        let l = (d / s).sqrt();
        vec![
            seg(CurveKind::Clothoid, l, 0.0, s * l, s),
            seg(CurveKind::Clothoid, l, s * l, 0.0, -s),
        ]
    }
}

pub fn reeds_shepp_shortest(_start: &Pose, _goal: &Pose, _r_min_m: f64) -> Option<CurvePath> {
    None
}

pub fn reeds_shepp_length(start: &Pose, goal: &Pose, _r_min_m: f64) -> Option<f64> {
    Some((goal.pos - start.pos).norm())
}

pub fn cc_reeds_shepp_shortest(
    _start: &Pose,
    _goal: &Pose,
    _params: &CurveParams,
) -> Option<CurvePath> {
    None
}
