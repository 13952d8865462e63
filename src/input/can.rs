//! The CAN adapter: received frames (NMEA 2000, J1939 / ISO 11783 and agsteer's proprietary
//! frames, as `dbc/agsteer.dbc` defines them) in, [`Input`]s out.
//!
//! It checks what the frames carry for their own integrity (length, CRC, rolling counter,
//! fast-packet order) and reports it as [`Input::FrameCheck`]; it converts the bus's edge units
//! (degrees, clockwise-from-North courses) to the seam's SI conventions, once. It keeps no state
//! but the counters and the fast-packet reassembly.

use super::{
    AttitudeInput, CheckedLink, CourseSpeedInput, FixQuality, FrameCheckInput, HeadingInput,
    HeadingReference, Input, MachineInfoInput, OperatorCommand, OperatorInput, PositionInput,
    QualityInput, SensorStatus, SourceId, WheelAngleInput, WheelSpeedInput,
};
use crate::can::codec::{
    self, CodecError, CogSogRapidCogReference, CounterCheck, Message, OperatorCommandCommand,
    VesselHeadingReference, WheelAngleStatus, WheelSpeedDirection,
};
use crate::can::fastpacket::Reassembler;
use crate::can::gnss::{yaw_from_north_cw, GnssPosition, METHOD_RTK_FIXED, METHOD_RTK_FLOAT};
use crate::can::TimedFrame;
use crate::geo::Direction;

/// The inputs one frame produced (at most two: its check and its value).
#[derive(Debug, Clone, Copy, Default)]
pub struct FrameInputs {
    items: [Option<Input>; 2],
}

impl FrameInputs {
    fn push(&mut self, input: Input) {
        if let Some(slot) = self.items.iter_mut().find(|s| s.is_none()) {
            *slot = Some(input);
        }
    }
    fn check(&mut self, t: f64, source: SourceId, link: Option<CheckedLink>, ok: bool) {
        self.push(Input::FrameCheck(FrameCheckInput {
            t,
            source,
            link,
            ok,
        }));
    }
    /// Nothing came of the frame (not ours, or not an input).
    pub fn is_empty(&self) -> bool {
        self.items[0].is_none()
    }
}

impl IntoIterator for FrameInputs {
    type Item = Input;
    type IntoIter = std::iter::Flatten<std::array::IntoIter<Option<Input>, 2>>;
    fn into_iter(self) -> Self::IntoIter {
        self.items.into_iter().flatten()
    }
}

/// Positioning method of NMEA 2000 129029 → fix quality.
pub fn quality_of_method(method: u8) -> FixQuality {
    match method {
        METHOD_RTK_FIXED => FixQuality::RtkFixed,
        METHOD_RTK_FLOAT => FixQuality::RtkFloat,
        0 => FixQuality::None,
        _ => FixQuality::Other,
    }
}

/// The link a received message's counter and CRC protect.
fn link_of(index: usize) -> Option<CheckedLink> {
    use crate::can::codec::{DbcMessage, ImuAttitude, OperatorCommand, WheelAngle};
    match index {
        WheelAngle::INDEX => Some(CheckedLink::WheelAngle),
        OperatorCommand::INDEX => Some(CheckedLink::Operator),
        ImuAttitude::INDEX => Some(CheckedLink::Imu),
        _ => None,
    }
}

fn reference(r: HeadingReferenceRaw) -> HeadingReference {
    match r {
        HeadingReferenceRaw::True => HeadingReference::True,
        HeadingReferenceRaw::Magnetic => HeadingReference::Magnetic,
        HeadingReferenceRaw::Unknown => HeadingReference::Unknown,
    }
}

/// 127250's and 129026's references share one table (canboat's DIRECTION_REFERENCE).
enum HeadingReferenceRaw {
    True,
    Magnetic,
    Unknown,
}

impl From<VesselHeadingReference> for HeadingReferenceRaw {
    fn from(r: VesselHeadingReference) -> Self {
        match r {
            VesselHeadingReference::True => HeadingReferenceRaw::True,
            VesselHeadingReference::Magnetic => HeadingReferenceRaw::Magnetic,
            VesselHeadingReference::Other(_) => HeadingReferenceRaw::Unknown,
        }
    }
}

impl From<CogSogRapidCogReference> for HeadingReferenceRaw {
    fn from(r: CogSogRapidCogReference) -> Self {
        match r {
            CogSogRapidCogReference::True => HeadingReferenceRaw::True,
            CogSogRapidCogReference::Magnetic => HeadingReferenceRaw::Magnetic,
            CogSogRapidCogReference::Other(_) => HeadingReferenceRaw::Unknown,
        }
    }
}

/// An operator command; one whose command, nudge or job is not available is no command.
fn operator_command(c: &codec::OperatorCommand) -> OperatorCommand {
    let Some(command) = c.command else {
        return OperatorCommand::None;
    };
    match command {
        OperatorCommandCommand::None => OperatorCommand::None,
        OperatorCommandCommand::Engage => OperatorCommand::Engage,
        OperatorCommandCommand::Disengage => OperatorCommand::Disengage,
        OperatorCommandCommand::Pause => OperatorCommand::Pause,
        OperatorCommandCommand::Resume => OperatorCommand::Resume,
        OperatorCommandCommand::Nudge => match c.nudge {
            Some(steps) => OperatorCommand::Nudge {
                steps: steps.round() as i32,
            },
            None => OperatorCommand::None,
        },
        OperatorCommandCommand::SetA => OperatorCommand::SetA,
        OperatorCommandCommand::SetB => OperatorCommand::SetB,
        OperatorCommandCommand::SelectJob => match c.job {
            Some(job) => OperatorCommand::SelectJob {
                job: job.clamp(0.0, 255.0) as u8,
            },
            None => OperatorCommand::None,
        },
        OperatorCommandCommand::Calibrate => OperatorCommand::Calibrate,
        OperatorCommandCommand::Other(code) => OperatorCommand::Unknown { code },
    }
}

/// Frames → [`Input`]s.
#[derive(Debug, Clone, Default)]
pub struct CanAdapter {
    counters: CounterCheck,
    fast: Reassembler,
}

impl CanAdapter {
    /// The inputs of one received frame. Frames of identifiers the DBC does not define produce
    /// none; a frame that fails its checks produces only its failed [`Input::FrameCheck`].
    pub fn on_frame(&mut self, tf: &TimedFrame) -> FrameInputs {
        let mut out = FrameInputs::default();
        let t = tf.t;
        let source = SourceId::Can(tf.frame.source());
        let d = match codec::decode(tf.frame.id, tf.frame.payload()) {
            Ok(d) => d,
            Err(CodecError::UnknownId(_)) => return out,
            Err(_) => {
                let link = codec::find(tf.frame.id).and_then(|(i, _)| link_of(i));
                out.check(t, source, link, false);
                return out;
            }
        };
        if let Some(link) = link_of(d.index) {
            let ok = self.counters.check(&d);
            out.check(t, source, Some(link), ok);
            if !ok {
                return out;
            }
        }
        let Some(message) = d.message() else {
            return out;
        };
        match message {
            Message::WheelAngle(m) => out.push(Input::WheelAngle(WheelAngleInput {
                t,
                source,
                angle: m.angle.map(f64::to_radians),
                status: match m.status {
                    Some(WheelAngleStatus::Ok) => SensorStatus::Ok,
                    Some(WheelAngleStatus::Fault) => SensorStatus::Fault,
                    Some(WheelAngleStatus::OperatorOverride) => SensorStatus::OperatorOverride,
                    Some(WheelAngleStatus::Other(_)) | None => SensorStatus::Unknown,
                },
            })),
            Message::PositionRapid(m) => {
                if let (Some(lat_deg), Some(lon_deg)) = (m.latitude, m.longitude) {
                    out.push(Input::Position(PositionInput {
                        t,
                        source,
                        lat_deg,
                        lon_deg,
                        altitude_m: None,
                        latency_s: None,
                        quality: None,
                    }));
                }
            }
            Message::ImuAttitude(m) => out.push(Input::Attitude(AttitudeInput {
                t,
                source,
                roll: m.roll.filter(|r| r.is_finite()).map(f64::to_radians),
                pitch: m.pitch.filter(|p| p.is_finite()).map(f64::to_radians),
            })),
            Message::VesselHeading(m) => {
                if let Some(h) = m.heading {
                    out.push(Input::Heading(HeadingInput {
                        t,
                        source,
                        heading: yaw_from_north_cw(h),
                        reference: m
                            .reference
                            .map_or(HeadingReference::Unknown, |r| reference(r.into())),
                        variation: m.variation,
                    }));
                }
            }
            Message::CogSogRapid(m) => {
                // A course over ground is given only when it is true (referred to the
                // geographic North); a magnetic one would need the variation, which 129026
                // does not carry.
                let is_true = m
                    .cog_reference
                    .is_some_and(|r| reference(r.into()) == HeadingReference::True);
                out.push(Input::CourseSpeed(CourseSpeedInput {
                    t,
                    source,
                    course: m.cog.filter(|_| is_true).map(yaw_from_north_cw),
                    speed_mps: m.sog,
                }))
            }
            Message::WheelSpeed(m) => out.push(Input::WheelSpeed(WheelSpeedInput {
                t,
                source,
                speed_mps: m.speed,
                direction: match m.direction {
                    Some(WheelSpeedDirection::Forward) => Some(Direction::Forward),
                    Some(WheelSpeedDirection::Reverse) => Some(Direction::Reverse),
                    Some(WheelSpeedDirection::Other(_)) | None => None,
                },
            })),
            Message::GnssPositionData(_) => match self.fast.push(d.source, tf.frame.payload()) {
                Ok(Some(payload)) => match GnssPosition::decode(payload) {
                    Ok(g) => out.push(Input::Quality(QualityInput {
                        t,
                        source,
                        quality: g.method.map_or(FixQuality::None, quality_of_method),
                        satellites: g.satellites,
                        hdop: g.hdop,
                        correction_age_s: g.correction_age_s(),
                        horizontal_sigma_m: None,
                    })),
                    Err(_) => out.check(t, source, None, false),
                },
                Ok(None) => {}
                Err(_) => out.check(t, source, None, false),
            },
            Message::OperatorCommand(m) => out.push(Input::Operator(OperatorInput {
                t,
                source,
                command: operator_command(&m),
            })),
            Message::GuidanceMachineInfo(m) => {
                use codec::{
                    GuidanceMachineInfoMechanicalLockout as Lockout,
                    GuidanceMachineInfoRequestResetCommandStatus as Reset,
                    GuidanceMachineInfoSteeringReadiness as Ready,
                };
                out.push(Input::MachineInfo(MachineInfoInput {
                    t,
                    source,
                    // ISO 11783-7: km⁻¹, positive = right turn; ours is 1/m, positive left.
                    curvature: m.estimated_curvature.map(|k| -k * 1e-3),
                    ready: m.steering_readiness.map(|r| r == Ready::Ready),
                    lockout: m.mechanical_lockout.map(|l| l != Lockout::NotActive),
                    reset_requested: m
                        .request_reset_command_status
                        .map(|r| r != Reset::ResetNotRequired),
                    exit_reason: m.exit_reason_code.map(|c| c.clamp(0.0, 63.0) as u8),
                }))
            }
            // agsteer's own outputs.
            Message::SteeringCommand(_)
            | Message::GuidanceStatus(_)
            | Message::DirectionRequest(_)
            | Message::OperatorReply(_)
            | Message::GuidanceSystemCommand(_) => {}
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::can::codec::{
        OperatorCommand as OpFrame, Packer, VesselHeading, WheelAngle, WheelSpeed,
        WheelSpeedKeySwitch,
    };
    use crate::can::fastpacket::split;
    use crate::can::Frame;

    fn inputs(a: &mut CanAdapter, f: Frame) -> Vec<Input> {
        a.on_frame(&TimedFrame { t: 2.0, frame: f })
            .into_iter()
            .collect()
    }

    #[test]
    fn wheel_angle_is_checked_then_converted() {
        let mut a = CanAdapter::default();
        let mut was = Packer::new(0x13);
        let f = was
            .pack(&WheelAngle {
                angle: Some(-12.5),
                status: Some(WheelAngleStatus::OperatorOverride),
            })
            .unwrap();
        let got = inputs(&mut a, f);
        assert_eq!(got.len(), 2);
        let Input::FrameCheck(c) = got[0] else {
            panic!("{got:?}")
        };
        assert!(c.ok && c.link == Some(CheckedLink::WheelAngle));
        let Input::WheelAngle(w) = got[1] else {
            panic!("{got:?}")
        };
        assert_eq!(w.source, SourceId::Can(0x13));
        assert!((w.angle.unwrap() - (-12.5f64).to_radians()).abs() < 1e-12);
        assert_eq!(w.status, SensorStatus::OperatorOverride);
        // The same frame again: its counter did not advance; only the failed check comes out.
        let got = inputs(&mut a, f);
        assert_eq!(got.len(), 1);
        assert!(matches!(got[0], Input::FrameCheck(c) if !c.ok));
        // A corrupted CRC.
        let mut g = was
            .pack(&WheelAngle {
                angle: Some(1.0),
                status: Some(WheelAngleStatus::Ok),
            })
            .unwrap();
        g.data[7] ^= 1;
        let got = inputs(&mut a, g);
        assert!(
            matches!(got[..], [Input::FrameCheck(c)] if !c.ok && c.link == Some(CheckedLink::WheelAngle))
        );
    }

    #[test]
    fn heading_speed_and_operator_in_seam_units() {
        let mut a = CanAdapter::default();
        let mut gnss = Packer::new(0x1C);
        let f = gnss
            .pack(&VesselHeading {
                sid: Some(1.0),
                heading: Some(std::f64::consts::FRAC_PI_2), // East, clockwise from North
                deviation: None,
                variation: Some(0.05),
                reference: Some(VesselHeadingReference::Magnetic),
            })
            .unwrap();
        let [Input::Heading(h)] = inputs(&mut a, f)[..] else {
            panic!()
        };
        assert!(h.heading.abs() < 1e-4, "East is yaw 0");
        assert_eq!(h.reference, HeadingReference::Magnetic);
        assert_eq!(h.variation, Some(0.05));
        let f = Packer::new(0xF0)
            .pack(&WheelSpeed {
                speed: Some(2.5),
                distance: Some(1.0),
                max_time_tractor_power: None,
                key_switch: Some(WheelSpeedKeySwitch::NotOff),
                direction: Some(WheelSpeedDirection::Reverse),
            })
            .unwrap();
        let [Input::WheelSpeed(s)] = inputs(&mut a, f)[..] else {
            panic!()
        };
        assert_eq!(
            (s.speed_mps, s.direction),
            (Some(2.5), Some(Direction::Reverse))
        );
        let f = Packer::new(0x26)
            .pack(&OpFrame {
                command: Some(OperatorCommandCommand::Nudge),
                nudge: Some(-15.0),
                job: None,
            })
            .unwrap();
        let got = inputs(&mut a, f);
        let Input::Operator(o) = got[1] else {
            panic!("{got:?}")
        };
        assert_eq!(o.command, OperatorCommand::Nudge { steps: -15 });
    }

    #[test]
    fn guidance_machine_info_reads_byte_3_as_iso_11783_7_lays_it_out() {
        let mut a = CanAdapter::default();
        // Bytes as AgIsoStack++ (isobus_guidance_interface.cpp) sends them: curvature raw
        // 32128 + 40 (10 km⁻¹ right); byte 2: lockout not active (00), readiness ready (01)
        // << 2, input position (11 n/a) << 4, request reset required (01) << 6; byte 3: limit
        // status not limited << 5; byte 4: exit reason 5 (remote command timeout), remote
        // engage switch n/a (11) << 6.
        let k = (32128u16 + 40).to_le_bytes();
        let b2 = 0b01_11_01_00;
        let f = Frame::new(0x0CAC_FF1C, &[k[0], k[1], b2, 0x1F, 0xC5, 0xFF, 0xFF, 0xFF]);
        let [Input::MachineInfo(m)] = inputs(&mut a, f)[..] else {
            panic!()
        };
        assert_eq!(m.source, SourceId::Can(0x1C));
        assert!(
            (m.curvature.unwrap() + 0.010).abs() < 1e-12,
            "10 km⁻¹ right = −0.01 /m"
        );
        assert_eq!(m.lockout, Some(false));
        assert_eq!(m.ready, Some(true));
        assert_eq!(m.reset_requested, Some(true));
        assert_eq!(m.exit_reason, Some(5));
        // Lockout active, not ready, no reset; everything else not available.
        let f = Frame::new(
            0x0CAC_FF1C,
            &[0xFF, 0xFF, 0b11_11_00_01, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF],
        );
        let [Input::MachineInfo(m)] = inputs(&mut a, f)[..] else {
            panic!()
        };
        assert_eq!(
            (
                m.curvature,
                m.lockout,
                m.ready,
                m.reset_requested,
                m.exit_reason
            ),
            (None, Some(true), Some(false), None, None)
        );
    }

    #[test]
    fn fast_packet_129029_gives_the_fix_quality_once_complete() {
        let mut a = CanAdapter::default();
        let g = GnssPosition {
            satellites: Some(14),
            ..crate::can::gnss::fix_message(0, 52.0, 5.0, METHOD_RTK_FLOAT)
        };
        let mut frames = Vec::new();
        split(&g.encode(), 2, &mut frames);
        let n = frames.len();
        let mut got = Vec::new();
        for (i, d) in frames.iter().enumerate() {
            let out = inputs(&mut a, Frame::new(0x0DF8051C, d));
            assert_eq!(out.is_empty(), i + 1 < n, "frame {i}");
            got.extend(out);
        }
        let [Input::Quality(q)] = got[..] else {
            panic!("{got:?}")
        };
        assert_eq!(q.quality, FixQuality::RtkFloat);
        assert_eq!(q.satellites, Some(14));
        assert_eq!(q.correction_age_s, Some(1.0));
        // A frame out of order drops the message: one failed check.
        let out = inputs(&mut a, Frame::new(0x0DF8051C, &frames[2]));
        assert!(matches!(out[..], [Input::FrameCheck(c)] if !c.ok && c.link.is_none()));
    }

    #[test]
    fn unknown_identifiers_give_nothing_and_known_ones_of_a_wrong_length_fail() {
        let mut a = CanAdapter::default();
        assert!(inputs(&mut a, Frame::new(0x18FEF1F1, &[0; 8])).is_empty());
        let got = inputs(&mut a, Frame::new(0x09F8011C, &[0; 5]));
        assert!(matches!(got[..], [Input::FrameCheck(c)] if !c.ok && c.link.is_none()));
    }
}
