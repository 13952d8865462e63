//! The simulator's disturbances.

use super::*;
use crate::geo::Pose;

fn run(sim: &mut Simulator, until: f64) -> Vec<SimOutput> {
    let mut out = Vec::new();
    sim.advance_to(until, &mut out);
    out
}

// ---- Disturbances -------------------------------------------------------------------

fn quiet() -> SimParams {
    SimParams {
        gnss_sigma: 0.0,
        heading_sigma: 0.0,
        speed_sigma: 0.0,
        was_noise: 0.0,
        ..SimParams::default()
    }
}

fn fixes(out: &[SimOutput]) -> Vec<GnssMeasurement> {
    out.iter()
        .filter_map(|o| match o {
            SimOutput::Gnss(m) => Some(*m),
            _ => None,
        })
        .collect()
}

#[test]
fn disturbances_draw_from_their_own_stream() {
    // A correlated GNSS error leaves the white noise of every other output unchanged.
    let mut a = Simulator::new(SimParams::default(), Pose::new(0.0, 0.0, 0.0), 3.0);
    let mut b = Simulator::new(
        SimParams {
            dist: Disturbances {
                gnss_markov_sigma: 0.02,
                gnss_markov_tau: 10.0,
                ..Disturbances::default()
            },
            ..SimParams::default()
        },
        Pose::new(0.0, 0.0, 0.0),
        3.0,
    );
    a.set_command(0.05);
    b.set_command(0.05);
    let (oa, ob) = (run(&mut a, 20.0), run(&mut b, 20.0));
    assert_eq!(oa.len(), ob.len());
    let mut moved = 0;
    for (x, y) in oa.iter().zip(&ob) {
        match (x, y) {
            (SimOutput::Gnss(p), SimOutput::Gnss(q)) => {
                assert_eq!((p.heading, p.speed), (q.heading, q.speed));
                moved += usize::from(p.antenna != q.antenna);
            }
            _ => assert_eq!(x, y),
        }
    }
    assert!(moved > 100);
}

#[test]
fn gauss_markov_sigma_and_autocorrelation() {
    let (sigma, tau) = (0.015, 30.0);
    let p = SimParams {
        dist: Disturbances {
            gnss_markov_sigma: sigma,
            gnss_markov_tau: tau,
            ..Disturbances::default()
        },
        ..quiet()
    };
    let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 0.0);
    // 200 000 s at 10 Hz: about 6 700 time constants.
    let mut out = Vec::new();
    let mut xs = Vec::with_capacity(2_000_001);
    let mut t = 0.0;
    while t < 200_000.0 {
        t += 1000.0;
        out.clear();
        s.advance_to(t, &mut out);
        xs.extend(fixes(&out).iter().map(|m| m.antenna.x));
    }
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
    let sd = var.sqrt();
    assert!((sd - sigma).abs() < 0.05 * sigma, "σ {sd}");
    let lag1 = xs
        .windows(2)
        .map(|w| (w[0] - mean) * (w[1] - mean))
        .sum::<f64>()
        / (n - 1.0)
        / var;
    let expect = (-0.1f64 / tau).exp();
    assert!((lag1 - expect).abs() < 2e-4, "ρ1 {lag1} vs {expect}");
    // Correlated over τ: lag 300 (30 s) ≈ e^-1.
    let lag_tau = xs
        .windows(301)
        .map(|w| (w[0] - mean) * (w[300] - mean))
        .sum::<f64>()
        / (n - 300.0)
        / var;
    assert!((lag_tau - (-1f64).exp()).abs() < 0.05, "ρ(τ) {lag_tau}");
}

#[test]
fn multipath_jumps_at_the_configured_rate_magnitude_and_duration() {
    let p = SimParams {
        dist: Disturbances {
            multipath_rate: 20.0 / 3600.0,
            multipath_magnitude: 0.3,
            multipath_duration: 5.0,
            ..Disturbances::default()
        },
        ..quiet()
    };
    let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 0.0);
    let f = fixes(&run(&mut s, 36_000.0));
    let jumped: Vec<&GnssMeasurement> = f.iter().filter(|m| m.antenna.norm() > 1e-9).collect();
    for m in &jumped {
        assert!((m.antenna.norm() - 0.3).abs() < 1e-9);
    }
    // Each jump lasts 5 s (50 fixes); 200 expected in 10 h.
    let starts = f
        .windows(2)
        .filter(|w| w[0].antenna.norm() < 1e-9 && w[1].antenna.norm() > 1e-9)
        .count();
    assert!((150..=250).contains(&starts), "{starts} jumps");
    let per_jump = jumped.len() as f64 / starts as f64;
    assert!((per_jump - 50.0).abs() <= 1.0, "{per_jump} fixes per jump");
}

#[test]
fn rtk_float_window_reports_float_and_a_larger_error() {
    let p = SimParams {
        dist: Disturbances {
            float_windows: vec![(10.0, 20.0)],
            float_sigma: 0.2,
            float_tau: 5.0,
            ..Disturbances::default()
        },
        ..quiet()
    };
    let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 0.0);
    let f = fixes(&run(&mut s, 40.0));
    for m in &f {
        let inside = m.t_measured >= 10.0 - 1e-9 && m.t_measured < 30.0 - 1e-9;
        if inside {
            assert_eq!(m.fix, FixQuality::RtkFloat, "t {}", m.t_measured);
        } else {
            assert_eq!(m.fix, FixQuality::RtkFixed, "t {}", m.t_measured);
            assert!(m.antenna.norm() < 1e-12);
        }
    }
    let err: f64 = f
        .iter()
        .filter(|m| m.fix == FixQuality::RtkFloat)
        .map(|m| m.antenna.norm())
        .fold(0.0, f64::max);
    assert!(err > 0.05, "float error {err}");
}

fn on_slope(deg: f64, up: f64) -> SimParams {
    SimParams {
        antenna_up: up,
        dist: Disturbances {
            terrain_slope: deg.to_radians(),
            // Downhill to the East.
            terrain_downhill: 0.0,
            terrain_wavelength: 100.0,
            imu_rate_hz: 10.0,
            ..Disturbances::default()
        },
        ..quiet()
    }
}

#[test]
fn roll_moves_the_antenna_sideways_by_height_times_sin_roll() {
    // Heading north across a slope falling East: right side down, roll +2°.
    let north = std::f64::consts::FRAC_PI_2;
    let mut s = Simulator::new(on_slope(2.0, 3.0), Pose::new(0.0, 0.0, north), 0.0);
    let out = run(&mut s, 1.0);
    let (roll, pitch) = s.attitude();
    assert!((roll - 2f64.to_radians()).abs() < 1e-3, "roll {roll}");
    assert!(pitch.abs() < 1e-12);
    let shift = 3.0 * 2f64.to_radians().sin();
    assert!((shift - 0.1047).abs() < 1e-3);
    for m in fixes(&out) {
        // Moved right (East), not along the track.
        assert!((m.antenna.x - shift).abs() < 1e-3, "{}", m.antenna.x);
        assert!(m.antenna.y.abs() < 1e-12);
    }
    // The IMU reports it, in degrees on the bus: here in rad.
    let att: Vec<(f64, f64)> = out
        .iter()
        .filter_map(|o| match o {
            SimOutput::Attitude { roll, pitch, .. } => Some((*roll, *pitch)),
            _ => None,
        })
        .collect();
    assert_eq!(att.len(), 11);
    assert!(att.iter().all(|(r, _)| (r - roll).abs() < 1e-12));
    // Coming back south the other side is down; the antenna still leans downhill (East).
    let s = Simulator::new(on_slope(2.0, 3.0), Pose::new(0.0, 0.0, -north), 0.0);
    assert!((s.attitude().0 + 2f64.to_radians()).abs() < 1e-3);
    assert!((s.true_state().antenna.x - shift).abs() < 1e-3);
    // Driving downhill (East) pitches the nose down.
    let s = Simulator::new(on_slope(2.0, 3.0), Pose::new(0.0, 0.0, 0.0), 0.0);
    let (r, p) = s.attitude();
    assert!(r.abs() < 1e-12 && (p + 2f64.to_radians()).abs() < 1e-3);
}

#[test]
fn terrain_varies_with_the_wavelength() {
    let mut p = on_slope(0.0, 0.0);
    p.dist.terrain_slope_amp = 3f64.to_radians();
    p.dist.terrain_wavelength = 40.0;
    let north = std::f64::consts::FRAC_PI_2;
    // Contour direction (downhill East turned left) is North: quarter wavelength → peak.
    let roll_at = |y: f64| {
        Simulator::new(p.clone(), Pose::new(0.0, y, north), 0.0)
            .attitude()
            .0
    };
    assert!(roll_at(0.0).abs() < 1e-12);
    assert!((roll_at(10.0) - 3f64.to_radians()).abs() < 1e-3);
    assert!((roll_at(30.0) + 3f64.to_radians()).abs() < 1e-3);
    assert!((roll_at(50.0) - roll_at(10.0)).abs() < 1e-9);
}

#[test]
fn slip_moves_the_vehicle_downhill_at_the_configured_rate() {
    // 2° roll, 0.015 m/s per degree → 3 cm/s to the right (East) while driving north.
    let mut p = on_slope(2.0, 0.0);
    p.dist.slip_per_roll = 0.015f64.to_degrees();
    let north = std::f64::consts::FRAC_PI_2;
    let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, north), 3.0);
    run(&mut s, 100.0);
    let t = s.true_state();
    let rate = t.pose.pos.x / 100.0;
    let roll_deg = 2f64.to_radians().tan().atan().to_degrees();
    assert!((rate - 0.015 * roll_deg).abs() < 1e-6, "slip {rate} m/s");
    // Heading unchanged: it crabs, it does not turn.
    assert!((t.pose.heading - north).abs() < 1e-12);
    // Southward the downhill side is the right too: still East.
    let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, -north), 3.0);
    run(&mut s, 100.0);
    assert!((s.true_state().pose.pos.x / 100.0 - rate).abs() < 1e-6);
    // Flat ground: no slip.
    p.dist.terrain_slope = 0.0;
    let mut s = Simulator::new(p, Pose::new(0.0, 0.0, north), 3.0);
    run(&mut s, 100.0);
    assert!(s.true_state().pose.pos.x.abs() < 1e-12);
    // A constant slip needs no slope, and none while standing still.
    let p = SimParams {
        dist: Disturbances {
            slip: 0.02,
            ..Disturbances::default()
        },
        ..quiet()
    };
    let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, 0.0), 2.0);
    run(&mut s, 50.0);
    assert!((s.true_state().pose.pos.y + 1.0).abs() < 1e-6);
    let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 0.0);
    run(&mut s, 50.0);
    assert!(s.true_state().pose.pos.norm() < 1e-12);
}

fn was_mean(out: &[SimOutput], from: f64) -> f64 {
    let v: Vec<f64> = out
        .iter()
        .filter_map(|o| match o {
            SimOutput::WheelAngle { t, angle } if *t >= from => Some(*angle),
            _ => None,
        })
        .collect();
    v.iter().sum::<f64>() / v.len() as f64
}

#[test]
fn was_bias_appears_in_the_reported_angle_and_offsets_the_wheels() {
    let bias = 0.5f64.to_radians();
    let p = SimParams {
        dist: Disturbances {
            was_bias: bias,
            ..Disturbances::default()
        },
        ..SimParams::default()
    };
    let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 2.0);
    s.set_command(0.1);
    let out = run(&mut s, 20.0);
    // The steering controller servos the biased reading to the command: the wheels sit
    // at command − bias, the sensor reads the command.
    assert!((s.true_state().wheel_angle - (0.1 - bias)).abs() < 1e-9);
    let m = was_mean(&out, 5.0);
    assert!((m - 0.1).abs() < 2e-4, "mean {m}");
}

#[test]
fn deadband_holds_small_commands() {
    let db = 0.5f64.to_radians();
    let p = SimParams {
        dist: Disturbances {
            deadband: db,
            ..Disturbances::default()
        },
        ..quiet()
    };
    let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, 0.0), 2.0);
    s.set_command(0.8 * db);
    run(&mut s, 5.0);
    assert_eq!(s.true_state().wheel_angle, 0.0);
    // A larger command moves the wheels, to within the deadband of it.
    s.set_command(5.0 * db);
    run(&mut s, 10.0);
    let w = s.true_state().wheel_angle;
    assert!((w - 4.0 * db).abs() < 1e-6, "{w}");
    // Without the deadband it gets there.
    let mut s = Simulator::new(quiet(), Pose::new(0.0, 0.0, 0.0), 2.0);
    s.set_command(0.8 * db);
    run(&mut s, 5.0);
    assert!((s.true_state().wheel_angle - 0.8 * db).abs() < 1e-9);
}

#[test]
fn backlash_is_lost_at_a_reversal() {
    let play = 1f64.to_radians();
    let p = SimParams {
        dist: Disturbances {
            backlash: play,
            ..Disturbances::default()
        },
        ..quiet()
    };
    let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 2.0);
    s.set_command(0.1);
    run(&mut s, 5.0);
    // Moving left the wheels trail the actuator by half the play (the play is centred).
    let w1 = s.true_state().wheel_angle;
    assert!((w1 - (0.1 - 0.5 * play)).abs() < 1e-6, "{w1}");
    // Reverse by less than the play: the wheels don't move.
    s.set_command(0.1 - 0.9 * play);
    run(&mut s, 10.0);
    assert!((s.true_state().wheel_angle - w1).abs() < 1e-12);
    // Reverse further: the wheels move only by what is beyond the play.
    s.set_command(0.05);
    run(&mut s, 15.0);
    let w2 = s.true_state().wheel_angle;
    assert!((w2 - (0.05 + 0.5 * play)).abs() < 1e-6, "{w2}");
    // Actuator travel 0.05, wheel travel 0.05 - play.
    assert!(((w1 - w2) - (0.05 - play)).abs() < 1e-6);
}

#[test]
fn disturbed_runs_are_deterministic_by_seed() {
    let mk = |seed| {
        let p = SimParams {
            seed,
            antenna_up: 3.0,
            dist: Disturbances {
                gnss_markov_sigma: 0.015,
                gnss_markov_tau: 30.0,
                multipath_rate: 0.01,
                multipath_magnitude: 0.1,
                multipath_duration: 2.0,
                float_windows: vec![(5.0, 5.0)],
                float_sigma: 0.2,
                float_tau: 10.0,
                terrain_slope: 0.03,
                terrain_downhill: 0.3,
                terrain_slope_amp: 0.02,
                terrain_wavelength: 30.0,
                imu_rate_hz: 50.0,
                imu_noise: 0.001,
                slip_per_roll: 1.0,
                slip: 0.01,
                was_bias: 0.01,
                heading_bias: 0.0,
                heading_bias_at: 0.0,
                deadband: 0.002,
                backlash: 0.01,
            },
            ..SimParams::default()
        };
        let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 3.0);
        s.set_command(0.1);
        run(&mut s, 20.0)
    };
    assert_eq!(mk(3), mk(3));
    assert_ne!(mk(3), mk(4));
}
