//! Continuous-curvature (CC) turns (docs/METHODS.md, Curves; seed 004 formulas 1–4;
//! Fraichard & Scheuer,
//! "From Reeds and Shepp's to continuous-curvature paths", IEEE T-RO 2004).
//!
//! A CC turn starts and ends at zero curvature. For a heading change |δ| ≥ δ_min = κ_max²/σ_max
//! it is clothoid (0 → ±κ_max at σ_max) + arc + clothoid (±κ_max → 0); below δ_min it is two
//! symmetric clothoids (an *elementary path*) whose sharpness σ < σ_max is chosen so that the
//! turn ends on the same *CC circle* as the full turns would (formula 1):
//!
//! σ = π·[cos(δ/2)·C(√(δ/π)) + sin(δ/2)·S(√(δ/π))]² / (R_Ω² · sin²(δ/2 + μ)),
//!
//! where the CC circle has centre Ω (the centre of the κ_max arc), radius R_Ω = |Ω − q| for a
//! turn start q, and μ is the angle between the heading at q and the circle tangent. Every CC
//! turn from a configuration q at κ = 0 therefore ends at a κ = 0 configuration on the same
//! circle, with the heading at the same angle μ from the tangent; this is what
//! [`super::cc_reeds_shepp`] builds on. At δ = 0 the turn degenerates to the straight chord of
//! length 2·R_Ω·sin μ.

use super::fresnel::fresnel;
use super::path::{CurveParams, CurvePath, CurveSegment};
use crate::geo::{Direction, Pose};
use std::f64::consts::PI;

/// Geometry of the CC circle for given limits (computed once per parameter set).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CcCircle {
    /// κ_max, 1/m.
    pub kappa: f64,
    /// σ_max, 1/m².
    pub sigma: f64,
    /// Radius R_Ω of the CC circle, m.
    pub radius: f64,
    /// Angle μ between the heading at a turn start and the circle tangent, rad.
    pub mu: f64,
    /// sin μ.
    pub sin_mu: f64,
    /// cos μ.
    pub cos_mu: f64,
    /// δ_min = κ_max²/σ_max, rad.
    pub delta_min: f64,
}

impl CcCircle {
    /// CC circle of `params` (κ_max > 0, σ_max > 0 expected; callers validate the config).
    pub fn new(params: &CurveParams) -> Self {
        let kappa = params.kappa_max;
        let sigma = params.sigma_max;
        // End of the clothoid 0 → κ_max from the origin, heading 0, turning left.
        let l = kappa / sigma;
        let k = (sigma / PI).sqrt();
        let (c, s) = fresnel(k * l);
        let (xi, yi) = (c / k, s / k);
        let theta_i = 0.5 * kappa * l;
        let xc = xi - theta_i.sin() / kappa;
        let yc = yi + theta_i.cos() / kappa;
        let radius = xc.hypot(yc);
        let mu = xc.atan2(yc);
        CcCircle {
            kappa,
            sigma,
            radius,
            mu,
            sin_mu: mu.sin(),
            cos_mu: mu.cos(),
            delta_min: kappa * kappa / sigma,
        }
    }

    /// Sharpness (1/m², ≥ 0) of the elementary path of deflection `delta` (0 ≤ δ < δ_min)
    /// ending on the CC circle (formula 1).
    pub fn elementary_sharpness(&self, delta: f64) -> f64 {
        let x = (delta / PI).sqrt();
        let (c, s) = fresnel(x);
        let h = 0.5 * delta;
        let num = h.cos() * c + h.sin() * s;
        let den = self.radius * (h + self.mu).sin();
        PI * num * num / (den * den)
    }

    /// Length (m) of a CC turn with absolute heading change `delta` ≥ 0 (formulas 3 and 4).
    pub fn turn_length(&self, delta: f64) -> f64 {
        if delta >= self.delta_min {
            2.0 * self.kappa / self.sigma + (delta - self.delta_min) / self.kappa
        } else if delta <= 1e-12 {
            2.0 * self.radius * self.sin_mu
        } else {
            let sigma = self.elementary_sharpness(delta).min(self.sigma);
            2.0 * (delta / sigma).sqrt()
        }
    }

    /// Like [`CcCircle::turn_length`], but infinite when the turn would not end on the CC
    /// circle: an elementary path needing more than σ_max (possible only for long clothoids,
    /// δ_min = κ_max²/σ_max of the order of π or more), or a non-finite deflection.
    pub fn circle_turn_length(&self, delta: f64) -> f64 {
        if !delta.is_finite() {
            return f64::INFINITY;
        }
        if delta > 1e-12 && delta < self.delta_min {
            let sigma = self.elementary_sharpness(delta);
            if sigma.is_nan() || sigma > self.sigma {
                return f64::INFINITY;
            }
            return 2.0 * (delta / sigma).sqrt();
        }
        self.turn_length(delta)
    }

    /// Segments of a CC turn of absolute heading change `delta` ≥ 0, turning left when
    /// `left` (positive steering curvature), driven in `direction`. Appends to `out`.
    pub fn turn_segments(
        &self,
        delta: f64,
        left: bool,
        direction: Direction,
        out: &mut Vec<CurveSegment>,
    ) {
        let sgn = if left { 1.0 } else { -1.0 };
        if delta >= self.delta_min {
            let lc = self.kappa / self.sigma;
            let k = sgn * self.kappa;
            out.push(CurveSegment::clothoid(direction, lc, 0.0, k));
            let arc = (delta - self.delta_min) / self.kappa;
            if arc > 0.0 {
                out.push(CurveSegment::arc(direction, arc, k));
            }
            out.push(CurveSegment::clothoid(direction, lc, k, 0.0));
        } else if delta <= 1e-12 {
            out.push(CurveSegment::line(
                direction,
                2.0 * self.radius * self.sin_mu,
            ));
        } else {
            let sigma = self.elementary_sharpness(delta).min(self.sigma);
            let lc = (delta / sigma).sqrt();
            let k = sgn * sigma * lc;
            out.push(CurveSegment::clothoid(direction, lc, 0.0, k));
            out.push(CurveSegment::clothoid(direction, lc, k, 0.0));
        }
    }
}

/// A CC turn changing the vehicle heading by `delta_rad` (signed, radians, θ_end − θ_start,
/// positive counter-clockwise), driven in `direction`. Starts and ends at κ = 0.
///
/// Sign convention: `delta_rad` is always the change of the heading (yaw). Forward, a positive
/// δ is a left turn (κ > 0). **In reverse a positive δ needs right steering (κ < 0)**, because the
/// heading changes by κ·ds with ds < 0; seen by the driver looking backwards the rear of the
/// vehicle then swings to the left (CCW). So `cc_turn(δ, Reverse)` followed by
/// `cc_turn(−δ, Forward)` returns to the starting heading.
///
/// |δ| ≥ δ_min = κ_max²/σ_max: clothoid + arc + clothoid at κ_max, σ_max; |δ| < δ_min: two
/// clothoids with the reduced sharpness of [`CcCircle::elementary_sharpness`] (so that the end
/// lies on the CC circle); δ = 0: a straight segment of length 2·R_Ω·sin μ.
pub fn cc_turn(delta_rad: f64, direction: Direction, params: &CurveParams) -> Vec<CurveSegment> {
    let circle = CcCircle::new(params);
    let mut out = Vec::with_capacity(3);
    let forward = direction == Direction::Forward;
    let left = (delta_rad >= 0.0) == forward;
    circle.turn_segments(delta_rad.abs(), left, direction, &mut out);
    out
}

/// [`cc_turn`] as a path from `start`.
pub fn cc_turn_path(
    start: &Pose,
    delta_rad: f64,
    direction: Direction,
    params: &CurveParams,
) -> CurvePath {
    CurvePath {
        start: *start,
        segments: cc_turn(delta_rad, direction, params),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::{v2, wrap_angle};

    fn params(sigma: f64) -> CurveParams {
        CurveParams {
            kappa_max: 0.2,
            sigma_max: sigma,
        }
    }

    /// Checks one turn: κ 0 at both ends, continuous, within limits, exact heading change, and
    /// the end lies on the CC circle of the start (radius R_Ω, heading μ off the tangent).
    fn check(delta: f64, dir: Direction, p: &CurveParams) {
        let cc = CcCircle::new(p);
        let start = Pose::new(3.0, -2.0, 0.7);
        let path = cc_turn_path(&start, delta, dir, p);
        let segs = &path.segments;
        assert_eq!(segs.first().map(|s| s.kappa_start), Some(0.0));
        assert!(segs.last().map(|s| s.kappa_end.abs()).unwrap_or(1.0) < 1e-12);
        assert!(path.max_curvature() <= p.kappa_max + 1e-9, "δ {delta}");
        assert!(path.max_curvature_rate() <= p.sigma_max + 1e-9, "δ {delta}");
        assert!(path.max_curvature_jump() < 1e-12);
        let end = path.end_pose();
        let dh = wrap_angle(end.heading - start.heading - delta);
        assert!(dh.abs() < 1e-12, "δ {delta} {dir:?}: heading error {dh}");
        // Sum of segment heading changes equals δ too.
        let sum: f64 = segs.iter().map(|s| s.heading_change()).sum();
        assert!((sum - delta).abs() < 1e-12);
        // CC circle of the start (turning side from the first segment).
        let left = segs
            .iter()
            .map(|s| s.kappa_start + s.kappa_end)
            .sum::<f64>()
            > 0.0
            || (delta == 0.0);
        let (l, s) = (
            if left { 1.0 } else { -1.0 },
            if dir == Direction::Forward { 1.0 } else { -1.0 },
        );
        let rot =
            |th: f64, x: f64, y: f64| v2(th.cos() * x - th.sin() * y, th.sin() * x + th.cos() * y);
        let r = cc.radius;
        let c0 = start.pos + rot(start.heading, r * s * cc.sin_mu, r * l * cc.cos_mu);
        let c1 = end.pos + rot(end.heading, -r * s * cc.sin_mu, r * l * cc.cos_mu);
        assert!(
            (c0 - c1).norm() < 1e-9,
            "δ {delta} {dir:?}: end not on the start's CC circle ({})",
            (c0 - c1).norm()
        );
        // Length formula agrees with the segments.
        assert!((cc.turn_length(delta.abs()) - path.length()).abs() < 1e-12);
    }

    #[test]
    fn both_regimes_both_directions() {
        for sigma in [0.05, 0.1, 1.0, 5.0] {
            let p = params(sigma);
            let dmin = p.delta_min();
            for delta in [
                0.0,
                1e-6,
                0.01,
                0.3 * dmin,
                0.999 * dmin,
                dmin,
                1.001 * dmin,
                0.5,
                1.5,
                3.0,
                PI,
                5.0,
            ] {
                for d in [delta, -delta] {
                    check(d, Direction::Forward, &p);
                    check(d, Direction::Reverse, &p);
                }
            }
        }
    }

    #[test]
    fn small_turns_use_reduced_sharpness_and_continuous_length() {
        let p = params(0.1);
        let cc = CcCircle::new(&p);
        let dmin = cc.delta_min;
        // σ grows with δ up to σ_max at δ_min; the length is continuous there.
        let mut last = 0.0;
        for i in 1..100 {
            let s = cc.elementary_sharpness(dmin * i as f64 / 100.0);
            assert!(s > last && s < p.sigma_max);
            last = s;
        }
        assert!((cc.elementary_sharpness(dmin) - p.sigma_max).abs() < 1e-9);
        let below = cc.turn_length(dmin * (1.0 - 1e-9));
        let above = cc.turn_length(dmin);
        assert!((below - above).abs() < 1e-6, "{below} vs {above}");
        assert!((cc.turn_length(1e-10) - 2.0 * cc.radius * cc.sin_mu).abs() < 1e-4);
        // Two clothoids, no arc.
        let segs = cc_turn(0.5 * dmin, Direction::Forward, &p);
        assert_eq!(segs.len(), 2);
        assert!(segs[0].sharpness < p.sigma_max);
    }

    /// The CC-RS search prunes with turn_length(0) as a lower bound for every turn.
    #[test]
    fn turn_length_non_decreasing() {
        for sigma in [0.01, 0.1, 1.0, 10.0] {
            let cc = CcCircle::new(&params(sigma));
            let mut last = cc.turn_length(0.0);
            for i in 1..=4000 {
                let l = cc.turn_length(i as f64 * 0.0016);
                assert!(l >= last - 1e-12, "σ {sigma}, δ {}", i as f64 * 0.0016);
                last = l;
            }
        }
    }

    #[test]
    fn reverse_sign_convention() {
        let p = params(0.1);
        let segs = cc_turn(1.0, Direction::Reverse, &p);
        // Not vacuous: a 1 rad turn has curved segments.
        assert!(segs
            .iter()
            .any(|s| s.kappa_start != 0.0 || s.kappa_end != 0.0));
        assert!(segs
            .iter()
            .all(|s| s.kappa_start <= 0.0 && s.kappa_end <= 0.0));
        let segs = cc_turn(1.0, Direction::Forward, &p);
        assert!(segs
            .iter()
            .any(|s| s.kappa_start != 0.0 || s.kappa_end != 0.0));
        assert!(segs
            .iter()
            .all(|s| s.kappa_start >= 0.0 && s.kappa_end >= 0.0));
    }
}
