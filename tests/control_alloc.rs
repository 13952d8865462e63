//! The control path allocates nothing per period (docs/CONVENTIONS.md, The control path): a
//! counting global allocator (tests/common/counting_alloc.rs: this thread's allocations only)
//! counts what `ControllerNode::on_frame` and `ControllerNode::tick` allocate while the node
//! drives an AB job closed loop against the simulator on an in-memory bus, from the first frame
//! to the end of the job (three lines and their turns). The simulator, the bus and the test's own bookkeeping are not counted; the one
//! allocation allowed is the source selector listing a source the first time it is seen.

use agsteer::can::bus::{CanBus, MemBus};
use agsteer::can::codec::{OperatorCommand, OperatorCommandCommand, Packer};
use agsteer::can::Frame;
use agsteer::config::Config;
use agsteer::geo::Pose;
use agsteer::safety::SafetyState;
use agsteer::sim::can_node::{Scenario, SimAddresses, SimNode};
use agsteer::sim::Simulator;
use agsteer::track::registry::TrackerKind;
#[path = "common/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::counted;

#[test]
fn the_controller_node_allocates_nothing_per_period() {
    for &kind in TrackerKind::ALL {
        drive_and_count(kind);
    }
}

fn drive_and_count(kind: TrackerKind) {
    let mut cfg = Config::default();
    cfg.job.line_num = 3;
    cfg.track.kind = kind;
    let resolved = cfg.resolved();
    let mut node = agsteer::job::node_for_config(&cfg, None).unwrap();
    let start = node
        .controller()
        .path_start()
        .map(|(p, _)| p)
        .unwrap_or(Pose::new(
            resolved.planning.ab.point_a.x,
            resolved.planning.ab.point_a.y,
            (resolved.planning.ab.point_b - resolved.planning.ab.point_a)
                .y
                .atan2((resolved.planning.ab.point_b - resolved.planning.ab.point_a).x),
        ));
    let mut sim = SimNode::new(
        Simulator::new(resolved.sim.params.clone(), start, resolved.sim.speed),
        *node.enu(),
        SimAddresses::default(),
        Scenario::default(),
    );
    let mut bus_ctrl = MemBus::new();
    let mut bus_sim = bus_ctrl.node();
    let mut terminal_bus = bus_ctrl.node();
    let mut terminal = Packer::new(0x26);
    let dt = resolved.control.dt;
    let mut sim_frames: Vec<(f64, Frame)> = Vec::with_capacity(64);
    let mut ctrl_frames: Vec<Frame> = Vec::with_capacity(16);
    let mut per_tick: Vec<(f64, u64, &'static str)> = Vec::new();
    let mut engaged_ticks = 0u64;
    let mut first_sight = 0u64;
    let mut first_engaged: Option<f64> = None;
    for k in 0..(400.0 / dt) as u64 {
        let t = k as f64 * dt;
        sim_frames.clear();
        sim.advance_to(t, &mut sim_frames);
        for (ts, f) in &sim_frames {
            bus_sim.set_time(*ts);
            let _ = bus_sim.send(f);
        }
        let engage = node.status().state == SafetyState::Ready;
        if engage {
            let f = terminal
                .pack(&OperatorCommand {
                    command: Some(OperatorCommandCommand::Engage),
                    nudge: Some(0.0),
                    job: Some(0.0),
                })
                .unwrap();
            terminal_bus.set_time(t);
            let _ = terminal_bus.send(&f);
        }
        while let Ok(Some(tf)) = bus_ctrl.try_recv() {
            let known = node.sources().seen().len();
            let (_, n) = counted(|| node.on_frame(&tf));
            if node.sources().seen().len() > known {
                // The source selector lists a source the first time it is seen (at most
                // `input::source::MAX_LISTED`): once per source, not per period.
                first_sight += n;
            } else if n > 0 {
                per_tick.push((
                    t,
                    n,
                    if engage {
                        "on_frame (engage)"
                    } else {
                        "on_frame"
                    },
                ));
            }
        }
        ctrl_frames.clear();
        let (cmd, n) = counted(|| node.tick(t, &mut ctrl_frames));
        if n > 0 {
            per_tick.push((t, n, "tick"));
        }
        bus_ctrl.set_time(t);
        for f in &ctrl_frames {
            let _ = bus_ctrl.send(f);
        }
        while let Ok(Some(tf)) = bus_sim.try_recv() {
            sim.on_frame(&tf);
        }
        while let Ok(Some(_)) = terminal_bus.try_recv() {}
        if cmd.engaged {
            engaged_ticks += 1;
            first_engaged.get_or_insert(t);
        }
        let g = node.controller_mut().guidance_mut();
        if g.has_events() {
            g.drain_events().for_each(drop);
        }
        if node.controller().guidance().is_finished() {
            break;
        }
    }
    let finished = node.controller().guidance().is_finished();
    eprintln!(
        "{}: engaged {engaged_ticks} periods from t = {first_engaged:?}; job finished: {finished}; \
         allocations when a source was first seen: {first_sight}; periods with allocations: {}",
        kind.name(),
        per_tick.len()
    );
    for (t, n, what) in per_tick.iter().take(40) {
        eprintln!("  t = {t:.2} s: {n} allocation(s) in {what}");
    }
    // The default tracker drives the whole job (lines, turns, line changes, the end); the
    // references drive at least a line and a turn (on the simulator's default plant they may
    // give the steering back, and the job then runs out of time).
    assert!(
        engaged_ticks > 3000 && (finished || kind != TrackerKind::default()),
        "{}: the node did not drive the job",
        kind.name()
    );
    assert!(
        per_tick.is_empty(),
        "{}: the control path allocated",
        kind.name()
    );
}
