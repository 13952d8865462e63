//! The simulator's basic behaviour and the true vehicle's plant model.

use super::*;

fn run(sim: &mut Simulator, until: f64) -> Vec<SimOutput> {
    let mut out = Vec::new();
    sim.advance_to(until, &mut out);
    out
}

#[test]
fn same_seed_same_outputs() {
    let mk = |seed| {
        let p = SimParams {
            seed,
            ..SimParams::default()
        };
        let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 3.0);
        s.set_command(0.1);
        run(&mut s, 5.0)
    };
    assert_eq!(mk(7), mk(7));
    assert_ne!(mk(7), mk(8));
}

#[test]
fn constant_angle_drives_a_circle() {
    let p = SimParams::default();
    let delta: f64 = 0.2;
    let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, 0.0), 2.0);
    s.set_command(delta);
    run(&mut s, 3.0);
    // After the transient the yaw rate is v·tanδ/L: check the radius from the heading change.
    let a = s.true_state();
    run(&mut s, 6.0);
    let b = s.true_state();
    let dth = wrap_angle(b.pose.heading - a.pose.heading);
    let r = 2.0 * 3.0 / dth;
    let expect = p.wheelbase / delta.tan();
    assert!((r - expect).abs() / expect < 1e-3, "r {r} vs {expect}");
}

#[test]
fn dead_time_and_rate_limit() {
    let p = SimParams {
        tau: 0.0,
        ..SimParams::default()
    };
    let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, 0.0), 1.0);
    s.set_command(0.5);
    let mut out = Vec::new();
    let mut prev = 0.0;
    let mut first_move = None;
    for k in 1..=1000 {
        let t = k as f64 * 0.001;
        s.advance_to(t, &mut out);
        let w = s.true_state().wheel_angle;
        assert!(
            (w - prev).abs() <= p.max_rate * p.step + 1e-12,
            "rate limit"
        );
        if w != 0.0 && first_move.is_none() {
            first_move = Some(t);
        }
        prev = w;
    }
    let t0 = first_move.unwrap();
    assert!((t0 - p.dead_time).abs() <= 2.0 * p.step, "moved at {t0}");
    assert!(prev <= p.max_wheel_angle);
}

#[test]
fn gnss_rate_latency_and_noise() {
    let p = SimParams::default();
    let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, 0.0), 0.0);
    let out = run(&mut s, 1000.0);
    let fixes: Vec<GnssMeasurement> = out
        .iter()
        .filter_map(|o| match o {
            SimOutput::Gnss(m) => Some(*m),
            _ => None,
        })
        .collect();
    assert!((fixes.len() as i64 - 10_000).abs() <= 1, "{}", fixes.len());
    for w in fixes.windows(2) {
        assert!((w[1].t_measured - w[0].t_measured - 0.1).abs() < 1e-9);
    }
    assert!(fixes
        .iter()
        .all(|m| (m.t_delivered - m.t_measured - 0.05).abs() < 1e-12));
    let n = fixes.len() as f64;
    let var = fixes.iter().map(|m| m.antenna.x.powi(2)).sum::<f64>() / n;
    assert!((var.sqrt() - 0.01).abs() < 0.0005, "σ {}", var.sqrt());
    let was = out
        .iter()
        .filter(|o| matches!(o, SimOutput::WheelAngle { .. }))
        .count();
    assert!((was as i64 - 100_000).abs() <= 1);
}

#[test]
fn antenna_forward_offset_is_ahead() {
    let p = SimParams {
        antenna_forward: 2.0,
        gnss_sigma: 0.0,
        ..SimParams::default()
    };
    let s = Simulator::new(p, Pose::new(1.0, 1.0, std::f64::consts::FRAC_PI_2), 0.0);
    let t = s.true_state();
    assert!((t.antenna - Vec2::new(1.0, 3.0)).norm() < 1e-12);
}

#[test]
fn bad_parameters_are_errors() {
    let p = SimParams {
        step: 0.0,
        ..SimParams::default()
    };
    assert!(Simulator::try_new(p, Pose::new(0.0, 0.0, 0.0), 1.0).is_err());
    let mut s = Simulator::new(SimParams::default(), Pose::new(0.0, 0.0, 0.0), 1.0);
    s.set_command(f64::NAN);
    run(&mut s, 1.0);
    assert!(s.true_state().pose.pos.x.is_finite());
}

// ---- The true vehicle: not the model ------------------------------------------------------

/// A quiet plant with an ideal actuator (no dead time, lag or rate limit to wait for).
fn ideal(lateral: Option<LateralDynamics>) -> SimParams {
    SimParams {
        gnss_sigma: 0.0,
        heading_sigma: 0.0,
        speed_sigma: 0.0,
        was_noise: 0.0,
        dead_time: 0.0,
        tau: 0.0,
        max_rate: 10.0,
        lateral,
        ..SimParams::default()
    }
}

/// Drive at `speed` with the wheels at `delta` for `secs` s; the state at the end.
fn steady(p: &SimParams, speed: f64, delta: f64, secs: f64) -> TrueState {
    let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, 0.0), speed);
    s.set_command(delta);
    run(&mut s, secs);
    s.true_state()
}

#[test]
fn was_gain_and_offset_are_in_the_reading_and_the_servo() {
    let (gain, offset) = (1.08, 1f64.to_radians());
    let p = SimParams {
        was_gain: gain,
        dist: Disturbances {
            was_bias: offset,
            ..Disturbances::default()
        },
        ..ideal(None)
    };
    let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 2.0);
    s.set_command(0.1);
    let out = run(&mut s, 2.0);
    // The servo puts the reading at the command: the wheels at (command − offset) / gain.
    let w = s.true_state().wheel_angle;
    assert!((w - (0.1 - offset) / gain).abs() < 1e-9, "{w}");
    let last = out.iter().rev().find_map(|o| match o {
        SimOutput::WheelAngle { angle, .. } => Some(*angle),
        _ => None,
    });
    assert!((last.unwrap() - 0.1).abs() < 1e-9);
    // Held, the wheels stay where they are although the reading is not the true angle.
    s.hold_wheels();
    run(&mut s, 4.0);
    assert!((s.true_state().wheel_angle - w).abs() < 1e-12);
}

#[test]
fn the_true_wheelbase_and_antenna_are_the_plant_s_own() {
    // The circle of a 3.3 m wheelbase, whatever a controller believes.
    let p = SimParams {
        wheelbase: 3.3,
        antenna_forward: 1.5,
        antenna_left: -0.2,
        ..ideal(None)
    };
    let a = steady(&p, 2.0, 0.1, 10.0);
    let r = 2.0 / a.yaw_rate;
    assert!((r - 3.3 / 0.1f64.tan()).abs() < 1e-9, "r {r}");
    let h = crate::geo::heading_vec(a.pose.heading);
    let expect = a.pose.pos + h * 1.5 + crate::geo::left_normal(&h) * -0.2;
    assert!((a.antenna - expect).norm() < 1e-12);
}

#[test]
fn steady_circle_radius_follows_the_understeer_gradient() {
    // δ = L/R + K·v²/R (linear single-track model, small angles): R = (L + K·v²)/δ.
    let delta = 0.04;
    for (name, lat) in [
        ("understeer (default tractor)", LateralDynamics::default()),
        (
            "oversteer (stiff front)",
            LateralDynamics {
                cornering_stiffness_front: 300_000.0,
                cornering_stiffness_rear: 150_000.0,
                ..LateralDynamics::default()
            },
        ),
        (
            "soft soil, understeer",
            LateralDynamics {
                cornering_stiffness_front: 50_000.0,
                cornering_stiffness_rear: 110_000.0,
                ..LateralDynamics::default()
            },
        ),
    ] {
        let p = ideal(Some(lat));
        let k = lat.understeer_gradient(p.wheelbase);
        for v in [2.0, 4.0, 7.0] {
            let st = steady(&p, v, delta, 40.0);
            let ground = st.speed.hypot(st.lateral_velocity);
            let r = ground / st.yaw_rate;
            let expect = (p.wheelbase + k * v * v) / delta;
            assert!(
                (r - expect).abs() / expect < 0.005,
                "{name} at {v} m/s: R {r:.3} vs (L + K v²)/δ {expect:.3} (K {k:.5})"
            );
            // Not the kinematic circle: the difference is the understeer term, clearly there.
            let kinematic = p.wheelbase / delta.tan();
            assert!((r - kinematic).abs() > 0.2 * (k * v * v / delta).abs());
        }
    }
}

#[test]
fn rear_slip_angle_grows_with_lateral_acceleration() {
    // α_r = m·(a/L)·a_y / C_r: the faster and the tighter, the more it slips.
    let lat = LateralDynamics::default();
    let p = ideal(Some(lat));
    let mut last = 0.0;
    for (v, delta) in [(2.0, 0.05), (3.0, 0.08), (4.0, 0.1), (6.0, 0.1)] {
        let st = steady(&p, v, delta, 40.0);
        let a_y = st.speed * st.yaw_rate;
        let slip = (-st.lateral_velocity).atan2(st.speed);
        let expect = lat.rear_slip_angle(p.wheelbase, a_y);
        assert!(
            (slip - expect).abs() < 0.01 * expect,
            "v {v} δ {delta}: α_r {slip} vs {expect} at a_y {a_y}"
        );
        assert!(slip > last, "slip grows: {slip} after {last}");
        last = slip;
    }
    // Very stiff tyres are the kinematic bicycle.
    let stiff = ideal(Some(LateralDynamics {
        cornering_stiffness_front: 1e9,
        cornering_stiffness_rear: 1e9,
        ..lat
    }));
    let st = steady(&stiff, 4.0, 0.1, 40.0);
    let r = 4.0 / st.yaw_rate;
    assert!((r - 3.0 / 0.1f64.tan()).abs() < 1e-3 * r, "{r}");
}

#[test]
fn implement_side_draft_makes_a_crab_that_a_steady_wheel_angle_holds_straight() {
    // Side force S (left) at the hitch h behind the rear axle, straight line (r = 0):
    // F_f + F_r + S = 0, a·F_f − b·F_r − (b + h)·S = 0 ⇒ F_f = h·S/L, F_r = −S·(L + h)/L;
    // the rear axle crabs at v = S·(L + h)·u / (L·C_r) and the wheels must sit at
    // δ = v/u + h·S/(L·C_f).
    let lat = LateralDynamics {
        side_force: 3000.0, // pulling right
        hitch_behind_rear: 1.2,
        ..LateralDynamics::default()
    };
    let p = ideal(Some(lat));
    let (l, u) = (p.wheelbase, 3.0);
    let s_left = -lat.side_force;
    let crab = s_left * (l + lat.hitch_behind_rear) / (l * lat.cornering_stiffness_rear);
    let delta = crab + lat.hitch_behind_rear * s_left / (l * lat.cornering_stiffness_front);
    let st = steady(&p, u, delta, 60.0);
    // (The closed form takes sin δ ≈ δ: a yaw rate of a few µrad/s is left.)
    assert!(st.yaw_rate.abs() < 1e-5, "turning at {}", st.yaw_rate);
    assert!(
        (st.lateral_velocity / u - crab).abs() < 1e-3 * crab.abs(),
        "crab {} vs {crab}",
        st.lateral_velocity / u
    );
    // Pulled right: it crabs right and needs the wheels right.
    assert!(crab < 0.0 && delta < 0.0);
    // With straight wheels it turns away instead.
    let st = steady(&p, u, 0.0, 20.0);
    assert!(st.yaw_rate.abs() > 1e-3);
}

#[test]
fn a_side_slope_pulls_the_dynamic_vehicle_downhill_through_its_tyres() {
    // Gravity G = −m·g·sin(roll) (left) at the centre of gravity, straight line:
    // F_r = −G·a/L, so the rear axle crabs downhill at v = G·a·u / (L·C_r).
    let lat = LateralDynamics::default();
    let p = SimParams {
        dist: Disturbances {
            terrain_slope: 3f64.to_radians(),
            terrain_downhill: 0.0,
            terrain_wavelength: 100.0,
            ..Disturbances::default()
        },
        ..ideal(Some(lat))
    };
    let north = std::f64::consts::FRAC_PI_2;
    let (l, b, u) = (p.wheelbase, lat.cg_ahead_of_rear, 3.0);
    let roll = 3f64.to_radians().tan().atan();
    let g = -lat.mass * 9.80665 * roll.sin();
    let crab = g * (l - b) / (l * lat.cornering_stiffness_rear);
    let delta = crab - g * b / (l * lat.cornering_stiffness_front);
    let mut s = Simulator::new(p, Pose::new(0.0, 0.0, north), u);
    s.set_command(delta);
    run(&mut s, 60.0);
    let st = s.true_state();
    assert!(st.yaw_rate.abs() < 1e-5, "turning at {}", st.yaw_rate);
    assert!((st.lateral_velocity / u - crab).abs() < 1e-3 * crab.abs());
    // Heading north on a slope falling East: it slides East.
    assert!(st.pose.pos.x > 0.5, "{}", st.pose.pos.x);
}

#[test]
fn the_dynamic_model_rests_at_standstill_and_reverses() {
    let p = ideal(Some(LateralDynamics::default()));
    // Steered at standstill: nothing moves, nothing blows up.
    let st = steady(&p, 0.0, 0.3, 10.0);
    assert!(
        st.pose.pos.norm() < 1e-9 && st.pose.heading.abs() < 1e-9,
        "{st:?}"
    );
    // Driving, then stopped: the lateral motion dies out.
    let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, 0.0), 5.0);
    s.set_command(0.2);
    run(&mut s, 10.0);
    s.set_speed_target(0.0);
    run(&mut s, 30.0);
    let st = s.true_state();
    assert!(st.speed == 0.0 && st.lateral_velocity.abs() < 1e-6 && st.yaw_rate.abs() < 1e-6);
    // Slowly backwards it drives the kinematic circle.
    let st = steady(&p, -1.0, 0.1, 40.0);
    let r = 1.0 / st.yaw_rate.abs();
    assert!((r - 3.0 / 0.1f64.tan()).abs() < 0.01 * r, "{r}");
    assert!(
        st.yaw_rate < 0.0,
        "reversing with the wheels left turns clockwise"
    );
}

#[test]
fn dynamic_runs_are_deterministic_and_noise_free_runs_agree_with_the_kinematic_model_slowly() {
    let p = SimParams {
        lateral: Some(LateralDynamics::default()),
        ..SimParams::default()
    };
    let mk = |p: &SimParams| {
        let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, 0.0), 3.0);
        s.set_command(0.1);
        run(&mut s, 20.0)
    };
    assert_eq!(mk(&p), mk(&p));
    // At 1 m/s on a gentle curve the slip is tiny: within 5 cm of the kinematic model after
    // 30 m.
    let a = steady(&ideal(Some(LateralDynamics::default())), 1.0, 0.05, 30.0);
    let b = steady(&ideal(None), 1.0, 0.05, 30.0);
    assert!(
        (a.pose.pos - b.pose.pos).norm() < 0.05,
        "{:?} {:?}",
        a.pose,
        b.pose
    );
}

#[test]
fn bad_plant_parameters_are_errors() {
    for lat in [
        LateralDynamics {
            cg_ahead_of_rear: 3.5,
            ..LateralDynamics::default()
        },
        LateralDynamics {
            relaxation_length: 0.0,
            ..LateralDynamics::default()
        },
        LateralDynamics {
            mass: f64::NAN,
            ..LateralDynamics::default()
        },
    ] {
        let p = SimParams {
            lateral: Some(lat),
            ..SimParams::default()
        };
        assert!(Simulator::try_new(p, Pose::new(0.0, 0.0, 0.0), 1.0).is_err());
    }
    let p = SimParams {
        was_gain: 0.0,
        ..SimParams::default()
    };
    assert!(Simulator::try_new(p, Pose::new(0.0, 0.0, 0.0), 1.0).is_err());
}

#[test]
fn the_tyres_slide_at_the_friction_limit() {
    // Full lock at 6 m/s asks for v²·tanδ/L ≈ 8.4 m/s² on the kinematic model; the tyres can
    // give μ·g = 5.9 m/s² at most: the tractor ploughs on a wider circle.
    let lat = LateralDynamics::default();
    let p = ideal(Some(lat));
    let st = steady(&p, 6.0, 0.6, 30.0);
    let a_y = st.speed * st.yaw_rate;
    let limit = lat.friction * 9.80665;
    assert!(
        a_y < 1.02 * limit && a_y > 0.8 * limit,
        "a_y {a_y} vs μg {limit}"
    );
    assert!(st.pose.pos.x.is_finite());
}

#[test]
fn a_driver_holding_an_arc_s_steering_drives_the_arc_from_the_start() {
    // Started on an R 15 m arc (centre 15 m to the left of the start, heading east) with the
    // arc's steering held: no command comes, and the vehicle stays on the arc. The hold is in
    // the sensor's terms and fills the dead time, so a WAS offset and gain error, a dead time
    // and a backlash do not move the wheels.
    let radius = 15.0;
    let plants = [
        ("kinematic", SimParams::default()),
        (
            "WAS 1.05 / +1°, dead time 0.2 s, lag, 1° backlash",
            SimParams {
                was_gain: 1.05,
                dead_time: 0.2,
                tau: 0.3,
                dist: Disturbances {
                    was_bias: 1f64.to_radians(),
                    backlash: 1f64.to_radians(),
                    ..Disturbances::default()
                },
                ..SimParams::default()
            },
        ),
    ];
    for (name, p) in plants {
        let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 3.0);
        s.hold_curvature(1.0 / radius);
        for k in 1..=30 {
            run(&mut s, 0.1 * k as f64);
            let off = (s.true_state().pose.pos - crate::geo::v2(0.0, radius)).norm() - radius;
            assert!(off.abs() < 1e-3, "{name}: {off} m off the arc at {k}");
        }
    }
    // With tyre slip the held angle carries the understeer term: the steady circle at 6 m/s
    // is the arc's (the kinematic angle alone drives one about 8 % wider here).
    let p = ideal(Some(LateralDynamics::default()));
    let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 6.0);
    s.hold_curvature(1.0 / radius);
    run(&mut s, 20.0);
    let st = s.true_state();
    let r = st.speed.hypot(st.lateral_velocity) / st.yaw_rate;
    assert!((r - radius).abs() < 0.02 * radius, "R {r}");
}
