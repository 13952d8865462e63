//! A manoeuvre path: segments of constant curvature rate (lines, arcs, clothoids), each driven
//! forward or in reverse.

use super::fresnel::fresnel;
use crate::geo::{v2, wrap_angle, Direction, Pose};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The shape of one segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveKind {
    /// Zero curvature.
    Line,
    /// Constant non-zero curvature.
    Arc,
    /// Curvature changing linearly with arc length (sharpness ≠ 0).
    Clothoid,
}

/// One segment of a path. Curvature varies linearly along it:
/// κ(s) = `kappa_start` + `sharpness`·s for s in [0, `length`], with s the distance driven.
/// Curvature is the steering curvature tan(δ)/wheelbase (positive = wheels turned left,
/// docs/CONVENTIONS.md, Signs), whatever the driving direction: along a segment the heading changes
/// by κ·ds with ds the signed displacement (negative in reverse), as in the kinematic bicycle
/// model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CurveSegment {
    pub kind: CurveKind,
    pub direction: Direction,
    /// Length driven, m (≥ 0).
    pub length: f64,
    /// Curvature at the start, 1/m.
    pub kappa_start: f64,
    /// Curvature at the end, 1/m.
    pub kappa_end: f64,
    /// Curvature rate along the distance driven, 1/m².
    pub sharpness: f64,
}

impl CurveSegment {
    /// A straight segment.
    pub fn line(direction: Direction, length_m: f64) -> Self {
        CurveSegment {
            kind: CurveKind::Line,
            direction,
            length: length_m,
            kappa_start: 0.0,
            kappa_end: 0.0,
            sharpness: 0.0,
        }
    }

    /// A circular arc of curvature `kappa` (1/m, steering sign).
    pub fn arc(direction: Direction, length_m: f64, kappa: f64) -> Self {
        CurveSegment {
            kind: if kappa == 0.0 {
                CurveKind::Line
            } else {
                CurveKind::Arc
            },
            direction,
            length: length_m,
            kappa_start: kappa,
            kappa_end: kappa,
            sharpness: 0.0,
        }
    }

    /// A clothoid from `kappa_start` to `kappa_end` over `length_m` (> 0).
    pub fn clothoid(direction: Direction, length_m: f64, kappa_start: f64, kappa_end: f64) -> Self {
        let sharpness = if length_m > 0.0 {
            (kappa_end - kappa_start) / length_m
        } else {
            0.0
        };
        CurveSegment {
            kind: CurveKind::Clothoid,
            direction,
            length: length_m,
            kappa_start,
            kappa_end,
            sharpness,
        }
    }

    /// +1 forward, −1 reverse.
    #[inline]
    pub fn sign(&self) -> f64 {
        match self.direction {
            Direction::Forward => 1.0,
            Direction::Reverse => -1.0,
        }
    }

    /// Curvature after driving `s` metres along the segment, 1/m.
    #[inline]
    pub fn kappa_at(&self, s: f64) -> f64 {
        self.kappa_start + self.sharpness * s
    }

    /// Heading change over the whole segment (signed, radians; κ·ds with ds negative in
    /// reverse).
    #[inline]
    pub fn heading_change(&self) -> f64 {
        self.sign() * (self.kappa_start + 0.5 * self.sharpness * self.length) * self.length
    }

    /// Pose after driving `s` metres (0 ≤ s ≤ `length`) from `start`. Exact: lines and arcs in
    /// closed form, clothoids from the Fresnel integrals (seed 004 formula 5).
    pub fn pose_at(&self, start: &Pose, s: f64) -> Pose {
        let d = self.sign();
        // Heading along the segment: φ(u) = θ0 + b·u + a·u²/2.
        let b = d * self.kappa_start;
        let a = d * self.sharpness;
        let (ix, iy) = heading_integral(start.heading, b, a, s);
        Pose {
            pos: start.pos + v2(d * ix, d * iy),
            heading: wrap_angle(start.heading + b * s + 0.5 * a * s * s),
        }
    }

    /// Pose at the end of the segment.
    #[inline]
    pub fn end_pose(&self, start: &Pose) -> Pose {
        self.pose_at(start, self.length)
    }
}

/// ∫₀ˢ (cos φ(u), sin φ(u)) du with φ(u) = θ0 + b·u + a·u²/2.
fn heading_integral(theta0: f64, b: f64, a: f64, s: f64) -> (f64, f64) {
    if s <= 0.0 {
        return (0.0, 0.0);
    }
    if a.abs() * s * s < 1e-13 {
        // Arc (or line): chord s·sinc(bs/2) in direction θ0 + bs/2 (+ the mean quadratic
        // term, negligible below the threshold).
        let half = 0.5 * b * s + a * s * s / 6.0;
        let chord = if half.abs() < 1e-8 {
            s * (1.0 - half * half / 6.0)
        } else {
            s * half.sin() / half
        };
        let dir = theta0 + half;
        return (chord * dir.cos(), chord * dir.sin());
    }
    let k = (a.abs() / PI).sqrt();
    let t0 = k * (b / a);
    let t1 = k * (s + b / a);
    if t0.abs().max(t1.abs()) > 4.0 {
        // Far from the clothoid's inflection the Fresnel differences cancel; integrate
        // numerically instead (8-point Gauss–Legendre on pieces of ≤ 0.25 rad phase change).
        return gauss_heading_integral(theta0, b, a, s);
    }
    // φ(u) = θv + (a/2)(u + b/a)²; t = k (u + b/a), k = √(|a|/π):
    // ∫ = (1/k) e^{iθv} [ΔC + i·sgn(a)·ΔS].
    let sg = a.signum();
    let theta_v = theta0 - b * b / (2.0 * a);
    let (c0, s0) = fresnel(t0);
    let (c1, s1) = fresnel(t1);
    let re = (c1 - c0) / k;
    let im = sg * (s1 - s0) / k;
    let (sv, cv) = theta_v.sin_cos();
    (cv * re - sv * im, sv * re + cv * im)
}

/// Composite 8-point Gauss–Legendre version of [`heading_integral`].
fn gauss_heading_integral(theta0: f64, b: f64, a: f64, s: f64) -> (f64, f64) {
    const X: [f64; 4] = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    const W: [f64; 4] = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    let phase = b.abs() * s + 0.5 * a.abs() * s * s;
    let n = ((phase / 0.25).ceil() as usize).clamp(1, 100_000);
    let h = s / n as f64;
    let (mut x, mut y) = (0.0, 0.0);
    for i in 0..n {
        let mid = h * (i as f64 + 0.5);
        for j in 0..4 {
            for sgn in [-1.0, 1.0] {
                let u = mid + sgn * 0.5 * h * X[j];
                let p = theta0 + b * u + 0.5 * a * u * u;
                x += W[j] * p.cos();
                y += W[j] * p.sin();
            }
        }
    }
    (0.5 * h * x, 0.5 * h * y)
}

/// Vehicle limits for continuous-curvature paths.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CurveParams {
    /// Maximum steering curvature, 1/m (1 / minimum turning radius).
    pub kappa_max: f64,
    /// Maximum curvature rate per metre driven, 1/m² (steering speed limit / speed).
    pub sigma_max: f64,
}

impl CurveParams {
    /// δ_min = κ_max² / σ_max: heading change of the two full clothoids of a CC turn (rad).
    #[inline]
    pub fn delta_min(&self) -> f64 {
        self.kappa_max * self.kappa_max / self.sigma_max
    }
}

/// A path: segments driven one after the other from `start`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CurvePath {
    pub start: Pose,
    pub segments: Vec<CurveSegment>,
}

/// One sampled point of a [`CurvePath`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathSample {
    pub pose: Pose,
    /// Distance driven from the start (sum of segment lengths, whatever the direction), m.
    pub s: f64,
    /// Steering curvature here, 1/m.
    pub kappa: f64,
    /// Driving direction of the segment this sample belongs to.
    pub direction: Direction,
    /// Index of that segment.
    pub segment: usize,
}

impl CurvePath {
    /// Total length driven, m.
    pub fn length(&self) -> f64 {
        self.segments.iter().map(|s| s.length).sum()
    }

    /// Length driven in reverse, m.
    pub fn reverse_length(&self) -> f64 {
        self.segments
            .iter()
            .filter(|s| s.direction == Direction::Reverse)
            .map(|s| s.length)
            .sum()
    }

    /// Number of direction changes (segments of zero length are ignored).
    pub fn cusps(&self) -> usize {
        let mut last: Option<Direction> = None;
        let mut n = 0;
        for seg in self.segments.iter().filter(|s| s.length > 0.0) {
            if let Some(d) = last {
                if d != seg.direction {
                    n += 1;
                }
            }
            last = Some(seg.direction);
        }
        n
    }

    /// Pose at the end of the path.
    pub fn end_pose(&self) -> Pose {
        self.segments
            .iter()
            .fold(self.start, |p, seg| seg.end_pose(&p))
    }

    /// Largest |κ| along the path, 1/m.
    pub fn max_curvature(&self) -> f64 {
        self.segments
            .iter()
            .map(|s| s.kappa_start.abs().max(s.kappa_end.abs()))
            .fold(0.0, f64::max)
    }

    /// Largest |dκ/ds| inside segments, 1/m² (jumps between segments are reported by
    /// [`CurvePath::max_curvature_jump`]).
    pub fn max_curvature_rate(&self) -> f64 {
        self.segments
            .iter()
            .filter(|s| s.length > 0.0)
            .map(|s| s.sharpness.abs())
            .fold(0.0, f64::max)
    }

    /// Largest curvature step between consecutive segments, 1/m (0 for a continuous-curvature
    /// path).
    pub fn max_curvature_jump(&self) -> f64 {
        self.segments
            .windows(2)
            .map(|w| (w[1].kappa_start - w[0].kappa_end).abs())
            .fold(0.0, f64::max)
    }

    /// Samples every `spacing_m` metres driven (clamped to ≥ 1 mm) into `out` (cleared first).
    /// The first sample is the start; every segment contributes its interior samples and its
    /// end (so every segment boundary and the path end are included once, attributed to the
    /// segment that ends there; a cusp shows as a direction change between consecutive
    /// samples). Spacing restarts at each segment boundary.
    pub fn sample(&self, spacing_m: f64, out: &mut Vec<PathSample>) {
        self.sample_while(spacing_m, out, &mut |_| true);
    }

    /// [`CurvePath::sample`], stopping at the first sample whose position `keep` refuses
    /// (false then; `out` holds the samples up to that one): the samples `sample` makes, in
    /// its order, so a path refused anywhere is refused without sampling the rest of it.
    pub fn sample_while(
        &self,
        spacing_m: f64,
        out: &mut Vec<PathSample>,
        keep: &mut dyn FnMut(&crate::geo::Vec2) -> bool,
    ) -> bool {
        out.clear();
        let spacing = spacing_m.max(1e-3);
        let first_dir = self
            .segments
            .first()
            .map(|s| s.direction)
            .unwrap_or_default();
        out.push(PathSample {
            pose: self.start,
            s: 0.0,
            kappa: self.segments.first().map(|s| s.kappa_start).unwrap_or(0.0),
            direction: first_dir,
            segment: 0,
        });
        if !keep(&self.start.pos) {
            return false;
        }
        let mut pose = self.start;
        let mut s0 = 0.0;
        for (i, seg) in self.segments.iter().enumerate() {
            if seg.length > 0.0 {
                let n = (seg.length / spacing).ceil().max(1.0) as usize;
                let step = seg.length / n as f64;
                for k in 1..=n {
                    let s = if k == n { seg.length } else { step * k as f64 };
                    let at = seg.pose_at(&pose, s);
                    out.push(PathSample {
                        pose: at,
                        s: s0 + s,
                        kappa: seg.kappa_at(s),
                        direction: seg.direction,
                        segment: i,
                    });
                    if !keep(&at.pos) {
                        return false;
                    }
                }
            }
            pose = seg.end_pose(&pose);
            s0 += seg.length;
        }
        true
    }

    /// Concatenation: `other` is driven after `self` (its start should be `self`'s end; the
    /// start of `other` is not checked).
    pub fn then(mut self, other: CurvePath) -> CurvePath {
        self.segments.extend(other.segments);
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference pose by composite Simpson integration of the heading (independent of the
    /// Fresnel closed form).
    fn simpson_pose(seg: &CurveSegment, start: &Pose, s: f64) -> Pose {
        let d = seg.sign();
        let phi = |u: f64| start.heading + d * (seg.kappa_start * u + 0.5 * seg.sharpness * u * u);
        let n = 20_000;
        let h = s / n as f64;
        let (mut x, mut y) = (0.0, 0.0);
        for i in 0..=n {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let p = phi(h * i as f64);
            x += w * p.cos();
            y += w * p.sin();
        }
        Pose {
            pos: start.pos + v2(d * x * h / 3.0, d * y * h / 3.0),
            heading: wrap_angle(phi(s)),
        }
    }

    #[test]
    fn segment_poses_match_numeric_integration() {
        let start = Pose::new(1.0, 2.0, -2.5);
        let segs = [
            CurveSegment::line(Direction::Forward, 7.0),
            CurveSegment::arc(Direction::Reverse, 9.0, -0.2),
            CurveSegment::arc(Direction::Forward, 3.0, 1e-9),
            CurveSegment::clothoid(Direction::Forward, 2.0, 0.0, 0.2),
            CurveSegment::clothoid(Direction::Reverse, 2.0, 0.2, 0.0),
            CurveSegment::clothoid(Direction::Reverse, 5.0, -0.3, 0.4),
            CurveSegment::clothoid(Direction::Forward, 30.0, 0.0, 0.5),
            CurveSegment::clothoid(Direction::Forward, 4.0, 0.1, 0.1 + 1e-10),
        ];
        for seg in segs {
            for frac in [0.0, 0.3, 1.0] {
                let s = seg.length * frac;
                let got = seg.pose_at(&start, s);
                let want = simpson_pose(&seg, &start, s);
                assert!(
                    (got.pos - want.pos).norm() < 1e-9,
                    "{seg:?} at {s}: {:?} vs {:?}",
                    got.pos,
                    want.pos
                );
                assert!(wrap_angle(got.heading - want.heading).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn path_measures_and_sampling() {
        let start = Pose::new(0.0, 0.0, 0.0);
        let path = CurvePath {
            start,
            segments: vec![
                CurveSegment::clothoid(Direction::Forward, 2.0, 0.0, 0.2),
                CurveSegment::clothoid(Direction::Forward, 2.0, 0.2, 0.0),
                CurveSegment::line(Direction::Reverse, 3.05),
                CurveSegment::arc(Direction::Forward, 0.0, 0.1),
                CurveSegment::arc(Direction::Forward, 1.0, 0.1),
            ],
        };
        assert!((path.length() - 8.05).abs() < 1e-12);
        assert!((path.reverse_length() - 3.05).abs() < 1e-12);
        assert_eq!(path.cusps(), 2);
        assert!((path.max_curvature() - 0.2).abs() < 1e-12);
        assert!((path.max_curvature_rate() - 0.1).abs() < 1e-12);
        assert!((path.max_curvature_jump() - 0.1).abs() < 1e-12);
        let mut out = Vec::new();
        path.sample(0.5, &mut out);
        let first = out.first().expect("samples");
        let last = out.last().expect("samples");
        assert_eq!(first.pose, start);
        assert!((last.s - path.length()).abs() < 1e-12);
        let end = path.end_pose();
        assert!((last.pose.pos - end.pos).norm() < 1e-12);
        // Spacing never exceeds the request, s is increasing, positions are consistent with s.
        for w in out.windows(2) {
            let ds = w[1].s - w[0].s;
            assert!(ds > 0.0 && ds <= 0.5 + 1e-12);
            assert!((w[1].pose.pos - w[0].pose.pos).norm() <= ds + 1e-12);
        }
        // Every segment boundary is a sample.
        let mut acc = 0.0;
        for seg in &path.segments {
            acc += seg.length;
            assert!(out.iter().any(|p| (p.s - acc).abs() < 1e-12));
        }
        // Concatenation keeps the start and appends.
        let a = CurvePath {
            start,
            segments: path.segments[..2].to_vec(),
        };
        let b = CurvePath {
            start: a.end_pose(),
            segments: path.segments[2..].to_vec(),
        };
        let ab = a.then(b);
        assert_eq!(ab, path);
    }
}
