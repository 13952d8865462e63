//! The simulator's steer-ready tractor: a steering ECU that speaks ISO 11783 only, as a stock
//! ISOBUS tractor with guidance readiness does. It claims its address (ISO 11783-5, NAME
//! function 16 "steering control"), takes the Guidance System Command (0xAD00) addressed to it,
//! and sends Guidance Machine Info (0xAC00) every 100 ms with its estimated curvature (from its
//! own wheel-angle sensor), readiness, mechanical lockout, request reset and exit reason
//! (ISO 11783-7, the fields as AgIsoStack++'s guidance interface reads them). No proprietary
//! wheel-angle frame goes out.
//!
//! It steers to the commanded curvature only while the command says "intended to steer", it is
//! ready and not locked out, and no reset is pending. It leaves automatic steering on an
//! operator override (exit reason 3) or when commands stop for 250 ms (exit reason 5, remote
//! command timeout) and then requests a reset: it steers again only after a command "not
//! intended to steer" has acknowledged it.

use crate::can::address_claim::{AddressClaimer, ClaimParams};
use crate::can::codec::{
    self, GuidanceMachineInfo, GuidanceMachineInfoMechanicalLockout,
    GuidanceMachineInfoRequestResetCommandStatus, GuidanceMachineInfoSteeringInputPositionStatus,
    GuidanceMachineInfoSteeringReadiness, GuidanceSystemCommand,
    GuidanceSystemCommandCommandStatus, Packer,
};
use crate::can::isobus::{destination_of, Name, NameFields, GLOBAL_ADDRESS};
use crate::can::Frame;

/// ISO 11783-7's guidance message period, s.
const INFO_PERIOD: f64 = 0.1;
/// Commands older than this end automatic steering, s (the default of `sim.command_timeout_s`).
const COMMAND_TIMEOUT: f64 = 0.25;
/// ISO 11783-7 exit reason codes (AgIsoStack++'s `GuidanceSystemCommandExitReasonCode`).
const EXIT_OPERATOR_OVERRIDE: u8 = 3;
const EXIT_REMOTE_COMMAND_TIMEOUT: u8 = 5;

/// The steering ECU's NAME: steering control (function 16) of an agricultural tractor.
pub fn steering_ecu_name() -> Name {
    Name::new(&NameFields {
        self_configurable: false,
        industry_group: 2,
        device_class_instance: 0,
        device_class: 1,
        function: 16,
        function_instance: 0,
        ecu_instance: 0,
        manufacturer_code: 0,
        identity_number: 16,
    })
}

/// What the steering ECU decided on a frame or a period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Steer {
    /// Steer the wheels to this angle, rad.
    To(f64),
    /// Leave the wheels to the driver.
    Hold,
    /// The commands stopped: the driver takes the wheel, centres it and keeps straight.
    Centre,
}

/// The steer-ready tractor's steering ECU.
#[derive(Debug, Clone)]
pub struct SteerReadyEcu {
    claimer: AddressClaimer,
    packer: Packer,
    wheelbase: f64,
    engaged: bool,
    reset_required: bool,
    exit_reason: u8,
    last_command: Option<f64>,
    next_info: f64,
    /// The ECU's wheel-angle sensor, rad.
    measured: f64,
    /// Commands refused (not ready, locked out or a reset pending).
    refused: u64,
    /// Commands older than this end automatic steering, s (infinite: never).
    command_timeout: f64,
}

impl SteerReadyEcu {
    /// An ECU at `address` on a tractor of `wheelbase` (m).
    pub fn new(address: u8, wheelbase: f64) -> Self {
        SteerReadyEcu {
            claimer: AddressClaimer::new(ClaimParams {
                name: steering_ecu_name(),
                preferred: address,
                range: (address, address),
            }),
            packer: Packer::new(address),
            wheelbase,
            engaged: false,
            reset_required: false,
            exit_reason: 0,
            last_command: None,
            next_info: 0.0,
            measured: 0.0,
            refused: 0,
            command_timeout: COMMAND_TIMEOUT,
        }
    }

    /// End automatic steering when commands stop for `timeout` s (`None`: never).
    pub fn with_command_timeout(mut self, timeout: Option<f64>) -> Self {
        self.command_timeout = timeout.unwrap_or(f64::INFINITY);
        self
    }

    /// Steering by the guidance system's commands.
    pub fn engaged(&self) -> bool {
        self.engaged
    }
    /// Commands "intended to steer" refused so far.
    pub fn refused(&self) -> u64 {
        self.refused
    }
    /// A reset is requested of the guidance system.
    pub fn reset_required(&self) -> bool {
        self.reset_required
    }
    /// The ECU's wheel-angle sensor read `angle` (rad).
    pub fn on_wheel_angle(&mut self, angle: f64) {
        self.measured = angle;
    }

    fn leave(&mut self, reason: u8) {
        if self.engaged {
            self.engaged = false;
            self.reset_required = true;
            self.exit_reason = reason;
        }
    }

    /// A received frame at `t` with the steering's `lockout` switch and the operator's
    /// `override`: what the wheels should do, when the frame decides it.
    pub fn on_frame(&mut self, t: f64, f: &Frame, lockout: bool, operator: bool) -> Option<Steer> {
        self.claimer.on_frame(t, f);
        let address = self.claimer.address(t)?;
        if destination_of(f.id).is_some_and(|d| d != address && d != GLOBAL_ADDRESS) {
            return None;
        }
        let cmd = codec::decode(f.id, f.payload())
            .ok()?
            .to::<GuidanceSystemCommand>()?;
        self.last_command = Some(t);
        let intended =
            cmd.command_status == Some(GuidanceSystemCommandCommandStatus::IntendedToSteer);
        if operator {
            self.leave(EXIT_OPERATOR_OVERRIDE);
        }
        if !intended {
            // "Not intended to steer" acknowledges a requested reset.
            self.engaged = false;
            self.reset_required = false;
            return Some(Steer::Hold);
        }
        match cmd.curvature {
            Some(k) if !lockout && !self.reset_required && !operator => {
                if !self.engaged {
                    self.exit_reason = 0;
                }
                self.engaged = true;
                // ISO 11783-7: km⁻¹, positive = right turn; the wheel angle is positive left.
                Some(Steer::To((-k * 1e-3 * self.wheelbase).atan()))
            }
            _ => {
                self.refused += 1;
                self.engaged = false;
                Some(Steer::Hold)
            }
        }
    }

    /// Advance to `t`: the address claim, the command timeout and the Machine Info due by
    /// now go into `out` (stamped `t`); returns `Hold` when steering just ended.
    pub fn advance(
        &mut self,
        t: f64,
        lockout: bool,
        operator: bool,
        out: &mut Vec<(f64, Frame)>,
    ) -> Option<Steer> {
        let mut claim = Vec::new();
        self.claimer.tick(t, &mut claim);
        out.extend(claim.into_iter().map(|f| (t, f)));
        let was = self.engaged;
        if operator {
            self.leave(EXIT_OPERATOR_OVERRIDE);
        }
        if lockout {
            self.engaged = false;
        }
        let timed_out = self
            .last_command
            .is_none_or(|l| t - l > self.command_timeout);
        if timed_out {
            self.leave(EXIT_REMOTE_COMMAND_TIMEOUT);
        }
        let ended = if timed_out {
            Steer::Centre
        } else {
            Steer::Hold
        };
        let Some(address) = self.claimer.address(t) else {
            self.engaged = false;
            return (was && !self.engaged).then_some(ended);
        };
        self.packer.set_source(address);
        if t + 1e-9 >= self.next_info {
            self.next_info = t + INFO_PERIOD;
            let k = self.measured.tan() / self.wheelbase;
            let info = GuidanceMachineInfo {
                estimated_curvature: Some((-k * 1e3).clamp(-8032.0, 8031.75)),
                mechanical_lockout: Some(if lockout {
                    GuidanceMachineInfoMechanicalLockout::Active
                } else {
                    GuidanceMachineInfoMechanicalLockout::NotActive
                }),
                steering_readiness: Some(if lockout {
                    GuidanceMachineInfoSteeringReadiness::NotReady
                } else {
                    GuidanceMachineInfoSteeringReadiness::Ready
                }),
                steering_input_position_status: Some(
                    GuidanceMachineInfoSteeringInputPositionStatus::InPosition,
                ),
                request_reset_command_status: Some(if self.reset_required {
                    GuidanceMachineInfoRequestResetCommandStatus::ResetRequired
                } else {
                    GuidanceMachineInfoRequestResetCommandStatus::ResetNotRequired
                }),
                limit_status: None,
                exit_reason_code: Some(self.exit_reason as f64),
                remote_engage_switch_status: None,
            };
            if let Ok(f) = self.packer.pack(&info) {
                out.push((t, f));
            }
        }
        (was && !self.engaged).then_some(ended)
    }
}
