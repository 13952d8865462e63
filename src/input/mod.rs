//! The input seam: everything the controller learns from the outside world arrives as an
//! [`Input`], whatever carried it (NMEA 2000 / ISOBUS frames on CAN, NMEA 0183 or UBX over a
//! serial port, USB, UDP or TCP).
//!
//! Contract:
//! - Adapters (the CAN frame decoder, the serial GNSS parsers) turn bytes into `Input`s and
//!   nothing else: no estimation, no unit conversion beyond the edge (degrees → radians,
//!   clockwise-from-North → counter-clockwise-from-East happen here, once), no state about the
//!   job.
//! - Every `Input` carries its arrival time `t` on the controller's monotonic clock (s) and the
//!   [`SourceId`] it came from, so one source per input kind can be selected downstream.
//! - Values the sender marked not available are `None`, never a number.
//! - The controller consumes `Input`s only; adding a GNSS transport never touches it.
//!
//! Edge conventions (see `docs/CONVENTIONS.md`): positions are WGS-84 degrees (converted to the
//! local ENU frame by the consumer, which owns the job's origin); angles are radians; headings
//! and courses are yaw, counter-clockwise from East, in (-π, π]; speeds m/s; positive wheel
//! angle turns left.

pub mod can;
pub mod source;

use serde::Serialize;

pub mod nmea0183;
pub mod ubx;

/// Where an input came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SourceId {
    /// A CAN node by its source address (J1939 / ISO 11783-5).
    Can(u8),
    /// A byte-stream GNSS input (serial, USB, UDP, TCP), numbered in configuration order.
    Stream(u8),
    /// The in-process simulator or a test.
    Local,
}

/// GNSS solution quality, as NMEA 2000 129029's method and NMEA 0183 GGA's quality indicator
/// both express it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FixQuality {
    /// RTK with fixed integer ambiguities: centimetre class.
    RtkFixed,
    /// RTK float: decimetre class.
    RtkFloat,
    /// Any other solution (autonomous, SBAS, DGNSS, PPP, dead reckoning...).
    Other,
    /// No solution.
    None,
}

/// Reference of a heading.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum HeadingReference {
    True,
    /// Magnetic: usable only with the magnetic variation applied.
    Magnetic,
    /// The sender did not say (NMEA 2000: error or not available).
    Unknown,
}

/// A GNSS antenna position.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PositionInput {
    pub t: f64,
    pub source: SourceId,
    pub lat_deg: f64,
    pub lon_deg: f64,
    /// Height above the ellipsoid, m, when sent.
    pub altitude_m: Option<f64>,
    /// Time between the fix's time of validity and its arrival, s, when the sender's time
    /// stamp allows computing it.
    pub latency_s: Option<f64>,
    /// Quality carried with the position itself (NMEA 0183 GGA, UBX NAV-PVT); `None` when
    /// it comes separately (NMEA 2000 129029).
    pub quality: Option<FixQuality>,
}

/// GNSS solution quality and its details (NMEA 2000 129029, GGA, GST, NAV-PVT).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct QualityInput {
    pub t: f64,
    pub source: SourceId,
    pub quality: FixQuality,
    pub satellites: Option<u8>,
    pub hdop: Option<f64>,
    /// Age of the differential (RTK) corrections, s.
    pub correction_age_s: Option<f64>,
    /// 1-σ horizontal position error the receiver reports, m.
    pub horizontal_sigma_m: Option<f64>,
}

/// Course and speed over ground.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CourseSpeedInput {
    pub t: f64,
    pub source: SourceId,
    /// Course over ground as yaw (rad, counter-clockwise from East), when moving.
    pub course: Option<f64>,
    /// Speed over ground, m/s (no sign: GNSS cannot tell reversing).
    pub speed_mps: Option<f64>,
}

/// Vehicle heading (a dual-antenna or moving-base receiver, a compass).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HeadingInput {
    pub t: f64,
    pub source: SourceId,
    /// Yaw, rad, counter-clockwise from East, as sent (not corrected for variation).
    pub heading: f64,
    pub reference: HeadingReference,
    /// Magnetic variation, rad, positive East, when sent.
    pub variation: Option<f64>,
}

/// Attitude from an IMU.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AttitudeInput {
    pub t: f64,
    pub source: SourceId,
    /// Roll, rad, positive when the right side is down.
    pub roll: Option<f64>,
    pub pitch: Option<f64>,
}

/// The steered wheels' angle (a wheel-angle sensor).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WheelAngleInput {
    pub t: f64,
    pub source: SourceId,
    /// Front-wheel angle, rad, positive left.
    pub angle: Option<f64>,
    pub status: SensorStatus,
}

/// What a sensor says of itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SensorStatus {
    Ok,
    /// The sensor reports a fault of its own.
    Fault,
    /// The driver is turning the wheel (the steering gives way to him).
    OperatorOverride,
    /// A status code the sender's definition does not name.
    Unknown,
}

/// Wheel-based speed and driving direction (the tractor's own measurement).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WheelSpeedInput {
    pub t: f64,
    pub source: SourceId,
    /// Speed, m/s, without sign.
    pub speed_mps: Option<f64>,
    /// The direction the tractor says it is driving; `None` when not available or in error.
    pub direction: Option<crate::geo::Direction>,
}

/// The steering ECU's report (ISO 11783-7 Guidance Machine Info, PGN 0xAC00): its steering
/// feedback and its gate for guidance commands. A field not available is `None`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MachineInfoInput {
    pub t: f64,
    pub source: SourceId,
    /// Estimated curvature of the path driven, 1/m, positive left.
    pub curvature: Option<f64>,
    /// The steering system is ready for guidance commands.
    pub ready: Option<bool>,
    /// The mechanical system lockout (the operator's switch) is active.
    pub lockout: Option<bool>,
    /// The steering asks the guidance system to reset its command status to "not intended to
    /// steer".
    pub reset_requested: Option<bool>,
    /// Why the steering cannot accept (or last stopped accepting) commands (0 = all clear).
    pub exit_reason: Option<u8>,
}

/// A command from the operator's terminal.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "command", rename_all = "snake_case")]
pub enum OperatorCommand {
    None,
    Engage,
    Disengage,
    Pause,
    Resume,
    /// Shift the line sideways by this many nudge steps, positive left.
    Nudge {
        steps: i32,
    },
    SetA,
    SetB,
    SelectJob {
        job: u8,
    },
    /// Start the steering calibration (agsteerd's calibration mode).
    Calibrate,
    /// A command code the sender's definition does not name.
    Unknown {
        code: u8,
    },
}

/// An operator command with its arrival.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OperatorInput {
    pub t: f64,
    pub source: SourceId,
    pub command: OperatorCommand,
}

/// An input whose frames carry a rolling counter and a CRC (safety-relevant links).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CheckedLink {
    WheelAngle,
    Operator,
    Imu,
}

/// The integrity check of one received frame or message: a bad length, CRC, counter or
/// reassembly. The supervisor counts a checked link's results; every failure is a bad frame.
/// A frame that fails produces no other input.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FrameCheckInput {
    pub t: f64,
    pub source: SourceId,
    /// The checked link the frame belongs to, if any.
    pub link: Option<CheckedLink>,
    pub ok: bool,
}

/// Anything the controller is told. Adapters produce these; the controller node consumes
/// them (see the module contract).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Input {
    Position(PositionInput),
    Quality(QualityInput),
    CourseSpeed(CourseSpeedInput),
    Heading(HeadingInput),
    Attitude(AttitudeInput),
    WheelAngle(WheelAngleInput),
    WheelSpeed(WheelSpeedInput),
    Operator(OperatorInput),
    MachineInfo(MachineInfoInput),
    FrameCheck(FrameCheckInput),
}

impl Input {
    /// Arrival time on the controller clock, s.
    pub fn t(&self) -> f64 {
        match self {
            Input::Position(i) => i.t,
            Input::Quality(i) => i.t,
            Input::CourseSpeed(i) => i.t,
            Input::Heading(i) => i.t,
            Input::Attitude(i) => i.t,
            Input::WheelAngle(i) => i.t,
            Input::WheelSpeed(i) => i.t,
            Input::Operator(i) => i.t,
            Input::MachineInfo(i) => i.t,
            Input::FrameCheck(i) => i.t,
        }
    }

    /// Where it came from.
    pub fn source(&self) -> SourceId {
        match self {
            Input::Position(i) => i.source,
            Input::Quality(i) => i.source,
            Input::CourseSpeed(i) => i.source,
            Input::Heading(i) => i.source,
            Input::Attitude(i) => i.source,
            Input::WheelAngle(i) => i.source,
            Input::WheelSpeed(i) => i.source,
            Input::Operator(i) => i.source,
            Input::MachineInfo(i) => i.source,
            Input::FrameCheck(i) => i.source,
        }
    }
}
