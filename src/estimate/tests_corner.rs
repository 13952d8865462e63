//! The cornering slip ([`ObserverParams::corner_slip_tau`]): learnt in headland turns, carried
//! through an RTK float that begins in one.

use super::tests::{antenna_of, fix_without_roll, params};
use super::*;
use std::f64::consts::PI;

/// Speed (m/s, 10 km/h), turn radius (m) and straight length (m) of the drive.
const V: f64 = 2.78;
const R: f64 = 7.0;
const STRAIGHT: f64 = 20.0;

/// Lines east and west joined by U-turns of radius [`R`] (left, then right, ...), the rear axle
/// slipping outwards in the turns at `slip`·v·a_y (a slip angle of `slip` rad per m/s² of
/// lateral acceleration), fixes at 10 Hz with a 20 ms wheel-angle sample. The last turn is
/// driven with an RTK-float error of 0.3 m from its middle to 10 m into the line after it,
/// the estimator coasting. Returns the estimator's cornering slip before the float and its
/// lateral error (m, dead-reckoned position against the truth, across the heading) at the
/// float's end.
fn u_turns(turns: usize, slip: f64, corner_slip_tau: f64) -> (f64, f64) {
    let mut e = Estimator::new(EstimatorParams {
        observer: ObserverParams {
            bias_tau: 20.0,
            drift_tau: 60.0,
            slip_tau: 30.0,
            corner_slip_tau,
            coast_max: 30.0,
            robust: true,
            ..ObserverParams::default()
        },
        ..params(true)
    });
    let l = e.params().wheelbase;
    let (mut x, mut y, mut th) = (0.0, 0.0, 0.0);
    let mut t = 0.0;
    let mut learnt = 0.0;
    let mut error = f64::NAN;
    let dt = 0.02;
    // (wheel angle sign, length in m) of each piece: a straight, then a turn, ...
    let mut pieces = vec![(0.0, STRAIGHT)];
    for k in 0..turns {
        pieces.push((if k % 2 == 0 { 1.0 } else { -1.0 }, PI * R));
        pieces.push((0.0, STRAIGHT));
    }
    let last_turn = pieces.len() - 2;
    for (p, &(side, length)) in pieces.iter().enumerate() {
        let delta = side * (l / R).atan();
        let yaw_rate = V * delta.tan() / l;
        let steps = (length / V / dt).round() as usize;
        for k in 1..=steps {
            t += dt;
            // The rear axle's velocity: along the heading, and outwards by the slip angle.
            let lateral = -slip * V * (V * yaw_rate);
            let n = left_normal(&heading_vec(th + 0.5 * yaw_rate * dt));
            x += (V * (th + 0.5 * yaw_rate * dt).cos() + n.x * lateral) * dt;
            y += (V * (th + 0.5 * yaw_rate * dt).sin() + n.y * lateral) * dt;
            th += yaw_rate * dt;
            e.on_wheel_angle(t, delta);
            if k % 5 != 0 {
                continue;
            }
            let along = k as f64 * V * dt;
            let floating =
                (p == last_turn && along >= 0.5 * length) || (p == last_turn + 1 && along <= 10.0);
            let truth = Pose::new(x, y, th);
            let mut antenna = antenna_of(&e, &truth);
            if floating {
                antenna += v2(0.3, 0.0);
            } else if p < last_turn {
                learnt = e.corner_slip;
            }
            e.set_learning(!floating);
            e.set_coasting(floating);
            e.on_fix(&fix_without_roll(&e, t, antenna, th, V));
            if floating {
                if let Some(pose) = e.fix_pose {
                    error = (pose.pos - truth.pos).dot(&left_normal(&heading_vec(th)));
                }
            }
        }
    }
    (learnt, error)
}

/// Soft tyres (a slip angle of 0.4° per m/s², a_y 1.1 m/s² in the turns): after three turns the
/// cornering slip is learnt within a third, and the dead reckoning through a float that begins
/// half-way round the fourth leaves the line within 3 cm, where the kinematic model's leaves it
/// over 5 cm off. Without a slip, nothing is learnt.
#[test]
fn the_cornering_slip_is_learnt_in_turns_and_carried_through_a_float() {
    let slip = 0.4f64.to_radians();
    let (learnt, error) = u_turns(4, slip, 30.0);
    assert!(
        (learnt - slip).abs() < slip / 3.0,
        "learnt {learnt} of {slip}"
    );
    // The point that turns without it lies c·v² ahead of the rear axle (at most L/2).
    let mut e = Estimator::new(params(true));
    e.corner_slip = learnt;
    assert!((e.slip_free_lead(V) - learnt * V * V).abs() < 1e-12);
    assert_eq!(e.slip_free_lead(-V), 0.0);
    assert_eq!(e.slip_free_lead(100.0), 0.5 * e.params().wheelbase);
    assert!(error.abs() < 0.03, "dead-reckoned {error} m off");
    let (_, kinematic) = u_turns(4, slip, 0.0);
    assert!(kinematic.abs() > 0.05, "kinematic {kinematic} m off");
    let (none, error) = u_turns(4, 0.0, 30.0);
    assert!(none.abs() < slip / 5.0, "learnt {none} without a slip");
    assert!(
        error.abs() < 0.02,
        "dead-reckoned {error} m off without a slip"
    );
}
