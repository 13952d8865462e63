//! The node's ISOBUS side: its address claim (ISO 11783-5) and the steer-ready loop with a
//! steering ECU (ISO 11783-7 Guidance System Command out, Guidance Machine Info in).
//!
//! With the curvature output, Guidance Machine Info (0xAC00) from the steering ECU is the
//! steering feedback (its estimated curvature replaces the wheel-angle frame) and the gate:
//! nothing is commanded unless the ECU reports itself ready with its mechanical lockout
//! inactive, and a request reset sets the command status to "not intended to steer" until the
//! request clears and the operator engages again (ISO 11783-7, as AgIsoStack++'s
//! `AgriculturalGuidanceInterface` reads these fields). The Guidance System Command goes every
//! 100 ms (ISO 11783-7's repetition rate, AgIsoStack++'s `GUIDANCE_MESSAGE_TX_INTERVAL_MS`) and
//! at once when its status changes, to the steering ECU's address.

use crate::can::address_claim::{AddressClaimer, ClaimParams, ClaimStatus};
use crate::can::isobus::GLOBAL_ADDRESS;
use crate::can::Frame;
use crate::input::{MachineInfoInput, SourceId};
use crate::safety::FaultCode;
use serde::Serialize;

/// ISO 11783-7's repetition rate of the guidance messages, s.
pub const GUIDANCE_MESSAGE_PERIOD: f64 = 0.1;

/// The node's ISOBUS parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IsoParams {
    /// The address claim, `None` to send from the preferred address without claiming.
    pub claim: Option<ClaimParams>,
    /// The address sent from when not claiming.
    pub source_address: u8,
    /// The steering ECU's address, or 255 to find it by `steering_function`.
    pub steering_address: u8,
    pub steering_function: u8,
    /// Guidance Machine Info is the steering feedback and gate (the curvature output).
    pub steer_ready_loop: bool,
}

/// What the status reports of the ISOBUS side.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct IsoStatus {
    /// The address claim (`claimed` with the address when claiming is off).
    pub address_claim: ClaimStatus,
    /// Times the address was lost to a device with a lower NAME.
    pub address_losses: u64,
    /// The steering ECU commanded (its address), when known.
    pub steering_ecu: Option<u8>,
    /// Its last Guidance Machine Info: ready, lockout, request reset, exit reason code.
    pub steering_ready: Option<bool>,
    pub steering_lockout: Option<bool>,
    pub steering_reset_requested: Option<bool>,
    pub steering_exit_reason: Option<u8>,
}

/// The node's address claim and steering ECU link.
#[derive(Debug, Clone)]
pub struct IsoLink {
    params: IsoParams,
    /// The claim state machine; with claiming off it only keeps the table of NAMEs seen.
    claimer: AddressClaimer,
    info: Option<MachineInfoInput>,
    logged_exit: Option<u8>,
}

impl IsoLink {
    pub fn new(params: IsoParams) -> Self {
        let claim = params.claim.unwrap_or(ClaimParams {
            name: crate::can::isobus::Name(u64::MAX),
            preferred: params.source_address,
            range: (params.source_address, params.source_address),
        });
        IsoLink {
            params,
            claimer: AddressClaimer::new(claim),
            info: None,
            logged_exit: None,
        }
    }

    pub fn params(&self) -> &IsoParams {
        &self.params
    }

    /// A received frame (Requests and Address Claimed are the claimer's).
    pub fn on_frame(&mut self, t: f64, f: &Frame) {
        self.claimer.on_frame(t, f);
    }

    /// The link came up again (or the bus recovered from bus-off): claim again.
    pub fn restart(&mut self) {
        if self.params.claim.is_some() {
            self.claimer.restart();
        }
    }

    /// Start of a control period: the claim's frames go into `out`; returns the address the
    /// period's application frames may be sent from (`None`: send none).
    pub fn begin_tick(&mut self, t: f64, out: &mut Vec<Frame>) -> Option<u8> {
        if self.params.claim.is_none() {
            return Some(self.params.source_address);
        }
        self.claimer.tick(t, out);
        self.claimer.address(t)
    }

    /// Where the Guidance System Command goes: the configured address, or the device that
    /// claimed an address with the steering function.
    pub fn steering_destination(&self) -> Option<u8> {
        if self.params.steering_address != GLOBAL_ADDRESS {
            return Some(self.params.steering_address);
        }
        self.claimer.find_function(self.params.steering_function)
    }

    /// A Guidance Machine Info: kept when it comes from the steering ECU; returns whether it
    /// did (then its curvature is the steering feedback).
    pub fn on_machine_info(&mut self, m: &MachineInfoInput) -> bool {
        let from_ecu =
            matches!(m.source, SourceId::Can(a) if Some(a) == self.steering_destination());
        if !from_ecu {
            return false;
        }
        if m.exit_reason != self.logged_exit {
            if let Some(code) = m.exit_reason.filter(|&c| c != 0) {
                tracing::warn!(code, "steering ECU: guidance command exit reason");
            }
            self.logged_exit = m.exit_reason;
        }
        self.info = Some(*m);
        true
    }

    /// What forbids steering at `t`, or `FaultCode::None`: no address, and with the
    /// steer-ready loop the steering ECU's gate (unknown, not ready, locked out, asking for a
    /// reset). A stale Machine Info is the supervisor's wheel-angle timeout.
    pub fn interlock(&self, t: f64) -> FaultCode {
        if self.params.claim.is_some() && self.claimer.address(t).is_none() {
            return FaultCode::AddressLost;
        }
        if !self.params.steer_ready_loop {
            return FaultCode::None;
        }
        let Some(m) = self.info.filter(|_| self.steering_destination().is_some()) else {
            return FaultCode::SteeringNotReady;
        };
        if m.lockout != Some(false) {
            FaultCode::SteeringLockout
        } else if m.reset_requested == Some(true) {
            FaultCode::SteeringResetRequested
        } else if m.ready != Some(true) {
            FaultCode::SteeringNotReady
        } else {
            FaultCode::None
        }
    }

    pub fn status(&self) -> IsoStatus {
        IsoStatus {
            address_claim: match self.params.claim {
                Some(_) => self.claimer.status(),
                None => ClaimStatus::Claimed(self.params.source_address),
            },
            address_losses: self.claimer.losses(),
            steering_ecu: self.steering_destination(),
            steering_ready: self.info.and_then(|m| m.ready),
            steering_lockout: self.info.and_then(|m| m.lockout),
            steering_reset_requested: self.info.and_then(|m| m.reset_requested),
            steering_exit_reason: self.info.and_then(|m| m.exit_reason),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::can::isobus::{address_claimed, Name, NameFields};

    fn params(claim: bool, loop_: bool) -> IsoParams {
        IsoParams {
            claim: claim.then(|| ClaimParams {
                name: Name::new(&NameFields::GUIDANCE_CONTROLLER),
                preferred: 0x2A,
                range: (128, 235),
            }),
            source_address: 0x2A,
            steering_address: GLOBAL_ADDRESS,
            steering_function: 16,
            steer_ready_loop: loop_,
        }
    }

    fn info(t: f64, source: u8, ready: bool, lockout: bool, reset: bool) -> MachineInfoInput {
        MachineInfoInput {
            t,
            source: SourceId::Can(source),
            curvature: Some(0.0),
            ready: Some(ready),
            lockout: Some(lockout),
            reset_requested: Some(reset),
            exit_reason: Some(0),
        }
    }

    #[test]
    fn the_gate_follows_the_steering_ecu_found_by_its_function() {
        let mut l = IsoLink::new(params(false, true));
        assert_eq!(l.begin_tick(0.0, &mut Vec::new()), Some(0x2A));
        assert_eq!(l.interlock(0.0), FaultCode::SteeringNotReady, "no ECU yet");
        // Machine info from an unknown device is not taken.
        assert!(!l.on_machine_info(&info(0.1, 0x1C, true, false, false)));
        let steering = Name::new(&NameFields {
            function: 16,
            ..Name(0).fields()
        });
        l.on_frame(0.2, &address_claimed(steering, 0x1C));
        assert_eq!(l.steering_destination(), Some(0x1C));
        assert!(l.on_machine_info(&info(0.3, 0x1C, true, false, false)));
        assert_eq!(l.interlock(0.3), FaultCode::None);
        l.on_machine_info(&info(0.4, 0x1C, true, true, false));
        assert_eq!(l.interlock(0.4), FaultCode::SteeringLockout);
        l.on_machine_info(&info(0.5, 0x1C, true, false, true));
        assert_eq!(l.interlock(0.5), FaultCode::SteeringResetRequested);
        l.on_machine_info(&info(0.6, 0x1C, false, false, false));
        assert_eq!(l.interlock(0.6), FaultCode::SteeringNotReady);
        let s = l.status();
        assert_eq!(
            (s.steering_ecu, s.steering_ready),
            (Some(0x1C), Some(false))
        );
        // Without the steer-ready loop the ECU does not gate.
        let l = IsoLink::new(params(false, false));
        assert_eq!(l.interlock(0.0), FaultCode::None);
    }

    #[test]
    fn no_application_frames_until_the_address_is_claimed() {
        let mut l = IsoLink::new(params(true, false));
        let mut out = Vec::new();
        let mut t = 0.0;
        let mut first = None;
        while t < 1.0 {
            if l.begin_tick(t, &mut out).is_some() && first.is_none() {
                first = Some(t);
            }
            assert_eq!(
                l.interlock(t) == FaultCode::AddressLost,
                first.is_none(),
                "{t}"
            );
            t += 0.02;
        }
        // The request, then the claim; application frames 250 ms after the claim.
        assert_eq!(out.len(), 2);
        assert!(
            first.is_some_and(|f| (0.5 - 1e-9..0.5 + 0.153 + 0.05).contains(&f)),
            "{first:?}"
        );
        assert_eq!(l.status().address_claim, ClaimStatus::Claimed(0x2A));
    }
}
