//! The supervisor's fault codes: why it will not steer, as the guidance status frame and the
//! operator's replies carry them.

use serde::Serialize;

/// Why the supervisor will not steer. The numeric value goes on the bus.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
#[repr(u8)]
pub enum FaultCode {
    None = 0,
    GnssTimeout = 1,
    FixQuality = 2,
    WheelAngleTimeout = 3,
    WheelAngleInvalid = 4,
    SpeedOutOfRange = 5,
    OperatorOverride = 6,
    XteTooLarge = 7,
    HeadingErrorTooLarge = 8,
    NoGuidance = 9,
    BusDown = 10,
    OperatorInvalid = 11,
    ActuatorFault = 12,
    /// The rate limit cannot bring the angle within the lateral-acceleration limit (the speed
    /// rose too fast): steering is given back rather than break either limit.
    LateralAccelLimit = 13,
    /// No ISO 11783-5 source address: not claimed yet, lost to a device with a lower NAME, or
    /// none free (Cannot Claim). Nothing but address claims is sent meanwhile.
    AddressLost = 14,
    /// The steering ECU reports it is not ready for guidance (Guidance Machine Info readiness).
    SteeringNotReady = 15,
    /// The steering ECU reports its mechanical system lockout active (ISO 11783-7).
    SteeringLockout = 16,
    /// The steering ECU requests a reset of the command status (ISO 11783-7 request reset):
    /// the command goes to "not intended to steer" until the request clears and the operator
    /// engages again.
    SteeringResetRequested = 17,
    /// A sustained oscillation of the cross-track error or the wheel angle on a work line (a
    /// limit cycle): steering is given back rather than weave.
    TrackingUnstable = 18,
    /// |XTE| beyond `safety.off_line_m` for `safety.off_line_time_s` on a work line.
    OffLine = 19,
    /// The line's sharpest curve cannot be followed at this speed with these limits and this
    /// steering rate: engage refused, or, engaged, steering given back (a line that starts while
    /// engaged, or a speed-up on it).
    LineUnfollowable = 20,
    /// Moving above `safety.heading_mismatch_min_speed_kmh`, the GNSS heading's course over
    /// ground (crab in turns and reversing allowed for) is more than
    /// `safety.heading_mismatch_deg` off for `safety.heading_mismatch_time_s`: the heading is
    /// wrong, and every steering decision with it ([`super::heading`]).
    HeadingMismatch = 21,
    /// An engage beyond the engage gate found no approach path to the line (every one would
    /// leave the field or cross an obstacle): refused. Never a fault of the running system;
    /// only an engage's refusal reason (OperatorReply, `engage_refusal` in the status).
    NoApproachPath = 22,
    /// Farther than `safety.off_path_m` from a turn's, transit's, approach's or reversing
    /// path for `safety.off_line_time_s` ([`super::tracking`]).
    OffPath = 23,
    /// The job's next segment does not start where the last one ended: the plan has a gap
    /// there (the planner found no clear transit and said "drive there by hand"). The steering
    /// is given back at the gap and held until the operator acknowledges; engaged again at the
    /// segment, the engage gate (or an approach path) takes the tractor onto it.
    PathGap = 24,
}

impl FaultCode {
    /// Every code, in bus order.
    pub const ALL: [FaultCode; 25] = [
        FaultCode::None,
        FaultCode::GnssTimeout,
        FaultCode::FixQuality,
        FaultCode::WheelAngleTimeout,
        FaultCode::WheelAngleInvalid,
        FaultCode::SpeedOutOfRange,
        FaultCode::OperatorOverride,
        FaultCode::XteTooLarge,
        FaultCode::HeadingErrorTooLarge,
        FaultCode::NoGuidance,
        FaultCode::BusDown,
        FaultCode::OperatorInvalid,
        FaultCode::ActuatorFault,
        FaultCode::LateralAccelLimit,
        FaultCode::AddressLost,
        FaultCode::SteeringNotReady,
        FaultCode::SteeringLockout,
        FaultCode::SteeringResetRequested,
        FaultCode::TrackingUnstable,
        FaultCode::OffLine,
        FaultCode::LineUnfollowable,
        FaultCode::HeadingMismatch,
        FaultCode::NoApproachPath,
        FaultCode::OffPath,
        FaultCode::PathGap,
    ];
}
