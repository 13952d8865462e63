//! `agsteer sim`: the vehicle simulator on a CAN interface, in real time.

use crate::sim_gnss::GnssOut;
pub use crate::sim_gnss::SimGnssArgs;
use agsteer::can::bus::{monotonic_s, CanBus, SocketCanBus};
use agsteer::can::Frame;
use agsteer::config::{Config, JobKind};
use agsteer::geo::wgs84::EnuFrame;
use agsteer::geo::{left_normal, Pose};
use agsteer::job::JobDetail;
use agsteer::sim::can_node::{Scenario, SimAddresses, SimNode};
use agsteer::sim::Simulator;
use anyhow::{Context, Result};
use std::io::Write;
use std::path::Path;
use std::time::Duration;

/// Trajectory samples are written this often, s.
const TRAJECTORY_PERIOD_S: f64 = 0.05;

pub fn run(
    iface: &str,
    cfg: &Config,
    scenario: Option<&Path>,
    trajectory: Option<&Path>,
    duration_s: Option<f64>,
    realtime_priority: u8,
    gnss: &SimGnssArgs,
) -> Result<u8> {
    // The simulator stands in for sensors that are separate devices on a real bus.
    agsteer::daemon::run::set_realtime_priority(realtime_priority);
    let scenario: Scenario = match scenario {
        Some(p) => {
            let text = agsteer::envelope::read_text(p, agsteer::envelope::FileKind::Config)?;
            toml::from_str(&text).with_context(|| format!("scenario {}", p.display()))?
        }
        None => Scenario::default(),
    };
    // The job set up as agsteerd sets it up: a field or manoeuvre job starts on its first
    // segment, in the plan's frame; AB lines and arcs on line A→B.
    let resolved = cfg.resolve()?;
    let job = agsteer::job::prepare(&resolved.planning)
        .with_context(|| format!("job.kind = \"{}\"", job_kind_name(cfg.job.kind)))?;
    let segment_job = match &job.detail {
        JobDetail::Field(fj) => Some(&fj.job),
        JobDetail::Maneuver(mj, _) => Some(&mj.job),
        JobDetail::Lines => None,
    };
    let first = segment_job.and_then(|j| j.segments().first());
    let ab = &resolved.planning.ab;
    let (a, b) = match first.map(|s| s.points.as_slice()) {
        Some([a, b, ..]) => (*a, *b),
        _ => (ab.point_a, ab.point_b),
    };
    let setup = &resolved.sim;
    let dir = (b - a).normalize();
    let p = a + left_normal(&dir) * setup.start_offset;
    let start = Pose::new(p.x, p.y, dir.y.atan2(dir.x) + setup.start_heading);
    let enu = EnuFrame::new(job.origin.unwrap_or(resolved.planning.origin));
    let mut node = SimNode::new(
        Simulator::new(setup.params.clone(), start, setup.speed),
        enu,
        SimAddresses::default(),
        scenario,
    )
    .with_speed_profile(setup.speed_profile)
    .with_command_timeout(setup.command_timeout);
    // With the ISO curvature output the tractor is a steer-ready one (ISO 11783-7 only).
    if cfg.bus.output == agsteer::config::OutputKind::Curvature {
        node = node.with_steer_ready();
    }
    let gnss_sink = gnss.sink()?;
    if gnss_sink.is_some() {
        node = node.with_gnss_off_bus();
    }
    let mut bus =
        SocketCanBus::open(iface, &[]).with_context(|| format!("opening CAN interface {iface}"))?;
    let mut traj = match trajectory {
        Some(p) => {
            let mut f = std::io::BufWriter::new(
                std::fs::File::create(p).with_context(|| format!("creating {}", p.display()))?,
            );
            writeln!(
                f,
                "t_s,x_m,y_m,heading_rad,speed_m_s,wheel_angle_rad,engaged"
            )?;
            Some(f)
        }
        None => None,
    };
    let t0 = monotonic_s();
    let mut gnss_out = match gnss_sink {
        Some(sink) => Some(GnssOut::new(
            sink,
            gnss.messages.clone(),
            enu,
            t0,
            gnss.log.as_deref(),
        )?),
        None => None,
    };
    let mut frames: Vec<(f64, Frame)> = Vec::with_capacity(64);
    let mut next_traj = 0.0;
    let mut send_errors = 0u64;
    tracing::info!(interface = iface, "simulator running");
    loop {
        let t = monotonic_s() - t0;
        if duration_s.is_some_and(|d| t >= d) {
            break;
        }
        frames.clear();
        node.advance_to(t, &mut frames);
        for (_, f) in &frames {
            if bus.send(f).is_err() {
                send_errors += 1;
            }
        }
        if let Some(g) = gnss_out.as_mut() {
            g.pump(&mut node)?;
        }
        loop {
            match bus.try_recv() {
                Ok(Some(tf)) => node.on_frame(&tf),
                Ok(None) => break,
                Err(_) => {
                    std::thread::sleep(Duration::from_millis(10));
                    break;
                }
            }
        }
        if let Some(f) = traj.as_mut() {
            if t >= next_traj {
                let s = node.sim().true_state();
                writeln!(
                    f,
                    "{:.3},{:.4},{:.4},{:.6},{:.3},{:.5},{}",
                    t,
                    s.pose.pos.x,
                    s.pose.pos.y,
                    s.pose.heading,
                    s.speed,
                    s.wheel_angle,
                    node.engaged() as u8
                )?;
                f.flush()?;
                next_traj = t + TRAJECTORY_PERIOD_S;
            }
        }
        // The fastest output is the 100 Hz wheel angle; 2 ms keeps its jitter small.
        std::thread::sleep(Duration::from_millis(2));
    }
    tracing::info!(
        rejected_commands = node.rejected(),
        send_errors,
        gnss_epochs = gnss_out.as_ref().map_or(0, |g| g.epochs),
        gnss_epochs_unsent = gnss_out.as_ref().map_or(0, |g| g.unsent),
        "simulator stopped"
    );
    Ok(0)
}

/// The configuration name of a job kind.
fn job_kind_name(kind: JobKind) -> &'static str {
    match kind {
        JobKind::Ab => "ab",
        JobKind::Field => "field",
        JobKind::Arcs => "arcs",
        JobKind::Maneuver => "maneuver",
    }
}
