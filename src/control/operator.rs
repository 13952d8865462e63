//! Operator commands beyond disengage (issue 16 point 5), each answered by an OperatorReply
//! frame (command, result, the job now driven, the job's total nudge, and for a refused engage
//! the reason):
//!
//! - **engage**, **resume**: answered once the supervisor has decided, in the control period
//!   after: `done` (engaged) or `refused` with `Reason` the safety fault code of why (the
//!   engage gate's `xte_too_large`, `heading_error_too_large`, `line_unfollowable`, beyond it
//!   `no_approach_path`, or the fault that holds the system), so a terminal can say why
//!   nothing happened.
//! - **nudge**: the job's lines shift by `Nudge` × `guidance.nudge_step_m`, left of the job's
//!   reference direction (A→B) for steps > 0, at once and while engaged (a correction of the
//!   line, as a terminal's nudge buttons do); the total is saved with the progress
//!   ([`crate::guidance::progress::Progress::nudge_m`]) and kept across restarts. Nudge 0 asks
//!   for the total without changing it. Beyond ±[`MAX_NUDGE_M`]: refused, `out_of_range`.
//! - **set_a**: the vehicle's position (rear-axle centre, from the estimate) becomes point A.
//! - **set_b**: the position becomes point B and an AB job on A→B, with the configured line
//!   width, count and order, replaces the job (built by the job layer: [`JobRequest::Line`]);
//!   the line is recorded and can be selected again.
//! - **select_job**: job 0 is the configured job, 1..=250 a recorded line ([`JobRequest::Select`]).
//!
//! A job change is refused while engaged (`engaged`): the operator disengages first. The new
//! job starts from its first line, as a new job does. The node cannot plan (planning is the
//! job layer's, above it): it hands the request up ([`super::node::ControllerNode::take_job_request`])
//! and answers when the job layer says how it went
//! ([`super::node::ControllerNode::finish_job_request`]).

use crate::can::codec::{OperatorReply, OperatorReplyCommand, OperatorReplyResult};
use crate::geo::Vec2;

/// The shortest line set A / set B accepts, m (a shorter baseline makes a poor heading).
pub const MIN_LINE_LENGTH_M: f64 = 5.0;
/// Replies queued at most per control period (an operator presses buttons slowly).
pub const MAX_REPLIES: usize = 8;
/// The largest total nudge, m (the reply's range is ±32 m).
pub const MAX_NUDGE_M: f64 = 32.0;

/// A job change for the job layer to make.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JobRequest {
    /// An AB job on the line A→B (the node's local ENU, m), set by set A / set B.
    Line { a: Vec2, b: Vec2 },
    /// Job `job`: 0 the configured job, 1.. a line recorded by set A / set B.
    Select { job: u8 },
}

impl JobRequest {
    /// The command the request answers.
    pub fn command(&self) -> OperatorReplyCommand {
        match self {
            JobRequest::Line { .. } => OperatorReplyCommand::SetB,
            JobRequest::Select { .. } => OperatorReplyCommand::SelectJob,
        }
    }
}

/// The operator commands' state in the node.
#[derive(Debug, Clone, Default)]
pub struct OperatorState {
    /// Point A, once set (local ENU m).
    pub point_a: Option<Vec2>,
    /// A job change waiting for the job layer.
    pub pending: Option<JobRequest>,
    /// Replies to send with the next control period: command, result, reason (a
    /// [`crate::safety::FaultCode`], `None` unless refused).
    pub replies: Vec<(
        OperatorReplyCommand,
        OperatorReplyResult,
        crate::safety::FaultCode,
    )>,
    /// The job driven: 0 the configured one, k the k-th recorded line.
    pub job: u8,
}

impl OperatorState {
    /// Queue a reply (a few at most per period; an operator presses buttons slowly).
    pub fn reply(&mut self, command: OperatorReplyCommand, result: OperatorReplyResult) {
        if self.replies.len() < MAX_REPLIES {
            self.replies
                .push((command, result, crate::safety::FaultCode::None));
        }
    }

    /// Queue the answer to an engage or resume: `done` when engaged, else `refused` naming
    /// `reason`.
    pub fn reply_engage(
        &mut self,
        command: OperatorReplyCommand,
        engaged: bool,
        reason: crate::safety::FaultCode,
    ) {
        if self.replies.len() < MAX_REPLIES {
            self.replies.push(if engaged {
                (
                    command,
                    OperatorReplyResult::Done,
                    crate::safety::FaultCode::None,
                )
            } else {
                (command, OperatorReplyResult::Refused, reason)
            });
        }
    }

    /// The frame of a reply.
    pub fn frame(
        &self,
        command: OperatorReplyCommand,
        result: OperatorReplyResult,
        reason: crate::safety::FaultCode,
        nudge_m: f64,
    ) -> OperatorReply {
        OperatorReply {
            command: Some(command),
            result: Some(result),
            job: Some(self.job as f64),
            nudge: Some((nudge_m * 1e3).round().clamp(-32000.0, 32000.0)),
            reason: Some(reason as u8 as f64).filter(|&r| r <= 61.0),
        }
    }
}
