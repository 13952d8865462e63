//! The input seam: the controller node driven through `on_input` by a GNSS source that is not
//! CAN (positions carrying their own fix quality, as an NMEA 0183 GGA or a UBX NAV-PVT parser
//! produces them), closed-loop with the simulator.

use agsteer::can::{Frame, TimedFrame};
use agsteer::config::Config;
use agsteer::control::node::ControllerNode;
use agsteer::input::can::CanAdapter;
use agsteer::input::{FixQuality, Input, OperatorCommand, OperatorInput, SourceId};
use agsteer::sim::can_node::{Scenario, SimNode};
use agsteer::sim::Simulator;

fn config() -> Config {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/config/demo.toml");
    let mut cfg = Config::load(std::path::Path::new(path), &[]).unwrap();
    cfg.job.line_num = 4;
    cfg
}

/// Runs `seconds` of closed loop. The simulator's frames go through a CAN adapter of the
/// test's own; GNSS positions are re-sent as a serial receiver's (source `Stream(0)`, quality
/// attached when `serial_quality`), and the CAN 129029 quality is dropped. Returns the
/// engaged periods and the largest |XTE| once engaged.
fn run(serial_quality: bool, seconds: f64) -> (usize, f64, ControllerNode) {
    let cfg = config();
    let dt = cfg.dt();
    let mut node = agsteer::job::node_for_config(&cfg, None).unwrap();
    let mut sim = SimNode::new(
        Simulator::new(
            cfg.sim_params(),
            agsteer::geo::Pose::new(0.0, 0.0, std::f64::consts::FRAC_PI_2),
            cfg.speed(),
        ),
        *node.enu(),
        Default::default(),
        Scenario::default(),
    );
    let mut adapter = CanAdapter::default();
    let (mut sim_out, mut out) = (Vec::<(f64, Frame)>::new(), Vec::new());
    let (mut engaged, mut worst) = (0usize, 0.0f64);
    let mut t = 0.0;
    for _ in 0..(seconds / dt) as usize {
        t += dt;
        sim_out.clear();
        sim.advance_to(t, &mut sim_out);
        for (ts, f) in &sim_out {
            for input in adapter.on_frame(&TimedFrame { t: *ts, frame: *f }) {
                match input {
                    Input::Quality(_) => {}
                    Input::Position(mut p) => {
                        p.source = SourceId::Stream(0);
                        p.quality = serial_quality.then_some(FixQuality::RtkFixed);
                        node.on_input(&Input::Position(p));
                    }
                    other => {
                        node.on_input(&other);
                    }
                }
            }
        }
        if !node.status().engaged {
            node.on_input(&Input::Operator(OperatorInput {
                t,
                source: SourceId::Local,
                command: OperatorCommand::Engage,
            }));
        }
        out.clear();
        let cmd = node.tick(t, &mut out);
        for f in &out {
            sim.on_frame(&TimedFrame { t, frame: *f });
        }
        if cmd.engaged {
            engaged += 1;
            if let Some(x) = node.status().xte_m {
                worst = worst.max(x.abs());
            }
        }
    }
    (engaged, worst, node)
}

#[test]
fn a_serial_gnss_source_feeds_the_node_through_the_seam() {
    let (engaged, worst, node) = run(true, 30.0);
    let dt = config().dt();
    assert!(
        engaged as f64 * dt > 20.0,
        "engaged {:.1} s of 30",
        engaged as f64 * dt
    );
    assert!(worst < 0.5, "largest |XTE| once engaged {worst} m");
    assert_eq!(node.status().fix, FixQuality::RtkFixed);
    assert_eq!(node.status().bad_frames, 0);
}

#[test]
fn without_a_fix_quality_the_node_never_engages() {
    // The same positions, without the quality a serial receiver attaches and without 129029:
    // the supervisor has no fix quality and refuses to engage.
    let (engaged, _, node) = run(false, 10.0);
    assert_eq!(engaged, 0);
    assert_eq!(node.status().fix, FixQuality::None);
}
