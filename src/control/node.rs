//! The controller on the bus: frames in, frames out. `can` → `estimate` → `guidance` → `plan`
//! → `track` → `safety` → `can`, without I/O: the daemon feeds it SocketCAN frames, the demo
//! feeds it in-memory ones, so both run exactly the same code on exactly the same frames.

mod calibration;
mod commands;
mod cusp;
mod supervision;

pub use calibration::CalibrationProgress;

use super::isobus::{IsoLink, IsoStatus, GUIDANCE_MESSAGE_PERIOD};
use super::operator::{JobRequest, OperatorState};
use super::params::{BusParams, OutputKind};
use super::Controller;
use crate::can::codec::{
    DirectionRequest, DirectionRequestDirection, GuidanceStatus, GuidanceStatusState,
    GuidanceSystemCommand, GuidanceSystemCommandCommandStatus, OperatorReplyResult, Packer,
    SteeringCommand, SteeringCommandMode,
};
use crate::can::{Frame, TimedFrame};
use crate::estimate::GnssFix;
use crate::geo::wgs84::{EnuFrame, LatLon};
use crate::geo::Direction;
use crate::input::can::CanAdapter;
use crate::input::source::{SourceChange, SourceSelector};
use crate::input::{CheckedLink, Input, PositionInput, SensorStatus};
use crate::safety::{
    CheckedInput, FaultCode, FixQuality, SafetyParams, SafetyState, SteeringCommand as Cmd,
    Supervisor,
};
use cusp::CuspParams;
use serde::Serialize;

/// A dual-antenna heading older than this is not used, s.
const HEADING_MAX_AGE: f64 = 0.5;
/// An IMU roll older than this is not used to correct the antenna's lean, s.
const ROLL_MAX_AGE: f64 = 0.5;
/// A 129029 quality older than this no longer vouches for positions, s.
const QUALITY_MAX_AGE: f64 = 2.0;
/// The largest fault code GuidanceStatus.Fault carries (its DBC range).
const GUIDANCE_STATUS_FAULT_MAX: f64 = 61.0;

/// What `agsteer status` and the guidance status frame report.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct NodeStatus {
    pub state: SafetyState,
    pub fault: FaultCode,
    pub engaged: bool,
    /// Why the operator's last engage request was refused (`none` when it engaged, or
    /// before any): the engage gate's reason (`xte_too_large`, `line_unfollowable`, …).
    pub engage_refusal: FaultCode,
    pub fix: FixQuality,
    pub xte_m: Option<f64>,
    pub heading_error_deg: Option<f64>,
    /// Distance from the path being driven, to its nearest segment, m: what `off_path` watches
    /// off work lines (`safety.off_path_m`).
    pub path_distance_m: Option<f64>,
    pub line: u64,
    pub block: u64,
    pub lines_done: u64,
    /// How far the current line has been worked, m from its start (saved with progress; a
    /// resume out of the engage gate rejoins it there). `None` in a turn or before.
    pub line_worked_m: Option<f64>,
    pub finished: bool,
    pub wheel_angle_command_deg: f64,
    /// The steering's lost motion (backlash + actuator deadband) learnt so far, degrees.
    pub steering_lost_motion_deg: f64,
    pub bad_frames: u64,
    /// The job driven: 0 the configured one, k the k-th line recorded by set A / set B.
    pub job: u8,
    /// The operator's nudge: the job shifted left of A→B, m.
    pub nudge_m: f64,
    /// The address claim and the steering ECU (ISO 11783).
    #[serde(flatten)]
    pub isobus: IsoStatus,
}

/// The controller node.
pub struct ControllerNode {
    ctrl: Controller,
    supervisor: Supervisor,
    enu: EnuFrame,
    packer: Packer,
    /// Frames → inputs.
    can: CanAdapter,
    /// One source per input kind.
    sources: SourceSelector,
    /// GNSS comes from a byte stream (`gnss.source`): GNSS inputs from the bus are ignored.
    gnss_from_stream: bool,
    output: OutputKind,
    /// Address claim and steering ECU.
    iso: IsoLink,
    /// Control periods between two Guidance System Commands.
    command_every: u64,
    /// The command status last sent in a Guidance System Command.
    last_intended: Option<bool>,
    heading: Option<(f64, f64)>,
    /// Latest IMU roll: (time s, rad, positive right side down).
    roll: Option<(f64, f64)>,
    speed: f64,
    quality: Option<(f64, FixQuality)>,
    status_every: u64,
    ticks: u64,
    /// Time of the previous control period, s (a late one is a pause of the loop's).
    last_tick_t: Option<f64>,
    status: NodeStatus,
    cusps: CuspParams,
    /// A stop for a change of direction is under way (from the stop request until the vehicle
    /// moves the new way at the minimum speed).
    cusp: bool,
    /// The last approach request was refused (already logged).
    approach_refused: bool,
    /// An engage or resume to answer once the supervisor has decided on it.
    engage_reply: Option<crate::can::codec::OperatorReplyCommand>,
    /// The last engage beyond the gate found no approach path (its refusal says so).
    no_approach: bool,
    /// Guidance failed in the previous period (its error already logged).
    guidance_failing: bool,
    /// The work line the supervisor watches (None: none).
    supervised_line: Option<u64>,
    /// The segment of a segment job seen last (a gap is looked for when it changes).
    supervised_segment: Option<usize>,
    last_request: Option<DirectionRequestDirection>,
    /// The wheel-angle sensor: gain and offset (rad), see [`BusParams::was_gain`].
    was_gain: f64,
    was_offset: f64,
    /// Nudge, set A / set B, select job (see [`super::operator`]).
    operator: OperatorState,
    /// The steering calibration mode ([`calibration`]).
    calibration: calibration::CalibrationState,
}

/// A control period this many dt after the previous one follows a pause of the loop's.
const LATE_PERIOD: f64 = 1.5;

/// Control periods between two status frames (at least 1).
fn status_every(status_period: f64, dt: f64) -> u64 {
    ((status_period / dt).round() as u64).max(1)
}

/// The supervisor's parameters: with the steer-ready loop, the steering feedback is Guidance
/// Machine Info, stale after `bus.machine_info_timeout`.
fn node_safety_params(safety: &SafetyParams, bus: &BusParams) -> SafetyParams {
    let mut p = safety.clone();
    if bus.iso.steer_ready_loop {
        p.wheel_angle_timeout = bus.machine_info_timeout;
    }
    p
}

fn checked_input(link: CheckedLink) -> CheckedInput {
    match link {
        CheckedLink::WheelAngle => CheckedInput::WheelAngle,
        CheckedLink::Operator => CheckedInput::Operator,
        CheckedLink::Imu => CheckedInput::Imu,
    }
}

impl ControllerNode {
    /// The node running `ctrl` under a supervisor with `safety`, on the bus as `bus` says,
    /// converting GNSS positions about `origin` (the origin of the job's local coordinates:
    /// `job.origin_*`, or the field's for a field plan).
    pub fn new(ctrl: Controller, safety: &SafetyParams, bus: &BusParams, origin: LatLon) -> Self {
        let c = ctrl.params().cusp;
        let dt = ctrl.params().dt;
        ControllerNode {
            ctrl,
            supervisor: Supervisor::new(node_safety_params(safety, bus)),
            enu: EnuFrame::new(origin),
            packer: Packer::new(bus.source_address),
            can: CanAdapter::default(),
            sources: SourceSelector::new(bus.sources),
            gnss_from_stream: bus.gnss_from_stream,
            output: bus.output,
            iso: IsoLink::new(bus.iso),
            command_every: ((GUIDANCE_MESSAGE_PERIOD / dt).round() as u64).max(1),
            last_intended: None,
            heading: None,
            roll: None,
            speed: 0.0,
            quality: None,
            status_every: status_every(bus.status_period, dt),
            ticks: 0,
            last_tick_t: None,
            cusps: CuspParams {
                decel: c.decel,
                stopped_speed: c.stopped_speed,
                capture: c.capture,
                dt,
                min_speed: safety.min_speed,
            },
            cusp: false,
            approach_refused: false,
            engage_reply: None,
            no_approach: false,
            guidance_failing: false,
            supervised_line: None,
            supervised_segment: None,
            last_request: None,
            was_gain: if bus.was_gain.is_finite() && bus.was_gain > 0.0 {
                bus.was_gain
            } else {
                1.0
            },
            was_offset: if bus.was_offset.is_finite() {
                bus.was_offset
            } else {
                0.0
            },
            operator: OperatorState {
                // Replies are queued in the control period: room for them up front.
                replies: Vec::with_capacity(crate::control::operator::MAX_REPLIES),
                ..OperatorState::default()
            },
            calibration: calibration::CalibrationState::new(),
            status: NodeStatus {
                state: SafetyState::Disengaged,
                fault: FaultCode::None,
                engaged: false,
                engage_refusal: FaultCode::None,
                fix: FixQuality::None,
                xte_m: None,
                path_distance_m: None,
                heading_error_deg: None,
                line: 0,
                block: 0,
                lines_done: 0,
                line_worked_m: None,
                finished: false,
                wheel_angle_command_deg: 0.0,
                steering_lost_motion_deg: 0.0,
                bad_frames: 0,
                job: 0,
                nudge_m: 0.0,
                isobus: IsoLink::new(bus.iso).status(),
            },
        }
    }

    pub fn controller(&self) -> &Controller {
        &self.ctrl
    }
    pub fn controller_mut(&mut self) -> &mut Controller {
        &mut self.ctrl
    }
    pub fn supervisor(&self) -> &Supervisor {
        &self.supervisor
    }
    pub fn supervisor_mut(&mut self) -> &mut Supervisor {
        &mut self.supervisor
    }
    /// Apply new tuning (tracker, estimator, safety limits, output) at once. The caller has
    /// checked that nothing defining the job changed.
    pub fn apply_tuning(
        &mut self,
        control: &super::ControlParams,
        safety: &SafetyParams,
        bus: &BusParams,
    ) {
        self.ctrl.set_tuning(control);
        self.set_supervisor_params(node_safety_params(safety, bus));
        self.output = bus.output;
        self.sources.set_params(bus.sources);
        self.status_every = status_every(bus.status_period, self.ctrl.params().dt);
    }

    pub fn status(&self) -> NodeStatus {
        self.status
    }
    /// The ENU frame GNSS positions are converted into.
    pub fn enu(&self) -> &EnuFrame {
        &self.enu
    }

    /// Send from the configured source address without claiming it (an offline replay of a
    /// log, whose frames show the address the daemon held).
    pub fn without_address_claim(mut self) -> Self {
        let mut p = *self.iso.params();
        p.claim = None;
        self.iso = IsoLink::new(p);
        self
    }

    /// The CAN link came up again (or recovered from bus-off): the address is claimed again.
    pub fn on_link_up(&mut self) {
        self.iso.restart();
    }

    /// One received frame: the CAN adapter's inputs, in order. True when a GNSS fix entered
    /// the controller (the daemon then computes the command at once, issue 16 point 7).
    pub fn on_frame(&mut self, tf: &TimedFrame) -> bool {
        let mut fix = false;
        self.iso.on_frame(tf.t, &tf.frame);
        for input in self.can.on_frame(tf) {
            let gnss = matches!(
                input,
                Input::Position(_) | Input::Quality(_) | Input::CourseSpeed(_) | Input::Heading(_)
            );
            if gnss && self.gnss_from_stream {
                continue;
            }
            fix |= self.on_input(&input);
        }
        fix
    }

    /// The GNSS sources seen and selected.
    pub fn sources(&self) -> &SourceSelector {
        &self.sources
    }

    /// One input, from any adapter (CAN, serial GNSS, the simulator). Positions, courses,
    /// headings and fix qualities pass the source selector first. True when it was a GNSS fix
    /// the controller took.
    pub fn on_input(&mut self, input: &Input) -> bool {
        let (input, change) = self.sources.select(input);
        if let Some(c) = change {
            self.on_source_change(&c);
        }
        let Some(input) = input else {
            return false;
        };
        self.calibration_input(&input);
        if let Input::Position(p) = &input {
            self.on_position(p);
            return true;
        }
        match input {
            Input::FrameCheck(c) => {
                if !c.ok {
                    self.status.bad_frames += 1;
                }
                if let Some(link) = c.link {
                    self.supervisor.on_frame_check(checked_input(link), c.ok);
                }
            }
            // With the steer-ready loop the steering feedback is Guidance Machine Info.
            Input::WheelAngle(_) if self.iso.params().steer_ready_loop => {}
            Input::MachineInfo(m) => {
                if self.iso.on_machine_info(&m) && self.iso.params().steer_ready_loop {
                    if let Some(k) = m.curvature {
                        let a = (k * self.supervisor.params().wheelbase).atan();
                        self.supervisor.on_wheel_angle(m.t, a, false, false);
                        self.ctrl.on_wheel_angle(m.t, a);
                    }
                }
            }
            Input::WheelAngle(w) => {
                // The sensor's reading to the true angle (calibration's gain and offset).
                if let Some(a) = w.angle.map(|a| (a - self.was_offset) / self.was_gain) {
                    self.supervisor.on_wheel_angle(
                        w.t,
                        a,
                        w.status == SensorStatus::OperatorOverride,
                        w.status == SensorStatus::Fault,
                    );
                    self.ctrl.on_wheel_angle(w.t, a);
                }
            }
            Input::Position(_) => {}
            Input::Quality(q) => self.quality = Some((q.t, q.quality)),
            Input::Attitude(a) => {
                if let Some(roll) = a.roll {
                    self.roll = Some((a.t, roll));
                }
            }
            Input::Heading(h) => {
                self.heading = Some((h.t, h.heading));
                self.supervisor.on_heading(h.t, h.heading);
            }
            Input::CourseSpeed(c) => {
                if let (Some(course), Some(sog)) = (c.course, c.speed_mps) {
                    self.supervisor.on_course(c.t, course, sog);
                }
                if let Some(sog) = c.speed_mps {
                    if self.heading.is_none() {
                        // SOG has no sign: keep the direction the wheel-speed frame reported.
                        self.speed = if self.speed < 0.0 { -sog } else { sog };
                    }
                }
            }
            Input::WheelSpeed(s) => {
                if let Some(v) = s.speed_mps {
                    let v = if s.direction == Some(Direction::Reverse) {
                        -v
                    } else {
                        v
                    };
                    self.speed = v;
                    self.supervisor.on_speed(s.t, v);
                }
            }
            Input::Operator(o) => self.on_operator(o.t, o.command),
        }
        false
    }

    /// A GNSS antenna position: the one place a fix enters the controller, with the latest
    /// heading, roll and fix quality that are fresh enough.
    fn on_position(&mut self, p: &PositionInput) {
        let t = p.t;
        let antenna = self.enu.to_enu(LatLon {
            lat_deg: p.lat_deg,
            lon_deg: p.lon_deg,
        });
        let heading = self
            .heading
            .filter(|(th, _)| t - th <= HEADING_MAX_AGE)
            .map(|(_, h)| h);
        let q = match (p.quality, self.quality) {
            (Some(q), _) => q,
            (None, Some((tq, q))) if t - tq <= QUALITY_MAX_AGE => q,
            _ => FixQuality::None,
        };
        self.ctrl
            .set_fix_quality(q == FixQuality::RtkFixed, q == FixQuality::RtkFloat);
        self.ctrl.on_fix(&GnssFix {
            t_received: t,
            antenna,
            heading,
            speed: self.speed,
            roll: self
                .roll
                .filter(|(tr, _)| t - tr <= ROLL_MAX_AGE)
                .map(|(_, r)| r),
            // The sentence's own latency (NMEA 0183 / UBX); NMEA 2000 carries none.
            latency: p.latency_s,
        });
        self.status.fix = q;
        self.supervisor.on_gnss(t, q);
    }

    /// A kind's source changed: logged; a change (not the first choice) disengages unless
    /// configured otherwise. The same source chosen again after it went stale is no change
    /// (the supervisor's input timeouts deal with the gap).
    fn on_source_change(&mut self, c: &SourceChange) {
        match c.from {
            None => tracing::info!(kind = ?c.kind, source = ?c.to, "input source selected"),
            Some(from) if from == c.to => {
                tracing::info!(kind = ?c.kind, source = ?c.to, "input source back")
            }
            Some(from) => {
                tracing::warn!(kind = ?c.kind, ?from, to = ?c.to, "input source changed");
                if self.sources.params().disengage_on_change {
                    self.supervisor.request_disengage();
                }
            }
        }
    }

    /// A job change set A / set B or select job asked for, for the job layer to make (then
    /// [`ControllerNode::finish_job_request`]).
    pub fn take_job_request(&mut self) -> Option<JobRequest> {
        self.operator.pending.take()
    }

    /// The job layer made (or could not make) the change `request` asked for: `result`, and
    /// with `done` the controller of the new job and its number (0 the configured job, k the
    /// k-th recorded line). Answered on the bus with the next period.
    pub fn finish_job_request(
        &mut self,
        request: JobRequest,
        result: OperatorReplyResult,
        done: Option<(super::Controller, u8)>,
    ) {
        if let Some((ctrl, job)) = done {
            self.replace_job(ctrl, job);
        }
        self.operator.reply(request.command(), result);
    }

    /// Drive another job from now on (not while engaged: the caller has checked): the
    /// supervisor, the bus link and the sources stay as they are.
    pub fn replace_job(&mut self, ctrl: super::Controller, job: u8) {
        self.supervisor.request_disengage();
        self.ctrl = ctrl;
        self.ctrl.set_engaged(false);
        self.operator.job = job;
        self.operator.point_a = None;
        self.cusp = false;
        self.approach_refused = false;
        self.supervised_line = None;
        self.supervised_segment = None;
        self.last_request = None;
        tracing::info!(job, "operator: job selected");
    }

    /// Say which job the node was built for (0 the configured one, k the k-th recorded line).
    pub fn set_job_number(&mut self, job: u8) {
        self.operator.job = job;
    }

    /// The job driven: 0 the configured one, k the k-th recorded line.
    pub fn job_number(&self) -> u8 {
        self.operator.job
    }

    /// A period without an ISO 11783-5 address (claiming, lost, or Cannot Claim): nothing but
    /// the claim goes out and the control loop idles (inputs are still taken), so that the
    /// first period with an address is the first period on the bus, as a replay of the log
    /// sees it. Steering stops: the operator engages again once the address is claimed.
    fn idle_without_address(&mut self) -> Cmd {
        let was_engaged = self.supervisor.state() == SafetyState::Engaged;
        self.supervisor.request_disengage();
        self.ctrl.set_engaged(false);
        let angle = self.supervisor.expected_wheel_angle();
        let state = if was_engaged || matches!(self.status.state, SafetyState::Fault(_)) {
            SafetyState::Fault(FaultCode::AddressLost)
        } else {
            SafetyState::Disengaged
        };
        self.status = NodeStatus {
            state,
            fault: FaultCode::AddressLost,
            engaged: false,
            isobus: self.iso.status(),
            ..self.status
        };
        Cmd {
            engaged: false,
            wheel_angle: angle,
            curvature: angle.tan() / self.supervisor.params().wheelbase,
            state,
            fault: FaultCode::AddressLost,
        }
    }

    /// One control period at `t`: appends the frames to send.
    pub fn tick(&mut self, t: f64, out: &mut Vec<Frame>) -> Cmd {
        // A period more than LATE_PERIOD·dt after the previous one: the loop could not run
        // from when it was due (the previous + dt) until now, and the inputs' timeouts do not
        // count that (safety::pauses). Judged from the periods' times alone, so a replay of
        // the bus log reproduces it.
        let dt = self.ctrl.params().dt;
        if let Some(prev) = self.last_tick_t.filter(|p| t - p > LATE_PERIOD * dt) {
            self.supervisor.on_loop_pause(prev + dt, t);
        }
        if t.is_finite() {
            self.last_tick_t = Some(t);
        }
        // The address claim first: until it stands, nothing else goes out.
        let address = self.iso.begin_tick(t, out);
        if let Some(a) = address {
            self.packer.set_source(a);
        }
        if address.is_none() {
            return self.idle_without_address();
        }
        self.supervisor.set_interlock(self.iso.interlock(t));
        let c = match self.ctrl.tick(t) {
            Ok(c) => {
                if self.guidance_failing {
                    self.guidance_failing = false;
                    tracing::info!("guidance recovered");
                }
                c
            }
            Err(e) => {
                // Logged once when it starts, not every control period while it persists.
                if self.guidance_failing {
                    tracing::trace!("guidance: {e}");
                } else {
                    self.guidance_failing = true;
                    tracing::error!("guidance: {e}; not steering until it clears");
                }
                super::ControlOutput {
                    wheel_angle: None,
                    estimate: None,
                    xte: None,
                    heading_error: None,
                    track: None,
                    direction: crate::geo::Direction::Forward,
                    path_curvature: None,
                }
            }
        };
        // While calibrating, the procedure's demand replaces the tracker's.
        let calibration = self.calibration_demand(t);
        // The frames before the command (direction request, operator replies) are moved after
        // it below: the command leaves first (a fix's latency counts to the command).
        let first = out.len();
        let request = match self.calibration_direction() {
            Some(r) => Some(r),
            None => self.direction_request(&c),
        };
        if let Some(r) = request {
            // `safety.max_stop_time_s` bounds the time *below* the minimum speed: the stop
            // starts counting once the vehicle is that slow, not when braking begins (from
            // 25 km/h at 0.5 m/s² braking alone takes 14 s).
            let slow = self.speed.abs() < self.supervisor.params().min_speed;
            self.supervisor.set_direction_change(t, self.cusp && slow);
            let due = self.last_request != Some(r) || self.ticks % self.status_every == 0;
            if due {
                if let Ok(f) = self.packer.pack(&DirectionRequest { direction: Some(r) }) {
                    out.push(f);
                }
                self.last_request = Some(r);
            }
        }
        if calibration.is_none() {
            self.supervise_path(c.estimate.as_ref());
        }
        if !self.operator.replies.is_empty() {
            let nudge = self.ctrl.guidance().nudge_m();
            // Sent in place and cleared: the queue keeps its room (no allocation per reply).
            for i in 0..self.operator.replies.len() {
                let (command, result, reason) = self.operator.replies[i];
                let reply = self.operator.frame(command, result, reason, nudge);
                if let Ok(f) = self.packer.pack(&reply) {
                    out.push(f);
                }
            }
            self.operator.replies.clear();
        }
        self.supervisor
            .set_path_curvature(c.path_curvature.unwrap_or(0.0));
        let cmd = match calibration {
            Some(demand) => self.supervisor.step(t, demand, Some(0.0), Some(0.0)),
            None => self
                .supervisor
                .step(t, c.wheel_angle, c.xte, c.heading_error),
        };
        self.calibration_sent(t, &cmd);
        self.answer_engage(&cmd);
        self.ctrl.set_engaged(cmd.engaged && calibration.is_none());
        let angle_deg = cmd.wheel_angle.to_degrees().clamp(-90.0, 90.0);
        // The steering servos the sensor's reading: command in its terms.
        let sensed_deg = (self.was_gain * cmd.wheel_angle + self.was_offset)
            .to_degrees()
            .clamp(-90.0, 90.0);

        let commands_at = out.len() - first;
        if matches!(self.output, OutputKind::Angle | OutputKind::Both) {
            if let Ok(f) = self.packer.pack(&SteeringCommand {
                angle: Some(sensed_deg),
                mode: Some(if cmd.engaged {
                    SteeringCommandMode::Engaged
                } else {
                    SteeringCommandMode::Disengaged
                }),
            }) {
                out.push(f);
            }
        }
        let due = self.ticks % self.command_every == 0 || self.last_intended != Some(cmd.engaged);
        let dest = self.iso.steering_destination();
        if let (true, Some(dest), true) = (
            matches!(self.output, OutputKind::Curvature | OutputKind::Both),
            dest,
            due,
        ) {
            // ISO 11783-7: km⁻¹, positive = right turn; ours is 1/m, positive = left.
            let k = (-cmd.curvature * 1000.0).clamp(-8032.0, 8031.75);
            if let Ok(mut f) = self.packer.pack(&GuidanceSystemCommand {
                curvature: Some(k),
                command_status: Some(if cmd.engaged {
                    GuidanceSystemCommandCommandStatus::IntendedToSteer
                } else {
                    GuidanceSystemCommandCommandStatus::NotIntendedToSteer
                }),
            }) {
                // Destination specific (PDU1): to the steering ECU.
                f.id = crate::can::isobus::with_destination(f.id, dest);
                out.push(f);
                self.last_intended = Some(cmd.engaged);
            }
        }
        if let Some(rest) = out.get_mut(first..) {
            rest.rotate_right(rest.len() - commands_at.min(rest.len()));
        }
        let refusal = self.engage_refusal();
        if refusal != self.status.engage_refusal && refusal != FaultCode::None {
            // Once per change: an operator holding the button logs one line.
            tracing::warn!(reason = ?refusal, "engage refused");
        }
        let g = self.ctrl.guidance();
        self.status = NodeStatus {
            state: cmd.state,
            fault: cmd.fault,
            engaged: cmd.engaged,
            engage_refusal: refusal,
            xte_m: c.xte,
            heading_error_deg: c.heading_error.map(f64::to_degrees),
            path_distance_m: self.supervisor.path_distance(),
            line: g.current_line(),
            block: g.index_block(),
            lines_done: g.lines_done(),
            line_worked_m: g.worked_m(),
            finished: g.is_finished(),
            wheel_angle_command_deg: angle_deg,
            steering_lost_motion_deg: self.ctrl.lost_motion().to_degrees(),
            job: self.operator.job,
            nudge_m: g.nudge_m(),
            isobus: self.iso.status(),
            ..self.status
        };
        if self.ticks % self.status_every == 0 {
            let s = &self.status;
            let msg = GuidanceStatus {
                state: GuidanceStatusState::from_raw(s.state.code()),
                // The DBC's range ends below the field's not-available codes (J1939-71): a
                // value past it is sent as not available.
                fault: Some(s.fault as u8 as f64).filter(|&f| f <= GUIDANCE_STATUS_FAULT_MAX),
                xte: s
                    .xte_m
                    .map(|x| (x * 1000.0).round().clamp(-32767.0, 32764.0)),
                heading_error: s.heading_error_deg.map(|h| h.clamp(-180.0, 180.0)),
                line: (s.line <= 64255).then_some(s.line as f64),
                block: (s.block <= 250).then_some(s.block as f64),
            };
            if let Ok(f) = self.packer.pack(&msg) {
                out.push(f);
            }
        }
        self.ticks += 1;
        cmd
    }
}
