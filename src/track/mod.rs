//! Tracking: the local path and the steering laws that follow it.
//!
//! Every law implements [`law::SteeringLaw`] and is registered once in [`registry`], which
//! builds it from its [`registry::TrackerKind`] (the `track.kind` key). A law states what it
//! needs from the rest of the controller ([`law::LawNeeds`]: a latency-compensated,
//! dead-reckoned pose, the disturbance observer, integral action, lost-motion compensation);
//! the controller asks, it never checks which law it runs. [`pure_pursuit`] is the seed-000
//! law: fed the latest fix it is the plain reference, fed the predicted pose and the observer's
//! course it is the predictive tracker; [`stanley`] is the Stanley reference; [`lqr`] is a
//! speed-scheduled LQR with the steering's lag in its model.
//!
//! To add a tracker: a module with a type implementing [`law::SteeringLaw`], and one entry in
//! [`registry`] (its kind, name and constructor).
//!
//! Contract: pure functions of the local path, the pose and the speed; nothing allocates or
//! logs per call. Uses [`crate::geo`] and [`crate::estimate`] only.

pub mod lag_lead;
pub mod law;
pub mod local_path;
pub mod lost_motion;
pub mod lqr;
pub mod pure_pursuit;
pub mod registry;
pub mod stanley;

pub use pure_pursuit::pure_pursuit;
pub use stanley::stanley;

use crate::geo::{Direction, Pose, Vec2};
use std::f64::consts::PI;

/// Tracker parameters, SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackerParams {
    /// Wheelbase L, m.
    pub wheelbase: f64,
    /// Minimum look-ahead distance, m.
    pub ld_min: f64,
    /// Look-ahead growth with speed, s: Ld = max(ld_min, ld_gain·|v|).
    pub ld_gain: f64,
    /// Largest front-wheel angle, rad.
    pub max_wheel_angle: f64,
    /// The steering's response the default law's look-ahead covers
    /// ([`TrackerParams::response_time`]); 0 where not known.
    pub steering: SteeringResponse,
}

/// What the controller knows of the steering actuator (the keys `agsteer calibrate` owns:
/// `safety.actuator_dead_time_s`, `safety.actuator_tau_s`, `safety.actuator_rate_deg_s`), SI.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SteeringResponse {
    /// First-order lag of the wheel angle behind the command, s.
    pub lag: f64,
    /// Dead time the prediction does not cover (the actuator's less `track.lead_time_s`), s.
    pub dead_time: f64,
    /// Rate limit of the wheel angle (the slower of the actuator and the command limit),
    /// rad/s; 0 = none.
    pub rate: f64,
    /// The wheel angle the steering still has to sweep when the exit of a planned turn has
    /// been driven (atan(L / turn radius) for turns of arcs, 0 for continuous-curvature turns
    /// planned within the steering's rate; `Config::turn_exit_slew`), rad.
    pub sweep: f64,
    /// The vehicle's own lag behind its wheels (tyres, yaw inertia) as learnt so far
    /// (`estimate::yaw_lag`), s: set by the controller every period, 0 in the configuration.
    /// Only the curvature feed-forward's lead uses it (`pure_pursuit::FeedForward`).
    pub vehicle_lag: f64,
}

/// The lag's phase budget: a look-ahead time of at least this many times the steering's lag
/// (and unpredicted dead time) keeps the lag's phase at pure pursuit's natural frequency
/// ωn = √2/T below atan(√2/2.66) ≈ 28°. Measured on the envelope's lag_0.6 row (15 km/h): 2.0
/// weaves (11 cm RMS, 3 m max), 2.66 holds 2.9 cm, 3.5 and 4.5 converge slower (3.0, 10.9).
pub const LAG_PHASE_BUDGET: f64 = 2.66;

impl SteeringResponse {
    /// The look-ahead time the steering needs, s: the larger of
    /// - [`LAG_PHASE_BUDGET`] × (lag + the dead time not predicted): pure pursuit's loop is
    ///   second order with ωn = √2·v/Ld (linearised about a straight line), so a look-ahead of
    ///   v·T puts it at √2/T rad/s, where a lag τ costs atan(√2·τ/T) of phase;
    /// - lag + dead time + the time to sweep the wheels out of the planned turn at the rate
    ///   limit: a rate-limited steering that is still slewing when the look-ahead has been
    ///   driven cannot follow the command, and the loop turns into a limit cycle (the
    ///   rate-limit weave of a 20°/s motor, issue 15).
    ///
    /// The default law's look-ahead is at least v·T ([`scheduled_lookahead`]); it asks every
    /// period (a few operations), with the lag its lead leaves ([`lag_lead::residual`]).
    pub fn response_time(&self) -> f64 {
        let s = self;
        let delay = s.lag.max(0.0) + s.dead_time.max(0.0);
        let slew = if s.rate > 0.0 && s.rate.is_finite() {
            s.sweep.max(0.0) / s.rate
        } else {
            0.0
        };
        let t = (LAG_PHASE_BUDGET * delay).max(delay + slew);
        if t.is_finite() {
            t
        } else {
            0.0
        }
    }
}

impl TrackerParams {
    /// The steering's [`SteeringResponse::response_time`], s.
    pub fn response_time(&self) -> f64 {
        self.steering.response_time()
    }
}

/// The tracker's result for one period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackOutput {
    /// Front-wheel angle, rad (positive left), within ±max_wheel_angle. 0 when the inputs were
    /// not finite (then `valid` is false).
    pub wheel_angle: f64,
    /// Path curvature demanded, 1/m.
    pub curvature: f64,
    /// Look-ahead distance used, m.
    pub lookahead: f64,
    /// The preview point.
    pub target: Vec2,
    /// Angle from the heading to the preview point, rad.
    pub alpha: f64,
    /// The path's own curvature at the preview point, 1/m (positive left); 0 from laws that do
    /// not report it (then [`CurvatureScale`] neither learns nor adds anything).
    pub path_curvature: f64,
    pub valid: bool,
}

impl TrackOutput {
    /// The zero command of a law whose inputs were not usable (`valid` false), with the
    /// preview point `target` and look-ahead `lookahead` (m) it would have used.
    pub fn invalid(target: Vec2, lookahead: f64) -> TrackOutput {
        TrackOutput {
            wheel_angle: 0.0,
            curvature: 0.0,
            lookahead,
            target,
            alpha: 0.0,
            path_curvature: 0.0,
            valid: false,
        }
    }
}

/// Driving in reverse about the rear axle is, kinematically, driving forward with the heading
/// turned by π and the steering curvature negated: the bicycle model ẋ = v·cos θ,
/// θ̇ = v·κ with v < 0 becomes, for θ' = θ + π and v' = −v > 0, ẋ = v'·cos θ', θ̇' = v'·(−κ).
/// Any law that steers forward therefore steers a reverse segment when it is given
/// [`travel_pose`] and |v|, and its output goes through [`steering_from_travel`].
pub fn travel_pose(pose: &Pose, direction: Direction) -> Pose {
    match direction {
        Direction::Forward => *pose,
        Direction::Reverse => Pose::new(pose.pos.x, pose.pos.y, pose.heading + PI),
    }
}

/// The steering command of a law computed in the driving direction (see [`travel_pose`]).
pub fn steering_from_travel(out: TrackOutput, direction: Direction) -> TrackOutput {
    match direction {
        Direction::Forward => out,
        Direction::Reverse => TrackOutput {
            wheel_angle: -out.wheel_angle,
            curvature: -out.curvature,
            alpha: -out.alpha,
            path_curvature: -out.path_curvature,
            ..out
        },
    }
}

/// The look-ahead distance at speed `v`, m.
#[inline]
pub fn lookahead(params: &TrackerParams, speed: f64) -> f64 {
    params.ld_min.max(params.ld_gain * speed.abs())
}

/// The look-ahead distance at speed `v` scheduled on the steering's response, m:
/// max([`lookahead`], |v|·`response_time`), the response time worked out once at
/// configuration ([`TrackerParams::response_time`]).
#[inline]
pub fn scheduled_lookahead(params: &TrackerParams, response_time: f64, speed: f64) -> f64 {
    lookahead(params, speed).max(response_time * speed.abs())
}

/// The point `distance` along the local path from sample `start` (extrapolated along the
/// last segment when the path is shorter).
pub fn point_along(points: &[Vec2], start: usize, distance: f64) -> Vec2 {
    let mut left = distance;
    let mut i = start.min(points.len().saturating_sub(1));
    while i + 1 < points.len() {
        let seg = (points[i + 1] - points[i]).norm();
        if seg >= left && seg > 0.0 {
            return points[i] + (points[i + 1] - points[i]) * (left / seg);
        }
        left -= seg;
        i += 1;
    }
    let n = points.len();
    if n >= 2 {
        let d = points[n - 1] - points[n - 2];
        let len = d.norm();
        if len > 0.0 {
            return points[n - 1] + d * (left / len);
        }
    }
    points.last().copied().unwrap_or_else(Vec2::zeros)
}

/// The curvature of the local path at `distance` along it from sample `start`, 1/m (positive
/// left): the circle through the points `distance` − `half`, `distance` and `distance` + `half`
/// along it (0 where they are collinear or coincide). Allocation-free.
pub fn curvature_along(points: &[Vec2], start: usize, distance: f64, half: f64) -> f64 {
    let a = point_along(points, start, (distance - half).max(0.0));
    let b = point_along(points, start, distance);
    let c = point_along(points, start, distance + half);
    curvature_through(&a, &b, &c)
}

/// The curvature of the circle through `a`, `b` and `c`, 1/m (positive turning left from a
/// to c); 0 where they are collinear or coincide.
pub fn curvature_through(a: &Vec2, b: &Vec2, c: &Vec2) -> f64 {
    let (ab, bc, ac) = (b - a, c - b, c - a);
    let denom = ab.norm() * bc.norm() * ac.norm();
    let k = 2.0 * crate::geo::cross(&ab, &bc) / denom;
    if denom > 1e-9 && k.is_finite() {
        k
    } else {
        0.0
    }
}

/// How the curvature scale learns (`track.curvature_gain_per_m_s`,
/// `track.curvature_scale_limit`; see [`CurvatureScale`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvatureScaleParams {
    /// Learning rate, 1/(m of XTE · s); 0 = off.
    pub gain: f64,
    /// Largest |scale| (a fraction of the wheel angle the path's curvature asks for).
    pub limit: f64,
    /// Learns only while |XTE| is below this, m (`track.integral_capture_m`).
    pub capture: f64,
    /// Learns only above this speed, m/s (`track.integral_min_speed_mps`).
    pub min_speed: f64,
    /// Learns only while the heading error is below this, rad: the vehicle runs parallel to
    /// the path, so the XTE is a standing error and not a line start's transient.
    pub max_heading_error: f64,
}

impl Default for CurvatureScaleParams {
    fn default() -> Self {
        CurvatureScaleParams {
            gain: 0.0,
            limit: 0.3,
            capture: 0.3,
            min_speed: 0.5,
            max_heading_error: CURVATURE_SCALE_MAX_HEADING_ERROR,
        }
    }
}

impl CurvatureScaleParams {
    /// As configured for a law with integral action; off for the others (the references).
    pub fn for_needs(self, needs: law::LawNeeds) -> Self {
        CurvatureScaleParams {
            gain: if needs.integral { self.gain } else { 0.0 },
            ..self
        }
    }
}

/// The heading error below which the curvature scale learns, rad (1°).
pub const CURVATURE_SCALE_MAX_HEADING_ERROR: f64 = 0.0175;

/// Paths curving less than this teach the curvature scale nothing, 1/m (R 100 m: the XTE there
/// is the tracker's own corrections and noise, not a curvature bias).
pub const CURVATURE_SCALE_MIN_CURVATURE: f64 = 0.01;

/// A learnt error of the wheel angle a curve needs, in proportion to the path's curvature:
/// the plant turns less (or more) for a wheel angle than the kinematic model with the
/// configured wheelbase says — a wheelbase that differs from the configured one, tyre slip
/// that grows with the curvature at the job speed (understeer: δ = κ·(L + K·v²)), an antenna
/// mounted elsewhere along the vehicle than configured (the heading error on a curve is its
/// distance over R). A geometric law settles every such error as a standing XTE on a curve,
/// on the outside for understeer, and a constant-offset integral cannot learn it on lines that
/// curve both ways. This learns a scale s on curved work paths: ds/dt = −gain · XTE · sign κ,
/// and adds s · atan(L·κ) to the wheel angle on every path (the turns have the same bias).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvatureScale {
    pub params: CurvatureScaleParams,
    /// The configured wheelbase, m.
    pub wheelbase: f64,
    /// The learnt scale (0: the model is right; 0.1: curves need 10 % more wheel angle).
    pub scale: f64,
}

impl CurvatureScale {
    /// A scale learnt with `params` for wheelbase `wheelbase` (m), keeping `learnt` (clamped).
    pub fn new(params: CurvatureScaleParams, wheelbase: f64, learnt: f64) -> Self {
        let limit = params.limit.max(0.0);
        CurvatureScale {
            params,
            wheelbase,
            scale: if learnt.is_finite() {
                learnt.clamp(-limit, limit)
            } else {
                0.0
            },
        }
    }

    /// Learn from one period of `dt` s at cross-track error `xte` (m, positive = left of the
    /// path) and heading error `heading_error` (rad) on a path of curvature `curvature` (1/m,
    /// positive left, in the vehicle's frame) at `speed` (m/s) when `learning` (work paths
    /// driven forward) and within the bounds of [`CurvatureScaleParams`]; return the wheel
    /// angle to add, rad.
    pub fn update(
        &mut self,
        (xte, heading_error): (f64, f64),
        curvature: f64,
        speed: f64,
        dt: f64,
        learning: bool,
    ) -> f64 {
        let p = self.params;
        if p.gain <= 0.0 || !curvature.is_finite() {
            return 0.0;
        }
        if learning
            && xte.is_finite()
            && xte.abs() < p.capture
            && heading_error.abs() < p.max_heading_error
            && curvature.abs() >= CURVATURE_SCALE_MIN_CURVATURE
            && dt.is_finite()
            && dt > 0.0
            && dt < 1.0
            && speed.abs() >= p.min_speed
        {
            let limit = p.limit.max(0.0);
            self.scale = (self.scale - p.gain * xte * curvature.signum() * dt).clamp(-limit, limit);
        }
        self.scale * (self.wheelbase * curvature).atan()
    }
}

/// Integral action on the cross-track error: a slowly learnt wheel-angle offset that cancels
/// steady disturbances a pure geometric law leaves as a standing error (a wheel-angle sensor
/// bias, side-slope slip). It learns only on work paths, driving forward, above a speed and
/// within a capture band of the line, and is clamped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntegralAction {
    /// Gain, rad of wheel angle per (m of XTE · s).
    pub gain: f64,
    /// Largest offset, rad.
    pub limit: f64,
    /// Learns only while |XTE| is below this, m.
    pub capture: f64,
    /// Learns only above this speed, m/s.
    pub min_speed: f64,
    /// The learnt offset, rad (positive = left).
    pub offset: f64,
}

impl IntegralAction {
    /// Learn from one period of `dt` s with cross-track error `xte` (m, positive = left of
    /// the path) when `learning`, and return the offset to add to the wheel angle, rad.
    pub fn update(&mut self, xte: f64, speed: f64, dt: f64, learning: bool) -> f64 {
        if self.gain > 0.0
            && learning
            && xte.is_finite()
            && dt.is_finite()
            && dt > 0.0
            && dt < 1.0
            && xte.abs() < self.capture
            && speed.abs() >= self.min_speed
        {
            self.offset = (self.offset - self.gain * xte * dt).clamp(-self.limit, self.limit);
        }
        if self.gain > 0.0 {
            self.offset
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::local_path::{LocalPath, LocalPathParams};
    use super::*;
    use crate::geo::{v2, PathPoint};

    fn params() -> TrackerParams {
        TrackerParams {
            wheelbase: 3.0,
            ld_min: 3.0,
            ld_gain: 1.0,
            max_wheel_angle: 35f64.to_radians(),
            steering: SteeringResponse::default(),
        }
    }

    /// Tracker parameters with a steering of lag `lag` s, rate `rate_deg` °/s and turn-exit
    /// sweep `sweep` rad (for the laws' tests).
    pub(crate) fn tracker_with_steering(lag: f64, rate_deg: f64, sweep: f64) -> TrackerParams {
        TrackerParams {
            wheelbase: 3.0,
            ld_min: 3.0,
            ld_gain: 1.2,
            max_wheel_angle: 35f64.to_radians(),
            steering: SteeringResponse {
                lag,
                dead_time: 0.0,
                rate: rate_deg.to_radians(),
                sweep,
                vehicle_lag: 0.0,
            },
        }
    }

    /// The local path of the straight x axis (a point a metre) near `at`.
    pub(crate) fn straight_local(at: &Vec2) -> LocalPath {
        let g: Vec<PathPoint> = (0..50)
            .map(|i| PathPoint::work(v2(i as f64, 0.0)))
            .collect();
        let mut lp = LocalPath::new(&LocalPathParams {
            nodes_before: 1,
            nodes_after: 8,
            ..Default::default()
        });
        lp.rebuild(&g, at.x.round() as usize);
        lp.nearest(at);
        lp
    }

    #[test]
    fn steers_back_toward_a_straight_line() {
        let left = Pose::new(10.0, 0.5, 0.0);
        let out = pure_pursuit(&straight_local(&left.pos), &left, 2.0, &params());
        assert!(
            out.valid && out.wheel_angle < 0.0,
            "left of line steers right: {out:?}"
        );
        let right = Pose::new(10.0, -0.5, 0.0);
        let out = pure_pursuit(&straight_local(&right.pos), &right, 2.0, &params());
        assert!(out.wheel_angle > 0.0, "right of line steers left");
        let on = Pose::new(10.0, 0.0, 0.0);
        let out = pure_pursuit(&straight_local(&on.pos), &on, 2.0, &params());
        assert!(out.wheel_angle.abs() < 1e-9);
    }

    #[test]
    fn stanley_steers_back_and_corrects_heading() {
        let p = params();
        let left = Pose::new(10.0, 0.5, 0.0);
        let out = stanley(&straight_local(&left.pos), &left, 2.0, &p, 2.5, 1.0);
        assert!(
            out.valid && out.wheel_angle < 0.0,
            "left steers right: {out:?}"
        );
        // atan(2.5·0.5 / 3) exactly, on a straight with no heading error.
        assert!((out.wheel_angle + (2.5f64 * 0.5 / 3.0).atan()).abs() < 1e-6);
        let right = Pose::new(10.0, -0.5, 0.0);
        let out = stanley(&straight_local(&right.pos), &right, 2.0, &p, 2.5, 1.0);
        assert!(out.wheel_angle > 0.0, "right steers left");
        // On the line, heading 0.1 rad to the left: steer right by about that much.
        let skew = Pose::new(10.0, -0.3, 0.1);
        let on_front = stanley(&straight_local(&skew.pos), &skew, 2.0, &p, 0.0, 1.0);
        assert!((on_front.wheel_angle + 0.1).abs() < 1e-6, "{on_front:?}");
        let bad = Pose::new(f64::NAN, 0.0, 0.0);
        assert!(!stanley(&straight_local(&left.pos), &bad, 2.0, &p, 2.5, 1.0).valid);
    }

    #[test]
    fn integral_action_learns_only_when_allowed_and_is_clamped() {
        let mut i = IntegralAction {
            gain: 0.1,
            limit: 0.02,
            capture: 0.3,
            min_speed: 0.5,
            offset: 0.0,
        };
        // Left of the line (positive XTE): the offset turns right, 0.1 · 0.05 · 1 s.
        let o = i.update(0.05, 3.0, 1.0 / 3.0, true);
        assert!(o < 0.0);
        i.update(0.05, 3.0, 1.0 / 3.0, true);
        i.update(0.05, 3.0, 1.0 / 3.0, true);
        assert!((i.offset + 0.1 * 0.05).abs() < 1e-12, "{}", i.offset);
        let before = i.offset;
        i.update(0.05, 3.0, 0.1, false); // not learning (a turn)
        i.update(0.5, 3.0, 0.1, true); // outside the capture band
        i.update(0.05, 0.1, 0.1, true); // too slow
        i.update(f64::NAN, 3.0, 0.1, true);
        assert_eq!(i.offset, before);
        for _ in 0..10_000 {
            i.update(-0.2, 3.0, 0.1, true);
        }
        assert_eq!(i.offset, 0.02, "clamped");
        i.gain = 0.0;
        assert_eq!(i.update(-0.2, 3.0, 0.1, true), 0.0, "off");
    }

    #[test]
    fn curvature_on_a_circle_matches_its_radius() {
        let r = 20.0;
        let g: Vec<PathPoint> = (0..60)
            .map(|i| {
                let a = i as f64 * 0.05;
                PathPoint::turn(v2(r * a.sin(), r - r * a.cos()))
            })
            .collect();
        let mut lp = LocalPath::new(&LocalPathParams {
            nodes_before: 1,
            nodes_after: 10,
            ..Default::default()
        });
        lp.rebuild(&g, 10);
        let a = 0.5f64;
        let pose = Pose::new(r * a.sin(), r - r * a.cos(), a);
        lp.nearest(&pose.pos);
        let out = pure_pursuit(&lp, &pose, 2.0, &params());
        assert!(
            (out.curvature - 1.0 / r).abs() < 0.03 / r,
            "κ {} vs {}",
            out.curvature,
            1.0 / r
        );
        // The path's own curvature at the preview point, left positive; mirrored, right.
        assert!(
            (out.path_curvature - 1.0 / r).abs() < 0.03 / r,
            "path κ {}",
            out.path_curvature
        );
        let mirrored: Vec<Vec2> = lp.points().iter().map(|p| v2(p.x, -p.y)).collect();
        let k = curvature_along(&mirrored, lp.index_local(), 2.0, 1.0);
        assert!((k + 1.0 / r).abs() < 0.03 / r, "mirrored κ {k}");
        let line: Vec<Vec2> = (0..20).map(|i| v2(i as f64 * 0.5, 1.0)).collect();
        assert_eq!(curvature_along(&line, 0, 3.0, 1.0), 0.0);
    }

    /// A toy loop: a plant that turns `ratio` times less than the model for a wheel angle
    /// settles, under a proportional law on a circle, at a standing error on the outside; the
    /// scale learns until the curve is driven on the line, whichever way it curves.
    #[test]
    fn curvature_scale_learns_the_curve_bias_either_way_and_only_when_allowed() {
        let params = CurvatureScaleParams {
            gain: 0.5,
            limit: 0.3,
            capture: 0.3,
            min_speed: 0.5,
            max_heading_error: CURVATURE_SCALE_MAX_HEADING_ERROR,
        };
        let (l, r, ratio) = (3.0, 15.0, 1.1);
        for side in [1.0, -1.0] {
            let kappa = side / r;
            let mut s = CurvatureScale::new(params, l, 0.0);
            let mut xte = 0.0;
            for _ in 0..3000 {
                // The law's own correction (2·XTE/Ld² for a 3 m look-ahead) and the scale's
                // share; the plant turns 1/ratio of the commanded wheel angle's curvature; the
                // error moves by the curvature shortfall (steady state of pure pursuit).
                let add = s.update((xte, 0.0), kappa, 3.0, 0.02, true);
                let delta = (l * kappa).atan() + add - 2.0 * xte / 9.0 * l;
                let driven = delta.tan() / (l * ratio);
                xte += (driven - kappa) * 9.0 / 2.0 * side.abs() * 0.02 * 5.0;
            }
            assert!((s.scale - (ratio - 1.0)).abs() < 0.02, "scale {}", s.scale);
            assert!(xte.abs() < 0.002, "xte {xte}");
        }
        // Nothing is learnt on a straight, off the line, turning hard, slowly, on a turn, or
        // from NaN; it is clamped; gain 0 adds nothing.
        let mut s = CurvatureScale::new(params, l, 0.0);
        for (xte, he, k, v, learn) in [
            (0.05, 0.0, 0.001, 3.0, true),
            (0.5, 0.0, 0.1, 3.0, true),
            (0.05, 0.05, 0.1, 3.0, true),
            (0.05, 0.0, 0.1, 0.1, true),
            (0.05, 0.0, 0.1, 3.0, false),
            (f64::NAN, 0.0, 0.1, 3.0, true),
        ] {
            s.update((xte, he), k, v, 0.1, learn);
            assert_eq!(s.scale, 0.0, "learnt from {xte} {he} {k} {v} {learn}");
        }
        for _ in 0..10_000 {
            s.update((-0.2, 0.0), 0.1, 3.0, 0.1, true);
        }
        assert_eq!(s.scale, 0.3, "clamped");
        assert_eq!(CurvatureScale::new(params, l, 0.9).scale, 0.3);
        let off = CurvatureScaleParams {
            gain: 0.0,
            ..params
        };
        assert_eq!(
            CurvatureScale::new(off, l, 0.2).update((0.1, 0.0), 0.1, 3.0, 0.1, true),
            0.0
        );
    }

    /// Closed loop on the kinematic bicycle model: backing along a straight line from 0.5 m
    /// off and 5° out converges onto it, with the reverse mirror of the forward law.
    #[test]
    fn reverse_pursuit_about_the_rear_axle_converges() {
        // The path runs towards −x (driving order), the vehicle points +x and backs up.
        let g: Vec<PathPoint> = (0..200)
            .map(|i| PathPoint {
                pos: v2(-(i as f64) * 0.5, 0.0),
                tag: crate::geo::Tag::Work,
                direction: Direction::Reverse,
            })
            .collect();
        let mut lp = LocalPath::new(&LocalPathParams::default());
        let p = params();
        let (mut x, mut y, mut th) = (-2.0, 0.5, 5f64.to_radians());
        let (v, h): (f64, f64) = (-1.0, 0.02);
        let mut worst_late: f64 = 0.0;
        for k in 0..2500 {
            let pose = Pose::new(x, y, th);
            let hint = ((-x / 0.5).round().max(0.0) as usize).min(g.len() - 1);
            lp.rebuild(&g, hint);
            lp.nearest(&pose.pos);
            let out = steering_from_travel(
                pure_pursuit(&lp, &travel_pose(&pose, Direction::Reverse), v.abs(), &p),
                Direction::Reverse,
            );
            assert!(out.valid);
            x += v * th.cos() * h;
            y += v * th.sin() * h;
            th += v * out.wheel_angle.tan() / p.wheelbase * h;
            if k > 1500 {
                worst_late = worst_late.max(y.abs());
            }
        }
        assert!(x < -40.0, "backed along the path: x = {x}");
        assert!(
            worst_late < 0.01,
            "converged onto the line: |y| {worst_late}"
        );
        // North of a westward reverse path, pointing east: the wheels go right, so that the
        // heading turns counter-clockwise and the rear swings south onto the line.
        let pose = Pose::new(-20.0, 0.3, 0.0);
        lp.rebuild(&g, 40);
        lp.nearest(&pose.pos);
        let mirrored = steering_from_travel(
            pure_pursuit(&lp, &travel_pose(&pose, Direction::Reverse), 1.0, &p),
            Direction::Reverse,
        );
        assert!(mirrored.wheel_angle < 0.0, "{mirrored:?}");
    }

    #[test]
    fn the_default_look_ahead_covers_the_steering_response() {
        let mut p = params();
        // Nothing known of the steering: the configured look-ahead.
        assert_eq!(p.response_time(), 0.0);
        assert_eq!(scheduled_lookahead(&p, p.response_time(), 5.0), 5.0);
        // The nominal steering (0.15 s lag, 30°/s, out of a 5 m turn with L = 3 m): the slew
        // (1.03 s) + lag, under the 1.2 s of `track.ld_gain_s`.
        let sweep = (3.0f64 / 5.0).atan();
        p.steering = SteeringResponse {
            lag: 0.15,
            dead_time: 0.0,
            rate: 30f64.to_radians(),
            sweep,
            vehicle_lag: 0.0,
        };
        let t = p.response_time();
        assert!(
            (t - (0.15 + sweep / 30f64.to_radians())).abs() < 1e-12,
            "{t}"
        );
        assert!(t < 1.2);
        // A 20°/s motor: 1.70 s, the look-ahead at 10 km/h from 2.78 to 4.7 m.
        p.steering.rate = 20f64.to_radians();
        assert!((p.response_time() - 1.70).abs() < 0.01);
        assert!((scheduled_lookahead(&p, p.response_time(), 2.78) - 4.72).abs() < 0.02);
        // A 0.6 s lag at 90°/s: the phase budget, 2.66 × 0.6 s.
        p.steering.rate = 90f64.to_radians();
        p.steering.lag = 0.6;
        assert!((p.response_time() - LAG_PHASE_BUDGET * 0.6).abs() < 1e-12);
        // Nonsense stays finite.
        p.steering.rate = 0.0;
        p.steering.lag = f64::INFINITY;
        assert_eq!(p.response_time(), 0.0);
    }

    #[test]
    fn lookahead_grows_with_speed() {
        assert_eq!(lookahead(&params(), 1.0), 3.0);
        assert_eq!(lookahead(&params(), 5.0), 5.0);
        assert_eq!(lookahead(&params(), -5.0), 5.0);
    }

    #[test]
    fn nan_inputs_give_an_invalid_zero_command() {
        let p = Pose {
            pos: v2(f64::NAN, 0.0),
            heading: 0.0,
        };
        let out = pure_pursuit(&straight_local(&v2(1.0, 0.0)), &p, 2.0, &params());
        assert!(!out.valid);
        assert_eq!(out.wheel_angle, 0.0);
        let empty = LocalPath::new(&LocalPathParams::default());
        assert!(!pure_pursuit(&empty, &Pose::new(0.0, 0.0, 0.0), 1.0, &params()).valid);
    }

    #[test]
    fn wheel_angle_is_clamped() {
        let p = Pose::new(10.0, 0.0, std::f64::consts::PI * 0.9);
        let out = pure_pursuit(&straight_local(&p.pos), &p, 1.0, &params());
        assert!(out.wheel_angle.abs() <= 35f64.to_radians() + 1e-12);
    }
}
