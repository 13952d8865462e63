//! The guided procedure: a state machine fed the bus's inputs and ticked every control period,
//! answering the steering command to send and what the operator is asked to do. No I/O: the
//! caller (the simulator on the in-memory bus, a live bus) moves the frames.
//!
//! 1. **Stop.** The operator stops the tractor (the steering tests run at a standstill, below
//!    `standstill_speed`).
//! 2. **Steering tests**, twice: from 4° right of centre to centre (the play taken up from
//!    one side), then steps of ±`step` (dead time, lag, rate limit) and small steps forward and
//!    back (deadband and backlash). The two repetitions are fitted apart and must agree.
//! 3. **Drive**: the operator drives ahead at about `drive_speed`; the wheels are held at a
//!    sensed 0, ±`hold_angle`, ±`hold_angle`/2 in turn, settling then measuring the yaw rate
//!    (the WAS gain and zero, [`super::was`]).
//! 4. **Slalom**, driving on: the wheels swing ±`hold_angle` with a period of 4 s; the GNSS
//!    heading's delay against the sensor's yaw rate is the GNSS latency ([`super::latency`]).
//! 5. **Two-way pass** (unless `antenna_pass` is off): the operator steers by hand along a
//!    straight line marked on the ground (a string, a wheel track) for `PASS_TIME`, turns
//!    round, and drives back over the same line, the wheels in the same tracks; the antenna's
//!    lateral offset changes sign with the direction ([`super::antenna`]). The way back is
//!    taken once the heading is reversed (within 15°) and the antenna within 2 m of the out
//!    line, and recorded until it has passed the start of the out pass.
//!
//! Refused, with the reason: moving faster than allowed in a phase, the operator taking the
//! wheel (override status, a disengage), the wheels held away from the command, no response.

use super::antenna::MIN_OVERLAP_M;
use super::antenna_forward::DriveTrack;
use super::identify::SteeringRecord;
use super::latency::Slalom;
use super::was::Hold;
use super::{CalibrationError, CalibrationParams};
use crate::geo::wgs84::{EnuFrame, LatLon};
use crate::geo::{left_normal, vec_heading, wrap_angle, Vec2};
use crate::input::{Input, OperatorCommand, SensorStatus};

/// What the operator is asked to do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Instruction {
    /// Stop and stay stopped (hands off the wheel).
    Stop,
    /// Drive ahead at this speed, m/s, on open ground (hands off the wheel).
    Drive(f64),
    /// Steer by hand along the straight line marked on the ground at about this speed, m/s.
    Line(f64),
    /// Turn round (by hand) and drive back over the same line, the wheels in the same
    /// tracks, at about this speed, m/s.
    TurnBack(f64),
    /// Done: take over.
    Finished,
}

/// One tick's answer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tick {
    /// The command to send (sensor terms, rad); `None`: send a disengaged command.
    pub command: Option<f64>,
    pub instruction: Instruction,
    /// The phase, for progress messages.
    pub phase: &'static str,
}

/// The steering tests of one repetition: (offset from centre in units of the small-step
/// degree for the small steps, hold s). The first two entries preload the play from below.
const PRELOAD: [(f64, f64); 2] = [(-4.0, 3.0), (0.0, 4.0)];
/// Big steps (× `step`) then small steps (degrees).
const BIG: [(f64, f64); 4] = [(1.0, 4.0), (-1.0, 4.5), (1.0, 4.5), (0.0, 4.0)];
const SMALL: [(f64, f64); 7] = [
    (3.0, 2.5),
    (4.0, 2.5),
    (2.5, 2.5),
    (1.5, 2.5),
    (3.0, 2.5),
    (0.5, 2.5),
    (0.0, 3.0),
];
/// Repetitions of the steering tests.
pub const REPETITIONS: usize = 2;
/// Drive holds: settle, then measure, s.
const HOLD_SETTLE: f64 = 4.0;
const HOLD_MEASURE: f64 = 12.0;
/// Sensed angles held on the drive, × `hold_angle`: one way across, so that each move is a
/// small one (half `hold_angle`) and settles quickly.
const HOLDS: [f64; 5] = [1.0, 0.5, 0.0, -0.5, -1.0];
/// The slalom: period (s, not scaled: the swing must stay within what a slow steering
/// follows) and number of periods (scaled, at least 3).
const SLALOM_PERIOD: f64 = 4.0;
const SLALOM_PERIODS: f64 = 8.0;
/// The two-way pass: settling after the operator takes the wheel, s (not scaled), and the out
/// pass recorded, s (scaled, at least 8 s).
const PASS_SETTLE: f64 = 8.0;
const PASS_TIME: f64 = 24.0;
/// The way back starts within this heading (rad) and distance (m) of the out line reversed.
const BACK_HEADING: f64 = 0.26;
const BACK_DISTANCE: f64 = 2.0;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    WaitStop { since: Option<f64> },
    Steering,
    WaitDrive { since: Option<f64> },
    Holds,
    Slalom,
    PassOut,
    TurnBack { since: Option<f64> },
    PassBack,
    Done,
}

/// The out pass's line: where it starts, its direction and its stretch (along-track from
/// `origin`, m), once the out pass is recorded.
#[derive(Debug, Clone, Copy, PartialEq)]
struct OutLine {
    origin: Vec2,
    u: Vec2,
    start: f64,
}

/// The procedure's time scale, kept in a sane range (a non-finite or non-positive value is 1).
fn time_scale(p: &CalibrationParams) -> f64 {
    if p.time_scale.is_finite() && p.time_scale > 0.0 {
        p.time_scale.clamp(0.05, 10.0)
    } else {
        1.0
    }
}

/// The procedure's state and what it recorded.
#[derive(Debug, Clone)]
pub struct Session {
    pub(super) params: CalibrationParams,
    phase: Phase,
    phase_start: f64,
    /// Steering script: (offset rad, hold s), and where the pattern of each repetition starts
    /// (s from the steering phase's start).
    script: Vec<(f64, f64)>,
    pub(super) markers: Vec<(f64, f64)>,
    pub(super) steering: SteeringRecord,
    pub(super) holds: Vec<Hold>,
    pub(super) slalom: Slalom,
    /// When the slalom's position fixes arrived, s (the receiver's fix interval: what the
    /// supervisor's GNSS timeout times).
    pub(super) slalom_fixes: Vec<f64>,
    /// The holds' and the slalom's positions, headings and speeds (the antenna's forward
    /// offset, [`super::antenna_forward`]).
    pub(super) drive: DriveTrack,
    /// Antenna positions (time s, local ENU m) of the out and the back pass.
    pub(super) pass_out: Vec<(f64, Vec2)>,
    pub(super) pass_back: Vec<(f64, Vec2)>,
    out_line: Option<OutLine>,
    enu: Option<EnuFrame>,
    position: Option<Vec2>,
    /// The latest heading, or course over ground without a heading receiver, rad.
    direction: Option<f64>,
    last_command: Option<f64>,
    speed: Option<(f64, f64)>,
    wheel_speed: Option<(f64, f64)>,
    sensed: Option<f64>,
    heading_seen: bool,
    started: Option<f64>,
}

impl Session {
    pub fn new(params: CalibrationParams) -> Session {
        let small = 1f64.to_radians();
        let k = time_scale(&params);
        let mut script = Vec::new();
        for _ in 0..REPETITIONS {
            for (o, h) in PRELOAD {
                script.push((o * small, h * k));
            }
            for (o, h) in BIG {
                script.push((o * params.step, h * k));
            }
            for (o, h) in SMALL {
                script.push((o * small, h * k));
            }
        }
        Session {
            params,
            phase: Phase::WaitStop { since: None },
            phase_start: 0.0,
            script,
            markers: Vec::new(),
            steering: SteeringRecord {
                approach: 1.0,
                ..Default::default()
            },
            holds: Vec::new(),
            slalom: Slalom::default(),
            slalom_fixes: Vec::new(),
            drive: DriveTrack::default(),
            pass_out: Vec::new(),
            pass_back: Vec::new(),
            out_line: None,
            enu: None,
            position: None,
            direction: None,
            last_command: None,
            speed: None,
            wheel_speed: None,
            sensed: None,
            heading_seen: false,
            started: None,
        }
    }

    /// The steering tests' duration, s.
    pub fn steering_duration(&self) -> f64 {
        self.script.iter().map(|s| s.1).sum()
    }

    /// The drive's holds: settling time and whole hold, s.
    fn hold_times(&self) -> (f64, f64) {
        let k = time_scale(&self.params);
        (HOLD_SETTLE * k, (HOLD_SETTLE + HOLD_MEASURE) * k)
    }

    /// The slalom's duration, s (whole periods).
    fn slalom_duration(&self) -> f64 {
        (SLALOM_PERIODS * time_scale(&self.params)).round().max(3.0) * SLALOM_PERIOD
    }

    /// The out pass: settling, then recording, s.
    fn pass_times(&self) -> (f64, f64) {
        (PASS_SETTLE, (PASS_TIME * time_scale(&self.params)).max(8.0))
    }

    /// The procedure's duration once the tractor is stopped and driving when asked, s (the
    /// way back not counted: it depends on the operator's turn).
    pub fn nominal_duration(&self) -> f64 {
        let (settle, pass) = self.pass_times();
        let passes = if self.params.antenna_pass {
            2.0 * (settle + pass)
        } else {
            0.0
        };
        self.steering_duration()
            + HOLDS.len() as f64 * self.hold_times().1
            + self.slalom_duration()
            + passes
    }

    /// The command actually sent at `t` (sensor terms, rad), when something between the
    /// procedure and the steering limits it (the supervisor's rate limit): the steering tests
    /// are fitted to what the steering was sent, not to what the procedure asked.
    pub fn sent(&mut self, t: f64, command: f64) {
        if self.phase != Phase::Steering || !command.is_finite() {
            return;
        }
        let c = &mut self.steering.commands;
        match c.last_mut() {
            Some(last) if last.0 == t => last.1 = command,
            Some(last) if last.1 == command => {}
            _ => c.push((t, command)),
        }
    }

    /// Feed one input.
    pub fn on_input(&mut self, input: &Input) -> Result<(), CalibrationError> {
        match input {
            Input::WheelAngle(w) => {
                if w.status == SensorStatus::OperatorOverride && self.active() {
                    return Err(CalibrationError::OperatorIntervened {
                        t: w.t,
                        how: "the steering reports an operator override".into(),
                    });
                }
                if let Some(a) = w.angle.filter(|a| a.is_finite()) {
                    self.sensed = Some(a);
                    match self.phase {
                        Phase::Steering => self.steering.samples.push((w.t, a)),
                        Phase::Holds => {
                            if let Some(h) = self.measuring_hold(w.t) {
                                h.sensed.push((w.t, a));
                            }
                        }
                        Phase::Slalom => self.slalom.sensed.push((w.t, a)),
                        _ => {}
                    }
                }
            }
            Input::Heading(h) if h.heading.is_finite() => {
                self.heading_seen = true;
                self.slalom.course = false;
                self.direction = Some(h.heading);
                if let Some(hold) = self.measuring_hold(h.t) {
                    hold.heading.push((h.t, h.heading));
                }
                if self.phase == Phase::Slalom {
                    self.slalom.heading.push((h.t, h.heading));
                }
                if self.driving() {
                    self.drive.headings.push((h.t, h.heading));
                }
            }
            Input::CourseSpeed(c) => {
                if let Some(v) = c.speed_mps.filter(|v| v.is_finite()) {
                    self.speed = Some((c.t, v));
                    if let Some(hold) = self.measuring_hold(c.t) {
                        hold.speed.push((c.t, v));
                    }
                    if self.phase == Phase::Slalom {
                        self.slalom.speed.push((c.t, v));
                    }
                    if self.driving() {
                        self.drive.speeds.push((c.t, v));
                    }
                }
                // Without a heading receiver the course over ground turns at the same rate
                // (on a steady turn; in the slalom its crab is allowed for).
                if let Some(course) = c.course.filter(|c| c.is_finite() && !self.heading_seen) {
                    self.direction = Some(course);
                    if let Some(hold) = self.measuring_hold(c.t) {
                        hold.heading.push((c.t, course));
                    }
                    if self.phase == Phase::Slalom {
                        self.slalom.course = true;
                        self.slalom.heading.push((c.t, course));
                    }
                }
            }
            Input::Position(p) => {
                let ll = LatLon {
                    lat_deg: p.lat_deg,
                    lon_deg: p.lon_deg,
                };
                if ll.lat_deg.is_finite() && ll.lon_deg.is_finite() {
                    let pos = self.enu.get_or_insert_with(|| EnuFrame::new(ll)).to_enu(ll);
                    self.position = Some(pos);
                    match self.phase {
                        Phase::PassOut if self.pass_recording(p.t) => {
                            self.pass_out.push((p.t, pos))
                        }
                        Phase::PassBack => self.pass_back.push((p.t, pos)),
                        Phase::Slalom => self.slalom_fixes.push(p.t),
                        _ => {}
                    }
                    if self.driving() {
                        self.drive.positions.push((p.t, pos));
                    }
                }
            }
            Input::WheelSpeed(s) => {
                if let Some(v) = s.speed_mps.filter(|v| v.is_finite()) {
                    self.wheel_speed = Some((s.t, v));
                }
            }
            Input::Operator(o) if self.active() => {
                if matches!(
                    o.command,
                    OperatorCommand::Disengage | OperatorCommand::Pause
                ) {
                    return Err(CalibrationError::OperatorIntervened {
                        t: o.t,
                        how: format!("the operator sent {:?}", o.command),
                    });
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// Driving ahead with the wheels steered: the holds and the slalom.
    fn driving(&self) -> bool {
        matches!(self.phase, Phase::Holds | Phase::Slalom)
    }

    fn active(&self) -> bool {
        matches!(self.phase, Phase::Steering | Phase::Holds | Phase::Slalom)
    }

    /// Whether the out pass is being recorded at `t` (past its settling, within its time).
    fn pass_recording(&self, t: f64) -> bool {
        let (settle, pass) = self.pass_times();
        let into = t - self.phase_start;
        self.phase == Phase::PassOut && into >= settle && into < settle + pass
    }

    /// The out pass recorded: its line.
    fn out_line(&self) -> Option<OutLine> {
        let (first, last) = (self.pass_out.first()?.1, self.pass_out.last()?.1);
        let d = last - first;
        (d.norm() > 1.0).then(|| OutLine {
            origin: first,
            u: d / d.norm(),
            start: 0.0,
        })
    }

    /// The hold being measured at `t`, if any (the settling part is not recorded).
    fn measuring_hold(&mut self, t: f64) -> Option<&mut Hold> {
        if self.phase != Phase::Holds {
            return None;
        }
        let (settle, span) = self.hold_times();
        let into = t - self.phase_start;
        let i = (into / span).floor();
        if i < 0.0 || into - i * span < settle {
            return None;
        }
        self.holds.get_mut(i as usize)
    }

    /// The speed now: the larger of the latest GNSS and wheel speeds not older than 1 s.
    fn speed_at(&self, t: f64) -> Option<f64> {
        [self.speed, self.wheel_speed]
            .iter()
            .flatten()
            .filter(|(ts, _)| t - ts <= 1.0)
            .map(|(_, v)| v.abs())
            .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))))
    }

    fn enter(&mut self, phase: Phase, t: f64) {
        self.phase = phase;
        self.phase_start = t;
    }

    fn too_fast(&self, phase: &'static str, speed: f64, limit: f64) -> CalibrationError {
        CalibrationError::TooFast {
            phase,
            speed_kmh: speed * 3.6,
            limit_kmh: limit * 3.6,
        }
    }

    /// On the drive: not faster than allowed, not slower than needed.
    fn check_drive_speed(&self, speed: Option<f64>) -> Result<(), CalibrationError> {
        let p = &self.params;
        match speed {
            Some(v) if v > p.drive_speed_max => {
                Err(self.too_fast("the drive", v, p.drive_speed_max))
            }
            Some(v) if v < p.drive_speed_min => Err(CalibrationError::NoData(format!(
                "the tractor slowed to {:.1} km/h during the drive (at least {:.1})",
                v * 3.6,
                p.drive_speed_min * 3.6
            ))),
            _ => Ok(()),
        }
    }

    /// One control period at `t`.
    pub fn tick(&mut self, t: f64) -> Result<Tick, CalibrationError> {
        let p = self.params;
        let started = *self.started.get_or_insert(t);
        let speed = self.speed_at(t);
        let limit = |a: f64| a.clamp(-p.max_angle, p.max_angle);
        let out = match self.phase {
            Phase::WaitStop { since } => {
                let stopped = speed.is_some_and(|v| v <= p.standstill_speed);
                let since = if stopped { since.or(Some(t)) } else { None };
                // Stopped for a second (scaled with the holds): not just passing through zero.
                if since.is_some_and(|s| t - s >= (time_scale(&p)).max(0.3)) {
                    self.enter(Phase::Steering, t);
                    self.steering.commands.clear();
                    self.steering.samples.clear();
                    // Room for a 200 Hz sensor and a command every 5 ms, so that recording
                    // does not allocate in the control period (a daemon runs this).
                    let n = (self.steering_duration() * 200.0) as usize + 256;
                    self.steering.samples.reserve(n);
                    self.steering.commands.reserve(n);
                    return self.tick(t);
                }
                if t - started > p.wait_timeout {
                    return Err(match speed {
                        Some(v) => {
                            self.too_fast("stopping for the steering tests", v, p.standstill_speed)
                        }
                        None => CalibrationError::NoData(
                            "no speed (GNSS or wheel speed) received".into(),
                        ),
                    });
                }
                self.phase = Phase::WaitStop { since };
                Tick {
                    command: None,
                    instruction: Instruction::Stop,
                    phase: "stop the tractor",
                }
            }
            Phase::Steering => {
                if let Some(v) = speed.filter(|v| *v > p.standstill_speed) {
                    return Err(self.too_fast("steering tests", v, p.standstill_speed));
                }
                let into = t - self.phase_start;
                let mut acc = 0.0;
                let mut command = None;
                let per_rep = PRELOAD.len() + BIG.len() + SMALL.len();
                for (k, &(o, h)) in self.script.iter().enumerate() {
                    if k % per_rep == PRELOAD.len() && self.markers.len() <= k / per_rep {
                        let rep_end = acc
                            + self.script[k..k + per_rep - PRELOAD.len()]
                                .iter()
                                .map(|s| s.1)
                                .sum::<f64>();
                        self.markers
                            .push((self.phase_start + acc, self.phase_start + rep_end));
                    }
                    if into < acc + h {
                        command = Some(limit(o));
                        break;
                    }
                    acc += h;
                }
                match command {
                    Some(c) => {
                        if self.last_command != Some(c) {
                            self.steering.commands.push((t, c));
                        }
                        Tick {
                            command: Some(c),
                            instruction: Instruction::Stop,
                            phase: "steering tests",
                        }
                    }
                    None => {
                        self.enter(Phase::WaitDrive { since: None }, t);
                        return self.tick(t);
                    }
                }
            }
            Phase::WaitDrive { since } => {
                if let Some(v) = speed.filter(|v| *v > p.drive_speed_max) {
                    return Err(self.too_fast("the drive", v, p.drive_speed_max));
                }
                let ok = speed.is_some_and(|v| v >= p.drive_speed_min);
                let since = if ok { since.or(Some(t)) } else { None };
                if since.is_some_and(|s| t - s >= (2.0 * time_scale(&p)).max(0.5)) {
                    self.enter(Phase::Holds, t);
                    let n = (self.hold_times().1 * 200.0) as usize + 64;
                    self.holds = (0..HOLDS.len())
                        .map(|_| Hold {
                            sensed: Vec::with_capacity(n),
                            heading: Vec::with_capacity(n),
                            speed: Vec::with_capacity(n),
                        })
                        .collect();
                    return self.tick(t);
                }
                if t - self.phase_start > p.wait_timeout {
                    return Err(CalibrationError::NoData(format!(
                        "the tractor did not reach {:.1} km/h within {:.0} s",
                        p.drive_speed_min * 3.6,
                        p.wait_timeout
                    )));
                }
                self.phase = Phase::WaitDrive { since };
                Tick {
                    command: Some(0.0),
                    instruction: Instruction::Drive(p.drive_speed),
                    phase: "drive ahead",
                }
            }
            Phase::Holds => {
                self.check_drive_speed(speed)?;
                let (settle, span) = self.hold_times();
                let into = t - self.phase_start;
                let i = (into / span).floor() as usize;
                match HOLDS.get(i) {
                    Some(&h) => {
                        let c = limit(h * p.hold_angle);
                        // The wheels must follow while measuring: held away, someone steers.
                        if into - i as f64 * span > settle {
                            if let Some(s) =
                                self.sensed.filter(|s| (s - c).abs() > p.follow_tolerance)
                            {
                                return Err(CalibrationError::OperatorIntervened {
                                    t,
                                    how: format!(
                                        "the wheels are held at {:.1}° against a command of {:.1}°",
                                        s.to_degrees(),
                                        c.to_degrees()
                                    ),
                                });
                            }
                        }
                        Tick {
                            command: Some(c),
                            instruction: Instruction::Drive(p.drive_speed),
                            phase: "drive: wheel-angle sensor",
                        }
                    }
                    None => {
                        self.enter(Phase::Slalom, t);
                        let n = (self.slalom_duration() * 200.0) as usize + 64;
                        self.slalom.sensed.reserve(n);
                        self.slalom.heading.reserve(n / 10);
                        self.slalom.speed.reserve(n / 10);
                        self.slalom_fixes.reserve(n / 10);
                        return self.tick(t);
                    }
                }
            }
            Phase::Slalom => {
                self.check_drive_speed(speed)?;
                let into = t - self.phase_start;
                if into >= self.slalom_duration() {
                    if !p.antenna_pass {
                        self.enter(Phase::Done, t);
                        return self.tick(t);
                    }
                    self.enter(Phase::PassOut, t);
                    let n = (self.pass_times().1 * 50.0) as usize + 64;
                    self.pass_out.reserve(n);
                    self.pass_back.reserve(4 * n);
                    return self.tick(t);
                }
                // From and back to the last hold's side (−hold_angle): a cosine.
                let phase = 2.0 * std::f64::consts::PI * into / SLALOM_PERIOD;
                Tick {
                    command: Some(limit(-p.hold_angle * phase.cos())),
                    instruction: Instruction::Drive(p.drive_speed),
                    phase: "drive: slalom (GNSS latency)",
                }
            }
            Phase::PassOut => {
                if let Some(v) = speed.filter(|v| *v > p.drive_speed_max) {
                    return Err(self.too_fast("the two-way pass", v, p.drive_speed_max));
                }
                let (settle, pass) = self.pass_times();
                if t - self.phase_start >= settle + pass {
                    self.out_line = self.out_line();
                    if self.out_line.is_none() {
                        return Err(CalibrationError::NoData(
                            "the tractor did not move along the line".into(),
                        ));
                    }
                    self.enter(Phase::TurnBack { since: None }, t);
                    return self.tick(t);
                }
                Tick {
                    command: None,
                    instruction: Instruction::Line(p.drive_speed),
                    phase: "two-way pass: out along the line",
                }
            }
            Phase::TurnBack { since } => {
                if let Some(v) = speed.filter(|v| *v > p.drive_speed_max) {
                    return Err(self.too_fast("the two-way pass", v, p.drive_speed_max));
                }
                let back = match (self.out_line, self.position, self.direction) {
                    (Some(l), Some(pos), Some(dir)) => {
                        let across = (pos - l.origin).dot(&left_normal(&l.u));
                        let heading_back = wrap_angle(dir - vec_heading(&(-l.u))).abs();
                        across.abs() < BACK_DISTANCE && heading_back < BACK_HEADING
                    }
                    _ => false,
                };
                let since = if back { since.or(Some(t)) } else { None };
                if since.is_some_and(|s| t - s >= 1.0) {
                    self.enter(Phase::PassBack, t);
                    return self.tick(t);
                }
                if t - self.phase_start > 4.0 * p.wait_timeout {
                    return Err(CalibrationError::NoData(format!(
                        "the tractor did not come back onto the line within {:.0} s",
                        4.0 * p.wait_timeout
                    )));
                }
                self.phase = Phase::TurnBack { since };
                Tick {
                    command: None,
                    instruction: Instruction::TurnBack(p.drive_speed),
                    phase: "two-way pass: turn round onto the same line",
                }
            }
            Phase::PassBack => {
                if let Some(v) = speed.filter(|v| *v > p.drive_speed_max) {
                    return Err(self.too_fast("the two-way pass", v, p.drive_speed_max));
                }
                // Done once past the start of the out pass, or after three times its time.
                let past = match (self.out_line, self.position) {
                    (Some(l), Some(pos)) => (pos - l.origin).dot(&l.u) < l.start - 2.0,
                    _ => false,
                };
                let long = t - self.phase_start > 3.0 * self.pass_times().1 + MIN_OVERLAP_M;
                if past || long {
                    self.enter(Phase::Done, t);
                    return self.tick(t);
                }
                Tick {
                    command: None,
                    instruction: Instruction::Line(p.drive_speed),
                    phase: "two-way pass: back along the line",
                }
            }
            Phase::Done => Tick {
                command: None,
                instruction: Instruction::Finished,
                phase: "done",
            },
        };
        self.last_command = out.command;
        Ok(out)
    }

    /// Whether the procedure has run to its end.
    pub fn is_done(&self) -> bool {
        self.phase == Phase::Done
    }
}
