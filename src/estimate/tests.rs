//! The estimator: prediction, the observer, coasting.

use super::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{FRAC_PI_2, PI};

pub(super) fn params(predict: bool) -> EstimatorParams {
    EstimatorParams {
        wheelbase: 3.0,
        antenna: AntennaOffset {
            forward: 1.5,
            left: 0.2,
            up: 3.0,
        },
        gnss_latency: 0.05,
        predict,
        lead_time: 0.0,
        roll_compensation: true,
        observer: ObserverParams::default(),
    }
}

/// True rear-axle pose on a circle of radius r at time t (speed v, start at origin east).
fn circle(r: f64, v: f64, t: f64) -> Pose {
    let a = v * t / r;
    Pose::new(r * a.sin(), r - r * a.cos(), a)
}

pub(super) fn antenna_of(e: &Estimator, p: &Pose) -> Vec2 {
    let a = e.params().antenna;
    let h = heading_vec(p.heading);
    p.pos + h * a.forward + left_normal(&h) * a.left
}

#[test]
fn antenna_offset_round_trip_and_roll() {
    let e = Estimator::new(params(false));
    let p = Pose::new(3.0, 4.0, 0.7);
    let ant = antenna_of(&e, &p);
    assert!((e.antenna_to_rear_axle(&ant, p.heading, None) - p.pos).norm() < 1e-12);
    // 2° of roll, right side down: the antenna is 3·sin 2° ≈ 10.5 cm right of where it
    // would be; the rear axle comes out right where it is.
    let roll = 2f64.to_radians();
    let shifted = ant - left_normal(&heading_vec(p.heading)) * (3.0 * roll.sin());
    let back = e.antenna_to_rear_axle(&shifted, p.heading, Some(roll));
    assert!((back - p.pos).norm() < 1e-12);
}

#[test]
fn prediction_beats_the_raw_fix_under_latency() {
    let (r, v, lat) = (10.0, 3.0, 0.05);
    let delta = (3.0f64 / r).atan();
    let mut pred = Estimator::new(params(true));
    let mut raw = Estimator::new(params(false));
    for k in 0..=100 {
        let t = k as f64 * 0.01;
        pred.on_wheel_angle(t, delta);
    }
    // Fix measured at 0.9 s, received at 0.95 s; estimate at 1.0 s.
    let truth_then = circle(r, v, 0.9);
    let fix = GnssFix {
        t_received: 0.9 + lat,
        antenna: antenna_of(&pred, &truth_then),
        heading: Some(truth_then.heading),
        speed: v,
        roll: None,
        latency: None,
    };
    pred.on_fix(&fix);
    raw.on_fix(&fix);
    let truth_now = circle(r, v, 1.0);
    let e_pred = (pred.estimate(1.0).unwrap().pose.pos - truth_now.pos).norm();
    let e_raw = (raw.estimate(1.0).unwrap().pose.pos - truth_now.pos).norm();
    assert!(e_raw > 0.25, "raw error {e_raw}");
    assert!(e_pred < 1e-3, "predicted error {e_pred}");
    let h = pred.estimate(1.0).unwrap().pose.heading;
    assert!((h - truth_now.heading).abs() < 1e-4);
}

#[test]
fn a_fix_with_its_own_latency_is_compensated_by_it() {
    // Configured 0.05 s; the sentence's time stamp says 0.15 s (measured 0.8, received 0.95).
    let (r, v) = (10.0, 3.0);
    let delta = (3.0f64 / r).atan();
    let truth_then = circle(r, v, 0.8);
    let truth_now = circle(r, v, 1.0);
    let error = |latency: Option<f64>, predict: bool| {
        let mut e = Estimator::new(params(predict));
        for k in 0..=100 {
            e.on_wheel_angle(k as f64 * 0.01, delta);
        }
        e.on_fix(&GnssFix {
            t_received: 0.95,
            antenna: antenna_of(&e, &truth_then),
            heading: Some(truth_then.heading),
            speed: v,
            roll: None,
            latency,
        });
        (e.estimate(1.0).unwrap().pose.pos - truth_now.pos).norm()
    };
    assert!(
        error(Some(0.15), true) < 1e-3,
        "{}",
        error(Some(0.15), true)
    );
    // Without it, the configured 0.05 s leaves the 0.1 s difference: about 0.3 m.
    assert!(error(None, true) > 0.25, "{}", error(None, true));
    // A latency that is not a number is the configured one.
    assert_eq!(error(Some(f64::NAN), true), error(None, true));
    // The plain reference (no prediction) takes the fix as it is, whatever its latency.
    assert_eq!(error(Some(0.15), false), error(None, false));
}

#[test]
fn wheel_history_interpolates() {
    let mut e = Estimator::new(params(true));
    assert_eq!(e.wheel_angle_at(1.0), 0.0);
    e.on_wheel_angle(1.0, 0.1);
    e.on_wheel_angle(2.0, 0.3);
    assert!((e.wheel_angle_at(1.5) - 0.2).abs() < 1e-12);
    assert_eq!(e.wheel_angle_at(0.0), 0.1);
    assert_eq!(e.wheel_angle_at(5.0), 0.3);
    for i in 0..1000 {
        e.on_wheel_angle(3.0 + i as f64, i as f64);
    }
    assert_eq!(e.wheel_angle_at(1e9), 999.0, "ring keeps the newest");
    // The prediction's cursor search gives what a search from the start gives, for
    // non-decreasing times before, within (on and between samples) and after the ring.
    let mut cursor = 1;
    for k in 0..=1600 {
        // The ring holds t = 875..=1002 s.
        let t = 800.0 + 0.25 * k as f64;
        let a = e.wheel_angle_from(t, &mut cursor);
        assert_eq!(a, e.wheel_angle_at(t), "t = {t}");
    }
    assert_eq!(cursor, RING, "ran past the newest sample");
}

#[test]
fn no_fix_and_bad_input_give_none_not_panics() {
    let mut e = Estimator::new(params(true));
    assert!(e.estimate(1.0).is_none());
    e.on_fix(&GnssFix {
        t_received: f64::NAN,
        antenna: v2(0.0, 0.0),
        heading: Some(0.0),
        speed: 1.0,
        roll: None,
        latency: None,
    });
    e.on_wheel_angle(f64::INFINITY, 0.2);
    assert!(e.estimate(1.0).is_none());
}

#[test]
fn heading_from_course_without_dual_antenna() {
    let mut e = Estimator::new(EstimatorParams {
        antenna: AntennaOffset::default(),
        ..params(false)
    });
    for k in 0..5 {
        e.on_fix(&GnssFix {
            t_received: k as f64 * 0.1,
            antenna: v2(k as f64 * 0.3, k as f64 * 0.3),
            heading: None,
            speed: 3.0,
            roll: None,
            latency: None,
        });
    }
    let est = e.estimate(0.5).unwrap();
    assert!((est.pose.heading - std::f64::consts::FRAC_PI_4).abs() < 1e-9);
}

/// A vehicle on a straight line with a wheel-angle sensor bias and a world drift, fed to
/// an estimator with the observer on: fixes at 10 Hz, wheel angles at 50 Hz, heading and
/// position exact. Returns the estimator after `seconds` s driven at 3 m/s along `heading`.
fn drive(
    e: &mut Estimator,
    t0: f64,
    seconds: f64,
    start: Pose,
    bias: f64,
    drift: Vec2,
    float: Option<(f64, f64, Vec2)>,
) -> Pose {
    drive_at(3.0, e, (t0, seconds), start, (bias, drift), float)
}

/// [`drive`] at `v` m/s.
fn drive_at(
    v: f64,
    e: &mut Estimator,
    span: (f64, f64),
    start: Pose,
    disturbances: (f64, Vec2),
    float: Option<(f64, f64, Vec2)>,
) -> Pose {
    drive_with_fixes_every(5, v, e, span, start, disturbances, float)
}

/// [`drive_at`] with a fix every `fix_steps` wheel-angle samples of 20 ms (5: 10 Hz).
fn drive_with_fixes_every(
    fix_steps: usize,
    v: f64,
    e: &mut Estimator,
    (t0, seconds): (f64, f64),
    start: Pose,
    (bias, drift): (f64, Vec2),
    float: Option<(f64, f64, Vec2)>,
) -> Pose {
    let (mut x, mut y, th) = (start.pos.x, start.pos.y, start.heading);
    let steps = (seconds / 0.02).round() as usize;
    for k in 1..=steps {
        let t = t0 + k as f64 * 0.02;
        x += (v * th.cos() + drift.x) * 0.02;
        y += (v * th.sin() + drift.y) * 0.02;
        // Straight: true wheel angle 0, the sensor reads the bias.
        e.on_wheel_angle(t, bias);
        if k % fix_steps == 0 {
            let truth = Pose::new(x, y, th);
            let mut antenna = antenna_of(e, &truth);
            let mut in_float = false;
            if let Some((a, b, err)) = float {
                if t >= a && t <= b {
                    antenna += err;
                    in_float = true;
                }
            }
            e.set_learning(!in_float);
            e.set_coasting(in_float);
            e.on_fix(&fix_without_roll(e, t, antenna, th, v));
        }
    }
    Pose::new(x, y, th)
}

/// A fix of `antenna` measured at `t` (received the configured latency later), with the
/// heading `th` and speed `v`, without roll or a latency of its own.
pub(super) fn fix_without_roll(e: &Estimator, t: f64, antenna: Vec2, th: f64, v: f64) -> GnssFix {
    GnssFix {
        t_received: t + e.params().gnss_latency,
        antenna,
        heading: Some(th),
        speed: v,
        roll: None,
        latency: None,
    }
}

fn observer_params() -> EstimatorParams {
    EstimatorParams {
        observer: ObserverParams {
            bias_tau: 5.0,
            drift_tau: 5.0,
            coast_max: 30.0,
            ..ObserverParams::default()
        },
        ..params(true)
    }
}

/// Passes north and south across a slope falling to the East, rolling `roll(along)` (right
/// side down driving north), the vehicle slipping downhill at `slip`·sin(roll) m/s, with an
/// IMU roll noise of ±0.05° (seeded, uniform) and the antenna 3 m up: the estimator's slip
/// coefficient and world drift afterwards.
fn slope_passes(roll: impl Fn(f64) -> f64, slip: f64, passes: usize) -> (f64, Vec2) {
    let mut e = Estimator::new(EstimatorParams {
        observer: ObserverParams {
            drift_tau: 60.0,
            slip_tau: 30.0,
            ..ObserverParams::default()
        },
        ..params(true)
    });
    let v = 4.0;
    let mut t = 0.0;
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for pass in 0..passes {
        let north = pass % 2 == 0;
        let th = if north { FRAC_PI_2 } else { -FRAC_PI_2 };
        let x0 = pass as f64 * 3.0;
        let (mut x, mut y) = (x0, if north { 0.0 } else { 150.0 });
        // Re-anchor at the start of each pass (a turn, not simulated, comes between).
        e.fix_pose = None;
        for k in 1..=(150.0 / v / 0.02) as usize {
            t += 0.02;
            let along = if north { y } else { 150.0 - y };
            // Positive roll when driving north (East side down); flips driving south.
            let r = if north { roll(along) } else { -roll(along) };
            let right = -left_normal(&heading_vec(th));
            x += (v * th.cos() + right.x * slip * r.sin()) * 0.02;
            y += (v * th.sin() + right.y * slip * r.sin()) * 0.02;
            e.on_wheel_angle(t, 0.0);
            if k % 5 == 0 {
                let measured = r + rng.gen_range(-0.05f64..0.05).to_radians();
                let truth = Pose::new(x, y, th);
                let antenna = antenna_of(&e, &truth)
                    - left_normal(&heading_vec(th)) * (e.params().antenna.up * r.sin());
                e.on_fix(&GnssFix {
                    t_received: t + e.params().gnss_latency,
                    antenna,
                    heading: Some(th),
                    speed: v,
                    roll: Some(measured),
                    latency: None,
                });
            }
        }
    }
    (e.slip, e.drift())
}

#[test]
fn the_observer_tells_slope_slip_from_a_world_drift() {
    // 0.015 m/s per degree of roll, the roll 2° ± 1° over 60 m: the downhill drift and the
    // slip push the same way on every pass; only the variation tells them apart.
    let c = 0.015f64.to_degrees();
    let varying = |along: f64| (2.0 + (along / 60.0 * std::f64::consts::TAU).sin()).to_radians();
    let (slip, drift) = slope_passes(varying, c, 12);
    assert!((slip - c).abs() < 0.1 * c, "slip {slip} vs {c}");
    assert!(drift.norm() < 0.004, "drift {drift:?}");
    // On an even slope they cannot be told apart; the sum must be right, and roll noise
    // (3 m up, it moves the antenna) must not drive them apart to their limits.
    let even = |_: f64| 2f64.to_radians();
    let (slip, drift) = slope_passes(even, c, 12);
    let total = drift.x + slip * 2f64.to_radians().sin();
    let truth = c * 2f64.to_radians().sin();
    assert!((total - truth).abs() < 0.003, "total {total} vs {truth}");
    assert!(
        slip.abs() < 2.0 * c && drift.norm() < 0.05,
        "slip {slip}, drift {drift:?}"
    );
}

#[test]
fn the_observer_learns_a_sensor_bias_and_a_world_drift_that_keeps_its_sign() {
    let mut e = Estimator::new(observer_params());
    let bias = 0.5f64.to_radians();
    // East drift of 3 cm/s while driving north, then south.
    let drift = v2(0.03, 0.0);
    let north = Pose::new(0.0, 0.0, std::f64::consts::FRAC_PI_2);
    let end = drive(&mut e, 0.0, 60.0, north, bias, drift, None);
    assert!(
        (e.wheel_offset() - bias).abs() < 0.05 * bias,
        "offset {} vs {bias}",
        e.wheel_offset()
    );
    assert!((e.drift() - drift).norm() < 0.003, "drift {:?}", e.drift());
    // Well out of the headings' noise (exact here): steered for as learnt.
    let steered = e.wheel_offset_for_steering();
    assert!(
        (steered - bias).abs() < 0.05 * bias,
        "steered {steered} vs {bias}"
    );
    // Turned about (the drift is on the other side of the vehicle now): the estimate is
    // still right from the first fix, and the prediction carries it.
    let south = Pose::new(end.pos.x + 3.0, end.pos.y, -std::f64::consts::FRAC_PI_2);
    let t = 61.0;
    drive(&mut e, t, 1.0, south, bias, drift, None);
    assert!((e.drift() - drift).norm() < 0.003, "drift {:?}", e.drift());
    // Without the observer the same drive leaves both at zero.
    let mut off = Estimator::new(params(true));
    drive(&mut off, 0.0, 20.0, north, bias, drift, None);
    assert_eq!((off.wheel_offset(), off.drift()), (0.0, Vec2::zeros()));
}

#[test]
fn at_a_crawl_the_drift_is_learnt_and_the_offset_is_not() {
    // 0.5 m/s, between the drift's and the offset's learning speeds: a 0.5° offset turns
    // the heading by 0.1° per second (the heading's noise on a receiver), a 3 cm/s drift is
    // 6 % of the motion.
    let mut e = Estimator::new(EstimatorParams {
        observer: ObserverParams {
            min_speed: 0.2,
            offset_min_speed: 1.0,
            ..observer_params().observer
        },
        ..observer_params()
    });
    let north = Pose::new(0.0, 0.0, std::f64::consts::FRAC_PI_2);
    let drift = v2(0.03, 0.0);
    drive_at(
        0.5,
        &mut e,
        (0.0, 60.0),
        north,
        (0.5f64.to_radians(), drift),
        None,
    );
    assert!((e.drift() - drift).norm() < 0.003, "drift {:?}", e.drift());
    assert_eq!(e.wheel_offset(), 0.0);
}

#[test]
fn a_1_hz_receiver_s_fixes_teach_the_drift_and_the_offset() {
    // Fixes 1 s apart (50 wheel-angle samples): the observer learns from the innovation over
    // the whole interval, as from 10 Hz fixes. It learnt nothing beyond 0.5 s, and a 2° slope's
    // 3 cm/s slip stood every pass 8 cm off.
    let mut e = Estimator::new(observer_params());
    let (bias, drift) = (0.5f64.to_radians(), v2(0.03, 0.0));
    let north = Pose::new(0.0, 0.0, FRAC_PI_2);
    drive_with_fixes_every(50, 3.0, &mut e, (0.0, 60.0), north, (bias, drift), None);
    assert!((e.drift() - drift).norm() < 0.003, "drift {:?}", e.drift());
    assert!(
        (e.wheel_offset() - bias).abs() < 0.05 * bias,
        "offset {} vs {bias}",
        e.wheel_offset()
    );
    // Fixes 2 s apart (a 1 Hz receiver losing every other one) are not learnt from: over
    // that long the dead reckoning's own error would be taken for drift.
    let mut sparse = Estimator::new(observer_params());
    drive_with_fixes_every(
        100,
        3.0,
        &mut sparse,
        (0.0, 60.0),
        north,
        (bias, drift),
        None,
    );
    assert_eq!(
        (sparse.wheel_offset(), sparse.drift()),
        (0.0, Vec2::zeros())
    );
}

#[test]
fn the_estimator_coasts_through_rtk_float_and_a_position_jump() {
    let mut e = Estimator::new(observer_params());
    let north = Pose::new(0.0, 0.0, std::f64::consts::FRAC_PI_2);
    // A 20 cm float error from 30 s to 40 s: the estimate dead-reckons and stays on the
    // true track instead.
    let err = v2(0.2, 0.0);
    let truth = drive(
        &mut e,
        0.0,
        35.0,
        north,
        0.0,
        Vec2::zeros(),
        Some((30.0, 40.0, err)),
    );
    assert!(e.is_coasting());
    let est = e.estimate(35.0).expect("an estimate").pose;
    assert!(
        (est.pos.x - truth.pos.x).abs() < 0.01,
        "{est:?} vs {truth:?}"
    );
    // Fixed again: the fixes are taken at once.
    let truth = drive(
        &mut e,
        35.0,
        10.0,
        truth,
        0.0,
        Vec2::zeros(),
        Some((30.0, 40.0, err)),
    );
    assert!(!e.is_coasting());
    let est = e.estimate(45.0).expect("an estimate").pose;
    assert!((est.pos.x - truth.pos.x).abs() < 0.01);
    // A 10 cm jump of a fixed solution (multipath) is not followed either, nor learnt.
    let truth = drive(&mut e, 45.0, 5.0, truth, 0.0, Vec2::zeros(), None);
    let before = e.drift();
    let jump = v2(0.1, 0.0);
    let ant = antenna_of(&e, &truth) + jump;
    e.on_fix(&GnssFix {
        t_received: 50.1,
        antenna: ant,
        heading: Some(truth.heading),
        speed: 3.0,
        roll: None,
        latency: None,
    });
    assert!(e.is_coasting());
    assert_eq!(e.drift(), before);
}

#[test]
fn small_angle_sin_cos_and_rotations_match_the_library() {
    for k in -1000..=1000 {
        let a = k as f64 * 1e-4;
        let (s, c) = crate::geo::small_sin_cos(a);
        assert!(
            (s - a.sin()).abs() <= 2e-17 && (c - a.cos()).abs() <= 2e-16,
            "{a}"
        );
    }
    // 400 rotations (a 2 s prediction at 5 ms steps) stay on the library's angle.
    let (mut sc, mut th) = (0.3f64.sin_cos(), 0.3);
    for i in 0..400 {
        let a = 0.01 * ((i as f64) * 0.1).sin();
        sc = crate::geo::rotate(sc, crate::geo::small_sin_cos(a));
        th += a;
    }
    assert!((sc.0 - th.sin()).abs() < 1e-13 && (sc.1 - th.cos()).abs() < 1e-13);
}

/// An estimator with the drift observer alone (time constant 20 s).
fn drift_observer() -> Estimator {
    Estimator::new(EstimatorParams {
        observer: ObserverParams {
            drift_tau: 20.0,
            ..ObserverParams::default()
        },
        ..params(true)
    })
}

/// Four passes north and south (60 s at 3 m/s each, 3 m apart) with the drift (world, m/s)
/// `drift_of(pass, left)` on each (`left` the vehicle's left normal), driving straight
/// (`straight`, the memory of the drift per direction on) or not: the error of the estimated
/// drift across the heading 1 s into each pass, m/s.
fn crab_passes(drift_of: impl Fn(usize, Vec2) -> Vec2, straight: bool) -> Vec<f64> {
    let mut e = drift_observer();
    e.set_straight(straight);
    let mut errors = Vec::new();
    for pass in 0..4 {
        let north = pass % 2 == 0;
        let th = if north { FRAC_PI_2 } else { -FRAC_PI_2 };
        let left = left_normal(&heading_vec(th));
        let drift = drift_of(pass, left);
        let t = pass as f64 * 61.0;
        // Re-anchor at the start of each pass (a turn, not simulated, comes between).
        e.fix_pose = None;
        let start = Pose::new(pass as f64 * 3.0, if north { 0.0 } else { 180.0 }, th);
        let at = drive(&mut e, t, 1.0, start, 0.0, drift, None);
        errors.push(left.dot(&(e.drift() - drift)).abs());
        drive(&mut e, t + 1.0, 59.0, at, 0.0, drift, None);
    }
    errors
}

#[test]
fn a_drift_of_the_vehicle_is_kept_per_direction_and_one_of_the_ground_is_not_swapped() {
    // 5 cm/s to the vehicle's right (a side draft's crab), or East on the ground.
    let vehicle = |_: usize, left: Vec2| left * -0.05;
    let ground = |_: usize, _: Vec2| v2(0.05, 0.0);
    // The vehicle's drift: from the third pass on each pass starts with its own.
    let kept = crab_passes(vehicle, true);
    assert!(kept[2] < 0.01 && kept[3] < 0.01, "{kept:?}");
    // Without the memory (not straight: a curve) the world vector is exactly wrong there.
    let world = crab_passes(vehicle, false);
    assert!(world[2] > 0.08 && world[3] > 0.08, "{world:?}");
    // A drift of the ground keeps its side on every pass, memory or not.
    for straight in [true, false] {
        let ground = crab_passes(ground, straight);
        assert!(ground[1..].iter().all(|&e| e < 0.01), "{ground:?}");
    }
    // A ground drift that grows (3 cm/s on the first pass, 6 from the second) keeps its newest
    // value: the third pass does not go back to what the first learnt (an error of 3 cm/s).
    let growing = |pass: usize, _: Vec2| v2(if pass == 0 { 0.03 } else { 0.06 }, 0.0);
    let newest = crab_passes(growing, true);
    assert!(newest[2] < 0.01 && newest[3] < 0.01, "{newest:?}");
}

/// Drives `seconds` from `start` at 3 m/s turning at `rate` (rad/s, the wheels at the angle the
/// kinematic model needs) with a drift of `crab` m/s to the vehicle's left plus `ground` (world,
/// m/s), a work path or not (`work`), straight when `rate` is 0: the end pose.
fn drive_curve(
    e: &mut Estimator,
    t0: f64,
    seconds: f64,
    start: Pose,
    rate: f64,
    (crab, ground): (f64, Vec2),
    work: bool,
) -> Pose {
    let v = 3.0;
    let wheel = (rate * e.params().wheelbase / v).atan();
    let (mut pos, mut th) = (start.pos, start.heading);
    e.set_work(work);
    e.set_straight(rate == 0.0);
    let steps = (seconds / 0.02).round() as usize;
    for k in 1..=steps {
        let t = t0 + k as f64 * 0.02;
        let h = heading_vec(th);
        pos += (h * v + left_normal(&h) * crab + ground) * 0.02;
        th = wrap_angle(th + rate * 0.02);
        e.on_wheel_angle(t, wheel);
        if k % 5 == 0 {
            e.on_fix(&GnssFix {
                t_received: t + e.params().gnss_latency,
                antenna: antenna_of(e, &Pose::new(pos.x, pos.y, th)),
                heading: Some(th),
                speed: v,
                roll: None,
                latency: None,
            });
        }
    }
    Pose::new(pos.x, pos.y, th)
}

/// The estimated drift's error across the heading `heading` against the truth, m/s.
fn drift_error_across(e: &Estimator, heading: f64, (crab, ground): (f64, Vec2)) -> f64 {
    let n = left_normal(&heading_vec(heading));
    (n.dot(&e.drift()) - (crab + n.dot(&ground))).abs()
}

#[test]
fn on_a_curved_work_path_a_crab_turns_with_the_vehicle() {
    // An arc of R 20 m (0.15 rad/s) for 90 s, 6 cm/s to the vehicle's right (a side draft).
    let crab = (-0.06, Vec2::zeros());
    let start = Pose::new(0.0, 0.0, 0.0);
    let mut errors = Vec::new();
    for work in [true, false] {
        let mut e = drift_observer();
        let end = drive_curve(&mut e, 0.0, 90.0, start, 0.15, crab, work);
        errors.push(drift_error_across(&e, end.heading, crab));
    }
    // On a work path the drift turns with the heading once learnt; a world vector learnt over
    // 20 s trails a heading that turns a radian in 7 s.
    assert!(errors[0] < 0.01 && errors[1] > 0.03, "{errors:?}");
}

#[test]
fn a_headland_turn_carries_a_crab_known_from_both_directions_but_not_a_ground_drift() {
    // Passes north, south and north again (40 s each), a half circle of R 3 m (1 rad/s)
    // between: the error across the heading 1 s into the third pass's start, and a second
    // later, with a crab and with a ground drift.
    for (drift, carried) in [
        ((-0.06, Vec2::zeros()), true),
        ((0.0, v2(0.06, 0.0)), false),
    ] {
        let mut e = drift_observer();
        let mut at = Pose::new(0.0, 0.0, FRAC_PI_2);
        let mut t = 0.0;
        for pass in 0..2 {
            if pass == 1 {
                // After the first turn nothing tells the two apart yet: the drift across the
                // way back is learnt afresh from zero, within 5 s either way (the crab's
                // world vector kept through the turn, 12 cm/s off, took a pass).
                at = drive_curve(&mut e, t, 5.0, at, 0.0, drift, true);
                let error = drift_error_across(&e, at.heading, drift);
                assert!(error < 0.015, "{drift:?}: {error} 5 s after the first turn");
                at = drive_curve(&mut e, t + 5.0, 35.0, at, 0.0, drift, true);
            } else {
                at = drive_curve(&mut e, t, 40.0, at, 0.0, drift, true);
            }
            let rate = if pass == 0 { 1.0 } else { -1.0 };
            at = drive_curve(&mut e, t + 40.0, PI, at, rate, drift, false);
            t += 40.0 + PI;
        }
        // The turn has just ended, heading north again: a crab turned with the vehicle (a
        // world vector kept through the turn would be 12 cm/s off), a ground drift stayed.
        assert_eq!(e.curve_carried(), carried, "{drift:?}");
        let turned = drift_error_across(&e, at.heading, drift);
        at = drive_curve(&mut e, t, 1.0, at, 0.0, drift, true);
        let error = drift_error_across(&e, at.heading, drift);
        assert!(
            turned < 0.01 && error < 0.01,
            "{drift:?}: {turned}, {error}"
        );
    }
}
