//! `agsteer calibrate` against the simulator: the calibration procedure
//! ([`crate::calibrate::Session`]) and the simulated tractor talking only through frames on the
//! in-memory bus, the simulated operator obeying the procedure's instructions (or not: the
//! refusal tests make him drive on, take the wheel or change the steering half-way).

use crate::calibrate::{Calibration, CalibrationError, CalibrationParams, Instruction, Session};
use crate::can::bus::{CanBus, MemBus};
use crate::can::codec::{Packer, SteeringCommand, SteeringCommandMode};
use crate::can::Frame;
use crate::config::Config;
use crate::geo::wgs84::EnuFrame;
use crate::geo::{heading_vec, left_normal, Pose, Vec2};
use crate::input::can::CanAdapter;
use crate::sim::can_node::{Scenario, SimAddresses, SimNode};
use crate::sim::{SimParams, Simulator};

/// How the simulated operator behaves.
#[derive(Debug, Clone, Default)]
pub struct Operator {
    /// Keeps driving at this speed (m/s) instead of stopping for the steering tests.
    pub ignores_stop: Option<f64>,
    /// Drives at this speed (m/s) on the drive instead of the speed asked.
    pub drive_speed: Option<f64>,
    /// Scripted faults (an operator override is the operator taking the wheel).
    pub scenario: Scenario,
    /// At this simulated time the steering's lag becomes this (s): a steering that changes
    /// during the tests.
    pub change_tau: Option<(f64, f64)>,
}

/// The simulated operator on the two-way pass: steers the true vehicle by hand (the steering
/// actuator, as a driver at the wheel does) along a straight ground line through where the
/// rear axle is when first asked, the way it faces; asked to turn, goes on a few metres, turns
/// round by a bulb turn (60° right, 300° left, 60° right at a radius of 6 m, which ends on the
/// same line, facing back) and drives back along the line: the rear axle runs along the same
/// ground line both ways, as the wheels in the same tracks do. Pure pursuit on the true
/// pose, look-ahead 4 m.
#[derive(Debug, Clone, Default)]
pub struct LineDriver {
    /// The path ahead, points 0.1 m apart, and the nearest point's index.
    path: Vec<Vec2>,
    near: usize,
    turning: bool,
}

const PATH_STEP: f64 = 0.1;
/// The turn starts this far past where the operator was asked to turn, m: the way back then
/// has as far to settle on the line before the stretch both passes cover.
const RUN_ON: f64 = 20.0;
/// Pure pursuit's look-ahead, m.
const LOOK_AHEAD: f64 = 4.0;

impl LineDriver {
    /// Steer along the line (first call: the line starts here).
    pub fn steer_line(&mut self, sim: &mut Simulator) {
        if self.path.is_empty() {
            let pose = sim.true_state().pose;
            let u = heading_vec(pose.heading);
            self.path = (0..5000)
                .map(|i| pose.pos + u * (i as f64 * PATH_STEP))
                .collect();
            self.near = 0;
        }
        self.follow(sim);
    }

    /// Turn round onto the same line, then follow it back (first call: the turn starts 20 m
    /// further along the line).
    pub fn steer_turn(&mut self, sim: &mut Simulator) {
        if !self.turning && self.path.len() > 1 {
            self.turning = true;
            let u = (self.path[1] - self.path[0]).normalize();
            let here = (sim.true_state().pose.pos - self.path[0]).dot(&u);
            let mut p = self.path[0] + u * (here + RUN_ON);
            let mut heading = u.y.atan2(u.x);
            let mut path: Vec<Vec2> = (0..(RUN_ON / PATH_STEP) as usize)
                .map(|i| self.path[0] + u * (here + i as f64 * PATH_STEP))
                .collect();
            let r = 6.0;
            let end = p;
            // The bulb turn (turn angle, rad): each arc in whole steps of its exact angle.
            for turn in [-60f64, 300.0, -60.0].map(f64::to_radians) {
                let n = (r * turn.abs() / PATH_STEP).round().max(1.0);
                let (dh, ds) = (turn / n, r * turn.abs() / n);
                for _ in 0..n as usize {
                    path.push(p);
                    heading += dh;
                    p += heading_vec(heading - 0.5 * dh) * ds;
                }
            }
            // The line back: exactly the out line, facing the other way.
            path.extend((0..5000).map(|i| end - u * (i as f64 * PATH_STEP)));
            self.path = path;
            self.near = 0;
        }
        self.follow(sim);
    }

    /// Pure pursuit on the path from the true pose.
    fn follow(&mut self, sim: &mut Simulator) {
        let pose = sim.true_state().pose;
        let end = (self.near + 200).min(self.path.len());
        if let Some((i, _)) = self.path[self.near..end]
            .iter()
            .enumerate()
            .map(|(i, q)| (i, (q - pose.pos).norm()))
            .min_by(|a, b| a.1.total_cmp(&b.1))
        {
            self.near += i;
        }
        let Some(target) = self
            .path
            .get((self.near + (LOOK_AHEAD / PATH_STEP) as usize).min(self.path.len() - 1))
        else {
            return;
        };
        let d = target - pose.pos;
        let h = heading_vec(pose.heading);
        let ld = d.norm().max(0.5);
        let lateral = d.dot(&left_normal(&h));
        let p = sim.params();
        let delta = (2.0 * lateral / (ld * ld) * p.wheelbase)
            .atan()
            .clamp(-p.max_wheel_angle, p.max_wheel_angle);
        let sensed = p.was_gain * delta + p.dist.was_bias;
        sim.set_command(sensed);
    }
}

/// The procedure's parameters from the configuration ([`Config::calibration_params`]).
pub fn params_for(cfg: &Config) -> CalibrationParams {
    cfg.calibration_params()
}

/// Progress: (simulated time s, phase), called when the phase changes.
pub type Progress<'a> = &'a mut dyn FnMut(f64, &str);

/// Run the procedure on the simulated tractor `sim_params` (started at rest, the operator
/// driving as `operator` says) with control period `dt`; the fitted calibration or why it
/// was refused.
pub fn run(
    params: CalibrationParams,
    sim_params: SimParams,
    dt: f64,
    operator: &Operator,
    progress: Progress,
) -> Result<Calibration, CalibrationError> {
    let start_speed = operator.ignores_stop.unwrap_or(0.0);
    let origin = crate::geo::wgs84::LatLon {
        lat_deg: 52.0,
        lon_deg: 5.0,
    };
    let enu = EnuFrame::new(origin);
    let mut sim = SimNode::new(
        Simulator::new(sim_params, Pose::new(0.0, 0.0, 0.0), start_speed),
        enu,
        SimAddresses::default(),
        operator.scenario.clone(),
    );
    let mut session = Session::new(params);
    let mut bus_tool = MemBus::new();
    let mut bus_sim = bus_tool.node();
    let mut packer = Packer::new(0x2A);
    let mut adapter = CanAdapter::default();
    let mut frames: Vec<(f64, Frame)> = Vec::with_capacity(64);
    // The waits for the operator (stop, drive, the turn of the two-way pass: 4 waits) on top.
    let limit = session.nominal_duration() + 6.0 * params.wait_timeout + 120.0;
    let mut phase = "";
    let mut changed = false;
    let mut driver = LineDriver::default();
    let mut k: u64 = 0;
    loop {
        let t = k as f64 * dt;
        k += 1;
        if t > limit {
            return Err(CalibrationError::NoData(format!(
                "the procedure did not finish within {limit:.0} s"
            )));
        }
        if let Some((at, tau)) = operator.change_tau {
            if !changed && t >= at {
                sim.sim_mut().set_actuator_tau(tau);
                changed = true;
            }
        }
        frames.clear();
        sim.advance_to(t, &mut frames);
        for (ts, f) in &frames {
            bus_sim.set_time(*ts);
            let _ = bus_sim.send(f);
        }
        while let Ok(Some(tf)) = bus_tool.try_recv() {
            for input in adapter.on_frame(&tf) {
                session.on_input(&input)?;
            }
        }
        let tick = session.tick(t)?;
        if tick.phase != phase {
            phase = tick.phase;
            progress(t, phase);
        }
        // The operator.
        match tick.instruction {
            Instruction::Stop => {
                sim.sim_mut()
                    .set_speed_target(operator.ignores_stop.unwrap_or(0.0));
            }
            Instruction::Drive(v) | Instruction::Line(v) | Instruction::TurnBack(v) => {
                sim.sim_mut()
                    .set_speed_target(operator.drive_speed.unwrap_or(v));
            }
            Instruction::Finished => {
                sim.sim_mut().set_speed_target(0.0);
                return session.finish();
            }
        }
        let msg = SteeringCommand {
            angle: Some(tick.command.unwrap_or(0.0).to_degrees()),
            mode: Some(if tick.command.is_some() {
                SteeringCommandMode::Engaged
            } else {
                SteeringCommandMode::Disengaged
            }),
        };
        if let Ok(f) = packer.pack(&msg) {
            bus_tool.set_time(t);
            let _ = bus_tool.send(&f);
        }
        while let Ok(Some(tf)) = bus_sim.try_recv() {
            sim.on_frame(&tf);
        }
        // On the two-way pass the operator steers (the tool sends no steering).
        match tick.instruction {
            Instruction::Line(_) => driver.steer_line(sim.sim_mut()),
            Instruction::TurnBack(_) => driver.steer_turn(sim.sim_mut()),
            _ => {}
        }
    }
}
