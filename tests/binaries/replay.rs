//! Bus log → replay (issue 16 point 6): a closed-loop run scheduled as agsteerd schedules it
//! (a control period every dt, and one at once on each GNSS fix, issue 16 point 7) writes every
//! frame in and out through the daemon's bus log (rotated files); `agsteer replay` on those
//! files reproduces every control period's frames; a replay under another configuration
//! does not.

use agsteer::can::bus::{CanBus, MemBus};
use agsteer::can::codec::{OperatorCommand, OperatorCommandCommand, Packer};
use agsteer::can::Frame;
use agsteer::config::Config;
use agsteer::daemon::bus_log::{BusLog, BusLogParams};
use agsteer::geo::{left_normal, v2, Pose};
use agsteer::safety::SafetyState;
use agsteer::sim::can_node::{Scenario, SimAddresses, SimNode};
use agsteer::sim::Simulator;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

const CONFIG: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/config/demo.toml");

fn config(set: &[&str]) -> Config {
    let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    Config::load(Path::new(CONFIG), &set).unwrap()
}

/// Time as the daemon hands it to the node: whole microseconds.
fn us(t: f64) -> f64 {
    agsteer::can::candump::log_time(t)
}

/// Run `seconds` of a job closed-loop, logging to `log`; returns (control periods, fix
/// periods, engaged periods).
fn closed_loop(cfg: &Config, seconds: f64, log: &BusLog) -> (u64, u64, u64) {
    let log = &Paced {
        log,
        sent: std::cell::Cell::new(0),
    };
    let mut node = agsteer::job::node_for_config(cfg, None).unwrap();
    let a = v2(cfg.job.point_a_m[0], cfg.job.point_a_m[1]);
    let b = v2(cfg.job.point_b_m[0], cfg.job.point_b_m[1]);
    let dir = (b - a).normalize();
    let p = a + left_normal(&dir) * 0.3;
    let start = Pose::new(p.x, p.y, dir.y.atan2(dir.x) + 0.05);
    let mut sim = SimNode::new(
        Simulator::new(agsteer::demo::sim_params(cfg), start, cfg.speed()),
        *node.enu(),
        SimAddresses::default(),
        Scenario::default(),
    );
    let mut bus_ctrl = MemBus::new();
    let mut bus_sim = bus_ctrl.node();
    let mut terminal_bus = bus_ctrl.node();
    let mut terminal = Packer::new(0x26);
    let dt = cfg.dt();
    let mut sim_frames: Vec<(f64, Frame)> = Vec::new();
    let mut out: Vec<Frame> = Vec::new();
    let (mut ticks, mut fix_ticks, mut engaged) = (0, 0, 0);
    let mut next_tick = 0.0;
    let mut tick = |t: f64, node: &mut agsteer::control::node::ControllerNode, bus: &mut MemBus| {
        out.clear();
        let cmd = node.tick(t, &mut out);
        bus.set_time(t);
        for f in &out {
            log.record(t, f);
            bus.send(f).unwrap();
        }
        node.controller_mut()
            .guidance_mut()
            .drain_events()
            .for_each(drop);
        // Periods on the bus (none before the ISO 11783-5 address is claimed).
        if out
            .iter()
            .any(|f| agsteer::control::replay::is_own(f, cfg.bus.source_address))
        {
            ticks += 1;
        }
        if cmd.engaged {
            engaged += 1;
        }
    };
    // The simulator steps every 1 ms; frames are stamped with their delivery time.
    let mut k = 0u64;
    loop {
        let t = us(k as f64 * 1e-3);
        if t > seconds {
            break;
        }
        k += 1;
        sim_frames.clear();
        sim.advance_to(t, &mut sim_frames);
        for (ts, f) in &sim_frames {
            bus_sim.set_time(us(*ts));
            bus_sim.send(f).unwrap();
        }
        if k % 100 == 0 && node.status().state == SafetyState::Ready {
            let f = terminal
                .pack(&OperatorCommand {
                    command: Some(OperatorCommandCommand::Engage),
                    nudge: Some(0.0),
                    job: Some(0.0),
                })
                .unwrap();
            terminal_bus.set_time(t);
            terminal_bus.send(&f).unwrap();
        }
        while let Ok(Some(tf)) = bus_ctrl.try_recv() {
            log.record(tf.t, &tf.frame);
            if node.on_frame(&tf) {
                // A fix: the command is computed at once and the timer restarts from it.
                tick(tf.t, &mut node, &mut bus_ctrl);
                fix_ticks += 1;
                next_tick = us(tf.t + dt);
            }
        }
        if t >= next_tick {
            tick(t, &mut node, &mut bus_ctrl);
            next_tick = us(t + dt);
        }
        while let Ok(Some(tf)) = bus_sim.try_recv() {
            sim.on_frame(&tf);
        }
        while let Ok(Some(_)) = terminal_bus.try_recv() {}
    }
    (ticks, fix_ticks, engaged)
}

/// The bus log fed at the pace its writer keeps: the simulated run is ~600× faster than real
/// time, so on a loaded host the writer thread could fall a whole channel behind and drop
/// frames, which a real bus (frames at real time) never does. `record` waits while the channel
/// is nearly full; what is recorded is unchanged.
struct Paced<'a> {
    log: &'a BusLog,
    sent: std::cell::Cell<u64>,
}

impl Paced<'_> {
    fn record(&self, t: f64, frame: &Frame) {
        let room = agsteer::daemon::bus_log::CHANNEL_FRAMES as u64 / 2;
        // At most 10 s: a writer that stopped shows as drops, as before.
        for _ in 0..10_000 {
            let s = self.log.stats();
            if self.sent.get() < s.lines + s.dropped + room {
                break;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        self.sent.set(self.sent.get() + 1);
        self.log.record(t, frame);
    }
}

fn replay(files: &[PathBuf], set: &[&str]) -> serde_json::Value {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_agsteer"));
    cmd.arg("replay")
        .args(files)
        .args(["--config", CONFIG, "--json"]);
    for s in set {
        cmd.args(["--set", s]);
    }
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn a_logged_run_replays_to_the_same_commands() {
    let cfg = config(&[]);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bus.log");
    let log = BusLog::start(BusLogParams {
        path: path.clone(),
        interface: "can0".into(),
        max_bytes: 300_000,
        files: 8,
    })
    .unwrap();
    let (ticks, fix_ticks, engaged) = closed_loop(&cfg, 60.0, &log);
    let stats = log.stats();
    log.finish(Duration::from_secs(30));
    println!(
        "REPLAY ticks={ticks} fix_ticks={fix_ticks} engaged={engaged} lines={} rotations={}",
        stats.lines, stats.rotations
    );
    assert_eq!(stats.dropped, 0);
    assert!(fix_ticks >= 500, "{fix_ticks} periods on fixes");
    assert!(engaged > ticks / 2, "engaged {engaged} of {ticks}");
    // The log was rotated: replay the files oldest first.
    let mut files: Vec<PathBuf> = (1..8)
        .rev()
        .map(|k| dir.path().join(format!("bus.log.{k}")))
        .filter(|p| p.exists())
        .collect();
    assert!(!files.is_empty(), "rotated");
    files.push(path);
    let r = replay(&files, &[]);
    let s = &r["summary"];
    assert_eq!(r["ticks_from"], "log");
    assert_eq!(s["ticks"], ticks, "{r}");
    assert_eq!(s["differing"], 0, "{r}");
    assert_eq!(s["matching"], ticks);
    assert_eq!(s["unreadable_lines"], 0);
    // Faster than real time.
    assert!(r["replay_s"].as_f64().unwrap() < r["log_span_s"].as_f64().unwrap());

    // Another tracker gain: the replay tells the commands apart from the logged ones.
    let other = replay(&files, &["track.ld_min_m=5.5"]);
    println!("REPLAY {r}\nOTHER {other}");
    assert!(
        other["summary"]["differing"].as_u64().unwrap() > 0,
        "{other}"
    );
    // --strict says so in its exit status (src/exit.rs: 9).
    let strict = Command::new(env!("CARGO_BIN_EXE_agsteer"))
        .arg("replay")
        .args(&files)
        .args(["--config", CONFIG, "--json", "--strict"])
        .args(["--set", "track.ld_min_m=5.5"])
        .output()
        .unwrap();
    assert_eq!(
        strict.status.code(),
        Some(i32::from(agsteer::exit::Exit::ReplayDiffers.code()))
    );
}
