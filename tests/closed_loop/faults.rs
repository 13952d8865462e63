//! Fault injection, in process: the simulator's scenario faults through the same frames as on
//! the bus, with the safety supervisor in the loop. Each asserts the time to the safe state
//! and the absence of limit violations (the limits themselves are the property suite's).
//! The same scenarios run on vcan in the VM suite.

use agsteer::config::Config;
use agsteer::demo::{run, DemoOptions, DemoRun};
use agsteer::sim::can_node::{Fault, FaultKind, Scenario};

const FAULT_AT: f64 = 30.0;

fn config() -> Config {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/config/demo.toml");
    let mut cfg = Config::load(std::path::Path::new(path), &[]).unwrap();
    cfg.job.line_num = 4;
    cfg
}

fn run_with(cfg: &Config, kind: FaultKind, duration_s: f64, reengage: bool) -> DemoRun {
    let opts = DemoOptions {
        scenario: Scenario {
            fault: vec![Fault {
                kind,
                at_s: FAULT_AT,
                duration_s,
            }],
        },
        no_reengage: !reengage,
        ..Default::default()
    };
    run(cfg, &opts, &mut |_| {}, &mut |_, _| {}).unwrap()
}

/// (time to the safe state after the fault starts, fault code).
fn first_disengage(r: &DemoRun) -> (f64, String) {
    let (t, code) = r
        .disengage_events
        .iter()
        .find(|(t, _)| *t >= FAULT_AT)
        .cloned()
        .unwrap_or_else(|| panic!("no disengage after the fault: {:?}", r.report));
    let before: Vec<_> = r
        .disengage_events
        .iter()
        .filter(|(t, _)| *t < FAULT_AT)
        .collect();
    assert!(before.is_empty(), "disengaged before the fault: {before:?}");
    println!("FAULT-TIME {code}: {:.3} s", t - FAULT_AT);
    (t - FAULT_AT, code)
}

#[test]
fn gnss_dropout_disengages_in_time_and_the_job_continues_on_the_same_line() {
    let cfg = config();
    let dt = cfg.dt();
    let clean = run(&cfg, &DemoOptions::default(), &mut |_| {}, &mut |_, _| {}).unwrap();
    let r = run_with(&cfg, FaultKind::GnssDropout, 2.0, true);
    let (dt_safe, code) = first_disengage(&r);
    assert_eq!(code, "gnss_timeout");
    assert!(
        dt_safe <= cfg.safety.gnss_timeout_s + dt + 1e-9,
        "{dt_safe}"
    );
    // The operator re-engages after the dropout; the job goes on with the same lines.
    assert!(r.report.finished, "{:?}", r.report);
    assert_eq!(r.finished_lines, clean.finished_lines);
}

#[test]
fn rtk_float_disengages_with_zero_tolerance() {
    let cfg = config();
    let r = run_with(&cfg, FaultKind::RtkFloat, 5.0, false);
    let (dt_safe, code) = first_disengage(&r);
    assert_eq!(code, "fix_quality");
    // The first float solution arrives within one GNSS period (+ its latency).
    assert!(
        dt_safe <= 1.0 / cfg.sim.gnss_rate_hz + cfg.sim.gnss_latency_s + cfg.dt() + 1e-9,
        "{dt_safe}"
    );
}

#[test]
fn rtk_float_is_tolerated_for_the_configured_time() {
    let mut cfg = config();
    cfg.safety.rtk_float_tolerance_s = 2.0;
    let r = run_with(&cfg, FaultKind::RtkFloat, 5.0, false);
    let (dt_safe, code) = first_disengage(&r);
    assert_eq!(code, "fix_quality");
    assert!(
        dt_safe >= 2.0 && dt_safe <= 2.0 + 0.2 + cfg.dt(),
        "{dt_safe}"
    );
}

#[test]
fn wheel_angle_crc_corruption_disengages_after_five_bad_frames() {
    let cfg = config();
    let r = run_with(&cfg, FaultKind::CorruptWheelAngleCrc, 2.0, false);
    let (dt_safe, code) = first_disengage(&r);
    assert_eq!(code, "wheel_angle_invalid");
    // Five bad frames at 100 Hz, then the next control period.
    assert!(
        dt_safe <= 5.0 / cfg.sim.was_rate_hz + cfg.dt() + 1e-9,
        "{dt_safe}"
    );
}

#[test]
fn frozen_wheel_angle_counter_disengages() {
    let cfg = config();
    let r = run_with(&cfg, FaultKind::FrozenWheelAngleCounter, 2.0, false);
    let (dt_safe, code) = first_disengage(&r);
    assert_eq!(code, "wheel_angle_invalid");
    assert!(
        dt_safe <= 6.0 / cfg.sim.was_rate_hz + cfg.dt() + 1e-9,
        "{dt_safe}"
    );
}

#[test]
fn wheel_angle_silence_disengages_after_its_timeout() {
    let cfg = config();
    let r = run_with(&cfg, FaultKind::WheelAngleSilence, 2.0, false);
    let (dt_safe, code) = first_disengage(&r);
    assert_eq!(code, "wheel_angle_timeout");
    assert!(
        dt_safe <= cfg.safety.wheel_angle_timeout_s + cfg.dt() + 1e-9,
        "{dt_safe}"
    );
}

#[test]
fn operator_override_disengages_at_once_and_nothing_reengages_by_itself() {
    let cfg = config();
    let r = run_with(&cfg, FaultKind::OperatorOverride, 2.0, false);
    let (dt_safe, code) = first_disengage(&r);
    assert_eq!(code, "operator_override");
    assert!(
        dt_safe <= 1.0 / cfg.sim.was_rate_hz + cfg.dt() + 1e-9,
        "{dt_safe}"
    );
    assert_eq!(
        r.disengage_events.len(),
        1,
        "no engagement after the fault without an operator"
    );
    assert!(!r.report.finished);
}

#[test]
fn garbage_on_every_known_id_is_counted_invalid_and_never_panics() {
    use agsteer::can::codec::{Role, MESSAGES};
    use agsteer::can::{Frame, TimedFrame};
    let cfg = config();
    let mut node = agsteer::job::node_for_config(&cfg, None).unwrap();
    let mut x: u64 = 0x1234_5678_9ABC_DEF1;
    let mut expected_bad = 0u64;
    for def in MESSAGES {
        let has_crc = def.signals.iter().any(|s| s.role == Role::Crc);
        for len in 0..=8usize {
            for _ in 0..200 {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let bytes = x.to_le_bytes();
                let f = Frame::new(def.id, &bytes[..len]);
                let crc_ok = agsteer::can::codec::decode(f.id, f.payload()).is_ok();
                if len != def.size as usize || (has_crc && !crc_ok) {
                    expected_bad += 1;
                }
                node.on_frame(&TimedFrame { t: 1.0, frame: f });
            }
        }
    }
    let st = node.status();
    assert!(
        st.bad_frames >= expected_bad,
        "{} < {expected_bad}",
        st.bad_frames
    );
    assert!(!st.engaged);
}

/// Drive a controller node with healthy inputs and the operator's engage, in process.
struct Bench {
    node: agsteer::control::node::ControllerNode,
    sim: agsteer::sim::can_node::SimNode,
    terminal: agsteer::can::codec::Packer,
    t: f64,
    out: Vec<agsteer::can::Frame>,
    sim_out: Vec<(f64, agsteer::can::Frame)>,
}

impl Bench {
    fn new(cfg: &Config) -> Bench {
        use agsteer::geo::Pose;
        let node = agsteer::job::node_for_config(cfg, None).unwrap();
        let sim = agsteer::sim::can_node::SimNode::new(
            agsteer::sim::Simulator::new(
                cfg.sim_params(),
                Pose::new(0.0, 0.0, std::f64::consts::FRAC_PI_2),
                cfg.speed(),
            ),
            *node.enu(),
            Default::default(),
            Scenario::default(),
        );
        Bench {
            node,
            sim,
            terminal: agsteer::can::codec::Packer::new(0x26),
            t: 0.0,
            out: Vec::new(),
            sim_out: Vec::new(),
        }
    }
    /// One period; `extra` frames arrive with the sensors'.
    fn period(
        &mut self,
        dt: f64,
        extra: &[agsteer::can::Frame],
    ) -> agsteer::safety::SteeringCommand {
        use agsteer::can::TimedFrame;
        self.t += dt;
        self.sim_out.clear();
        self.sim.advance_to(self.t, &mut self.sim_out);
        for (ts, f) in &self.sim_out {
            self.node.on_frame(&TimedFrame { t: *ts, frame: *f });
        }
        for f in extra {
            self.node.on_frame(&TimedFrame {
                t: self.t,
                frame: *f,
            });
        }
        self.out.clear();
        let cmd = self.node.tick(self.t, &mut self.out);
        for f in &self.out {
            self.sim.on_frame(&TimedFrame {
                t: self.t,
                frame: *f,
            });
        }
        cmd
    }
    /// The whole machine frozen for `freeze` s (one virtual CPU): the node's next period runs
    /// that late and before the simulated sensors have sent anything new.
    fn frozen_period(&mut self, dt: f64, freeze: f64) -> agsteer::safety::SteeringCommand {
        self.t += dt + freeze;
        self.out.clear();
        let cmd = self.node.tick(self.t, &mut self.out);
        // The sensors send again only after it; their frames of the frozen time are not sent.
        self.sim_out.clear();
        self.sim.advance_to(self.t, &mut self.sim_out);
        cmd
    }
    fn engage(&mut self, dt: f64) {
        for _ in 0..100 {
            // A new frame each time: a repeated one would be a frozen counter.
            let f = self
                .terminal
                .pack(&agsteer::can::codec::OperatorCommand {
                    command: Some(agsteer::can::codec::OperatorCommandCommand::Engage),
                    nudge: Some(0.0),
                    job: Some(0.0),
                })
                .unwrap();
            if self.period(dt, &[f]).engaged {
                return;
            }
        }
        panic!(
            "did not engage: {:?} refusal {:?}",
            self.node.status(),
            self.node.supervisor().last_refusal()
        );
    }
}

#[test]
fn interface_down_disengages_and_nothing_reengages_after_it_returns() {
    let cfg = config();
    let dt = cfg.dt();
    let mut b = Bench::new(&cfg);
    b.engage(dt);
    for _ in 0..50 {
        assert!(b.period(dt, &[]).engaged);
    }
    // The daemon tells the supervisor when sends fail (bus down) and when they work again.
    b.node.supervisor_mut().on_bus(false);
    let cmd = b.period(dt, &[]);
    assert!(!cmd.engaged, "disengaged within one period");
    assert_eq!(cmd.fault, agsteer::safety::FaultCode::BusDown);
    for _ in 0..(5.0 / dt) as usize {
        assert!(!b.period(dt, &[]).engaged);
    }
    b.node.supervisor_mut().on_bus(true);
    for _ in 0..100 {
        let c = b.period(dt, &[]);
        assert!(!c.engaged, "stays disengaged until an operator engage");
    }
    assert_eq!(
        b.node.supervisor().state(),
        agsteer::safety::SafetyState::Ready
    );
}

#[test]
fn can_flood_of_unrelated_ids_changes_nothing() {
    let cfg = config();
    let dt = cfg.dt();
    let mut b = Bench::new(&cfg);
    b.engage(dt);
    // 10 000 frames/s of another id for 10 s: 200 per 20 ms period.
    let flood: Vec<agsteer::can::Frame> = (0..(10_000.0 * dt) as u64)
        .map(|k| agsteer::can::Frame::new(0x18FEF1F1, &k.to_le_bytes()))
        .collect();
    let periods = (10.0 / dt) as usize;
    for _ in 0..periods {
        let c = b.period(dt, &flood);
        assert!(c.engaged, "keeps steering through the flood");
    }
    assert_eq!(
        b.node.status().bad_frames,
        0,
        "unrelated ids are not our frames"
    );
}

/// After a freeze of everything (the daemon and the simulated tractor on one frozen virtual
/// CPU, the vcan tests' situation), the late period finds the wheel angle older than its
/// timeout. Up to the timeout the freeze is the loop's own pause, not a silent sensor: the
/// steering stays engaged; a freeze longer than the wheel angle's timeout plus a period still
/// gives it back, with the wheel angle's fault.
#[test]
fn a_freeze_of_the_whole_machine_up_to_the_timeout_keeps_the_steering() {
    // The demo's configuration, and another control period and wheel-angle timeout (the GNSS
    // timeout, 0.3 s, still above the longer freeze less its credit).
    for variant in [None, Some((0.01, 0.15))] {
        let mut cfg = config();
        if let Some((dt_s, timeout_s)) = variant {
            cfg.control.dt_s = dt_s;
            cfg.safety.wheel_angle_timeout_s = timeout_s;
        }
        let dt = cfg.dt();
        let timeout = cfg.safety.wheel_angle_timeout_s;
        let mut b = Bench::new(&cfg);
        b.engage(dt);
        for _ in 0..50 {
            assert!(b.period(dt, &[]).engaged);
        }
        let freeze = timeout - dt / 2.0;
        let cmd = b.frozen_period(dt, freeze);
        assert!(cmd.engaged, "{variant:?}: a {freeze} s freeze: {cmd:?}");
        for _ in 0..50 {
            assert!(b.period(dt, &[]).engaged);
        }
        let freeze = 2.0 * timeout + dt;
        let cmd = b.frozen_period(dt, freeze);
        assert!(!cmd.engaged, "{variant:?}: a {freeze} s freeze");
        assert_eq!(cmd.fault, agsteer::safety::FaultCode::WheelAngleTimeout);
    }
}
