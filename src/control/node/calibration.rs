//! The node's calibration mode (issue 15 point 4): the operator command `calibrate` runs the
//! guided steering calibration ([`crate::calibrate::Session`]) in the node, on the same inputs
//! and under the same supervisor as guidance.
//!
//! - **Start**: only while not engaged, not already calibrating, and with the wheel-angle
//!   frame as steering feedback (not the steer-ready loop); answered `started`, else
//!   `engaged` or `failed`.
//! - **Steering**: the procedure's command replaces the tracker's demand. The supervisor
//!   engages once, when the procedure first steers (the operator's command is the consent),
//!   and then runs with calibration limits: a standstill is allowed (no minimum speed), the
//!   speed may not exceed the drive's limit, the engage gate does not look at the line, and the
//!   override by divergence from the actuator model is off (the model is what calibration
//!   measures; an operator taking the wheel shows as the override bit, a disengage, the wheels
//!   held off the command on the drive, or responses the model cannot explain). Every other
//!   check holds: GNSS, wheel angle and speed fresh and valid, RTK fixed, angle, rate and
//!   lateral-acceleration limits, bus and address. Whatever makes the supervisor give the
//!   steering back aborts the calibration, named.
//! - **The operator** is asked to stop or to drive through the direction request (Stop /
//!   Forward, as at a cusp) and through `agsteer status`.
//! - **End**: the steering tests are fitted to the commands actually sent (after the
//!   supervisor's limits). The fit is slow work: the node hands the recorded procedure up
//!   ([`ControllerNode::take_calibration`]) for the daemon to fit and save off the control
//!   loop, and answers `done` or `failed` when told ([`ControllerNode::calibration_fitted`]).
//!
//! Per control period nothing allocates: the procedure reserves its records when a phase
//! starts; logging happens at the start and the end only.

use super::ControllerNode;
use crate::calibrate::{CalibrationError, CalibrationParams, Instruction, Session};
use crate::can::codec::{DirectionRequestDirection, OperatorReplyCommand, OperatorReplyResult};
use crate::input::Input;
use crate::safety::{SafetyParams, SafetyState, SteeringCommand as Cmd};
use serde::Serialize;

/// What `agsteer status` shows of a calibration under way.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CalibrationProgress {
    /// The procedure's phase ("stop the tractor", "steering tests", "drive ahead", "drive:
    /// wheel-angle sensor", "done").
    pub phase: &'static str,
    /// What the operator is asked to do: "stop", "drive" (hands off), "line" (steer along the
    /// marked line by hand), "turn" (turn round onto the same line by hand) or "done".
    pub instruction: &'static str,
    /// The speed asked for on the drive, km/h.
    pub drive_speed_kmh: f64,
    /// Since the command, s.
    pub elapsed_s: f64,
    /// The procedure's length once stopped and driving when asked, s.
    pub nominal_s: f64,
}

/// A calibration under way.
struct Running {
    session: Session,
    /// The supervisor's parameters outside calibration, restored at the end.
    normal: SafetyParams,
    progress: CalibrationProgress,
    started: Option<f64>,
    /// The procedure asked for steering and the supervisor was asked to engage.
    engage_asked: bool,
    /// The procedure wants steering this period.
    steering: bool,
}

/// The calibration mode's state.
pub(super) struct CalibrationState {
    params: CalibrationParams,
    running: Option<Box<Running>>,
    /// A finished procedure (to fit) or why it stopped, for the daemon.
    outcome: Option<Result<Box<Session>, CalibrationError>>,
}

impl CalibrationState {
    pub(super) fn new() -> Self {
        CalibrationState {
            params: CalibrationParams::default(),
            running: None,
            outcome: None,
        }
    }
}

/// The supervisor's limits during calibration (see the module's documentation).
fn calibration_limits(normal: &SafetyParams, p: &CalibrationParams) -> SafetyParams {
    SafetyParams {
        min_speed: 0.0,
        max_speed: p.drive_speed_max.min(normal.max_speed),
        override_time: f64::INFINITY,
        max_engage_xte: f64::INFINITY,
        max_engage_heading_error: f64::INFINITY,
        ..normal.clone()
    }
}

fn instruction_name(i: Instruction) -> &'static str {
    match i {
        Instruction::Stop => "stop",
        Instruction::Drive(_) => "drive",
        Instruction::Line(_) => "line",
        Instruction::TurnBack(_) => "turn",
        Instruction::Finished => "done",
    }
}

impl ControllerNode {
    /// The calibration procedure's parameters (`[calibration]` and `[vehicle]`).
    pub fn set_calibration_params(&mut self, params: CalibrationParams) {
        self.calibration.params = params;
    }

    /// The calibration under way, if any.
    pub fn calibration_progress(&self) -> Option<CalibrationProgress> {
        self.calibration.running.as_ref().map(|r| r.progress)
    }

    /// Whether a calibration runs or waits to be fitted.
    pub fn calibrating(&self) -> bool {
        self.calibration.running.is_some() || self.calibration.outcome.is_some()
    }

    /// A calibration that ended: the recorded procedure to fit ([`Session::finish`]), or why
    /// it was refused (answered `failed` already). The caller fits it off the control loop and
    /// calls [`ControllerNode::calibration_fitted`].
    pub fn take_calibration(&mut self) -> Option<Result<Box<Session>, CalibrationError>> {
        self.calibration.outcome.take()
    }

    /// The fit of a finished calibration is done (`ok`: saved) or refused: answered on the bus
    /// with the next period.
    pub fn calibration_fitted(&mut self, ok: bool) {
        let result = if ok {
            OperatorReplyResult::Done
        } else {
            OperatorReplyResult::Failed
        };
        self.operator.reply(OperatorReplyCommand::Calibrate, result);
    }

    /// The supervisor's parameters (re-tuning): kept for the end of a calibration under way.
    pub(super) fn set_supervisor_params(&mut self, params: SafetyParams) {
        match self.calibration.running.as_mut() {
            Some(r) => {
                self.supervisor
                    .set_params(calibration_limits(&params, &self.calibration.params));
                r.normal = params;
            }
            None => self.supervisor.set_params(params),
        }
    }

    /// The operator command `calibrate` at `t`.
    pub(super) fn start_calibration(&mut self, t: f64) {
        let refusal = if self.status.engaged {
            Some((OperatorReplyResult::Engaged, "engaged: disengage first"))
        } else if self.calibrating() {
            Some((OperatorReplyResult::Failed, "a calibration is under way"))
        } else if self.iso.params().steer_ready_loop {
            Some((
                OperatorReplyResult::Failed,
                "the steering feedback is Guidance Machine Info (bus.output = \"curvature\"): \
                 calibration needs the wheel-angle frame",
            ))
        } else {
            None
        };
        if let Some((result, why)) = refusal {
            tracing::warn!("calibration refused: {why}");
            self.operator.reply(OperatorReplyCommand::Calibrate, result);
            return;
        }
        let normal = self.supervisor.params().clone();
        let p = self.calibration.params;
        self.supervisor.set_params(calibration_limits(&normal, &p));
        self.supervisor.request_disengage();
        // No work line is supervised while calibrating (set again after it).
        self.supervisor.set_line(None, 0.0);
        self.supervisor.set_path_distance(None);
        self.supervised_line = None;
        let session = Session::new(p);
        let nominal_s = session.nominal_duration();
        self.calibration.running = Some(Box::new(Running {
            session,
            normal,
            progress: CalibrationProgress {
                phase: "stop the tractor",
                instruction: "stop",
                drive_speed_kmh: p.drive_speed * 3.6,
                elapsed_s: 0.0,
                nominal_s,
            },
            started: None,
            engage_asked: false,
            steering: false,
        }));
        tracing::info!(t, nominal_s, "calibration started: stop the tractor");
        self.operator.reply(
            OperatorReplyCommand::Calibrate,
            OperatorReplyResult::Started,
        );
    }

    /// An input (after source selection, before the WAS correction) for the procedure.
    pub(super) fn calibration_input(&mut self, input: &Input) {
        let Some(r) = self.calibration.running.as_mut() else {
            return;
        };
        if let Err(e) = r.session.on_input(input) {
            self.end_calibration(Err(e));
        }
    }

    /// The demand of this period while calibrating (true wheel angle, rad; `None`: no
    /// steering); `None` when not calibrating.
    pub(super) fn calibration_demand(&mut self, t: f64) -> Option<Option<f64>> {
        let r = self.calibration.running.as_mut()?;
        let started = *r.started.get_or_insert(t);
        match r.session.tick(t) {
            Ok(tick) => {
                r.progress.phase = tick.phase;
                r.progress.instruction = instruction_name(tick.instruction);
                r.progress.elapsed_s = t - started;
                if tick.instruction == Instruction::Finished {
                    self.end_calibration(Ok(()));
                    return Some(None);
                }
                r.steering = tick.command.is_some();
                if r.steering && !r.engage_asked {
                    r.engage_asked = true;
                    self.supervisor.request_engage();
                }
                // The procedure's command is in the sensor's terms; the supervisor's in true
                // angles (the node sends `was_gain · angle + was_offset`).
                Some(tick.command.map(|c| (c - self.was_offset) / self.was_gain))
            }
            Err(e) => {
                self.end_calibration(Err(e));
                Some(None)
            }
        }
    }

    /// The direction to request while calibrating: stop for the steering tests, forward for
    /// the drive; `None` when not calibrating.
    pub(super) fn calibration_direction(&self) -> Option<DirectionRequestDirection> {
        let r = self.calibration.running.as_ref()?;
        Some(match r.progress.instruction {
            "drive" | "line" | "turn" => DirectionRequestDirection::Forward,
            _ => DirectionRequestDirection::Stop,
        })
    }

    /// After the supervisor's step: record the command sent; a supervisor that does not (or no
    /// longer) steers while the procedure wants steering aborts it.
    pub(super) fn calibration_sent(&mut self, t: f64, cmd: &Cmd) {
        let Some(r) = self.calibration.running.as_mut() else {
            return;
        };
        if cmd.engaged {
            r.session
                .sent(t, self.was_gain * cmd.wheel_angle + self.was_offset);
        } else if r.steering && r.engage_asked {
            let state = match cmd.state {
                SafetyState::Fault(_) => "gave the steering back",
                _ => "refused to steer",
            };
            let e = CalibrationError::OperatorIntervened {
                t,
                how: format!("the supervisor {state}: {:?}", cmd.fault),
            };
            self.end_calibration(Err(e));
        }
    }

    /// End the mode (`Ok`: the procedure ran to its end): the supervisor back to its
    /// parameters, disengaged; the recorded procedure or the refusal kept for the daemon; a
    /// refusal answered at once.
    fn end_calibration(&mut self, end: Result<(), CalibrationError>) {
        let Some(r) = self.calibration.running.take() else {
            return;
        };
        let Running {
            session, normal, ..
        } = *r;
        self.supervisor.set_params(normal);
        self.supervisor.request_disengage();
        self.ctrl.set_engaged(false);
        let outcome = match end {
            Ok(()) => {
                tracing::info!("calibration: the procedure is done; fitting");
                Ok(Box::new(session))
            }
            Err(e) => {
                tracing::warn!("calibration refused: {e}");
                self.operator
                    .reply(OperatorReplyCommand::Calibrate, OperatorReplyResult::Failed);
                Err(e)
            }
        };
        self.calibration.outcome = Some(outcome);
    }
}
