//! Pure pursuit, the seed-000 law: steer onto the arc through the preview point one look-ahead
//! along the local path. Registered twice: `predictive` (the default: the predicted pose, the
//! disturbance observer's course and wheel offset, integral action, lost-motion compensation)
//! and `pure_pursuit` (the plain reference on the latest fix).

use super::law::{LawNeeds, SteeringLaw};
use super::local_path::LocalPath;
use super::{
    curvature_along, lookahead, point_along, scheduled_lookahead, TrackOutput, TrackerParams,
};
use crate::geo::{cross, heading_vec, Pose};

/// Pure pursuit with what the controller feeds it chosen by `needs`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PurePursuit {
    pub needs: LawNeeds,
    /// The look-ahead is scheduled on the steering's response ([`scheduled_lookahead`]), its
    /// growth with speed (`ld_gain`) stopping at this distance, m; `None`: the seed's
    /// `ld_min`/`ld_gain` alone.
    pub scheduled: Option<f64>,
}

impl PurePursuit {
    /// The default tracker: pure pursuit on a latency-compensated, dead-reckoned pose, steering
    /// the course over ground with every compensation on; its look-ahead grows with speed up
    /// to `ld_max` m (`track.predictive_ld_max_m`), or further where the steering's response
    /// needs it.
    pub fn predictive(ld_max: f64) -> Self {
        PurePursuit {
            needs: LawNeeds {
                prediction: true,
                observer: true,
                integral: true,
                lost_motion: true,
                lag_lead: true,
            },
            scheduled: Some(ld_max),
        }
    }

    /// The plain seed-000 reference: the latest fix as it is, nothing added.
    pub fn plain() -> Self {
        PurePursuit {
            needs: LawNeeds {
                prediction: false,
                observer: false,
                integral: false,
                lost_motion: false,
                lag_lead: false,
            },
            scheduled: None,
        }
    }
}

impl SteeringLaw for PurePursuit {
    fn needs(&self) -> LawNeeds {
        self.needs
    }

    fn steer(
        &self,
        local: &LocalPath,
        pose: &Pose,
        speed: f64,
        _wheel_angle: Option<f64>,
        params: &TrackerParams,
    ) -> TrackOutput {
        let Some(ld_max) = self.scheduled else {
            return pure_pursuit_at(local, pose, lookahead(params, speed), params);
        };
        let growth = (params.ld_gain * speed.abs()).min(ld_max);
        // With the lead, the look-ahead covers only the lag it leaves.
        let mut steering = params.steering;
        if self.needs.lag_lead {
            steering.lag = super::lag_lead::residual(steering.lag);
        }
        let response_time = steering.response_time();
        let ld = scheduled_lookahead(
            &TrackerParams {
                ld_gain: 0.0,
                ..*params
            },
            response_time,
            speed,
        )
        .max(growth);
        let out = pure_pursuit_at(local, pose, ld, params);
        if out.valid {
            within_the_rate(local, pose, speed, params, out)
        } else {
            out
        }
    }
}

/// Share of the steering's rate limit a correction may ask for ([`within_the_rate`]). The
/// whole rate: the bound then acts only where the wheels could not follow at all. (Swept on
/// the envelope's slow-steering rows and the nominal suite: 0.5 slowed every line start after
/// a turn, +14 % on the nominal straights; 1.5 left a 10°/s motor's R 15 m arcs at 13 cm.)
const RATE_SHARE: f64 = 1.0;

/// Bisection steps of [`within_the_rate`].
const RATE_BISECTION_STEPS: usize = 6;

/// `out` (pure pursuit at its look-ahead), or pure pursuit at the shortest longer look-ahead
/// whose correction a rate-limited steering can follow. Pure pursuit's loop about the path
/// oscillates at ωn = √2·v/Ld, so a correction of Δδ (the command less the wheel angle the
/// path's curvature needs) asks the wheels for about Δδ·ωn rad/s: the larger the error, the
/// faster. Beyond the steering's rate the wheels lag the command, the lag adds phase and a
/// large transient (a curved line started with the wheels straight on a 10°/s motor) grows
/// into a weave. The look-ahead is lengthened until Δδ·ωn ≤ [`RATE_SHARE`] × the rate: a
/// describing-function bound, amplitude-dependent, so that near the path (Δδ small) nothing
/// changes and far from it the correction is slower but converges. Pure; at most
/// [`RATE_BISECTION_STEPS`] + 1 more pursuits, only while the bound is exceeded.
fn within_the_rate(
    local: &LocalPath,
    pose: &Pose,
    speed: f64,
    params: &TrackerParams,
    out: TrackOutput,
) -> TrackOutput {
    let rate = params.steering.rate;
    if !(rate > 0.0 && rate.is_finite()) {
        return out;
    }
    let v = speed.abs();
    // The wheel-angle rate the correction of `o` asks for, rad/s. What the path itself needs
    // is its mean curvature over the look-ahead: the circle through the nearest point, the
    // point half-way and the preview point ([`span_curvature`]).
    let points = local.points();
    let asks = |o: &TrackOutput| {
        let needed =
            (params.wheelbase * span_curvature(points, local.index_local(), o.lookahead)).atan();
        (o.wheel_angle - needed).abs() * std::f64::consts::SQRT_2 * v / o.lookahead
    };
    let allowed = RATE_SHARE * rate;
    let follows = |o: &TrackOutput| asks(o) <= allowed;
    if follows(&out) {
        return out;
    }
    // Δδ falls about as 1/Ld² and ωn as 1/Ld: Ld·(asks/allowed)^(1/3) is about where the bound
    // holds; twice that brackets it.
    let mut lo = out.lookahead;
    let mut hi = lo * 2.0 * (asks(&out) / allowed).cbrt();
    let mut best = pure_pursuit_at(local, pose, hi, params);
    if !best.valid {
        return out;
    }
    for _ in 0..RATE_BISECTION_STEPS {
        let mid = 0.5 * (lo + hi);
        let o = pure_pursuit_at(local, pose, mid, params);
        if o.valid && follows(&o) {
            hi = mid;
            best = o;
        } else {
            lo = mid;
        }
    }
    best
}

/// The path's mean curvature over the look-ahead `ld` from sample `start`, 1/m: the circle
/// through the points 0, `ld`/2 and `ld` along it. A correction is the command less this: the
/// curvature at the preview point alone counts the path's own way into or out of an arc as a
/// correction (an arc's exit, the preview on the straight, would be "corrected" towards the
/// straight and the arc left early), and a 2 m chord on a turn whose nodes are metres apart
/// reads 0 between two nodes.
fn span_curvature(points: &[crate::geo::Vec2], start: usize, ld: f64) -> f64 {
    curvature_along(points, start, 0.5 * ld, 0.5 * ld)
}

/// Half the chord over which the path's curvature at the preview point is measured, m.
const PATH_CURVATURE_HALF_M: f64 = 1.0;

/// Seed-000 pure pursuit: from the nearest local point integrate the look-ahead along the
/// local path to the preview point; α is the angle from the heading to it;
/// κ = 2·sin α / Ld and δ = atan(L·κ).
pub fn pure_pursuit(
    local: &LocalPath,
    pose: &Pose,
    speed: f64,
    params: &TrackerParams,
) -> TrackOutput {
    pure_pursuit_at(local, pose, lookahead(params, speed), params)
}

/// [`pure_pursuit`] with the look-ahead `ld` (m) given.
pub fn pure_pursuit_at(
    local: &LocalPath,
    pose: &Pose,
    ld: f64,
    params: &TrackerParams,
) -> TrackOutput {
    let points = local.points();
    let invalid = TrackOutput::invalid(pose.pos, ld);
    if points.is_empty()
        || !pose.pos.x.is_finite()
        || !pose.pos.y.is_finite()
        || !pose.heading.is_finite()
        || !ld.is_finite()
        || ld <= 0.0
    {
        return invalid;
    }
    let target = point_along(points, local.index_local(), ld);
    let to = target - pose.pos;
    let h = heading_vec(pose.heading);
    let alpha = cross(&h, &to).atan2(h.dot(&to));
    let curvature = 2.0 * alpha.sin() / ld;
    let max = params.max_wheel_angle;
    let wheel_angle = (params.wheelbase * curvature).atan().clamp(-max, max);
    TrackOutput {
        wheel_angle,
        curvature,
        lookahead: ld,
        target,
        alpha,
        path_curvature: curvature_along(points, local.index_local(), ld, PATH_CURVATURE_HALF_M),
        valid: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::tests::straight_local;

    fn params(rate_deg_s: f64) -> TrackerParams {
        crate::track::tests::tracker_with_steering(0.1, rate_deg_s, 0.0)
    }

    /// The wheel-angle rate pure pursuit's correction asks for, rad/s (the bound of
    /// `within_the_rate`, on a straight path).
    fn asked(out: &TrackOutput, speed: f64) -> f64 {
        out.wheel_angle.abs() * std::f64::consts::SQRT_2 * speed / out.lookahead
    }

    #[test]
    fn a_large_correction_is_slowed_to_what_the_steering_can_follow() {
        let law = PurePursuit::predictive(4.5);
        let speed = 10.0 / 3.6;
        let far = Pose::new(20.0, 1.0, 0.0);
        let local = straight_local(&far.pos);
        // The correction of a 1 m error at the scheduled look-ahead (an unknown rate, 0) asks
        // for more than a 10°/s steering gives: its look-ahead grows until it would not.
        let fast = law.steer(&local, &far, speed, None, &params(30.0));
        let slow = law.steer(&local, &far, speed, None, &params(10.0));
        assert!(fast.valid && slow.valid);
        assert!(asked(&fast, speed) <= 30f64.to_radians());
        assert!(
            slow.lookahead > fast.lookahead + 0.5,
            "slow {} fast {}",
            slow.lookahead,
            fast.lookahead
        );
        let rate = 10f64.to_radians();
        assert!(
            asked(&slow, speed) <= rate * 1.001,
            "{}",
            asked(&slow, speed)
        );
        // Not longer than needed: a look-ahead 5 % shorter would ask for more than the rate.
        let shorter = pure_pursuit_at(&local, &far, slow.lookahead * 0.95, &params(10.0));
        assert!(asked(&shorter, speed) > rate);
        assert!(slow.wheel_angle < 0.0 && slow.wheel_angle > fast.wheel_angle);
        // Near the line nothing changes, and an unknown rate (0) changes nothing.
        let near = Pose::new(20.0, 0.02, 0.0);
        let local = straight_local(&near.pos);
        let a = law.steer(&local, &near, speed, None, &params(10.0));
        let b = law.steer(&local, &near, speed, None, &params(0.0));
        assert_eq!(a, b);
        let scheduled = law.steer(&straight_local(&far.pos), &far, speed, None, &params(0.0));
        assert!((scheduled.lookahead - 1.2 * speed).abs() < 1e-9);
        assert!(asked(&scheduled, speed) > rate);
        assert!(scheduled.lookahead <= fast.lookahead && fast.lookahead < slow.lookahead);
    }

    /// The local path of an arc of radius `r` m (left, centre (0, r), from the origin, nodes
    /// `spacing` m apart) of length `arc` m, then the straight on from its end, near `at`.
    fn arc_then_straight(r: f64, arc: f64, spacing: f64, at: &crate::geo::Vec2) -> LocalPath {
        use crate::geo::{v2, PathPoint};
        use crate::track::local_path::LocalPathParams;
        let end = arc / r;
        let mut g: Vec<PathPoint> = (0..=(arc / spacing) as usize)
            .map(|i| {
                let a = i as f64 * spacing / r;
                PathPoint::work(v2(r * a.sin(), r * (1.0 - a.cos())))
            })
            .collect();
        let (p, t) = (
            v2(r * end.sin(), r * (1.0 - end.cos())),
            v2(end.cos(), end.sin()),
        );
        g.extend((1..30).map(|i| PathPoint::work(p + t * (i as f64 * spacing))));
        let mut lp = LocalPath::new(&LocalPathParams {
            nodes_before: 1,
            nodes_after: 10,
            ..Default::default()
        });
        let nearest = crate::track::local_path::nearest_global(&g, at, 0, g.len());
        lp.rebuild(&g, nearest);
        lp.nearest(at);
        lp
    }

    #[test]
    fn an_arc_followed_to_its_end_is_not_slowed_as_a_correction() {
        // On an R 10 m arc 3 m before it ends in a straight, on the path and along it, at
        // 15 km/h with a 10°/s steering: the command is the arc's own and no correction, so
        // the rate bound leaves the look-ahead as scheduled. (Measured against the curvature
        // at the preview point alone, on the straight, the arc's wheel angle counted as a
        // correction, the look-ahead grew and the vehicle left the arc early: a turn's exit
        // 30 cm off the next line.) Likewise in the middle of an arc of nodes 1.5 and 3 m
        // apart: with 3 m, the 2 m chord at the preview point read 0.014–0.23 /m on this
        // 0.1 /m arc, and the look-ahead grew to 5.6–9.6 m at each of 2.6, 3.0 and 4.4 m.
        let law = PurePursuit::predictive(4.5);
        let speed = 15.0 / 3.6;
        let (r, arc) = (10.0, 12.0);
        for (along, spacing) in [
            (arc - 3.0, 1.0),
            (4.0, 1.5),
            (4.7, 1.5),
            (5.3, 1.5),
            (2.6, 3.0),
            (3.0, 3.0),
            (4.4, 3.0),
        ] {
            let a: f64 = along / r;
            let pose = Pose::new(r * a.sin(), r * (1.0 - a.cos()), a);
            let local = arc_then_straight(r, arc, spacing, &pose.pos);
            let slow = law.steer(&local, &pose, speed, None, &params(10.0));
            let unbounded = law.steer(&local, &pose, speed, None, &params(0.0));
            assert!(slow.valid && unbounded.valid);
            assert_eq!(
                slow.lookahead, unbounded.lookahead,
                "{along} m along the arc, nodes {spacing} m apart"
            );
        }
    }
}
