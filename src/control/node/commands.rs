//! The node's operator commands (issue 16 point 5; [`super::super::operator`]): engage,
//! disengage, nudge, set A / set B, select job, and calibrate (handed to [`super::calibration`]).

use super::ControllerNode;
use crate::can::codec::{OperatorReplyCommand, OperatorReplyResult};
use crate::control::operator::{JobRequest, MAX_NUDGE_M, MIN_LINE_LENGTH_M};
use crate::input::OperatorCommand;
use crate::safety::FaultCode;

impl ControllerNode {
    /// Why the last engage was refused (`None`: it engaged, or none yet): the supervisor's
    /// reason, or `no_approach_path` where the gate refused because no approach path could
    /// bring the vehicle into it.
    pub(super) fn engage_refusal(&self) -> FaultCode {
        match self.supervisor.last_refusal() {
            FaultCode::XteTooLarge | FaultCode::HeadingErrorTooLarge if self.no_approach => {
                FaultCode::NoApproachPath
            }
            r => r,
        }
    }

    /// The supervisor decided on an engage or resume in this step: its answer goes out with
    /// the next period.
    pub(super) fn answer_engage(&mut self, cmd: &crate::safety::SteeringCommand) {
        if let Some(command) = self.engage_reply.take() {
            let reason = match self.engage_refusal() {
                FaultCode::None => cmd.fault,
                r => r,
            };
            self.operator.reply_engage(command, cmd.engaged, reason);
        }
    }

    pub(super) fn on_operator(&mut self, t: f64, command: OperatorCommand) {
        match command {
            OperatorCommand::Engage | OperatorCommand::Resume => {
                let approach = self.ctrl.plan_approach(t);
                self.no_approach = matches!(approach, Some(Err(_)));
                match approach {
                    Some(Ok(parts)) => {
                        self.approach_refused = false;
                        tracing::info!(
                            parts,
                            line_worked_m = ?self.ctrl.guidance().worked_m(),
                            "approach path planned: to where the line's work stopped (its start when none)"
                        )
                    }
                    // Logged once per run of refusals (an operator may hold the button).
                    Some(Err(e)) if !self.approach_refused => {
                        self.approach_refused = true;
                        tracing::warn!("no approach path: {e}")
                    }
                    _ => {}
                }
                self.supervisor.request_engage();
                self.engage_reply = Some(match command {
                    OperatorCommand::Resume => OperatorReplyCommand::Resume,
                    _ => OperatorReplyCommand::Engage,
                });
            }
            OperatorCommand::Disengage | OperatorCommand::Pause => {
                self.supervisor.request_disengage();
                self.supervisor.acknowledge();
            }
            OperatorCommand::Nudge { steps } => self.nudge(steps),
            OperatorCommand::SetA => {
                let result = match self.ctrl.position(t) {
                    Some(p) => {
                        self.operator.point_a = Some(p);
                        tracing::info!(east_m = p.x, north_m = p.y, "operator: point A set");
                        OperatorReplyResult::Done
                    }
                    None => OperatorReplyResult::NoPosition,
                };
                self.operator.reply(OperatorReplyCommand::SetA, result);
            }
            OperatorCommand::SetB => {
                let b = self.ctrl.position(t);
                let refusal = match (self.operator.point_a, b) {
                    _ if self.status.engaged => Some(OperatorReplyResult::Engaged),
                    (_, None) => Some(OperatorReplyResult::NoPosition),
                    (None, _) => Some(OperatorReplyResult::NoPointA),
                    (Some(a), Some(b)) if (b - a).norm() < MIN_LINE_LENGTH_M => {
                        Some(OperatorReplyResult::LineTooShort)
                    }
                    (Some(a), Some(b)) => {
                        self.operator.pending = Some(JobRequest::Line { a, b });
                        None
                    }
                };
                if let Some(r) = refusal {
                    self.operator.reply(OperatorReplyCommand::SetB, r);
                }
            }
            OperatorCommand::SelectJob { job } => {
                if self.status.engaged {
                    let r = OperatorReplyResult::Engaged;
                    self.operator.reply(OperatorReplyCommand::SelectJob, r);
                } else {
                    self.operator.pending = Some(JobRequest::Select { job });
                }
            }
            OperatorCommand::Calibrate => self.start_calibration(t),
            OperatorCommand::None | OperatorCommand::Unknown { .. } => {}
        }
    }

    /// Shift the job by `steps` nudge steps (0: report the total).
    fn nudge(&mut self, steps: i32) {
        let g = self.ctrl.guidance();
        let total = g.nudge_m() + steps as f64 * self.ctrl.params().nudge_step;
        let result = if total.abs() > MAX_NUDGE_M + 1e-9 {
            OperatorReplyResult::OutOfRange
        } else {
            if steps != 0 {
                // Whole millimetres, as the reply carries it and the file keeps it.
                let total = (total * 1e3).round() / 1e3;
                self.ctrl.guidance_mut().set_nudge(total);
                tracing::info!(nudge_m = total, "operator: job nudged");
            }
            OperatorReplyResult::Done
        };
        self.operator.reply(OperatorReplyCommand::Nudge, result);
    }
}
