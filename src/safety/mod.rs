//! The safety supervisor: the only path from the tracker to the steering command.
//!
//! In the manner of openpilot's panda safety, it is a small state machine that knows nothing
//! of planning. It watches input freshness and quality, counts bad frames, gates engagement on
//! the operator and on the vehicle being close to the line, and limits every engaged command
//! (angle, rate, lateral acceleration). Everything is a pure function of the inputs and the
//! times the caller passes in: no clocks, no I/O, no allocation.
//!
//! States: `Disengaged` → `Ready` (all inputs fresh and good) → `Engaged` (on an operator
//! engage) → `Fault(code)` (an engaged condition broke) → `Disengaged` once the condition has
//! cleared. Engaging needs an operator engage received while `Ready`; nothing re-engages by
//! itself. On a work line it also watches the tracking itself ([`tracking`]): a weave is
//! `tracking_unstable`, a persistent offset `off_line`, both held until the line changes or the
//! operator disengages; a line the vehicle cannot follow at its speed is refused at engage
//! and, engaged, given back as soon as the line (or the speed on it) makes it so
//! (`line_unfollowable`, held like the tracking faults). On every other path (a turn, a transit,
//! an approach, reversing) it watches the distance from the path: `off_path`, held the same way.

mod fault;
pub mod heading;
pub mod pauses;
pub mod tracking;

pub use fault::FaultCode;
pub use heading::{HeadingCheck, HeadingCheckParams};
use serde::Serialize;
pub use tracking::{TrackingMonitor, TrackingParams, TrackingVerdict};

/// Supervisor state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SafetyState {
    Disengaged,
    Ready,
    Engaged,
    Fault(FaultCode),
}

impl SafetyState {
    /// The state's number on the bus (guidance status frame).
    pub fn code(&self) -> u8 {
        match self {
            SafetyState::Disengaged => 0,
            SafetyState::Ready => 1,
            SafetyState::Engaged => 2,
            SafetyState::Fault(_) => 3,
        }
    }
}

pub use crate::input::FixQuality;

/// Inputs whose frames carry a counter and a CRC.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(usize)]
pub enum CheckedInput {
    WheelAngle = 0,
    Operator = 1,
    Gnss = 2,
    Imu = 3,
}
const CHECKED_INPUTS: usize = 4;

/// Tuning of the supervisor, SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct SafetyParams {
    /// GNSS older than this is stale, s (default 0.3).
    pub gnss_timeout: f64,
    /// RTK float is tolerated this long, s (default 0: never).
    pub rtk_float_tolerance: f64,
    /// Wheel angle older than this is stale, s (default 0.1).
    pub wheel_angle_timeout: f64,
    /// Validity score at which an input counts as invalid (+1 per bad frame, −1 per good one).
    pub invalid_threshold: u32,
    /// Allowed speed range, m/s (defaults 0.5–25 km/h).
    pub min_speed: f64,
    pub max_speed: f64,
    /// During a requested stop for a change of direction the speed may be below `min_speed`
    /// for at most this long, s (default 10).
    pub max_stop_time: f64,
    /// Measured angle this far from the command counts toward an override, rad.
    pub override_angle: f64,
    /// … for longer than this, s.
    pub override_time: f64,
    /// Engaging needs |XTE| below this, m (default 1).
    pub max_engage_xte: f64,
    /// Engaging needs |heading error| below this, rad (default 60°).
    pub max_engage_heading_error: f64,
    /// Command limits: angle, rad; rate, rad/s; lateral acceleration v²·κ, m/s².
    pub max_wheel_angle: f64,
    pub max_wheel_rate: f64,
    pub a_lat_max: f64,
    /// Wheelbase, m (curvature ↔ angle).
    pub wheelbase: f64,
    /// Model of the steering actuator used to judge an override: the measured angle is
    /// compared with where the actuator should be (the command after this dead time, s …
    pub actuator_dead_time: f64,
    /// … through a first-order lag of this time constant, s …
    pub actuator_tau: f64,
    /// … at most this fast, rad/s), not with the raw command.
    pub actuator_rate: f64,
    /// Tracking supervision on work lines (oscillation, offset, unfollowable lines).
    pub tracking: TrackingParams,
    /// Heading against course over ground.
    pub heading: HeadingCheckParams,
}

impl Default for SafetyParams {
    fn default() -> Self {
        SafetyParams {
            gnss_timeout: 0.3,
            rtk_float_tolerance: 0.0,
            wheel_angle_timeout: 0.1,
            invalid_threshold: 5,
            min_speed: 0.5 / 3.6,
            max_speed: 25.0 / 3.6,
            max_stop_time: 10.0,
            override_angle: 8f64.to_radians(),
            override_time: 0.5,
            max_engage_xte: 1.0,
            max_engage_heading_error: 60f64.to_radians(),
            max_wheel_angle: 35f64.to_radians(),
            max_wheel_rate: 45f64.to_radians(),
            a_lat_max: 2.0,
            wheelbase: 3.0,
            actuator_dead_time: 0.05,
            actuator_tau: 0.15,
            actuator_rate: 30f64.to_radians(),
            tracking: TrackingParams::default(),
            heading: HeadingCheckParams::default(),
        }
    }
}

impl SafetyParams {
    /// The largest wheel angle allowed at `speed` (m/s), rad: the angle limit, and the angle
    /// whose kinematic lateral acceleration v²·tan δ / L is `a_lat_max`.
    pub fn angle_limit(&self, speed: f64) -> f64 {
        let v2 = speed * speed;
        let by_alat = if v2 > 1e-9 {
            (self.a_lat_max * self.wheelbase / v2).atan()
        } else {
            self.max_wheel_angle
        };
        self.max_wheel_angle.min(by_alat)
    }
}

/// What goes to the steering frame this period.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SteeringCommand {
    /// Engaged (steer to `wheel_angle`) or not (the actuator must not steer).
    pub engaged: bool,
    /// Front-wheel angle, rad: the limited demand when engaged, the measured angle otherwise.
    pub wheel_angle: f64,
    /// Curvature of `wheel_angle`, 1/m.
    pub curvature: f64,
    pub state: SafetyState,
    /// Why not engaged (or `None`).
    pub fault: FaultCode,
}

/// The supervisor.
#[derive(Debug, Clone)]
pub struct Supervisor {
    params: SafetyParams,
    state: SafetyState,
    gnss_t: Option<f64>,
    fix: FixQuality,
    float_since: Option<f64>,
    wheel_t: Option<f64>,
    wheel_angle: f64,
    override_bit: bool,
    actuator_fault: bool,
    speed_t: Option<f64>,
    speed: f64,
    /// Since when a stop for a change of direction is under way.
    stopping_since: Option<f64>,
    scores: [u32; CHECKED_INPUTS],
    diverged_since: Option<f64>,
    last_command: f64,
    last_t: Option<f64>,
    engage_requested: bool,
    bus_down: bool,
    /// A condition outside the inputs that forbids steering (the node's bus and steering-ECU
    /// state), `FaultCode::None` when clear.
    interlock: FaultCode,
    last_refusal: FaultCode,
    /// Where the actuator model says the wheels should be, rad.
    expected: f64,
    /// Recent engaged commands (time, angle) for the model's dead time.
    history: [(f64, f64); HISTORY],
    history_len: usize,
    history_head: usize,
    /// The work line being driven (None: a turn, an approach, reversing, nothing).
    work_line: Option<u64>,
    /// Its sharpest curvature, 1/m.
    line_curvature: f64,
    /// The path's curvature at the vehicle, 1/m (positive left; [`Supervisor::set_path_curvature`]).
    path_curvature: f64,
    /// The vehicle's distance from the path this period, m ([`Supervisor::set_path_distance`]).
    path_distance: Option<f64>,
    tracking: TrackingMonitor,
    /// A tracking fault held until the line changes or the operator disengages.
    tracking_latch: Option<FaultCode>,
    heading_check: HeadingCheck,
    /// The control loop's own late periods: not counted against the inputs' ages.
    pauses: pauses::LoopPauses,
}

const HISTORY: usize = 64;

impl Supervisor {
    pub fn new(params: SafetyParams) -> Self {
        Supervisor {
            params,
            state: SafetyState::Disengaged,
            gnss_t: None,
            fix: FixQuality::None,
            float_since: None,
            wheel_t: None,
            wheel_angle: 0.0,
            override_bit: false,
            actuator_fault: false,
            speed_t: None,
            speed: 0.0,
            stopping_since: None,
            scores: [0; CHECKED_INPUTS],
            diverged_since: None,
            last_command: 0.0,
            last_t: None,
            engage_requested: false,
            bus_down: false,
            interlock: FaultCode::None,
            last_refusal: FaultCode::None,
            expected: 0.0,
            history: [(0.0, 0.0); HISTORY],
            history_len: 0,
            history_head: 0,
            work_line: None,
            line_curvature: 0.0,
            path_curvature: 0.0,
            path_distance: None,
            tracking: TrackingMonitor::new(),
            tracking_latch: None,
            heading_check: HeadingCheck::new(),
            pauses: pauses::LoopPauses::default(),
        }
    }

    /// The control loop could not run from `from` until `to` (s, the inputs' clock): a period
    /// that woke up late. The inputs' timeouts do not count that time, up to each timeout (see
    /// [`pauses`]): where the senders froze with the loop, the late period must not give the
    /// steering back for it.
    pub fn on_loop_pause(&mut self, from: f64, to: f64) {
        self.pauses.record(from, to);
    }

    /// The line being driven: `Some(id)` on a work line, where the tracking is supervised;
    /// `None` in a turn, an approach or reversing. A change of line restarts the supervision
    /// and clears a held tracking fault. `max_curvature` is the line's sharpest curvature, 1/m
    /// (the engage gate's `line_unfollowable`).
    pub fn set_line(&mut self, line: Option<u64>, max_curvature: f64) {
        if line != self.work_line {
            self.work_line = line;
            self.tracking.reset();
            self.tracking_latch = None;
        }
        self.line_curvature = if max_curvature.is_finite() {
            max_curvature.abs()
        } else {
            0.0
        };
    }

    /// The vehicle's distance from the path it is steered along this period (to the path's
    /// nearest segment), m; `None` when there is no path or no pose. Watched off work lines:
    /// `off_path` (see [`tracking`]).
    pub fn set_path_distance(&mut self, distance: Option<f64>) {
        self.path_distance = distance.filter(|d| d.is_finite());
    }

    /// The vehicle's distance from the path, as last set, m.
    pub fn path_distance(&self) -> Option<f64> {
        self.path_distance
    }

    /// The path's curvature at the vehicle this period, 1/m (positive left): a swing of the
    /// cross-track error that follows a change of the path's bend is the path's, not a weave
    /// (see [`tracking`]).
    pub fn set_path_curvature(&mut self, curvature: f64) {
        self.path_curvature = if curvature.is_finite() {
            curvature
        } else {
            0.0
        };
    }

    /// Would the current line be refused as unfollowable at the current speed?
    pub fn line_unfollowable(&self) -> bool {
        let p = &self.params;
        tracking::line_unfollowable(
            self.line_curvature,
            self.speed,
            p.wheelbase,
            p.max_wheel_angle,
            p.a_lat_max,
            p.actuator_rate.min(p.max_wheel_rate),
            p.tracking.off_line,
        )
    }

    /// The command the actuator acts on at `t`: the newest one at least a dead time old.
    fn delayed_command(&self, t: f64) -> Option<f64> {
        let cutoff = t - self.params.actuator_dead_time;
        (0..self.history_len)
            .map(|i| self.history[(self.history_head + HISTORY - 1 - i) % HISTORY])
            .find(|(tc, _)| *tc <= cutoff + 1e-9)
            .map(|(_, c)| c)
    }

    fn remember_command(&mut self, t: f64, angle: f64) {
        self.history[self.history_head] = (t, angle);
        self.history_head = (self.history_head + 1) % HISTORY;
        self.history_len = (self.history_len + 1).min(HISTORY);
    }

    /// Advance the actuator model by `dt` to time `t`.
    fn update_expected(&mut self, t: f64, dt: f64) {
        let Some(target) = self.delayed_command(t) else {
            return;
        };
        let p = &self.params;
        let wanted = if p.actuator_tau > 0.0 {
            (target - self.expected) * (dt / p.actuator_tau).min(1.0)
        } else {
            target - self.expected
        };
        let step = p.actuator_rate * dt;
        self.expected += wanted.clamp(-step, step);
    }

    /// Where the actuator model says the wheels should be, rad.
    pub fn expected_wheel_angle(&self) -> f64 {
        self.expected
    }

    pub fn params(&self) -> &SafetyParams {
        &self.params
    }

    /// Replace the tuning (limits, timeouts) atomically, keeping the state.
    pub fn set_params(&mut self, params: SafetyParams) {
        self.params = params;
    }

    pub fn state(&self) -> SafetyState {
        self.state
    }

    /// The reason the last engage request was refused.
    pub fn last_refusal(&self) -> FaultCode {
        self.last_refusal
    }

    /// A GNSS solution arrived at `t` (s).
    pub fn on_gnss(&mut self, t: f64, quality: FixQuality) {
        if !t.is_finite() {
            return;
        }
        self.gnss_t = Some(t);
        if quality == FixQuality::RtkFloat {
            if self.fix != FixQuality::RtkFloat || self.float_since.is_none() {
                self.float_since = Some(t);
            }
        } else {
            self.float_since = None;
        }
        self.fix = quality;
    }

    /// A valid wheel-angle frame arrived at `t`: measured angle (rad), the operator-override
    /// and fault bits of its status byte.
    pub fn on_wheel_angle(&mut self, t: f64, angle: f64, override_bit: bool, fault_bit: bool) {
        if !t.is_finite() || !angle.is_finite() {
            return;
        }
        self.wheel_t = Some(t);
        self.wheel_angle = angle;
        self.override_bit = override_bit;
        self.actuator_fault = fault_bit;
    }

    /// A GNSS heading (rad, CCW from East) arrived at `t`, for the heading check.
    pub fn on_heading(&mut self, t: f64, heading: f64) {
        self.heading_check.on_heading(t, heading);
    }

    /// A GNSS course (rad, CCW from East) and speed over ground (m/s) arrived at `t`, for the
    /// heading check.
    pub fn on_course(&mut self, t: f64, course: f64, speed: f64) {
        self.heading_check.on_course(t, course, speed);
    }

    /// The latest mismatch between the heading's expected course and the course, rad.
    pub fn heading_mismatch(&self) -> f64 {
        self.heading_check.mismatch()
    }

    /// A stop for a change of direction (a cusp) starts (`true`) or ends at `t`: while it
    /// lasts, and for at most `max_stop_time`, a speed below `min_speed` is not a fault.
    pub fn set_direction_change(&mut self, t: f64, active: bool) {
        if !active {
            self.stopping_since = None;
        } else if self.stopping_since.is_none() && t.is_finite() {
            self.stopping_since = Some(t);
        }
    }

    /// Vehicle speed (m/s, signed) measured at `t`.
    pub fn on_speed(&mut self, t: f64, speed: f64) {
        if t.is_finite() && speed.is_finite() {
            self.speed_t = Some(t);
            self.speed = speed;
        }
    }

    /// The counter/CRC check of one frame of a checked input (opendbc's scheme).
    pub fn on_frame_check(&mut self, input: CheckedInput, ok: bool) {
        let s = &mut self.scores[input as usize];
        if ok {
            *s = s.saturating_sub(1);
        } else {
            *s = (*s + 1).min(self.params.invalid_threshold * 2);
        }
    }

    /// The bus went down or came back.
    pub fn on_bus(&mut self, up: bool) {
        self.bus_down = !up;
    }

    /// A condition outside the inputs forbids steering (`code`), or none does
    /// (`FaultCode::None`): the node's address claim and the steering ECU's readiness.
    pub fn set_interlock(&mut self, code: FaultCode) {
        self.interlock = code;
    }

    /// The operator asked to engage. Acted on in the next [`Supervisor::step`].
    pub fn request_engage(&mut self) {
        self.engage_requested = true;
    }

    /// The operator asked to disengage (also pause): immediate.
    pub fn request_disengage(&mut self) {
        self.engage_requested = false;
        if self.state == SafetyState::Engaged {
            self.state = SafetyState::Disengaged;
        }
    }

    /// The path being driven ends here and the next does not start here (a gap in the plan):
    /// engaged, the steering is given back with `code` at the next step, held like a tracking
    /// fault (until a line change or the operator acknowledges).
    pub fn give_back(&mut self, code: FaultCode) {
        if self.state == SafetyState::Engaged {
            self.tracking_latch = Some(code);
        }
    }

    /// The operator acknowledged a held tracking fault (a disengage command while in it): the
    /// line may be engaged again.
    pub fn acknowledge(&mut self) {
        self.tracking_latch = None;
    }

    /// The held tracking fault, if any.
    pub fn tracking_fault(&self) -> Option<FaultCode> {
        self.tracking_latch
    }

    /// Is `input` currently counted as invalid?
    pub fn input_invalid(&self, input: CheckedInput) -> bool {
        self.scores[input as usize] >= self.params.invalid_threshold
    }

    /// The first condition that forbids steering at `t`, or `FaultCode::None`.
    fn input_fault(&self, t: f64) -> FaultCode {
        let p = &self.params;
        let fresh = |last: Option<f64>, timeout: f64| {
            last.is_some_and(|l| self.pauses.age(l, t, timeout) <= timeout && t >= l - 1.0)
        };
        if self.bus_down {
            return FaultCode::BusDown;
        }
        if self.interlock != FaultCode::None {
            return self.interlock;
        }
        if !fresh(self.gnss_t, p.gnss_timeout) {
            return FaultCode::GnssTimeout;
        }
        match self.fix {
            FixQuality::RtkFixed => {}
            FixQuality::RtkFloat => {
                let since = self.float_since.unwrap_or(t);
                if p.rtk_float_tolerance <= 0.0 || t - since > p.rtk_float_tolerance {
                    return FaultCode::FixQuality;
                }
            }
            _ => return FaultCode::FixQuality,
        }
        if self.input_invalid(CheckedInput::Gnss) {
            return FaultCode::FixQuality;
        }
        if !fresh(self.wheel_t, p.wheel_angle_timeout) {
            return FaultCode::WheelAngleTimeout;
        }
        if self.input_invalid(CheckedInput::WheelAngle) {
            return FaultCode::WheelAngleInvalid;
        }
        if self.input_invalid(CheckedInput::Operator) {
            return FaultCode::OperatorInvalid;
        }
        if self.actuator_fault {
            return FaultCode::ActuatorFault;
        }
        if self.override_bit {
            return FaultCode::OperatorOverride;
        }
        let stopping = self
            .stopping_since
            .is_some_and(|since| t - since <= p.max_stop_time);
        let speed_ok = fresh(self.speed_t, p.gnss_timeout.max(p.wheel_angle_timeout))
            && (self.speed.abs() >= p.min_speed || stopping)
            && self.speed.abs() <= p.max_speed;
        if !speed_ok {
            return FaultCode::SpeedOutOfRange;
        }
        FaultCode::None
    }

    /// One control period at `t` (s). `demand` is the tracker's wheel angle (rad), with the
    /// cross-track and heading errors it was computed from; `None` when guidance has nothing to
    /// steer by. Returns the command to send.
    pub fn step(
        &mut self,
        t: f64,
        demand: Option<f64>,
        xte: Option<f64>,
        heading_error: Option<f64>,
    ) -> SteeringCommand {
        let dt = match self.last_t {
            Some(l) if t.is_finite() && t > l => (t - l).min(1.0),
            _ => 0.0,
        };
        if t.is_finite() {
            self.last_t = Some(t);
        }
        let t = if t.is_finite() { t } else { f64::NEG_INFINITY };
        let mut fault = self.input_fault(t);
        let demand = demand.filter(|d| d.is_finite());
        let p = &self.params;
        let mismatch = self.heading_check.update(
            &p.heading,
            t,
            p.gnss_timeout,
            self.wheel_angle,
            p.wheelbase,
            self.speed < 0.0,
        );
        if fault == FaultCode::None && mismatch {
            fault = FaultCode::HeadingMismatch;
        }
        if fault == FaultCode::None && demand.is_none() {
            fault = FaultCode::NoGuidance;
        }
        if fault == FaultCode::None {
            if let Some(held) = self.tracking_latch {
                fault = held;
            }
        }
        // Operator override by divergence: the measured angle far, for too long, from where
        // the actuator should have taken the wheels.
        if self.state == SafetyState::Engaged {
            self.update_expected(t, dt);
        }
        if self.state == SafetyState::Engaged && fault == FaultCode::None {
            if (self.wheel_angle - self.expected).abs() > self.params.override_angle {
                let since = *self.diverged_since.get_or_insert(t);
                if t - since > self.params.override_time {
                    fault = FaultCode::OperatorOverride;
                }
            } else {
                self.diverged_since = None;
            }
        } else {
            self.diverged_since = None;
        }
        // Tracking on a work line: a weave or a persistent offset.
        if self.state == SafetyState::Engaged
            && fault == FaultCode::None
            && self.work_line.is_some()
        {
            // Engaged, the line stays under the engage gate's check: one that starts while
            // engaged, or that the speed has made unfollowable since the engage, is given back
            // at once rather than weaved on until it is `off_line`.
            let unfollowable = self.line_unfollowable();
            let p = &self.params;
            // The wheels' swings tell a weave on a straight line only: a line whose sharpest
            // bend asks for half the band or more moves them by design.
            let bend_wheel_angle = (p.wheelbase * self.line_curvature).atan();
            let watch_wheel = bend_wheel_angle < 0.5 * p.tracking.unstable_wheel;
            let path_bend = if self.path_curvature.abs() > tracking::BEND_CURVATURE {
                self.path_curvature.signum() as i8
            } else {
                0
            };
            let verdict = self.tracking.update(
                &p.tracking,
                t,
                dt,
                xte,
                self.wheel_angle,
                watch_wheel,
                path_bend,
                self.speed,
            );
            let code = match verdict {
                _ if unfollowable => FaultCode::LineUnfollowable,
                TrackingVerdict::Ok => FaultCode::None,
                TrackingVerdict::Unstable => FaultCode::TrackingUnstable,
                TrackingVerdict::OffLine => FaultCode::OffLine,
                TrackingVerdict::OffPath => FaultCode::OffPath,
            };
            if code != FaultCode::None {
                self.tracking_latch = Some(code);
                fault = code;
            }
        } else if self.state == SafetyState::Engaged && fault == FaultCode::None {
            // Off work lines (turns, transits, approaches, reversing): the path lost.
            let verdict =
                self.tracking
                    .update_manoeuvre(&self.params.tracking, t, self.path_distance);
            if verdict == TrackingVerdict::OffPath {
                self.tracking_latch = Some(FaultCode::OffPath);
                fault = FaultCode::OffPath;
            }
        }

        match self.state {
            SafetyState::Engaged if fault != FaultCode::None => {
                self.state = SafetyState::Fault(fault);
            }
            SafetyState::Fault(_) if fault == FaultCode::None => {
                self.state = SafetyState::Ready;
            }
            SafetyState::Fault(_) => self.state = SafetyState::Fault(fault),
            SafetyState::Disengaged | SafetyState::Ready => {
                self.state = if fault == FaultCode::None {
                    SafetyState::Ready
                } else {
                    SafetyState::Disengaged
                };
            }
            SafetyState::Engaged => {}
        }

        if std::mem::take(&mut self.engage_requested) {
            let p = &self.params;
            let refusal = if self.state != SafetyState::Ready {
                if fault == FaultCode::None {
                    FaultCode::None
                } else {
                    fault
                }
            } else if !xte.is_some_and(|x| x.abs() < p.max_engage_xte) {
                FaultCode::XteTooLarge
            } else if !heading_error.is_some_and(|h| h.abs() < p.max_engage_heading_error) {
                FaultCode::HeadingErrorTooLarge
            } else if self.line_unfollowable() {
                FaultCode::LineUnfollowable
            } else {
                FaultCode::None
            };
            if self.state == SafetyState::Ready && refusal == FaultCode::None {
                self.state = SafetyState::Engaged;
                // The rate limit and the actuator model start from where the wheels are.
                self.last_command = self.wheel_angle;
                self.expected = self.wheel_angle;
                self.history_len = 0;
                self.remember_command(t, self.wheel_angle);
                self.diverged_since = None;
                self.tracking.reset();
            }
            self.last_refusal = refusal;
        }

        if self.state == SafetyState::Engaged {
            match self.limit(demand.unwrap_or(self.wheel_angle), dt) {
                Some(limited) => {
                    self.last_command = limited;
                    self.remember_command(t, limited);
                    return SteeringCommand {
                        engaged: true,
                        wheel_angle: limited,
                        curvature: limited.tan() / self.params.wheelbase,
                        state: self.state,
                        fault: FaultCode::None,
                    };
                }
                None => self.state = SafetyState::Fault(FaultCode::LateralAccelLimit),
            }
        }
        let measured = self.wheel_angle;
        self.last_command = measured;
        SteeringCommand {
            engaged: false,
            wheel_angle: measured,
            curvature: measured.tan() / self.params.wheelbase,
            state: self.state,
            fault: match self.state {
                SafetyState::Fault(c) => c,
                _ => fault,
            },
        }
    }

    /// The largest wheel angle allowed at the current speed (angle and lateral acceleration).
    pub fn angle_limit(&self) -> f64 {
        self.params.angle_limit(self.speed)
    }

    /// The next engaged command: toward `demand` by at most the rate allowance, within the
    /// angle and lateral-acceleration limits. `None` when both cannot hold at once.
    fn limit(&self, demand: f64, dt: f64) -> Option<f64> {
        let lim = self.angle_limit();
        let target = demand.clamp(-lim, lim);
        let step = self.params.max_wheel_rate * dt;
        let prev = self.last_command;
        let next = prev + (target - prev).clamp(-step, step);
        (next.abs() <= lim + 1e-12).then_some(next)
    }
}

#[cfg(test)]
mod tests;
