//! `agsteer calibrate` against the simulator on the in-memory bus (issue 15 point 4):
//! random true steerings drawn from the envelope's ranges are identified within the issue's
//! tolerances, and the procedure refuses when the tractor moves too fast, the operator takes
//! the wheel or the steering changes under the tests. Simulated time only.

use agsteer::calibrate::{Calibration, CalibrationError, Figures};
use agsteer::config::Config;
use agsteer::demo::calibrate::{params_for, run, Operator};
use agsteer::sim::can_node::{Fault, FaultKind, Scenario};
use agsteer::sim::SimParams;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The true plant: what calibration identifies, drawn from the envelope's ranges (issue 15
/// point 2): dead time 0–0.25 s, lag 0.05–0.6 s, rate 10–90°/s, deadband and backlash up to
/// 1° (each present half the time), WAS noise up to 0.5°, gain ±10 %, offset up to 2°, GNSS
/// σ 0.5–5 cm, GNSS latency 0–0.3 s, the antenna up to 0.3 m left or right of where the
/// configuration says (heading σ 0.1°, as the default receiver). The wheelbase and the antenna's forward position
/// are the configured ones (calibration does not measure them).
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
    gnss_latency_s: f64,
    /// The true antenna's lateral offset less the configured one, m.
    antenna_left_error_m: f64,
    /// The true antenna's forward offset less the configured one, m.
    antenna_forward_error_m: f64,
    heading_sigma_deg: f64,
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
            gnss_latency_s: rng.gen_range(0.0..0.3),
            antenna_left_error_m: rng.gen_range(-0.3..0.3),
            // The default receiver's heading (the envelope does not vary it).
            heading_sigma_deg: 0.1,
            antenna_forward_error_m: rng.gen_range(-0.3..0.3),
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
        p.gnss_latency = self.gnss_latency_s;
        p.antenna_left = cfg.vehicle.antenna_left_m + self.antenna_left_error_m;
        p.antenna_forward = self.antenna_forward_m(cfg);
        p.heading_sigma = self.heading_sigma_deg.to_radians();
        p.seed = self.seed;
        p
    }

    fn antenna_left_m(&self, cfg: &Config) -> f64 {
        cfg.vehicle.antenna_left_m + self.antenna_left_error_m
    }

    fn antenna_forward_m(&self, cfg: &Config) -> f64 {
        cfg.vehicle.antenna_forward_m + self.antenna_forward_error_m
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

/// The GNSS latency within 10 ms or 10 %, whichever is larger.
const LATENCY_TOLERANCE_S: f64 = 0.010;
/// The antenna's lateral offset within 2 cm: the two-way pass reads it from two lines fitted
/// to 20 s of 10 Hz fixes each; with white GNSS noise σ up to 5 cm each line's value is known
/// to σ/√200 ≈ 0.35 cm, the offset (half the difference) to 0.25 cm, so 2 cm leaves room for
/// what the fit's σ does not see: the simulated operator's wheels not exactly in the same
/// track both ways (pure pursuit behind the plant's steering) and the position frames'
/// resolution (1e-7°, ≈ 1 cm).
const ANTENNA_TOLERANCE_M: f64 = 0.02;
/// The antenna's forward offset within 5 cm (4 % of the configured 1.2 m).
const FORWARD_TOLERANCE_M: f64 = 0.05;

/// Every identified parameter within the tolerances: 10 % (deadband and backlash
/// also within 0.1°, for small ones), offset within 0.1°, dead time within 10 ms, GNSS
/// latency within 10 ms (or 10 %), antenna lateral offset within 2 cm. A rate limit the tests
/// never reached is reported as a lower bound, which must hold. (The WAS gain is held to 1 %.)
fn misses(p: &Plant, f: &Figures) -> Vec<String> {
    let mut m = Vec::new();
    let mut check = |name: &str, got: f64, truth: f64, ok: bool| {
        if !ok {
            m.push(format!("{name} {got:.4} vs {truth:.4}"));
        }
    };
    let rel = |got: f64, truth: f64| (got - truth).abs() <= 0.1 * truth.abs();
    let dead_time = f.dead_time_ms.value / 1000.0;
    check(
        "dead time s",
        dead_time,
        p.dead_time,
        (dead_time - p.dead_time).abs() <= 0.010,
    );
    let lag = f.lag_ms.value / 1000.0;
    check("lag s", lag, p.tau, rel(lag, p.tau));
    let rate = f.rate_deg_s.value;
    check(
        "rate °/s",
        rate,
        p.rate_deg_s,
        if f.rate_reached {
            rel(rate, p.rate_deg_s)
        } else {
            rate <= p.rate_deg_s * 1.1
        },
    );
    // Deadband and backlash leave the same dead zone at a reversal (2·deadband = backlash);
    // only the lag's transient tells them apart, so what is checked is the lost motion they
    // make together (deadband + half the backlash: how far the wheels stop short).
    let lost = f.lost_motion_deg;
    let lost_truth = p.deadband_deg + 0.5 * p.backlash_deg;
    check(
        "lost motion °",
        lost,
        lost_truth,
        rel(lost, lost_truth) || (lost - lost_truth).abs() <= 0.1,
    );
    check(
        "WAS gain",
        f.was_gain.value,
        p.was_gain,
        (f.was_gain.value - p.was_gain).abs() <= 0.01 * p.was_gain,
    );
    check(
        "WAS offset °",
        f.was_offset_deg.value,
        p.was_offset_deg,
        (f.was_offset_deg.value - p.was_offset_deg).abs() <= 0.1,
    );
    match f.gnss_latency_ms {
        Some(l) => {
            let got = l.value / 1000.0;
            check(
                "GNSS latency s",
                got,
                p.gnss_latency_s,
                (got - p.gnss_latency_s).abs() <= LATENCY_TOLERANCE_S.max(0.1 * p.gnss_latency_s),
            );
        }
        None => check(
            "GNSS latency (not measured)",
            f64::NAN,
            p.gnss_latency_s,
            false,
        ),
    }
    let cfg = config();
    for (name, figure, truth, tolerance) in [
        (
            "antenna left m",
            f.antenna_left_m,
            p.antenna_left_m(&cfg),
            ANTENNA_TOLERANCE_M,
        ),
        (
            "antenna forward m",
            f.antenna_forward_m,
            p.antenna_forward_m(&cfg),
            FORWARD_TOLERANCE_M,
        ),
    ] {
        // Not measured: a miss.
        let got = figure.map_or(f64::NAN, |a| a.value);
        check(name, got, truth, (got - truth).abs() <= tolerance);
    }
    m
}

/// 20 plants: about 2 minutes of CPU in release (each a 3-minute procedure simulated at 1 ms
/// and three fits), so not in the default run; `cargo test --release --test closed_loop
/// calibrate:: -- --ignored` (figures in README.md, "Calibration").
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
    // Worst errors: dead time ms, lag %, rate % (reached), lost motion °, gain %, offset °,
    // GNSS latency ms, antenna left cm.
    let mut worst = [0.0f64; 9];
    let cfg = config();
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
                    c.gnss_latency.map_or(f64::INFINITY, |l| {
                        1000.0 * (l.value - p.gnss_latency_s).abs()
                    }),
                    c.antenna_left.map_or(f64::INFINITY, |a| {
                        100.0 * (a.value - p.antenna_left_m(&cfg)).abs()
                    }),
                    c.antenna_forward.map_or(f64::INFINITY, |a| {
                        100.0 * (a.value - p.antenna_forward_m(&cfg)).abs()
                    }),
                ];
                eprintln!(
                    "plant {}: latency {:.1} ms (truth {:.1}) ± {:.1}, antenna left {:.3} m \
                     (truth {:.3}) ± {:.3}, ahead {:.3} m (truth {:.3}) ± {:.3}",
                    p.seed,
                    c.gnss_latency.map_or(f64::NAN, |l| 1000.0 * l.value),
                    1000.0 * p.gnss_latency_s,
                    c.gnss_latency
                        .and_then(|l| l.sd)
                        .map_or(f64::NAN, |s| 1000.0 * s),
                    c.antenna_left.map_or(f64::NAN, |a| a.value),
                    p.antenna_left_m(&cfg),
                    c.antenna_left.and_then(|a| a.sd).unwrap_or(f64::NAN),
                    c.antenna_forward.map_or(f64::NAN, |a| a.value),
                    p.antenna_forward_m(&cfg),
                    c.antenna_forward.and_then(|a| a.sd).unwrap_or(f64::NAN),
                );
                for (w, x) in worst.iter_mut().zip(e) {
                    *w = w.max(x);
                }
                let m = misses(p, &c.figures());
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
         WAS gain {:.2} %, WAS offset {:.3}°, GNSS latency {:.1} ms, antenna left {:.2} cm, \
         antenna forward {:.2} cm",
        worst[0], worst[1], worst[2], worst[3], worst[4], worst[5], worst[6], worst[7], worst[8]
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
        gnss_latency_s: 0.08,
        antenna_left_error_m: -0.15,
        antenna_forward_error_m: 0.2,
        heading_sigma_deg: 0.1,
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
        ("track", "gnss_latency_s"),
        ("vehicle", "antenna_left_m"),
        ("vehicle", "antenna_forward_m"),
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

/// agsteerd's calibration mode, on the in-memory bus: the controller node as the daemon builds
/// it, the simulated tractor obeying the node's stop / forward requests, the operator command
/// `calibrate` from a terminal, and the daemon's fitting and saving
/// ([`agsteer::daemon::calibration::CalibrationRunner`]). Returns the calibrate replies and the
/// runner's status once the node answered done or failed (or the time ran out).
struct DaemonRig {
    node: agsteer::control::node::ControllerNode,
    sim: agsteer::sim::can_node::SimNode,
    runner: agsteer::daemon::calibration::CalibrationRunner,
    terminal: agsteer::can::codec::Packer,
    dt: f64,
    t: f64,
    replies: Vec<agsteer::can::codec::OperatorReplyResult>,
    engaged: bool,
    /// The operator on the two-way pass.
    driver: agsteer::demo::calibrate::LineDriver,
}

impl DaemonRig {
    fn new(cfg: &Config, plant: &Plant, state_dir: &std::path::Path) -> DaemonRig {
        let resolved = cfg.resolved();
        let job = agsteer::job::prepare(&resolved.planning).unwrap();
        let node = agsteer::job::build_node(&resolved, &job, None).unwrap();
        let sim = agsteer::sim::can_node::SimNode::new(
            agsteer::sim::Simulator::new(
                plant.sim_params(cfg),
                agsteer::geo::Pose::new(0.0, 0.0, std::f64::consts::FRAC_PI_2),
                cfg.speed(),
            ),
            *node.enu(),
            Default::default(),
            Scenario::default(),
        );
        DaemonRig {
            node,
            sim,
            runner: agsteer::daemon::calibration::CalibrationRunner::new(state_dir.into()),
            terminal: agsteer::can::codec::Packer::new(0x26),
            dt: resolved.control.dt,
            t: 0.0,
            replies: Vec::new(),
            engaged: false,
            driver: Default::default(),
        }
    }

    fn command(&mut self, code: agsteer::can::codec::OperatorCommandCommand) {
        let f = self
            .terminal
            .pack(&agsteer::can::codec::OperatorCommand {
                command: Some(code),
                nudge: Some(0.0),
                job: Some(0.0),
            })
            .unwrap();
        self.node.on_frame(&agsteer::can::TimedFrame {
            t: self.t,
            frame: f,
        });
    }

    /// Run until `until` holds or `seconds` of simulated time pass.
    fn run(&mut self, seconds: f64, until: impl Fn(&DaemonRig) -> bool) {
        use agsteer::can::codec::{self, OperatorReply, OperatorReplyCommand};
        let (mut sim_out, mut out) = (Vec::new(), Vec::new());
        let end = self.t + seconds;
        while self.t < end && !until(self) {
            self.t += self.dt;
            sim_out.clear();
            self.sim.advance_to(self.t, &mut sim_out);
            for (ts, f) in &sim_out {
                self.node
                    .on_frame(&agsteer::can::TimedFrame { t: *ts, frame: *f });
            }
            out.clear();
            let cmd = self.node.tick(self.t, &mut out);
            self.engaged = cmd.engaged;
            self.runner.poll(&mut self.node);
            for f in &out {
                self.sim.on_frame(&agsteer::can::TimedFrame {
                    t: self.t,
                    frame: *f,
                });
                if let Some(r) = codec::decode(f.id, f.payload())
                    .ok()
                    .and_then(|d| d.to::<OperatorReply>())
                    .filter(|r| r.command == Some(OperatorReplyCommand::Calibrate))
                {
                    self.replies.extend(r.result);
                }
            }
            // The operator steers the two-way pass by hand.
            match self.node.calibration_progress().map(|p| p.instruction) {
                Some("line") => self.driver.steer_line(self.sim.sim_mut()),
                Some("turn") => self.driver.steer_turn(self.sim.sim_mut()),
                _ => {}
            }
        }
    }

    fn status(&self) -> serde_json::Value {
        serde_json::to_value(self.runner.reply(&self.node)).unwrap()
    }
}

fn daemon_config() -> Config {
    let mut cfg = config();
    // The drive asked of the simulated operator; a quicker procedure (half the holds).
    cfg.control.speed_kmh = 3.0;
    cfg.calibration.time_scale = 0.5;
    cfg
}

#[test]
fn the_daemon_mode_calibrates_within_the_tolerances_and_saves_the_result() {
    use agsteer::can::codec::{OperatorCommandCommand as Code, OperatorReplyResult as Res};
    let dir = tempfile::tempdir().unwrap();
    let cfg = daemon_config();
    let plant = nominal();
    let mut rig = DaemonRig::new(&cfg, &plant, dir.path());
    rig.run(1.0, |_| false);
    rig.command(Code::Calibrate);
    rig.run(0.1, |r| !r.replies.is_empty());
    assert_eq!(rig.replies, vec![Res::Started]);
    assert_eq!(rig.status()["state"], "running", "{}", rig.status());
    // The node asks the tractor to stop; the supervisor steers through the tests.
    rig.run(30.0, |r| r.engaged);
    assert!(rig.engaged, "steering tests engaged: {}", rig.status());
    assert_eq!(rig.status()["instruction"], "stop");
    let mut drove = false;
    rig.run(400.0, |r| {
        r.replies.len() > 1 || r.node.calibration_progress().is_none() && !r.node.calibrating()
    });
    drove |= rig.sim.sim().true_state().pose.pos.norm() > 10.0;
    // The fit runs on the runner's thread, in real time.
    let waited = std::time::Instant::now();
    while rig.replies.len() < 2 && waited.elapsed().as_secs() < 60 {
        rig.run(rig.dt, |_| false);
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let st = rig.status();
    assert_eq!(rig.replies, vec![Res::Started, Res::Done], "{st}");
    assert!(drove, "the drive was driven");
    assert_eq!(st["state"], "done", "{st}");
    // The figures (edge units) against the plant's truth.
    let f: Figures = serde_json::from_value(st["figures"].clone()).unwrap();
    eprintln!("{}", f.report());
    let m = misses(&plant, &f);
    assert!(m.is_empty(), "{}: {}", m.join(", "), f.report());
    // The state directory holds the fragment (valid configuration) and the figures.
    let frag = std::fs::read_to_string(dir.path().join("calibration.toml")).unwrap();
    assert_eq!(frag, st["fragment"].as_str().unwrap());
    let c: Config = toml::from_str(&frag).expect("a configuration");
    assert!(c.validate().is_empty(), "{:?}", c.validate());
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("calibration.json")).unwrap(),
    )
    .unwrap();
    let saved: Figures = serde_json::from_value(json["figures"].clone()).unwrap();
    assert!((saved.was_offset_deg.value - f.was_offset_deg.value).abs() < 1e-9);
    assert!((saved.dead_time_ms.value - f.dead_time_ms.value).abs() < 1e-9);
    // Guidance has the supervisor back with its own limits: nothing engaged.
    assert!(!rig.engaged);
}

#[test]
fn the_daemon_mode_refuses_while_engaged_and_aborts_on_a_disengage() {
    use agsteer::can::codec::{OperatorCommandCommand as Code, OperatorReplyResult as Res};
    let dir = tempfile::tempdir().unwrap();
    let cfg = daemon_config();
    let mut rig = DaemonRig::new(&cfg, &nominal(), dir.path());
    rig.run(1.0, |_| false);
    rig.command(Code::Engage);
    rig.run(2.0, |r| r.engaged);
    assert!(rig.engaged, "engaged on the job");
    rig.command(Code::Calibrate);
    rig.run(0.1, |r| !r.replies.is_empty());
    assert_eq!(rig.replies, vec![Res::Engaged]);
    rig.command(Code::Disengage);
    rig.run(0.1, |_| false);
    rig.replies.clear();
    rig.command(Code::Calibrate);
    rig.run(30.0, |r| r.engaged);
    assert_eq!(rig.replies, vec![Res::Started]);
    rig.run(2.0, |_| false);
    // The operator disengages half-way through the steering tests: refused, named.
    rig.command(Code::Disengage);
    rig.run(0.1, |r| r.replies.len() > 1);
    assert_eq!(rig.replies, vec![Res::Started, Res::Failed]);
    let st = rig.status();
    assert_eq!(st["state"], "refused", "{st}");
    assert!(st["reason"].as_str().unwrap().contains("operator"), "{st}");
    assert!(!rig.engaged);
    assert!(!dir.path().join("calibration.toml").exists());
}
