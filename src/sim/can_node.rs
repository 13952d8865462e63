//! The simulator on the bus: the same vehicle model, speaking the DBC's frames.
//!
//! It sends GNSS (129025 position, 129026 COG/SOG, 127250 heading, 129029 fast-packet with
//! RTK fixed or float) at the GNSS rate with its latency, the wheel angle at its rate with
//! counter and CRC, and the wheel-based speed. It receives steering commands and checks their
//! CRC and counter as a real actuator would, ignoring bad ones; while not engaged (or without
//! valid commands) the "driver" holds the wheels where they are. With a command timeout
//! ([`SimNode::with_command_timeout`], `sim.command_timeout_s`) the steering controller leaves
//! automatic steering when valid commands stop for that long, as a real steering ECU does
//! (ISO 11783-7's remote command timeout), and the driver centres the wheels and keeps
//! straight instead of the tractor circling on the last command. A scenario scripts faults.
//! With an IMU configured it sends the roll and pitch (0xFF30) at the IMU rate with counter
//! and CRC; during the simulator's RTK-float windows 129029 reports method 5 (RTK float).

use super::steer_ready::{Steer, SteerReadyEcu};
use super::{FixQuality, GnssMeasurement, SimOutput, Simulator};
use crate::can::codec::{
    self, CogSogRapid, CogSogRapidCogReference, CounterCheck, DbcMessage, DirectionRequest,
    DirectionRequestDirection, ImuAttitude, Packer, PositionRapid, SteeringCommand,
    SteeringCommandMode, VesselHeading, VesselHeadingReference, WheelAngle, WheelAngleStatus,
    WheelSpeed, WheelSpeedDirection, WheelSpeedKeySwitch,
};
use crate::can::fastpacket::split;
use crate::can::gnss::{
    fix_message, north_cw_from_yaw, GnssPosition, METHOD_RTK_FIXED, METHOD_RTK_FLOAT,
};
use crate::can::{Frame, TimedFrame};
use crate::geo::wgs84::EnuFrame;
use serde::Deserialize;

/// A scripted fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FaultKind {
    /// No GNSS frames at all.
    GnssDropout,
    /// The receiver reports RTK float (and a larger error).
    RtkFloat,
    /// Wheel-angle frames with a wrong CRC.
    CorruptWheelAngleCrc,
    /// Wheel-angle frames with a counter that does not advance.
    FrozenWheelAngleCounter,
    /// No wheel-angle frames.
    WheelAngleSilence,
    /// No wheel-speed frames.
    SpeedSilence,
    /// The operator-override bit set in the wheel-angle status (the steer-ready tractor: the
    /// operator takes the wheel, its ECU leaves automatic steering).
    OperatorOverride,
    /// The steer-ready tractor's mechanical lockout switch active (and the ECU not ready).
    SteeringLockout,
}

/// One fault window.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fault {
    pub kind: FaultKind,
    /// Start, s of simulated time.
    pub at_s: f64,
    /// Duration, s.
    pub duration_s: f64,
}

/// A scenario file (TOML): `[[fault]] kind = "gnss_dropout", at_s = 30.0, duration_s = 2.0`.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    #[serde(default)]
    pub fault: Vec<Fault>,
}

impl Scenario {
    fn active(&self, kind: FaultKind, t: f64) -> bool {
        self.fault
            .iter()
            .any(|f| f.kind == kind && t >= f.at_s && t < f.at_s + f.duration_s)
    }
}

/// J1939 source addresses the simulator sends from.
#[derive(Debug, Clone, Copy)]
pub struct SimAddresses {
    pub gnss: u8,
    pub wheel_angle: u8,
    pub tractor: u8,
    pub imu: u8,
}

impl Default for SimAddresses {
    fn default() -> Self {
        SimAddresses {
            gnss: 0x1C,
            wheel_angle: 0x13,
            tractor: 0xF0,
            imu: 0x14,
        }
    }
}

/// The driver's (or the tractor's speed control's) speed profile going forward: the maximum
/// speed on the straight, slowing to the minimum in turns (at the line ends), at the
/// simulator's acceleration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedProfile {
    /// Speed in turns, m/s.
    pub min: f64,
    /// Speed on the straight, m/s.
    pub max: f64,
    /// Wheel angles beyond this are a turn, rad.
    pub turn_angle: f64,
}

/// The simulator node.
pub struct SimNode {
    sim: Simulator,
    enu: EnuFrame,
    gnss: Packer,
    was: Packer,
    tractor: Packer,
    imu: Packer,
    checks: CounterCheck,
    scenario: Scenario,
    outs: Vec<SimOutput>,
    fp: Vec<[u8; 8]>,
    seq: u8,
    sid: u8,
    engaged: bool,
    rejected: u64,
    frozen_counter: Option<Frame>,
    distance: f64,
    /// Speed magnitude at the start: what the tractor drives at either way, m/s.
    cruise: f64,
    profile: Option<SpeedProfile>,
    /// The last direction request was forward (or there was none).
    forward: bool,
    /// GNSS goes to a byte stream ([`SimNode::with_gnss_off_bus`]), not onto the bus.
    gnss_off_bus: bool,
    gnss_out: Vec<GnssMeasurement>,
    /// The steer-ready tractor ([`SimNode::with_steer_ready`]).
    steer_ready: Option<SteerReadyEcu>,
    /// Valid commands older than this end automatic steering, s (`None`: never).
    command_timeout: Option<f64>,
    /// Time of the last valid steering command, s.
    last_command_t: f64,
    /// Times automatic steering ended on the command timeout.
    timeouts: u64,
}

impl SimNode {
    pub fn new(sim: Simulator, enu: EnuFrame, addresses: SimAddresses, scenario: Scenario) -> Self {
        SimNode {
            cruise: sim.true_state().speed.abs(),
            sim,
            enu,
            gnss: Packer::new(addresses.gnss),
            was: Packer::new(addresses.wheel_angle),
            tractor: Packer::new(addresses.tractor),
            imu: Packer::new(addresses.imu),
            checks: CounterCheck::default(),
            scenario,
            outs: Vec::with_capacity(64),
            fp: Vec::with_capacity(8),
            seq: 0,
            sid: 0,
            engaged: false,
            rejected: 0,
            frozen_counter: None,
            distance: 0.0,
            profile: None,
            forward: true,
            gnss_off_bus: false,
            gnss_out: Vec::new(),
            steer_ready: None,
            command_timeout: None,
            last_command_t: 0.0,
            timeouts: 0,
        }
    }

    /// The steering controller leaves automatic steering when valid commands stop for
    /// `timeout` s, and the driver centres the wheels (`None`: the last command is held). Set
    /// it before [`SimNode::with_steer_ready`] for the steer-ready ECU to use it too.
    pub fn with_command_timeout(mut self, timeout: Option<f64>) -> Self {
        self.command_timeout = timeout.filter(|t| *t > 0.0 && t.is_finite());
        self
    }

    /// Times automatic steering ended because the commands stopped.
    pub fn command_timeouts(&self) -> u64 {
        self.timeouts
    }

    /// A steer-ready tractor: its steering ECU (at the tractor's address) speaks ISO 11783-7
    /// only — Guidance System Command in, Guidance Machine Info out, no wheel-angle frame
    /// (see [`steer_ready`](super::steer_ready)).
    pub fn with_steer_ready(mut self) -> Self {
        self.steer_ready = Some(
            SteerReadyEcu::new(self.tractor.source(), self.sim.params().wheelbase)
                .with_command_timeout(self.command_timeout),
        );
        self
    }

    /// The steer-ready tractor's steering ECU, when simulated.
    pub fn steer_ready(&self) -> Option<&SteerReadyEcu> {
        self.steer_ready.as_ref()
    }

    fn steer(&mut self, s: Option<Steer>) {
        match s {
            Some(Steer::To(angle)) => {
                self.engaged = true;
                self.sim.set_command(angle);
            }
            Some(Steer::Hold) => {
                self.engaged = false;
                self.sim.hold_wheels();
            }
            Some(Steer::Centre) => {
                self.engaged = false;
                self.timeouts += 1;
                self.sim.centre_wheels();
            }
            None => {}
        }
    }

    /// No GNSS frames on the bus: the measurements are handed out by
    /// [`SimNode::drain_gnss`] instead, for a receiver's byte stream
    /// ([`gnss_stream`](super::gnss_stream)). Scenario faults apply as on the bus (a GNSS
    /// dropout hands out nothing, RTK float is the measurements' fix).
    pub fn with_gnss_off_bus(mut self) -> Self {
        self.gnss_off_bus = true;
        self
    }

    /// Move the GNSS measurements delivered so far (with GNSS off the bus) into `out`, in
    /// delivery order.
    pub fn drain_gnss(&mut self, out: &mut Vec<GnssMeasurement>) {
        out.append(&mut self.gnss_out);
    }

    /// Drive forward with a speed profile (see [`SpeedProfile`]).
    pub fn with_speed_profile(mut self, profile: Option<SpeedProfile>) -> Self {
        self.profile = profile;
        self
    }

    pub fn sim(&self) -> &Simulator {
        &self.sim
    }
    pub fn sim_mut(&mut self) -> &mut Simulator {
        &mut self.sim
    }
    /// Is the last valid command engaged?
    pub fn engaged(&self) -> bool {
        self.engaged
    }
    /// Steering frames rejected (bad CRC or counter).
    pub fn rejected(&self) -> u64 {
        self.rejected
    }

    /// A received frame: steering commands are checked and applied.
    pub fn on_frame(&mut self, tf: &TimedFrame) {
        if let Some(ecu) = self.steer_ready.as_mut() {
            let lockout = self.scenario.active(FaultKind::SteeringLockout, tf.t);
            let operator = self.scenario.active(FaultKind::OperatorOverride, tf.t);
            let s = ecu.on_frame(tf.t, &tf.frame, lockout, operator);
            self.steer(s);
        }
        let Ok(d) = codec::decode(tf.frame.id, tf.frame.payload()) else {
            if codec::find(tf.frame.id).is_some_and(|(_, m)| m.name == "SteeringCommand") {
                self.rejected += 1;
            }
            return;
        };
        if let Some(r) = d.to::<DirectionRequest>() {
            // The tractor obeys: brake to a stop, or head for the cruise speed either way.
            use DirectionRequestDirection::{Reverse, Stop};
            self.forward = !matches!(r.direction, Some(Stop | Reverse));
            let target = match r.direction {
                Some(Stop) => 0.0,
                Some(Reverse) => -self.cruise,
                _ => self.cruise,
            };
            self.sim.set_speed_target(target);
            return;
        }
        let Some(cmd) = d
            .to::<SteeringCommand>()
            .filter(|_| self.steer_ready.is_none())
        else {
            return;
        };
        if !self.checks.check(&d) {
            self.rejected += 1;
            return;
        }
        self.last_command_t = tf.t;
        // An engaged command without an angle is no command: the driver holds the wheels.
        let angle = cmd
            .angle
            .filter(|_| cmd.mode == Some(SteeringCommandMode::Engaged));
        self.engaged = angle.is_some();
        if let Some(angle) = angle {
            self.sim.set_command(angle.to_radians());
        } else {
            // The driver holds the wheels.
            self.sim.hold_wheels();
        }
    }

    /// Advance to `t`, appending (send time, frame) pairs in time order.
    pub fn advance_to(&mut self, t: f64, out: &mut Vec<(f64, Frame)>) {
        if let Some(timeout) = self.command_timeout.filter(|_| self.steer_ready.is_none()) {
            if self.engaged && t - self.last_command_t > timeout {
                // The steering controller leaves automatic steering; the driver takes the
                // wheel and keeps straight.
                self.engaged = false;
                self.timeouts += 1;
                self.sim.centre_wheels();
            }
        }
        let before = self.sim.true_state().pose.pos;
        let float = self.scenario.active(FaultKind::RtkFloat, t);
        self.sim.set_fix(if float {
            FixQuality::RtkFloat
        } else {
            FixQuality::RtkFixed
        });
        if let (Some(p), true) = (self.profile, self.forward) {
            let turning = self.sim.true_state().wheel_angle.abs() > p.turn_angle;
            self.sim
                .set_speed_target(if turning { p.min } else { p.max });
        }
        self.outs.clear();
        let mut outs = std::mem::take(&mut self.outs);
        self.sim.advance_to(t, &mut outs);
        self.distance += (self.sim.true_state().pose.pos - before).norm();
        for o in outs.drain(..) {
            match o {
                SimOutput::WheelAngle { t: ts, angle } => match self.steer_ready.as_mut() {
                    // The steer-ready ECU reads its sensor; no proprietary frame.
                    Some(ecu) => ecu.on_wheel_angle(angle),
                    None => self.wheel_frames(ts, angle, out),
                },
                SimOutput::Attitude { t: ts, roll, pitch } => {
                    if let Ok(f) = self.imu.pack(&ImuAttitude {
                        roll: Some(roll.to_degrees().clamp(-90.0, 90.0)),
                        pitch: Some(pitch.to_degrees().clamp(-90.0, 90.0)),
                    }) {
                        out.push((ts, f));
                    }
                }
                SimOutput::Gnss(m) => {
                    let ts = m.t_delivered;
                    if self.scenario.active(FaultKind::GnssDropout, ts) {
                        continue;
                    }
                    if self.gnss_off_bus {
                        self.gnss_out.push(m);
                    } else {
                        self.gnss_frames(&m, out);
                    }
                    if !self.scenario.active(FaultKind::SpeedSilence, ts) {
                        let v = self.sim.true_state().speed;
                        if let Ok(f) = self.tractor.pack(&WheelSpeed {
                            speed: Some(v.abs().min(64.254)),
                            distance: Some(self.distance.rem_euclid(4_211_081.0)),
                            max_time_tractor_power: None,
                            key_switch: Some(WheelSpeedKeySwitch::NotOff),
                            direction: Some(if v < 0.0 {
                                WheelSpeedDirection::Reverse
                            } else {
                                WheelSpeedDirection::Forward
                            }),
                        }) {
                            out.push((ts, f));
                        }
                    }
                }
            }
        }
        self.outs = outs;
        if let Some(ecu) = self.steer_ready.as_mut() {
            let lockout = self.scenario.active(FaultKind::SteeringLockout, t);
            let operator = self.scenario.active(FaultKind::OperatorOverride, t);
            let s = ecu.advance(t, lockout, operator, out);
            self.steer(s);
        }
    }

    /// The NMEA 2000 GNSS frames of one measurement.
    fn gnss_frames(&mut self, m: &GnssMeasurement, out: &mut Vec<(f64, Frame)>) {
        let ts = m.t_delivered;
        self.sid = self.sid.wrapping_add(1) % 250;
        let ll = self.enu.to_latlon(m.antenna);
        let heading = north_cw_from_yaw(m.heading);
        if let Ok(f) = self.gnss.pack(&VesselHeading {
            sid: Some(self.sid as f64),
            heading: Some((heading / 1e-4).floor() * 1e-4),
            deviation: None,
            variation: None,
            reference: Some(VesselHeadingReference::True),
        }) {
            out.push((ts, f));
        }
        let speed = m.speed.abs().min(655.32);
        if let Ok(f) = self.gnss.pack(&CogSogRapid {
            sid: Some(self.sid as f64),
            cog_reference: Some(CogSogRapidCogReference::True),
            cog: Some((north_cw_from_yaw(m.course) / 1e-4).floor() * 1e-4),
            sog: Some(speed),
        }) {
            out.push((ts, f));
        }
        let g = GnssPosition {
            time_s: Some(m.t_measured.rem_euclid(86_400.0)),
            satellites: Some(20),
            hdop: Some(0.7),
            pdop: Some(1.2),
            ..fix_message(
                self.sid,
                ll.lat_deg,
                ll.lon_deg,
                if m.fix == FixQuality::RtkFloat {
                    METHOD_RTK_FLOAT
                } else {
                    METHOD_RTK_FIXED
                },
            )
        };
        self.fp.clear();
        split(&g.encode(), self.seq, &mut self.fp);
        self.seq = (self.seq + 1) & 7;
        let id = (codec::GnssPositionData::def().id & !0xFF) | self.gnss.source() as u32;
        for d in &self.fp {
            out.push((ts, Frame::new(id, d)));
        }
        if let Ok(f) = self.gnss.pack(&PositionRapid {
            latitude: Some(ll.lat_deg),
            longitude: Some(ll.lon_deg),
        }) {
            out.push((ts, f));
        }
    }

    fn wheel_frames(&mut self, ts: f64, angle: f64, out: &mut Vec<(f64, Frame)>) {
        if self.scenario.active(FaultKind::WheelAngleSilence, ts) {
            return;
        }
        let status = if self.scenario.active(FaultKind::OperatorOverride, ts) {
            WheelAngleStatus::OperatorOverride
        } else {
            WheelAngleStatus::Ok
        };
        let Ok(mut f) = self.was.pack(&WheelAngle {
            angle: Some(angle.to_degrees().clamp(-90.0, 90.0)),
            status: Some(status),
        }) else {
            return;
        };
        if self.scenario.active(FaultKind::FrozenWheelAngleCounter, ts) {
            let frozen = *self.frozen_counter.get_or_insert(f);
            // The first frozen frame repeated, counter and all: a stuck sender.
            f = frozen;
        } else {
            self.frozen_counter = None;
        }
        if self.scenario.active(FaultKind::CorruptWheelAngleCrc, ts) {
            f.data[7] ^= 0x5A;
        }
        out.push((ts, f));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::can::fastpacket::Reassembler;
    use crate::geo::wgs84::LatLon;
    use crate::geo::Pose;
    use crate::sim::{Disturbances, SimParams};

    fn node(dist: Disturbances) -> SimNode {
        let p = SimParams {
            antenna_up: 3.0,
            dist,
            ..SimParams::default()
        };
        SimNode::new(
            Simulator::new(p, Pose::new(0.0, 0.0, std::f64::consts::FRAC_PI_2), 3.0),
            EnuFrame::new(LatLon {
                lat_deg: 52.0,
                lon_deg: 5.0,
            }),
            SimAddresses::default(),
            Scenario::default(),
        )
    }

    /// (delivery time, 129029 method) of every GNSS Position Data message.
    fn methods(frames: &[(f64, Frame)]) -> Vec<(f64, u8)> {
        let mut fast = Reassembler::default();
        let mut out = Vec::new();
        for (t, f) in frames {
            let Ok(d) = codec::decode(f.id, f.payload()) else {
                continue;
            };
            if d.index == codec::GnssPositionData::INDEX {
                if let Ok(Some(p)) = fast.push(d.source, f.payload()) {
                    out.push((*t, GnssPosition::decode(p).unwrap().method.unwrap_or(0xFF)));
                }
            }
        }
        out
    }

    #[test]
    fn rtk_float_window_sends_method_float() {
        let mut n = node(Disturbances {
            float_windows: vec![(5.0, 3.0)],
            float_sigma: 0.2,
            float_tau: 10.0,
            ..Disturbances::default()
        });
        let mut frames = Vec::new();
        n.advance_to(12.0, &mut frames);
        let m = methods(&frames);
        assert!(m.len() > 100);
        for (t, method) in m {
            // Delivered 0.05 s after it was measured.
            let measured = t - 0.05;
            let expect = if (5.0 - 1e-9..8.0 - 1e-9).contains(&measured) {
                METHOD_RTK_FLOAT
            } else {
                METHOD_RTK_FIXED
            };
            assert_eq!(method, expect, "measured at {measured}");
        }
        // No IMU configured: no attitude frames.
        assert!(!frames.iter().any(|(_, f)| codec::decode(f.id, f.payload())
            .is_ok_and(|d| d.to::<ImuAttitude>().is_some())));
    }

    #[test]
    fn imu_frames_carry_roll_and_pitch_at_the_rate() {
        let mut n = node(Disturbances {
            terrain_slope: 2f64.to_radians(),
            terrain_wavelength: 100.0,
            imu_rate_hz: 50.0,
            ..Disturbances::default()
        });
        let mut frames = Vec::new();
        n.advance_to(2.0, &mut frames);
        let mut checks = CounterCheck::default();
        let imu: Vec<ImuAttitude> = frames
            .iter()
            .filter_map(|(_, f)| codec::decode(f.id, f.payload()).ok())
            .filter(|d| d.to::<ImuAttitude>().is_some())
            .map(|d| {
                assert!(checks.check(&d), "counter and CRC");
                d.to::<ImuAttitude>().unwrap()
            })
            .collect();
        assert_eq!(imu.len(), 101);
        for a in imu {
            // Driving north across a slope falling East: right side down, +2°.
            assert!((a.roll.unwrap() - 2.0).abs() < 0.011, "{:?}", a.roll);
            assert!(a.pitch.unwrap().abs() < 0.011);
        }
    }

    #[test]
    fn speed_profile_slows_in_turns_and_speeds_up_on_the_straight() {
        let p = SpeedProfile {
            min: 4.0 / 3.6,
            max: 15.0 / 3.6,
            turn_angle: 5f64.to_radians(),
        };
        let mut n = node(Disturbances::default()).with_speed_profile(Some(p));
        let mut frames = Vec::new();
        let mut prev = n.sim().true_state().speed;
        let mut t = 0.0;
        let mut step = |n: &mut SimNode, until: f64, prev: &mut f64| {
            while t < until {
                t += 0.02;
                frames.clear();
                n.advance_to(t, &mut frames);
                let v = n.sim().true_state().speed;
                // At most the simulator's acceleration (0.5 m/s²).
                assert!((v - *prev).abs() <= 0.5 * 0.02 + 1e-9);
                *prev = v;
            }
        };
        step(&mut n, 10.0, &mut prev);
        assert!((n.sim().true_state().speed - p.max).abs() < 1e-9);
        n.sim_mut().set_command(0.3);
        step(&mut n, 20.0, &mut prev);
        assert!((n.sim().true_state().speed - p.min).abs() < 1e-9);
        n.sim_mut().set_command(0.0);
        step(&mut n, 30.0, &mut prev);
        assert!((n.sim().true_state().speed - p.max).abs() < 1e-9);
        // Off: the start speed is kept.
        let mut n = node(Disturbances::default());
        n.advance_to(10.0, &mut frames);
        assert_eq!(n.sim().true_state().speed, 3.0);
    }

    /// Without commands for `sim.command_timeout_s` the steering controller leaves automatic
    /// steering and the driver centres the wheels; without a timeout the last command is held
    /// (the tractor circles).
    #[test]
    fn command_timeout_centres_the_wheels() {
        for timeout in [Some(0.25), None] {
            let mut n = node(Disturbances::default()).with_command_timeout(timeout);
            let mut daemon = Packer::new(0x1E);
            let mut frames = Vec::new();
            // Engaged at 20° left, a command every 10 ms for 2 s, then none.
            let mut t = 0.0;
            while t < 2.0 {
                let f = daemon
                    .pack(&SteeringCommand {
                        angle: Some(20.0),
                        mode: Some(SteeringCommandMode::Engaged),
                    })
                    .unwrap();
                n.on_frame(&TimedFrame { t, frame: f });
                t += 0.01;
                n.advance_to(t, &mut frames);
            }
            assert!(n.engaged());
            let steered = n.sim().true_state().wheel_angle;
            assert!((steered - 20f64.to_radians()).abs() < 0.01, "{steered}");
            n.advance_to(2.2, &mut frames);
            assert!(n.engaged(), "{timeout:?}: still within the timeout");
            n.advance_to(5.0, &mut frames);
            let wheel = n.sim().true_state().wheel_angle;
            match timeout {
                Some(_) => {
                    assert!(!n.engaged());
                    assert_eq!(n.command_timeouts(), 1);
                    assert!(wheel.abs() < 1e-6, "centred: {wheel}");
                }
                None => {
                    assert!(n.engaged());
                    assert_eq!(n.command_timeouts(), 0);
                    assert!((wheel - 20f64.to_radians()).abs() < 1e-3, "held: {wheel}");
                }
            }
        }
    }
}
