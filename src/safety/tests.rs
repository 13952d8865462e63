use super::*;

const DT: f64 = 0.02;

/// A supervisor fed good inputs up to `t`.
fn feed_good(s: &mut Supervisor, t: f64) {
    s.on_gnss(t, FixQuality::RtkFixed);
    s.on_wheel_angle(t, 0.0, false, false);
    s.on_speed(t, 10.0 / 3.6);
}

fn engaged_supervisor() -> (Supervisor, f64) {
    let mut s = Supervisor::new(SafetyParams::default());
    let mut t = 0.0;
    feed_good(&mut s, t);
    assert_eq!(
        s.step(t, Some(0.0), Some(0.1), Some(0.0)).state,
        SafetyState::Ready
    );
    s.request_engage();
    t += DT;
    feed_good(&mut s, t);
    let c = s.step(t, Some(0.0), Some(0.1), Some(0.0));
    assert!(c.engaged, "{c:?}");
    (s, t)
}

#[test]
fn engages_only_on_operator_request_when_ready() {
    let mut s = Supervisor::new(SafetyParams::default());
    // Nothing received yet: not ready, an engage is refused.
    s.request_engage();
    let c = s.step(0.0, Some(0.0), Some(0.0), Some(0.0));
    assert!(!c.engaged);
    assert_eq!(s.last_refusal(), FaultCode::GnssTimeout);
    feed_good(&mut s, 0.1);
    let c = s.step(0.1, Some(0.0), Some(0.0), Some(0.0));
    assert_eq!(c.state, SafetyState::Ready);
    assert!(!c.engaged, "ready is not engaged");
}

#[test]
fn refuses_far_from_the_line() {
    let mut s = Supervisor::new(SafetyParams::default());
    feed_good(&mut s, 0.0);
    s.request_engage();
    assert!(!s.step(0.0, Some(0.0), Some(1.5), Some(0.0)).engaged);
    assert_eq!(s.last_refusal(), FaultCode::XteTooLarge);
    s.request_engage();
    assert!(!s.step(0.02, Some(0.0), Some(0.1), Some(1.2)).engaged);
    assert_eq!(s.last_refusal(), FaultCode::HeadingErrorTooLarge);
}

#[test]
fn gnss_timeout_disengages_within_one_period_and_never_reengages() {
    let (mut s, mut t) = engaged_supervisor();
    let last_gnss = t;
    let mut disengaged_at = None;
    while t < last_gnss + 2.0 {
        t += DT;
        s.on_wheel_angle(t, 0.0, false, false);
        s.on_speed(t, 2.0);
        let c = s.step(t, Some(0.0), Some(0.0), Some(0.0));
        if !c.engaged && disengaged_at.is_none() {
            disengaged_at = Some(t);
            assert_eq!(c.fault, FaultCode::GnssTimeout);
        }
    }
    let at = disengaged_at.expect("disengaged");
    assert!(at - last_gnss <= 0.3 + DT + 1e-9, "{}", at - last_gnss);
    // GNSS returns: Ready, but not engaged without a fresh engage.
    for _ in 0..50 {
        t += DT;
        feed_good(&mut s, t);
        let c = s.step(t, Some(0.0), Some(0.0), Some(0.0));
        assert!(!c.engaged);
    }
    assert_eq!(s.state(), SafetyState::Ready);
}

#[test]
fn bad_frame_score_is_opendbc_style() {
    let (mut s, t) = engaged_supervisor();
    for _ in 0..4 {
        s.on_frame_check(CheckedInput::WheelAngle, false);
    }
    assert!(!s.input_invalid(CheckedInput::WheelAngle));
    assert!(s.step(t + DT, Some(0.0), Some(0.0), Some(0.0)).engaged);
    s.on_frame_check(CheckedInput::WheelAngle, false);
    assert!(s.input_invalid(CheckedInput::WheelAngle));
    let c = s.step(t + 2.0 * DT, Some(0.0), Some(0.0), Some(0.0));
    assert!(!c.engaged);
    assert_eq!(c.fault, FaultCode::WheelAngleInvalid);
    s.on_frame_check(CheckedInput::WheelAngle, true);
    assert!(
        !s.input_invalid(CheckedInput::WheelAngle),
        "−1 per good frame"
    );
}

#[test]
fn rate_limit_starts_from_measured_angle() {
    let mut s = Supervisor::new(SafetyParams::default());
    s.on_gnss(0.0, FixQuality::RtkFixed);
    s.on_speed(0.0, 2.0);
    s.on_wheel_angle(0.0, 0.1, false, false);
    s.step(0.0, Some(0.0), Some(0.0), Some(0.0));
    s.request_engage();
    let c = s.step(DT, Some(-0.5), Some(0.0), Some(0.0));
    assert!(c.engaged);
    let max_step = 45f64.to_radians() * DT;
    assert!(
        (c.wheel_angle - (0.1 - max_step)).abs() < 1e-12,
        "{}",
        c.wheel_angle
    );
}

#[test]
fn lateral_acceleration_limits_the_angle() {
    let p = SafetyParams::default();
    let mut s = Supervisor::new(p.clone());
    let v = 20.0 / 3.6;
    let mut t = 0.0;
    s.on_gnss(t, FixQuality::RtkFixed);
    s.on_wheel_angle(t, 0.0, false, false);
    s.on_speed(t, v);
    s.step(t, Some(0.0), Some(0.0), Some(0.0));
    s.request_engage();
    let mut last = 0.0;
    for _ in 0..200 {
        t += DT;
        s.on_gnss(t, FixQuality::RtkFixed);
        s.on_wheel_angle(t, last, false, false);
        s.on_speed(t, v);
        let c = s.step(t, Some(0.6), Some(0.0), Some(0.0));
        assert!(c.engaged);
        assert!(v * v * c.curvature.abs() <= p.a_lat_max + 1e-9);
        last = c.wheel_angle;
    }
    assert!(last > 0.1, "still steers up to the limit: {last}");
}

#[test]
fn override_bit_and_divergence_disengage() {
    let (mut s, t) = engaged_supervisor();
    s.on_wheel_angle(t + DT, 0.0, true, false);
    s.on_gnss(t + DT, FixQuality::RtkFixed);
    s.on_speed(t + DT, 2.0);
    let c = s.step(t + DT, Some(0.0), Some(0.0), Some(0.0));
    assert_eq!(c.fault, FaultCode::OperatorOverride);

    let (mut s, mut t) = engaged_supervisor();
    let mut fault_at = None;
    for _ in 0..100 {
        t += DT;
        s.on_gnss(t, FixQuality::RtkFixed);
        s.on_speed(t, 2.0);
        // The driver holds the wheels hard left while the command is straight.
        s.on_wheel_angle(t, 0.4, false, false);
        let c = s.step(t, Some(0.0), Some(0.0), Some(0.0));
        if !c.engaged {
            fault_at.get_or_insert((t, c.fault));
        }
    }
    let (_, code) = fault_at.expect("override detected");
    assert_eq!(code, FaultCode::OperatorOverride);
}

#[test]
fn rtk_float_tolerance() {
    let p = SafetyParams {
        rtk_float_tolerance: 1.0,
        ..SafetyParams::default()
    };
    let mut s = Supervisor::new(p);
    let mut t = 0.0;
    feed_good(&mut s, t);
    s.step(t, Some(0.0), Some(0.0), Some(0.0));
    s.request_engage();
    t += DT;
    feed_good(&mut s, t);
    assert!(s.step(t, Some(0.0), Some(0.0), Some(0.0)).engaged);
    let float_start = t + DT;
    let mut out_at = None;
    while t < float_start + 3.0 {
        t += DT;
        s.on_gnss(t, FixQuality::RtkFloat);
        s.on_wheel_angle(t, 0.0, false, false);
        s.on_speed(t, 2.0);
        if !s.step(t, Some(0.0), Some(0.0), Some(0.0)).engaged {
            out_at.get_or_insert(t);
        }
    }
    let dur = out_at.expect("float disengages after the tolerance") - float_start;
    assert!(dur > 1.0 - 1e-9 && dur <= 1.0 + 2.0 * DT, "{dur}");
}

#[test]
fn every_fault_code_fits_the_dbc_range() {
    // The DBC is the source of truth for the bus: GuidanceStatus.Fault's range holds every code.
    let msg = crate::can::codec::MESSAGES
        .iter()
        .find(|m| m.name == "GuidanceStatus")
        .unwrap();
    let sig = msg.signals.iter().find(|s| s.name == "Fault").unwrap();
    for (i, code) in FaultCode::ALL.iter().enumerate() {
        assert_eq!(*code as usize, i);
        assert!((i as f64) <= sig.max, "fault {i} beyond the DBC range");
    }
}

/// Engaged on work line 1, fed good inputs: the wheels follow the command exactly.
fn engaged_on_a_line(params: SafetyParams) -> (Supervisor, f64) {
    let mut s = Supervisor::new(params);
    s.set_line(Some(1), 0.0);
    let mut t = 0.0;
    feed_good(&mut s, t);
    s.step(t, Some(0.0), Some(0.0), Some(0.0));
    s.request_engage();
    t += DT;
    feed_good(&mut s, t);
    assert!(s.step(t, Some(0.0), Some(0.0), Some(0.0)).engaged);
    (s, t)
}

/// A headland pass of S-bends at r_min: the path bends left for 4 s, then right for 4 s, and
/// the cross-track error leaves the ±0.2 m band on the outside of each bend (0.3 m, the
/// tracker lagging the curvature's step). Those swings follow the path's bends, not a weave:
/// no fault over a minute. The same swings with the path straight are a weave.
#[test]
fn swings_that_follow_the_paths_bends_are_not_a_weave() {
    for bending in [true, false] {
        let (mut s, mut t) = engaged_on_a_line(SafetyParams::default());
        let start = t;
        let mut fault = None;
        while t < start + 60.0 {
            t += DT;
            feed_good(&mut s, t);
            let phase = ((t - start) / 4.0).floor() as i64;
            let side = if phase % 2 == 0 { 1.0 } else { -1.0 };
            // The error peaks a second into each bend, on its outside (right of a left bend).
            let into = (t - start) - 4.0 * phase as f64;
            let x = -side * 0.3 * (std::f64::consts::PI * into / 4.0).sin();
            s.set_path_curvature(if bending { side / 8.0 } else { 0.0 });
            let c = s.step(t, Some(0.0), Some(x), Some(0.0));
            if !c.engaged {
                fault = Some((t - start, c.fault));
                break;
            }
        }
        if bending {
            assert_eq!(fault, None, "the path's own bends");
        } else {
            let (at, code) = fault.expect("a weave on a straight path");
            assert_eq!(code, FaultCode::TrackingUnstable, "at {at} s");
        }
    }
}

#[test]
fn a_weave_on_a_work_line_disengages_and_is_held_until_the_next_line() {
    let (mut s, mut t) = engaged_on_a_line(SafetyParams::default());
    let start = t;
    let mut fault_at = None;
    while t < start + 60.0 {
        t += DT;
        feed_good(&mut s, t);
        let x = 0.45 * (std::f64::consts::TAU * (t - start) / 8.0).sin();
        let c = s.step(t, Some(0.0), Some(x), Some(0.0));
        if !c.engaged {
            assert_eq!(c.fault, FaultCode::TrackingUnstable);
            fault_at = Some(t - start);
            break;
        }
    }
    let at = fault_at.expect("a weave must disengage");
    assert!((10.0..15.0).contains(&at), "{at}");
    // Held: an engage on the same line is refused with the same fault.
    t += DT;
    feed_good(&mut s, t);
    s.request_engage();
    let c = s.step(t, Some(0.0), Some(0.0), Some(0.0));
    assert!(!c.engaged);
    assert_eq!(s.last_refusal(), FaultCode::TrackingUnstable);
    assert_eq!(c.state, SafetyState::Fault(FaultCode::TrackingUnstable));
    // The next line clears it.
    s.set_line(Some(2), 0.0);
    t += DT;
    feed_good(&mut s, t);
    s.request_engage();
    assert!(s.step(t, Some(0.0), Some(0.0), Some(0.0)).engaged);
}

#[test]
fn an_offset_on_a_work_line_is_off_line_and_the_operator_acknowledges_it() {
    let (mut s, mut t) = engaged_on_a_line(SafetyParams::default());
    let start = t;
    let mut fault_at = None;
    while t < start + 30.0 {
        t += DT;
        feed_good(&mut s, t);
        let x = if t - start < 5.0 { 0.01 } else { 2.5 };
        let c = s.step(t, Some(0.0), Some(x), Some(0.0));
        if !c.engaged {
            assert_eq!(c.fault, FaultCode::OffLine);
            fault_at = Some(t - start - 5.0);
            break;
        }
    }
    let at = fault_at.expect("an offset must disengage");
    assert!((at - 0.5).abs() <= 2.0 * DT + 1e-9, "{at}");
    s.request_disengage();
    s.acknowledge();
    t += DT;
    feed_good(&mut s, t);
    s.step(t, Some(0.0), Some(0.0), Some(0.0));
    s.request_engage();
    t += DT;
    feed_good(&mut s, t);
    assert!(s.step(t, Some(0.0), Some(0.0), Some(0.0)).engaged);
}

#[test]
fn the_work_line_checks_do_not_watch_other_paths() {
    // A weave and an offset of 2.5 m (beyond off_line, within off_path) in a turn: not a
    // fault.
    let (mut s, mut t) = engaged_on_a_line(SafetyParams::default());
    s.set_line(None, 0.0);
    let start = t;
    while t < start + 60.0 {
        t += DT;
        feed_good(&mut s, t);
        let x = 0.8 * (std::f64::consts::TAU * (t - start) / 8.0).sin();
        s.set_path_distance(Some(if t - start < 30.0 { x.abs() } else { 2.5 }));
        assert!(s.step(t, Some(0.0), Some(x), Some(0.0)).engaged, "{t}");
    }
}

#[test]
fn a_turn_lost_is_off_path_held_until_a_line_or_the_operator() {
    let (mut s, mut t) = engaged_on_a_line(SafetyParams::default());
    // On the work line the path distance is not what is watched (off_line is).
    s.set_path_distance(Some(10.0));
    for _ in 0..20 {
        t += DT;
        feed_good(&mut s, t);
        assert!(s.step(t, Some(0.0), Some(0.1), Some(0.0)).engaged);
    }
    s.set_line(None, 0.0);
    let start = t;
    let mut fault_at = None;
    while t < start + 10.0 {
        t += DT;
        feed_good(&mut s, t);
        // 1 m off for 2 s, then drifting away at 1 m/s: beyond 4 m from 5 s.
        let d = if t - start < 2.0 {
            1.0
        } else {
            1.0 + (t - start - 2.0)
        };
        s.set_path_distance(Some(d));
        // An unknown distance (no pose) for one period restarts the timing.
        if (t - start - 5.2).abs() < 0.5 * DT {
            s.set_path_distance(None);
        }
        let c = s.step(t, Some(0.0), Some(0.0), Some(0.0));
        if !c.engaged {
            assert_eq!(c.fault, FaultCode::OffPath);
            fault_at = Some(t - start);
            break;
        }
    }
    let at = fault_at.expect("a lost turn must disengage");
    assert!((at - 5.72).abs() <= 2.0 * DT + 1e-9, "{at}");
    // Held: back near the path, an engage is refused.
    s.set_path_distance(Some(0.1));
    t += DT;
    feed_good(&mut s, t);
    s.request_engage();
    let c = s.step(t, Some(0.0), Some(0.0), Some(0.0));
    assert!(!c.engaged);
    assert_eq!(s.last_refusal(), FaultCode::OffPath);
    // The next work line clears it.
    s.set_line(Some(7), 0.0);
    t += DT;
    feed_good(&mut s, t);
    s.request_engage();
    assert!(s.step(t, Some(0.0), Some(0.0), Some(0.0)).engaged);
}

#[test]
fn off_path_zero_is_off() {
    let params = SafetyParams {
        tracking: crate::safety::TrackingParams {
            off_path: 0.0,
            ..Default::default()
        },
        ..SafetyParams::default()
    };
    let (mut s, mut t) = engaged_on_a_line(params);
    s.set_line(None, 0.0);
    s.set_path_distance(Some(100.0));
    for _ in 0..500 {
        t += DT;
        feed_good(&mut s, t);
        assert!(s.step(t, Some(0.0), Some(0.0), Some(0.0)).engaged);
    }
}

#[test]
fn a_line_too_sharp_for_the_speed_is_refused() {
    let mut s = Supervisor::new(SafetyParams::default());
    // R 15 m at 25 km/h: 3.2 m/s² of lateral acceleration.
    s.set_line(Some(1), 1.0 / 15.0);
    let t = 0.0;
    s.on_gnss(t, FixQuality::RtkFixed);
    s.on_wheel_angle(t, 0.0, false, false);
    s.on_speed(t, 24.0 / 3.6);
    s.step(t, Some(0.0), Some(0.0), Some(0.0));
    s.request_engage();
    assert!(!s.step(t + DT, Some(0.0), Some(0.0), Some(0.0)).engaged);
    assert_eq!(s.last_refusal(), FaultCode::LineUnfollowable);
    // At 10 km/h it is followable.
    s.on_speed(t + DT, 10.0 / 3.6);
    s.request_engage();
    assert!(
        s.step(t + 2.0 * DT, Some(0.0), Some(0.0), Some(0.0))
            .engaged
    );
}

/// Engaged on a straight line at 25 km/h, the next line is an R 15 m curve (3.2 m/s²): it is
/// given back as it starts, before any XTE builds up, held on that line and cleared by the
/// next one.
#[test]
fn an_unfollowable_line_starting_while_engaged_is_given_back_at_once() {
    let mut s = Supervisor::new(SafetyParams::default());
    let mut t = 0.0;
    let feed = |s: &mut Supervisor, t: f64| {
        s.on_gnss(t, FixQuality::RtkFixed);
        s.on_wheel_angle(t, 0.0, false, false);
        s.on_speed(t, 25.0 / 3.6);
    };
    s.set_line(Some(1), 0.0);
    feed(&mut s, t);
    s.step(t, Some(0.0), Some(0.0), Some(0.0));
    s.request_engage();
    t += DT;
    feed(&mut s, t);
    assert!(s.step(t, Some(0.0), Some(0.0), Some(0.0)).engaged);
    for _ in 0..50 {
        t += DT;
        feed(&mut s, t);
        assert!(s.step(t, Some(0.0), Some(0.0), Some(0.0)).engaged);
    }
    s.set_line(Some(2), 1.0 / 15.0);
    t += DT;
    feed(&mut s, t);
    let c = s.step(t, Some(0.0), Some(0.0), Some(0.0));
    assert!(!c.engaged);
    assert_eq!(c.fault, FaultCode::LineUnfollowable);
    // Held on that line: the operator's engage is not taken.
    s.request_engage();
    t += DT;
    feed(&mut s, t);
    assert!(!s.step(t, Some(0.0), Some(0.0), Some(0.0)).engaged);
    // A straight line clears it.
    s.set_line(Some(3), 0.0);
    for _ in 0..3 {
        t += DT;
        feed(&mut s, t);
        s.step(t, Some(0.0), Some(0.0), Some(0.0));
    }
    s.request_engage();
    t += DT;
    feed(&mut s, t);
    assert!(s.step(t, Some(0.0), Some(0.0), Some(0.0)).engaged);
}

/// Engaged at 10 km/h on an R 15 m line, the tractor speeds up to 25 km/h: given back as
/// `line_unfollowable` once v²/R passes `a_lat_max` (2 m/s² at 19.7 km/h), not later.
#[test]
fn speeding_up_on_a_curve_past_the_lateral_limit_gives_the_steering_back() {
    let mut s = Supervisor::new(SafetyParams::default());
    s.set_line(Some(1), 1.0 / 15.0);
    let mut t = 0.0;
    let mut v: f64 = 10.0 / 3.6;
    let feed = |s: &mut Supervisor, t: f64, v: f64| {
        s.on_gnss(t, FixQuality::RtkFixed);
        s.on_wheel_angle(t, (3.0f64 / 15.0).atan(), false, false);
        s.on_speed(t, v);
    };
    feed(&mut s, t, v);
    s.step(t, Some(0.2), Some(0.0), Some(0.0));
    s.request_engage();
    t += DT;
    feed(&mut s, t, v);
    assert!(s.step(t, Some(0.2), Some(0.0), Some(0.0)).engaged);
    let mut given_back_at = None;
    while t < 20.0 {
        t += DT;
        v = (v + 0.5 * DT).min(25.0 / 3.6);
        feed(&mut s, t, v);
        let c = s.step(t, Some(0.2), Some(0.0), Some(0.0));
        if !c.engaged {
            assert_eq!(c.fault, FaultCode::LineUnfollowable);
            given_back_at = Some(v);
            break;
        }
    }
    let v = given_back_at.expect("given back") * 3.6;
    assert!((19.7..19.9).contains(&v), "at {v} km/h");
}

/// The loop frozen together with the sensors (one virtual CPU): the late period finds every
/// input older than the freeze. Up to the timeout, the freeze is the loop's, not the inputs'.
#[test]
fn a_pause_of_the_loop_is_not_a_silent_wheel_angle_sensor() {
    let (mut s, t) = engaged_supervisor();
    // Due at t + DT, ran 80 ms late: the wheel angle is 100 ms old, the timeout 100 ms.
    let woke = t + DT + 0.080;
    s.on_loop_pause(t + DT, woke);
    let c = s.step(woke, Some(0.0), Some(0.0), Some(0.0));
    assert!(c.engaged, "{c:?}");
    // The senders run again: fresh inputs, still engaged.
    feed_good(&mut s, woke + 0.001);
    assert!(s.step(woke + DT, Some(0.0), Some(0.0), Some(0.0)).engaged);
}

#[test]
fn without_the_pause_the_same_silence_disengages() {
    let (mut s, t) = engaged_supervisor();
    s.on_gnss(t + 0.1, FixQuality::RtkFixed);
    s.on_speed(t + 0.1, 10.0 / 3.6);
    let c = s.step(t + DT + 0.090, Some(0.0), Some(0.0), Some(0.0));
    assert!(!c.engaged);
    assert_eq!(c.fault, FaultCode::WheelAngleTimeout);
}

#[test]
fn a_pause_longer_than_the_timeout_still_disengages() {
    let (mut s, t) = engaged_supervisor();
    // 300 ms late: credited 100 ms (the wheel angle's timeout), 220 ms remain.
    let woke = t + DT + 0.300;
    s.on_loop_pause(t + DT, woke);
    s.on_gnss(woke, FixQuality::RtkFixed);
    s.on_speed(woke, 10.0 / 3.6);
    let c = s.step(woke, Some(0.0), Some(0.0), Some(0.0));
    assert!(!c.engaged);
    assert_eq!(c.fault, FaultCode::WheelAngleTimeout);
}

#[test]
fn a_sensor_silent_after_the_pause_is_still_caught() {
    let (mut s, t) = engaged_supervisor();
    let woke = t + DT + 0.080;
    s.on_loop_pause(t + DT, woke);
    assert!(s.step(woke, Some(0.0), Some(0.0), Some(0.0)).engaged);
    // The loop runs on time again but the wheel angle never comes back: caught by the
    // timeout plus the credited pause at most.
    let mut now = woke;
    let disengaged_at = loop {
        now += DT;
        s.on_gnss(now, FixQuality::RtkFixed);
        s.on_speed(now, 10.0 / 3.6);
        let c = s.step(now, Some(0.0), Some(0.0), Some(0.0));
        if !c.engaged {
            assert_eq!(c.fault, FaultCode::WheelAngleTimeout);
            break now;
        }
        assert!(now < woke + 1.0, "never disengaged");
    };
    assert!(
        disengaged_at - t <= 0.1 + 0.080 + DT + 1e-9,
        "{}",
        disengaged_at - t
    );
}
