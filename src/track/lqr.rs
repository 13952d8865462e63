//! A linear-quadratic regulator on the path-frame error model with the steering actuator in
//! the state, gains scheduled by speed, plus curvature feed-forward. Registered as `lqr`.
//!
//! Model (linearised about the path, rear axle, driving direction; Rajamani, *Vehicle Dynamics
//! and Control*, ch. 3, kinematic error model; Snider, *Automatic Steering Methods for
//! Autonomous Automobile Path Tracking*, CMU-RI-TR-09-08, §4 for LQR on it): the state is the
//! cross-track error e (m, positive = left of the path), the heading error ψ (rad, vehicle −
//! path) and the wheel angle's deviation δ̃ from the path's feed-forward angle (rad):
//!
//! ```text
//! ė = v·ψ,   ψ̇ = v/L · δ̃,   δ̃̇ = (u − δ̃)/τ
//! ```
//!
//! τ is the steering's calibrated first-order lag plus the dead time the prediction does not
//! cover (the prediction, `track.lead_time_s`, covers the rest). The cost weighs e, ψ and the
//! wheel-angle *rate* (u − δ)/τ by Bryson's rule (`track.lqr_xte_m`, `track.lqr_heading_deg`,
//! and a fraction `track.lqr_rate_fraction` of the calibrated rate limit), so a slower motor
//! gets gentler gains instead of a limit cycle. For a double integrator e'' = (v²/L)·δ a fixed
//! time-domain cost gives a closed loop whose bandwidth *in distance* does not depend on the
//! speed; the lag (a length v·τ) and the rate limit take it down at speed, which the schedule
//! does by itself.
//!
//! At configuration the model is discretised exactly (zero-order hold, matrix exponential
//! series) at the control period and the discrete algebraic Riccati equation is solved by the
//! structured doubling algorithm (Chu, Fan & Lin 2005) for every speed bin
//! ([`SPEED_STEP`] apart up to [`SPEEDS`]·[`SPEED_STEP`]); per period the gains are interpolated
//! from the table: nothing allocates.
//!
//! The command: u = δ_ff(s + v·τ) − K·[e, ψ, δ̃], δ_ff = atan(L·κ) with κ the path's curvature
//! (a three-point circle over ±[`CURVATURE_HALF_WINDOW_M`]) one response length ahead, so that
//! the lagging wheels reach the path's angle where it needs it. Far from the line the
//! cross-track term is capped at [`APPROACH_HEADING`] of heading, so the vehicle approaches at
//! a bounded angle rather than turning across.

use super::law::{LawNeeds, LawParams, SteeringLaw};
use super::local_path::LocalPath;
use super::{point_along, TrackOutput, TrackerParams};
use crate::geo::{left_normal, wrap_angle, Pose, Vec2};
use nalgebra::{Matrix3, Vector3};

/// Speed bins of the gain table.
pub const SPEEDS: usize = 48;
/// Speed step of the gain table, m/s (bins at 0.25 … 12 m/s).
pub const SPEED_STEP: f64 = 0.25;
/// The path's curvature is that of the circle through the points this far either side, m.
pub const CURVATURE_HALF_WINDOW_M: f64 = 1.5;
/// The path's heading at the nearest point is that of the chord over this far either side, m.
pub const TANGENT_HALF_WINDOW_M: f64 = 1.0;
/// Largest heading the cross-track term may ask for, rad (11.5°): more, and a rate-limited
/// steering coming out of a large correction overshoots into a limit cycle (a 1 m step at
/// 10 km/h with 0.35 rad).
pub const APPROACH_HEADING: f64 = 0.2;
/// Rate limit assumed where calibration has not given one, rad/s (30°/s).
const DEFAULT_RATE: f64 = std::f64::consts::FRAC_PI_6;

/// The LQR's cost (`[track]` lqr_* keys), SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LqrWeights {
    /// Cross-track error scale, m.
    pub xte: f64,
    /// Heading error scale, rad.
    pub heading: f64,
    /// The wheel-angle rate scale as a fraction of the calibrated rate limit.
    pub rate_fraction: f64,
}

impl Default for LqrWeights {
    fn default() -> Self {
        LqrWeights {
            xte: 0.1,
            heading: 6f64.to_radians(),
            rate_fraction: 0.5,
        }
    }
}

/// The regulator with its gain table.
#[derive(Debug, Clone, PartialEq)]
pub struct Lqr {
    /// Gains [k_e, k_ψ, k_δ] per speed bin (bin i at (i + 1)·SPEED_STEP).
    gains: [[f64; 3]; SPEEDS],
    /// The lag the model has, s (the feed-forward's preview time).
    lag: f64,
}

impl Lqr {
    /// The gain table for `tracker` (wheelbase, calibrated steering) at control period `dt` s.
    pub fn new(params: &LawParams, tracker: &TrackerParams, dt: f64) -> Self {
        let s = &tracker.steering;
        let dt = if dt.is_finite() && dt > 0.0 { dt } else { 0.02 };
        let lag = (s.lag.max(0.0) + s.dead_time.max(0.0)).max(dt);
        let rate = if s.rate.is_finite() && s.rate > 0.0 {
            s.rate
        } else {
            DEFAULT_RATE
        };
        let w = params.lqr;
        let weights = [
            1.0 / (w.xte * w.xte),
            1.0 / (w.heading * w.heading),
            1.0 / (w.rate_fraction * rate).powi(2),
        ];
        let mut gains = [[0.0; 3]; SPEEDS];
        for (i, g) in gains.iter_mut().enumerate() {
            let v = (i + 1) as f64 * SPEED_STEP;
            *g = gains_at(v, tracker.wheelbase, lag, dt, weights);
        }
        Lqr { gains, lag }
    }

    /// The gains at speed `v` (m/s), interpolated.
    pub fn gains(&self, v: f64) -> [f64; 3] {
        let x = (v.abs() / SPEED_STEP - 1.0).clamp(0.0, (SPEEDS - 1) as f64);
        let i = (x.floor() as usize).min(SPEEDS - 2);
        let f = x - i as f64;
        let (a, b) = (self.gains[i], self.gains[i + 1]);
        [
            a[0] + (b[0] - a[0]) * f,
            a[1] + (b[1] - a[1]) * f,
            a[2] + (b[2] - a[2]) * f,
        ]
    }
}

/// The discrete LQR gain [k_e, k_ψ, k_δ] at speed `v` for wheelbase `l`, lag `tau`, period
/// `dt` and Bryson weights [1/e², 1/ψ², 1/δ̇²].
fn gains_at(v: f64, l: f64, tau: f64, dt: f64, w: [f64; 3]) -> [f64; 3] {
    let p = Problem::at(v, l, tau, dt, w);
    let x = dare(&p.phi, &p.gamma, &p.q, p.r, &p.n);
    let k = (p.gamma.transpose() * x * p.phi + p.n.transpose())
        / (p.r + (p.gamma.transpose() * x * p.gamma)[0]);
    [k[0], k[1], k[2]]
}

/// The discrete LQR problem at speed `v`: the model (Φ, Γ) and the costs Q, R, N.
struct Problem {
    phi: Matrix3<f64>,
    gamma: Vector3<f64>,
    q: Matrix3<f64>,
    r: f64,
    n: Vector3<f64>,
}

impl Problem {
    fn at(v: f64, l: f64, tau: f64, dt: f64, w: [f64; 3]) -> Problem {
        let a = Matrix3::new(0.0, v, 0.0, 0.0, 0.0, v / l, 0.0, 0.0, -1.0 / tau);
        let b = Vector3::new(0.0, 0.0, 1.0 / tau);
        let (phi, gamma) = zoh(&a, &b, dt);
        // Cost per second: w_e·e² + w_ψ·ψ² + w_r·((u − δ̃)/τ)², i.e. Q, R and the cross term N.
        let rr = w[2] / (tau * tau);
        Problem {
            phi,
            gamma,
            q: Matrix3::from_diagonal(&Vector3::new(w[0], w[1], rr)) * dt,
            r: rr * dt,
            n: Vector3::new(0.0, 0.0, -rr) * dt,
        }
    }
}

/// Zero-order-hold discretisation (Φ, Γ) of ẋ = A·x + B·u over `dt`: the series of e^{A·dt}
/// and ∫₀^dt e^{A·s} ds · B (converges fast: ‖A·dt‖ is well under 1 at control periods).
fn zoh(a: &Matrix3<f64>, b: &Vector3<f64>, dt: f64) -> (Matrix3<f64>, Vector3<f64>) {
    let mut phi = Matrix3::identity();
    let mut integral = Matrix3::identity() * dt;
    let mut term = Matrix3::identity();
    for k in 1..30 {
        term = term * a * (dt / k as f64);
        phi += term;
        integral += term * (dt / (k + 1) as f64);
    }
    (phi, integral * b)
}

/// The stabilising solution X of the discrete algebraic Riccati equation with a cross term,
/// X = Q + ΦᵀXΦ − (ΦᵀXΓ + N)(R + ΓᵀXΓ)⁻¹(ΓᵀXΦ + Nᵀ), by the structured doubling algorithm
/// on the equivalent problem without a cross term (Φ − ΓR⁻¹Nᵀ, Q − NR⁻¹Nᵀ).
fn dare(
    phi: &Matrix3<f64>,
    gamma: &Vector3<f64>,
    q: &Matrix3<f64>,
    r: f64,
    n: &Vector3<f64>,
) -> Matrix3<f64> {
    let mut ak = phi - gamma * n.transpose() / r;
    let mut gk = gamma * gamma.transpose() / r;
    let mut hk = q - n * n.transpose() / r;
    let id = Matrix3::identity();
    for _ in 0..64 {
        let Some(w) = (id + gk * hk).try_inverse() else {
            break;
        };
        let a_next = ak * w * ak;
        let g_next = gk + ak * w * gk * ak.transpose();
        let h_next = hk + ak.transpose() * hk * w * ak;
        let change = (h_next - hk).norm();
        ak = a_next;
        gk = g_next;
        hk = h_next;
        if change <= 1e-12 * hk.norm().max(1e-300) {
            break;
        }
    }
    hk
}

impl SteeringLaw for Lqr {
    fn needs(&self) -> LawNeeds {
        LawNeeds {
            prediction: true,
            observer: true,
            integral: true,
            lost_motion: true,
            lag_lead: false,
        }
    }

    fn steer(
        &self,
        local: &LocalPath,
        pose: &Pose,
        speed: f64,
        wheel_angle: Option<f64>,
        params: &TrackerParams,
    ) -> TrackOutput {
        let points = local.points();
        let invalid = TrackOutput::invalid(pose.pos, 0.0);
        if points.len() < 2
            || !pose.pos.x.is_finite()
            || !pose.pos.y.is_finite()
            || !pose.heading.is_finite()
            || !speed.is_finite()
        {
            return invalid;
        }
        let spacing = local.params().spacing.max(1e-3);
        let i = local.index_local().min(points.len() - 1);
        let Some(tangent) = chord(points, i, samples(TANGENT_HALF_WINDOW_M, spacing)) else {
            return invalid;
        };
        let l = params.wheelbase;
        let max = params.max_wheel_angle;
        let kappa_here = curvature(points, i, samples(CURVATURE_HALF_WINDOW_M, spacing));
        let preview = speed.abs() * self.lag;
        let ahead = i + (preview / spacing).round() as usize;
        let kappa_ahead = curvature(
            points,
            ahead.min(points.len() - 1),
            samples(CURVATURE_HALF_WINDOW_M, spacing),
        );
        let ff_here = (l * kappa_here).atan();
        let ff_ahead = (l * kappa_ahead).atan();
        let e = left_normal(&tangent).dot(&(pose.pos - points[i]));
        let psi = wrap_angle(pose.heading - tangent.y.atan2(tangent.x));
        let delta = wheel_angle.filter(|d| d.is_finite()).unwrap_or(ff_here) - ff_here;
        let [ke, kpsi, kdelta] = self.gains(speed);
        // Far off the line, the cross-track term asks for at most APPROACH_HEADING of heading.
        let cap = kpsi.abs() * APPROACH_HEADING;
        let u = ff_ahead - (ke * e).clamp(-cap, cap) - kpsi * psi - kdelta * delta;
        if !u.is_finite() {
            return invalid;
        }
        let wheel_angle = u.clamp(-max, max);
        TrackOutput {
            wheel_angle,
            curvature: wheel_angle.tan() / l,
            lookahead: preview,
            target: point_along(points, i, preview),
            alpha: -psi,
            path_curvature: 0.0,
            valid: true,
        }
    }
}

/// Samples in `m` metres at `spacing`, at least 1.
fn samples(m: f64, spacing: f64) -> usize {
    ((m / spacing).round() as usize).max(1)
}

/// The unit chord of the path over `half` samples either side of sample `i`.
fn chord(points: &[Vec2], i: usize, half: usize) -> Option<Vec2> {
    let a = points[i.saturating_sub(half)];
    let b = points[(i + half).min(points.len() - 1)];
    let d = b - a;
    let n = d.norm();
    (n > 1e-9).then(|| d / n)
}

/// The signed curvature (1/m, positive left) of the circle through the samples `half` either
/// side of `i` and `i` itself; 0 where they are too close or in a line.
fn curvature(points: &[Vec2], i: usize, half: usize) -> f64 {
    let a = points[i.saturating_sub(half)];
    let b = points[i];
    let c = points[(i + half).min(points.len() - 1)];
    let (ab, bc, ca) = ((b - a).norm(), (c - b).norm(), (a - c).norm());
    let denom = ab * bc * ca;
    if denom < 1e-9 {
        return 0.0;
    }
    2.0 * crate::geo::cross(&(b - a), &(c - b)) / denom
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::{v2, PathPoint};
    use crate::track::local_path::LocalPathParams;

    fn tracker(lag: f64, rate_deg: f64) -> TrackerParams {
        crate::track::tests::tracker_with_steering(lag, rate_deg, 0.5)
    }

    fn law_params() -> LawParams {
        LawParams {
            predictive_ld_max: 4.5,
            feed_forward: true,
            stanley_gain: 2.5,
            stanley_soft_speed: 1.0,
            lqr: LqrWeights::default(),
            curvature: Default::default(),
        }
    }

    /// The Riccati solution satisfies its equation, and the closed loop of the discrete model
    /// decays, at every speed of the table.
    #[test]
    fn riccati_solution_is_the_stabilising_one() {
        let (l, tau, dt) = (3.0, 0.15, 0.02);
        let w = [400.0, 400.0, 1.0 / (0.5 * 30f64.to_radians()).powi(2)];
        for v in [0.25, 1.0, 2.78, 5.56, 6.94, 12.0] {
            let Problem {
                phi,
                gamma,
                q,
                r,
                n,
            } = Problem::at(v, l, tau, dt, w);
            let x = dare(&phi, &gamma, &q, r, &n);
            let g = gamma.transpose() * x * phi + n.transpose();
            let s = r + (gamma.transpose() * x * gamma)[0];
            let rhs = q + phi.transpose() * x * phi - g.transpose() * g / s;
            assert!((rhs - x).norm() <= 1e-6 * x.norm(), "v {v}: residual");
            let k = g / s;
            let closed = phi - gamma * k;
            let mut state = Vector3::new(0.3, 0.0, 0.0);
            for _ in 0..(60.0 / dt) as usize {
                state = closed * state;
            }
            assert!(state.norm() < 1e-3, "v {v}: {state:?}");
        }
    }

    /// The discretisation matches the closed form of the lag: Φ₃₃ = e^{−dt/τ}.
    #[test]
    fn zoh_matches_the_lag_closed_form() {
        let a = Matrix3::new(0.0, 2.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, -1.0 / 0.2);
        let b = Vector3::new(0.0, 0.0, 1.0 / 0.2);
        let (phi, gamma) = zoh(&a, &b, 0.05);
        assert!((phi[(2, 2)] - (-0.05f64 / 0.2).exp()).abs() < 1e-12);
        assert!((gamma[2] - (1.0 - (-0.05f64 / 0.2).exp())).abs() < 1e-12);
        assert!((phi[(0, 1)] - 2.0 * 0.05).abs() < 1e-12);
    }

    /// A slower steering motor gets gentler cross-track gains; gains are finite everywhere.
    #[test]
    fn gains_follow_the_steering_rate() {
        let fast = Lqr::new(&law_params(), &tracker(0.15, 30.0), 0.02);
        let slow = Lqr::new(&law_params(), &tracker(0.15, 10.0), 0.02);
        for v in [0.0, 1.0, 2.78, 6.94, 20.0] {
            let (f, s) = (fast.gains(v), slow.gains(v));
            assert!(
                f.iter().chain(s.iter()).all(|g| g.is_finite()),
                "{f:?} {s:?}"
            );
            assert!(f[0] > 0.0 && f[1] > 0.0, "{f:?}");
            if v > 0.5 {
                assert!(s[0] < f[0], "v {v}: {s:?} vs {f:?}");
            }
        }
    }

    fn local_on(global: &[PathPoint], at: &Pose, hint: usize) -> LocalPath {
        let mut lp = LocalPath::new(&LocalPathParams {
            nodes_before: 2,
            nodes_after: 10,
            ..Default::default()
        });
        lp.rebuild(global, hint);
        lp.nearest(&at.pos);
        lp
    }

    /// Closed loop on a kinematic bicycle with a lagging, rate-limited actuator: from 0.5 m
    /// off a straight line at 20 km/h the LQR settles within 2.5 cm in under 20 m without
    /// overshooting by more than 5 cm, and on a R 20 m circle at 10 km/h it stays on the
    /// circle (sampled every 1 m) once on it. Measured: 5.5 cm off the circle at worst, a gap
    /// on curves that pure pursuit does not have (issue 15; the law is not the default).
    #[test]
    fn settles_on_a_line_and_holds_a_circle() {
        let p = tracker(0.15, 30.0);
        let law = Lqr::new(&law_params(), &p, 0.02);
        let run = |global: &[PathPoint], start: Pose, v: f64, steps: usize| {
            let (mut x, mut y, mut th, mut d) = (start.pos.x, start.pos.y, start.heading, 0.0);
            let mut track = Vec::new();
            let h = 0.02;
            for _ in 0..steps {
                let pose = Pose::new(x, y, th);
                let hint = global
                    .iter()
                    .enumerate()
                    .min_by(|a, b| {
                        (a.1.pos - pose.pos)
                            .norm()
                            .total_cmp(&(b.1.pos - pose.pos).norm())
                    })
                    .map_or(0, |m| m.0);
                let lp = local_on(global, &pose, hint);
                let out = law.steer(&lp, &pose, v, Some(d), &p);
                assert!(out.valid);
                let rate = ((out.wheel_angle - d) / p.steering.lag)
                    .clamp(-p.steering.rate, p.steering.rate);
                d += rate * h;
                x += v * th.cos() * h;
                y += v * th.sin() * h;
                th += v * d.tan() / p.wheelbase * h;
                track.push(v2(x, y));
            }
            track
        };
        let line: Vec<PathPoint> = (0..400)
            .map(|i| PathPoint::work(v2(i as f64, 0.0)))
            .collect();
        let track = run(&line, Pose::new(5.0, 0.5, 0.0), 20.0 / 3.6, 1500);
        let settled_at = track
            .iter()
            .rposition(|q| q.y.abs() > 0.025)
            .map_or(5.0, |k| track[k].x);
        assert!(settled_at < 5.0 + 20.0, "settled at x = {settled_at:.1} m");
        let overshoot = track.iter().map(|q| -q.y).fold(0.0, f64::max);
        assert!(overshoot < 0.05, "overshoot {overshoot:.3} m");
        // The same westward, on the other side.
        let west: Vec<PathPoint> = (0..400)
            .map(|i| PathPoint::work(v2(-(i as f64), 0.0)))
            .collect();
        let track = run(
            &west,
            Pose::new(-5.0, 0.5, std::f64::consts::PI),
            20.0 / 3.6,
            1500,
        );
        let settled_at = track
            .iter()
            .rposition(|q| q.y.abs() > 0.025)
            .map_or(-5.0, |k| track[k].x);
        assert!(
            settled_at > -5.0 - 20.0,
            "westward: settled at x = {settled_at:.1} m"
        );
        let r = 20.0;
        let circle: Vec<PathPoint> = (0..250)
            .map(|i| {
                let a = i as f64 / r;
                PathPoint::work(v2(r * a.sin(), r - r * a.cos()))
            })
            .collect();
        let track = run(&circle, Pose::new(0.0, 0.0, 0.0), 10.0 / 3.6, 3000);
        let off: Vec<f64> = track[1500..]
            .iter()
            .map(|q| ((q - v2(0.0, r)).norm() - r).abs())
            .collect();
        let worst = off.iter().copied().fold(0.0, f64::max);
        assert!(worst < 0.1, "off the circle by {worst:.3} m");
    }
}
