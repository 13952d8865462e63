//! The job layer: the one job set-up and the one resume, used by `agsteerd`, `agsteer demo`,
//! `agsteer sim` and the accuracy suite.
//!
//! [`prepare`] turns the resolved [`Planning`] into a [`PreparedJob`]: the plan the guidance
//! drives (AB lines in the block order or in turn, arcs, a field's coverage plan from its file,
//! a manoeuvre planned on its map), the job's definition (saved with progress, with the plan's
//! checksum), the ENU origin of its coordinates and the field approach paths must stay in.
//! [`resume`] reads saved progress and says whether it belongs to the job. [`build_node`]
//! builds the controller node for a prepared job from the resolved parameters.
//!
//! Contract: blocking work done once before any control loop runs (file reading goes through
//! [`crate::store`]); never called per control period. It sees the configuration only as
//! [`Resolved`] parameters (and [`Config`] in the `*_config` conveniences); everything below it
//! gets typed parameters.

pub mod field;
pub mod identity;
pub mod maneuver;
pub mod operator;
pub mod resume;
pub mod startup;

use crate::config::{Config, ConfigError, JobKind, LineOrder, Planning, Resolved};
use crate::control::node::ControllerNode;
use crate::control::{ControlError, Controller};
use crate::geo::wgs84::LatLon;
use crate::guidance::progress::{JobDefinition, Progress};
use crate::plan::abline::{sequential_segments, AbPlan};
use crate::plan::arcs::arcs_segments;
use crate::plan::job::{JobPlan, SegmentJob};
use crate::plan::types::{Field, PlanError};
use field::{FieldJob, FieldJobError};
use maneuver::{ManeuverFileError, ManeuverJob};

/// Why the configured job cannot be set up.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    #[error(transparent)]
    Config(#[from] ConfigError),
    #[error("cannot plan the job: {0}")]
    Plan(#[from] PlanError),
    #[error("job.kind = \"field\": cannot prepare the field job")]
    Field(#[source] FieldJobError),
    #[error("job.kind = \"maneuver\": cannot prepare the manoeuvre")]
    Maneuver(#[source] ManeuverFileError),
    #[error(transparent)]
    Control(#[from] ControlError),
}

/// A job ready to drive.
#[derive(Debug, Clone)]
pub struct PreparedJob {
    /// What the guidance drives.
    pub plan: JobPlan,
    /// Its definition, saved with progress; progress saved under another one is not resumed.
    pub definition: JobDefinition,
    /// ENU origin of the plan's coordinates when it is not `job.origin_*` (a field plan).
    pub origin: Option<LatLon>,
    /// The field (local ENU about `origin`), which approach paths must stay in.
    pub field: Option<Field>,
    /// What was planned, for reports.
    pub detail: JobDetail,
}

/// What a prepared job was planned from.
#[derive(Debug, Clone)]
pub enum JobDetail {
    /// AB lines or arcs, from the configuration alone.
    Lines,
    /// A field's coverage plan.
    Field(Box<FieldJob>),
    /// A manoeuvre, and the map it was planned on (`None` = free space).
    Maneuver(Box<ManeuverJob>, Option<Field>),
}

/// The plan of an AB job: the seed-000 block plan, or (`job.line_order = "sequential"`) every
/// line and turn in turn as a segment job.
pub fn ab_plan(planning: &Planning) -> Result<JobPlan, PlanError> {
    Ok(match planning.line_order {
        LineOrder::Blocks => AbPlan::new(planning.ab.clone())?.into(),
        LineOrder::Sequential => JobPlan::Segments(SegmentJob::from_plan_segments(
            sequential_segments(&planning.ab)?,
        )?),
    })
}

/// Prepare the configured job: plan it (reading the field or the map for those kinds), define
/// it, and say where its coordinates are.
pub fn prepare(planning: &Planning) -> Result<PreparedJob, JobError> {
    let (plan, origin, field, detail) = match planning.kind {
        JobKind::Ab => (ab_plan(planning)?, None, None, JobDetail::Lines),
        JobKind::Arcs => {
            let job = SegmentJob::from_plan_segments(arcs_segments(&planning.arcs)?)?;
            (JobPlan::Segments(job), None, None, JobDetail::Lines)
        }
        JobKind::Field => {
            let fj = field::load(&planning.field).map_err(JobError::Field)?;
            (
                fj.job_plan(),
                Some(fj.origin()),
                Some(fj.loaded.field.clone()),
                JobDetail::Field(Box::new(fj)),
            )
        }
        JobKind::Maneuver => {
            let (mj, map) = maneuver::load(&planning.maneuver).map_err(JobError::Maneuver)?;
            (
                JobPlan::Segments(mj.job.clone()),
                None,
                None,
                JobDetail::Maneuver(Box::new(mj), map),
            )
        }
    };
    Ok(PreparedJob {
        definition: identity::define(planning, &plan, origin),
        plan,
        origin,
        field,
        detail,
    })
}

/// [`prepare`] the job of a configuration (taken as it is: see [`Config::resolved`]).
pub fn prepare_config(cfg: &Config) -> Result<PreparedJob, JobError> {
    prepare(&cfg.planning())
}

/// The job `plan` given by a caller (for example a field plan made elsewhere) as a prepared
/// job: defined with the configured job keys and the plan's checksum.
pub fn given(
    planning: &Planning,
    plan: JobPlan,
    origin: Option<LatLon>,
    field: Option<Field>,
) -> PreparedJob {
    PreparedJob {
        definition: identity::define(planning, &plan, origin),
        plan,
        origin,
        field,
        detail: JobDetail::Lines,
    }
}

/// The controller node driving `job`, continuing `resume` (which must belong to it): GNSS
/// positions converted about the job's origin, approach paths checked against its field.
pub fn build_node(
    resolved: &Resolved,
    job: &PreparedJob,
    resume: Option<&Progress>,
) -> Result<ControllerNode, ControlError> {
    let ctrl = build_controller(resolved, job, resume)?;
    let origin = job.origin.unwrap_or(resolved.planning.origin);
    let mut node = ControllerNode::new(ctrl, &resolved.safety, &resolved.bus, origin);
    node.set_calibration_params(resolved.calibration);
    Ok(node)
}

/// The controller driving `job`, continuing `resume`, approach paths checked against its field.
pub fn build_controller(
    resolved: &Resolved,
    job: &PreparedJob,
    resume: Option<&Progress>,
) -> Result<Controller, ControlError> {
    let mut ctrl = Controller::new(
        &resolved.control,
        job.plan.clone(),
        job.definition.clone(),
        resume,
    )?;
    if let Some(field) = &job.field {
        match maneuver::field_clearance(&resolved.planning.maneuver, field) {
            Ok(clear) => ctrl.set_approach_clearance(clear),
            Err(e) => tracing::warn!("approach paths are not checked against the field: {e}"),
        }
    }
    Ok(ctrl)
}

/// The controller node of a configuration's job (taken as it is: see [`Config::resolved`]),
/// new or continuing `resume`.
pub fn node_for_config(
    cfg: &Config,
    resume: Option<&Progress>,
) -> Result<ControllerNode, JobError> {
    let resolved = cfg.resolved();
    let job = prepare(&resolved.planning)?;
    Ok(build_node(&resolved, &job, resume)?)
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_identity;
