//! The daemon's work between a GNSS fix's arrival and its command (issue 16 point 7, issue 19
//! point 5): the vcan test job (`config/vcan.toml`, AB lines, dt 10 ms) driven closed-loop by
//! the CAN simulator over an in-memory bus, engaged, as `agsteerd` sets it up.
//!
//! - `fix/burst`: one GNSS epoch's frames into the node (heading, COG/SOG, the 129029 fast
//!   packet, then the 129025 position that makes the fix) and the control period it runs;
//! - `fix/tick`: that period alone (`ControllerNode::tick`, the frames packed);
//! - `timer/tick`: a period the timer runs between fixes.
//!
//! The median and p99 over 3 000 fixes are printed. Measured in the thread's CPU time: on a
//! shared host, wall time counts other processes' turns. Under the VM's TCG emulation every CPU
//! microsecond costs 10–50, so a native 20 µs here is about 1 ms of the VM test's figure.
//!
//! `cargo bench --bench fix_to_command`

use agsteer::can::bus::{CanBus, MemBus};
use agsteer::can::codec::{OperatorCommand, OperatorCommandCommand, Packer};
use agsteer::can::{Frame, TimedFrame};
use agsteer::config::Config;
use agsteer::control::node::ControllerNode;
use agsteer::geo::{left_normal, Pose};
use agsteer::safety::SafetyState;
use agsteer::sim::can_node::{Scenario, SimAddresses, SimNode};
use agsteer::sim::Simulator;
use criterion::{criterion_group, criterion_main, Criterion};
use std::time::Duration;

#[path = "common/thread_cpu.rs"]
mod thread_cpu;
use thread_cpu::{thread_cpu, ThreadCpu};

/// One period's measured parts.
#[derive(Default, Clone, Copy)]
struct Period {
    /// A GNSS fix entered the node in this period.
    fix: bool,
    /// The period's frames into the node.
    frames: Duration,
    /// Its control period.
    tick: Duration,
}

struct Rig {
    node: ControllerNode,
    sim: SimNode,
    bus_ctrl: MemBus,
    bus_sim: MemBus,
    terminal_bus: MemBus,
    terminal: Packer,
    sim_frames: Vec<(f64, Frame)>,
    rx: Vec<TimedFrame>,
    out: Vec<Frame>,
    k: u64,
    dt: f64,
}

impl Rig {
    fn new() -> Rig {
        let cfg = Config::load(std::path::Path::new("config/vcan.toml"), &[]).expect("config");
        let resolved = cfg.resolved();
        let job = agsteer::job::prepare(&resolved.planning).expect("job");
        let node = agsteer::job::build_node(&resolved, &job, None).expect("node");
        let ab = &resolved.planning.ab;
        let dir = (ab.point_b - ab.point_a).normalize();
        let p = ab.point_a + left_normal(&dir) * 0.2;
        let sim = SimNode::new(
            Simulator::new(
                resolved.sim.params.clone(),
                Pose::new(p.x, p.y, dir.y.atan2(dir.x)),
                resolved.sim.speed,
            ),
            *node.enu(),
            SimAddresses::default(),
            Scenario::default(),
        );
        let bus_ctrl = MemBus::new();
        let bus_sim = bus_ctrl.node();
        let terminal_bus = bus_ctrl.node();
        Rig {
            node,
            sim,
            bus_ctrl,
            bus_sim,
            terminal_bus,
            terminal: Packer::new(0x26),
            sim_frames: Vec::with_capacity(64),
            rx: Vec::with_capacity(64),
            out: Vec::with_capacity(8),
            k: 0,
            dt: resolved.control.dt,
        }
    }

    /// One control period: the simulator's frames to the node, then the node's period (both
    /// timed), its frames back to the simulator. A finished job starts again.
    fn period(&mut self) -> Period {
        let t = self.k as f64 * self.dt;
        self.k += 1;
        self.sim_frames.clear();
        self.sim.advance_to(t, &mut self.sim_frames);
        for (ts, f) in &self.sim_frames {
            self.bus_sim.set_time(*ts);
            let _ = self.bus_sim.send(f);
        }
        if self.node.status().state == SafetyState::Ready {
            if let Ok(f) = self.terminal.pack(&OperatorCommand {
                command: Some(OperatorCommandCommand::Engage),
                nudge: Some(0.0),
                job: Some(0.0),
            }) {
                self.terminal_bus.set_time(t);
                let _ = self.terminal_bus.send(&f);
            }
        }
        self.rx.clear();
        while let Ok(Some(tf)) = self.bus_ctrl.try_recv() {
            self.rx.push(tf);
        }
        let mut p = Period::default();
        let start = thread_cpu();
        for tf in &self.rx {
            p.fix |= self.node.on_frame(tf);
        }
        let mid = thread_cpu();
        self.out.clear();
        self.node.tick(t, &mut self.out);
        let end = thread_cpu();
        p.frames = mid - start;
        p.tick = end - mid;
        self.bus_ctrl.set_time(t);
        for f in &self.out {
            let _ = self.bus_ctrl.send(f);
        }
        while let Ok(Some(tf)) = self.bus_sim.try_recv() {
            self.sim.on_frame(&tf);
        }
        while let Ok(Some(_)) = self.terminal_bus.try_recv() {}
        let _ = self.node.controller_mut().guidance_mut().drain_events();
        p
    }

    /// Driven until engaged and 2 s past it.
    fn engaged() -> Rig {
        let mut rig = Rig::new();
        for _ in 0..6000 {
            rig.period();
            if rig.node.status().state == SafetyState::Engaged {
                break;
            }
        }
        assert_eq!(rig.node.status().state, SafetyState::Engaged, "engaged");
        for _ in 0..200 {
            rig.period();
        }
        rig
    }

    /// The next period, engaged: a finished job (or a disengagement) starts a new rig.
    fn next(&mut self) -> Period {
        loop {
            let p = self.period();
            if self.node.status().state == SafetyState::Engaged {
                return p;
            }
            *self = Rig::engaged();
        }
    }

    /// The next engaged period that had a fix.
    fn next_fix(&mut self) -> Period {
        loop {
            let p = self.next();
            if p.fix {
                return p;
            }
        }
    }
}

fn percentiles() {
    let mut rig = Rig::engaged();
    let (mut burst, mut tick, mut timer) = (Vec::new(), Vec::new(), Vec::new());
    while burst.len() < 3000 {
        let p = rig.next();
        if p.fix {
            burst.push(p.frames + p.tick);
            tick.push(p.tick);
        } else {
            timer.push(p.tick);
        }
    }
    for (name, v) in [
        ("fix/burst", &mut burst),
        ("fix/tick", &mut tick),
        ("timer/tick", &mut timer),
    ] {
        v.sort_unstable();
        let q = |p: f64| v[((v.len() as f64 * p) as usize).min(v.len() - 1)].as_secs_f64() * 1e6;
        eprintln!(
            "fix_to_command/{name}: median {:.2} µs, p99 {:.2} µs, max {:.1} µs over {} (thread CPU)",
            q(0.5),
            q(0.99),
            q(1.0),
            v.len()
        );
    }
}

fn bench(c: &mut Criterion<ThreadCpu>) {
    percentiles();
    let mut rig = Rig::engaged();
    c.bench_function("fix_to_command/fix/burst", |b| {
        b.iter_custom(|iters| {
            (0..iters)
                .map(|_| {
                    let p = rig.next_fix();
                    p.frames + p.tick
                })
                .sum()
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(ThreadCpu);
    targets = bench
}
criterion_main!(benches);
