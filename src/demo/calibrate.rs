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
use crate::geo::Pose;
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
    let limit = session.steering_duration() + 2.0 * params.wait_timeout + 120.0;
    let mut phase = "";
    let mut changed = false;
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
            Instruction::Drive(v) => {
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
    }
}
