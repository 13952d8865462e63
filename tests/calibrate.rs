//! `agsteer calibrate` against the simulator on the in-memory bus (issue 15 point 4):
//! random true steerings drawn from the envelope's ranges are identified within the issue's
//! tolerances, and the procedure refuses when the tractor moves too fast, the operator takes
//! the wheel or the steering changes under the tests. Simulated time only.

use agsteer::calibrate::{Calibration, CalibrationError};
use agsteer::config::Config;
use agsteer::demo::calibrate::{params_for, run, Operator};
use agsteer::sim::can_node::{Fault, FaultKind, Scenario};
use agsteer::sim::SimParams;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The true plant: what calibration identifies, drawn from the envelope's ranges (issue 15
/// point 2): dead time 0–0.25 s, lag 0.05–0.6 s, rate 10–90°/s, deadband and backlash up to
/// 1° (each present half the time), WAS noise up to 0.5°, gain ±10 %, offset up to 2°, GNSS
/// σ 0.5–5 cm. The geometry is the configured one (calibration does not measure it).
#[derive(Debug, Clone, Copy)]
struct Plant {
    dead_time: f64,
    tau: f64,
    rate_deg_s: f64,
    deadband_deg: f64,
    backlash_deg: f64,
    was_noise_deg: f64,
    was_gain: f64,
    was_offset_deg: f64,
    gnss_sigma_m: f64,
    seed: u64,
}

impl Plant {
    fn draw(rng: &mut ChaCha8Rng, seed: u64) -> Plant {
        let maybe = |rng: &mut ChaCha8Rng| {
            if rng.gen_bool(0.5) {
                rng.gen_range(0.1..1.0)
            } else {
                0.0
            }
        };
        Plant {
            dead_time: rng.gen_range(0.0..0.25),
            tau: rng.gen_range(0.05..0.6),
            rate_deg_s: rng.gen_range(10.0..90.0),
            deadband_deg: maybe(rng),
            backlash_deg: maybe(rng),
            was_noise_deg: rng.gen_range(0.0..0.5),
            was_gain: rng.gen_range(0.9..1.1),
            was_offset_deg: rng.gen_range(-2.0..2.0),
            gnss_sigma_m: rng.gen_range(0.005..0.05),
            seed,
        }
    }

    fn sim_params(&self, cfg: &Config) -> SimParams {
        let mut p = cfg.sim_params();
        p.dead_time = self.dead_time;
        p.tau = self.tau;
        p.max_rate = self.rate_deg_s.to_radians();
        p.dist.deadband = self.deadband_deg.to_radians();
        p.dist.backlash = self.backlash_deg.to_radians();
        p.was_noise = self.was_noise_deg.to_radians();
        p.was_gain = self.was_gain;
        p.dist.was_bias = self.was_offset_deg.to_radians();
        p.gnss_sigma = self.gnss_sigma_m;
        p.seed = self.seed;
        p
    }
}

fn config() -> Config {
    Config {
        vehicle: agsteer::config::VehicleConfig {
            antenna_forward_m: 1.2,
            antenna_left_m: 0.2,
            ..Default::default()
        },
        ..Config::default()
    }
}

fn calibrate(plant: &Plant, operator: &Operator) -> Result<Calibration, CalibrationError> {
    let cfg = config();
    run(
        params_for(&cfg),
        plant.sim_params(&cfg),
        cfg.control.dt_s,
        operator,
        &mut |_, _| {},
    )
}

/// Every identified parameter within the tolerances: 10 % (deadband and backlash
/// also within 0.1°, for small ones), offset within 0.1°, dead time within 10 ms. A rate
/// limit the tests never reached is reported as a lower bound, which must hold.
fn misses(p: &Plant, c: &Calibration) -> Vec<String> {
    let deg = |x: f64| x.to_degrees();
    let mut m = Vec::new();
    let mut check = |name: &str, got: f64, truth: f64, ok: bool| {
        if !ok {
            m.push(format!("{name} {got:.4} vs {truth:.4}"));
        }
    };
    let rel = |got: f64, truth: f64| (got - truth).abs() <= 0.1 * truth.abs();
    check(
        "dead time s",
        c.dead_time.value,
        p.dead_time,
        (c.dead_time.value - p.dead_time).abs() <= 0.010,
    );
    check("lag s", c.tau.value, p.tau, rel(c.tau.value, p.tau));
    let rate = deg(c.rate.value);
    check(
        "rate °/s",
        rate,
        p.rate_deg_s,
        if c.rate_reached {
            rel(rate, p.rate_deg_s)
        } else {
            rate <= p.rate_deg_s * 1.1
        },
    );
    // Deadband and backlash leave the same dead zone at a reversal (2·deadband = backlash);
    // only the lag's transient tells them apart, so what is checked is the lost motion they
    // make together (deadband + half the backlash: how far the wheels stop short).
    let lost = deg(c.deadband.value + 0.5 * c.backlash.value);
    let lost_truth = p.deadband_deg + 0.5 * p.backlash_deg;
    check(
        "lost motion °",
        lost,
        lost_truth,
        rel(lost, lost_truth) || (lost - lost_truth).abs() <= 0.1,
    );
    check(
        "WAS gain",
        c.was_gain.value,
        p.was_gain,
        (c.was_gain.value - p.was_gain).abs() <= 0.01 * p.was_gain,
    );
    check(
        "WAS offset °",
        deg(c.was_offset.value),
        p.was_offset_deg,
        (deg(c.was_offset.value) - p.was_offset_deg).abs() <= 0.1,
    );
    m
}

/// 20 plants: about 2 minutes of CPU in release (each a 3-minute procedure simulated at 1 ms
/// and three fits), so not in the default run; `cargo test --release --test calibrate --
/// --ignored` (figures in README.md, "Calibration").
#[test]
#[ignore]
fn twenty_random_plants_are_identified_within_the_tolerances() {
    let mut rng = ChaCha8Rng::seed_from_u64(15);
    let plants: Vec<Plant> = (0..20).map(|i| Plant::draw(&mut rng, 100 + i)).collect();
    let results: Vec<(Plant, Result<Calibration, CalibrationError>)> = std::thread::scope(|s| {
        let handles: Vec<_> = plants
            .chunks(10)
            .map(|chunk| {
                s.spawn(move || {
                    chunk
                        .iter()
                        .map(|p| (*p, calibrate(p, &Operator::default())))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("no panic"))
            .collect()
    });
    let mut failed = Vec::new();
    let mut unreached = 0;
    // Worst errors: dead time ms, lag %, rate % (reached), lost motion °, gain %, offset °.
    let mut worst = [0.0f64; 6];
    for (p, r) in &results {
        match r {
            Ok(c) => {
                unreached += usize::from(!c.rate_reached);
                let e = [
                    1000.0 * (c.dead_time.value - p.dead_time).abs(),
                    100.0 * (c.tau.value / p.tau - 1.0).abs(),
                    if c.rate_reached {
                        100.0 * (c.rate.value.to_degrees() / p.rate_deg_s - 1.0).abs()
                    } else {
                        0.0
                    },
                    ((c.deadband.value + 0.5 * c.backlash.value).to_degrees()
                        - (p.deadband_deg + 0.5 * p.backlash_deg))
                        .abs(),
                    100.0 * (c.was_gain.value / p.was_gain - 1.0).abs(),
                    (c.was_offset.value.to_degrees() - p.was_offset_deg).abs(),
                ];
                for (w, x) in worst.iter_mut().zip(e) {
                    *w = w.max(x);
                }
                let m = misses(p, c);
                if !m.is_empty() {
                    failed.push(format!("{p:?}: {}", m.join(", ")));
                }
            }
            Err(e) => failed.push(format!("{p:?}: refused: {e}")),
        }
    }
    eprintln!("rate limit not reached by the tests on {unreached} of 20 plants");
    eprintln!(
        "worst errors: dead time {:.1} ms, lag {:.1} %, rate {:.1} %, lost motion {:.3}°, \
         WAS gain {:.2} %, WAS offset {:.3}°",
        worst[0], worst[1], worst[2], worst[3], worst[4], worst[5]
    );
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

fn nominal() -> Plant {
    Plant {
        dead_time: 0.1,
        tau: 0.2,
        rate_deg_s: 30.0,
        deadband_deg: 0.2,
        backlash_deg: 0.4,
        was_noise_deg: 0.1,
        was_gain: 1.05,
        was_offset_deg: 1.0,
        gnss_sigma_m: 0.01,
        seed: 7,
    }
}

#[test]
fn the_fragment_names_the_keys_the_controller_reads() {
    let c = calibrate(&nominal(), &Operator::default()).expect("calibrates");
    let frag = c.toml_fragment();
    let table: toml::Table = toml::from_str(&frag).expect("valid TOML");
    for (t, k) in [
        ("safety", "actuator_dead_time_s"),
        ("safety", "actuator_tau_s"),
        ("safety", "actuator_rate_deg_s"),
        ("track", "lead_time_s"),
        ("track", "lost_motion_initial_deg"),
        ("vehicle", "was_gain"),
        ("vehicle", "was_offset_deg"),
    ] {
        assert!(table[t].get(k).is_some(), "{t}.{k} missing:\n{frag}");
    }
    // The configuration takes it (every key valid and in range).
    let cfg: Config = toml::from_str(&frag).expect("a configuration");
    assert!(cfg.validate().is_empty(), "{:?}", cfg.validate());
}

#[test]
fn refuses_when_the_tractor_does_not_stop() {
    let op = Operator {
        ignores_stop: Some(2.0 / 3.6),
        ..Default::default()
    };
    let e = calibrate(&nominal(), &op).expect_err("refused");
    assert!(matches!(e, CalibrationError::TooFast { .. }), "{e}");
}

#[test]
fn refuses_when_the_drive_is_too_fast() {
    let op = Operator {
        drive_speed: Some(9.0 / 3.6),
        ..Default::default()
    };
    let e = calibrate(&nominal(), &op).expect_err("refused");
    assert!(
        matches!(
            e,
            CalibrationError::TooFast {
                phase: "the drive",
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn refuses_when_the_operator_takes_the_wheel() {
    let op = Operator {
        scenario: Scenario {
            fault: vec![Fault {
                kind: FaultKind::OperatorOverride,
                at_s: 30.0,
                duration_s: 1.0,
            }],
        },
        ..Default::default()
    };
    let e = calibrate(&nominal(), &op).expect_err("refused");
    assert!(
        matches!(e, CalibrationError::OperatorIntervened { .. }),
        "{e}"
    );
}

#[test]
fn refuses_when_the_steering_changes_between_the_repetitions() {
    // The lag triples after the first repetition (about 40 s into the tests).
    let op = Operator {
        change_tau: Some((50.0, 0.6)),
        ..Default::default()
    };
    let e = calibrate(&nominal(), &op).expect_err("refused");
    assert!(matches!(e, CalibrationError::Inconsistent(_)), "{e}");
}
