//! The operator's job changes (issue 16 point 5), made in the job layer because they plan:
//! set A / set B builds an AB job on the spot on the line A→B (otherwise as configured: line
//! width, count, side, order, turns) and records the line in the job book; select job drives
//! the configured job (0) or a recorded line (1..). The book (`jobs.json` in the state
//! directory, [`crate::store::jobs_file`]) makes a restart drive the job selected last, whose
//! progress (nudge included) is then resumed as any job's is.

use super::{build_controller, prepare, JobError, PreparedJob};
use crate::can::codec::OperatorReplyResult;
use crate::config::{JobKind, Resolved};
use crate::control::node::ControllerNode;
use crate::control::operator::JobRequest;
use crate::geo::wgs84::{EnuFrame, LatLon};
use crate::geo::Vec2;
use crate::store::jobs_file::{JobBook, RecordedLine};

/// The AB job on the line `a`→`b` (local ENU m about `origin`), otherwise as configured.
pub fn line_job(
    resolved: &Resolved,
    origin: LatLon,
    a: Vec2,
    b: Vec2,
) -> Result<PreparedJob, JobError> {
    let mut planning = resolved.planning.clone();
    planning.kind = JobKind::Ab;
    planning.origin = origin;
    planning.ab.point_a = a;
    planning.ab.point_b = b;
    planning.definition.point_a_m = [a.x, a.y];
    planning.definition.point_b_m = [b.x, b.y];
    prepare(&planning)
}

/// The job the book selects (`configured` for 0, or when the line it names is missing).
pub fn selected_job(
    resolved: &Resolved,
    configured: PreparedJob,
    book: &JobBook,
) -> Result<PreparedJob, JobError> {
    let Some(line) = book.line(book.selected) else {
        return Ok(configured);
    };
    let origin = configured.origin.unwrap_or(resolved.planning.origin);
    let enu = EnuFrame::new(origin);
    line_job(resolved, origin, enu.to_enu(line.a), enu.to_enu(line.b))
}

/// Make the job change the node asks for, if any: plan the job, hand the node its controller
/// (or the refusal) and update `book`. True when the book changed (the caller saves it, off
/// the control loop).
pub fn apply_request(
    node: &mut ControllerNode,
    resolved: &Resolved,
    configured: &PreparedJob,
    book: &mut JobBook,
) -> bool {
    let Some(request) = node.take_job_request() else {
        return false;
    };
    let enu = *node.enu();
    let (job, number, record) = match request {
        JobRequest::Line { a, b } => {
            let line = RecordedLine {
                a: enu.to_latlon(a),
                b: enu.to_latlon(b),
            };
            let mut next = book.clone();
            let k = next.record(line);
            (line_job(resolved, enu.origin(), a, b), k, Some(next))
        }
        JobRequest::Select { job: 0 } => (Ok(configured.clone()), 0, None),
        JobRequest::Select { job: k } => match book.line(k) {
            Some(l) => (
                line_job(resolved, enu.origin(), enu.to_enu(l.a), enu.to_enu(l.b)),
                k,
                None,
            ),
            None => {
                node.finish_job_request(request, OperatorReplyResult::NoSuchJob, None);
                return false;
            }
        },
    };
    let ctrl = job.and_then(|j| Ok(build_controller(resolved, &j, None)?));
    match ctrl {
        Ok(ctrl) => {
            if let Some(next) = record {
                *book = next;
            }
            book.selected = number;
            node.finish_job_request(request, OperatorReplyResult::Done, Some((ctrl, number)));
            true
        }
        Err(e) => {
            tracing::warn!("operator: job {number} cannot be set up: {e}");
            node.finish_job_request(request, OperatorReplyResult::Failed, None);
            false
        }
    }
}
