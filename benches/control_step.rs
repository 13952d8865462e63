//! One control step of the default controller: the sensor inputs of the period (GNSS fixes with
//! the disturbance observer's innovation, wheel angles), estimator prediction, nearest global
//! point, local B-spline rebuild when the nearest global point moved, nearest local point, pure
//! pursuit on the course over ground. Criterion gives the mean/median; the p99 is measured over
//! 200 000 steps of a real closed-loop drive and printed. Targets: p99 < 20 µs, and the default
//! tracker (observer, prediction, roll) costs < 10 µs more per step than plain pure pursuit.

use agsteer::config::Config;
use agsteer::control::Controller;
use agsteer::estimate::GnssFix;
use agsteer::geo::Pose;
use agsteer::sim::{SimOutput, Simulator};
use criterion::{criterion_group, criterion_main, Criterion};
use std::time::Instant;

/// A controller and simulator on the default demo, fed up to `t`.
struct Rig {
    ctrl: Controller,
    sim: Simulator,
    outs: Vec<SimOutput>,
    /// Latest IMU roll, rad.
    roll: Option<f64>,
    k: u64,
    dt: f64,
}

impl Rig {
    fn new(kind: &str, extra: &[&str]) -> Rig {
        // A side slope with the IMU, so that roll correction and the slip estimate run too.
        let mut set = vec![
            format!("track.kind={kind}"),
            "job.line_num=0".into(),
            "sim.imu_rate_hz=100".into(),
            "sim.terrain_slope_deg=2".into(),
            "sim.slip_per_roll_mps_per_deg=0.015".into(),
        ];
        set.extend(extra.iter().map(|s| s.to_string()));
        let cfg = Config::parse_with("", &set).expect("config");
        let job = agsteer::job::prepare_config(&cfg).expect("job");
        let ctrl = Controller::new(&cfg.control_params(), job.plan, job.definition, None)
            .expect("controller");
        let sim = Simulator::new(
            cfg.sim_params(),
            Pose::new(0.0, 0.0, std::f64::consts::FRAC_PI_2),
            cfg.speed(),
        );
        Rig {
            ctrl,
            sim,
            outs: Vec::with_capacity(64),
            roll: None,
            k: 0,
            dt: cfg.dt(),
        }
    }

    /// Simulate the sensors of the next period (not timed).
    fn feed(&mut self) -> f64 {
        let t = self.k as f64 * self.dt;
        self.k += 1;
        self.outs.clear();
        self.sim.advance_to(t, &mut self.outs);
        t
    }

    /// The timed part: the period's inputs into the controller, then one control step.
    fn step(&mut self, t: f64) {
        for o in &self.outs {
            match *o {
                SimOutput::Gnss(ref m) => self.ctrl.on_fix(&GnssFix {
                    t_received: m.t_delivered,
                    antenna: m.antenna,
                    heading: Some(m.heading),
                    speed: m.speed,
                    roll: self.roll,
                    latency: None,
                }),
                SimOutput::WheelAngle { t, angle } => self.ctrl.on_wheel_angle(t, angle),
                SimOutput::Attitude { roll, .. } => self.roll = Some(roll),
            }
        }
        let out = self.ctrl.tick(t).expect("tick");
        for _ in self.ctrl.guidance_mut().drain_events() {}
        self.sim.set_command(out.wheel_angle.unwrap_or(0.0));
    }
}

fn percentiles(kind: &str, extra: &[&str]) {
    let mut rig = Rig::new(kind, extra);
    for _ in 0..500 {
        let t = rig.feed();
        rig.step(t);
    }
    let mut samples = Vec::with_capacity(200_000);
    for _ in 0..200_000 {
        let t = rig.feed();
        let start = Instant::now();
        rig.step(t);
        samples.push(start.elapsed().as_nanos() as u64);
    }
    samples.sort_unstable();
    let q = |p: f64| {
        samples[((samples.len() as f64 * p) as usize).min(samples.len() - 1)] as f64 / 1000.0
    };
    eprintln!(
        "control_step/{kind}{}: median {:.2} µs, p99 {:.2} µs, max {:.1} µs over {} steps",
        if extra.is_empty() {
            ""
        } else {
            " (with a 0.6 s steering lag: the lag lead on)"
        },
        q(0.5),
        q(0.99),
        q(1.0),
        samples.len()
    );
}

fn bench(c: &mut Criterion) {
    // The default tracker with a slow steering, whose lag the controller leads
    // (track::lag_lead): percentiles only.
    percentiles(
        "predictive",
        &["sim.actuator_tau_s=0.6", "safety.actuator_tau_s=0.6"],
    );
    for kind in ["predictive", "pure_pursuit"] {
        percentiles(kind, &[]);
        let mut rig = Rig::new(kind, &[]);
        c.bench_function(&format!("control_step/{kind}"), |b| {
            b.iter_custom(|iters| {
                let mut total = std::time::Duration::ZERO;
                for _ in 0..iters {
                    let t = rig.feed();
                    let start = Instant::now();
                    rig.step(t);
                    total += start.elapsed();
                }
                total
            })
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
