//! The identity of a job's plan, saved with its progress: everything the driven order and
//! geometry depend on, so progress saved for another plan is never resumed.
//!
//! Not a hand-picked list of keys: the planners are pure functions of their resolved
//! parameter structs, so the identity is every field of the struct the job's planner takes
//! (flattened from its `Debug` text, so a field added later is included by itself), the ENU
//! origin its coordinates are about, the planner's revision and, for a planned segment job
//! (field, manoeuvre, arcs), the checksum of the plan's segments themselves. A configuration
//! key that does not reach the planner (a tracker gain, a safety limit other than the ones
//! that set the turn radius) leaves it unchanged; `job::tests_identity` checks both ways
//! over every key of the configuration.

use crate::config::{JobKind, Planning};
use crate::geo::wgs84::LatLon;
use crate::guidance::progress::{flatten_debug, JobDefinition};
use crate::plan::job::JobPlan;
use std::collections::BTreeMap;

/// Raised whenever a planner changes what it makes of the same parameters, so progress saved
/// by an older planner is not resumed on a plan that is no longer the same.
pub const PLANNER_REVISION: u32 = 1;

/// The definition of the job `plan` planned from `planning`, its coordinates about `origin`
/// (`None` = the configured origin).
pub fn define(planning: &Planning, plan: &JobPlan, origin: Option<LatLon>) -> JobDefinition {
    let mut def = planning.definition.clone().with_plan(plan);
    def.identity = identity(planning, plan, origin);
    def
}

fn identity(
    planning: &Planning,
    plan: &JobPlan,
    origin: Option<LatLon>,
) -> BTreeMap<String, String> {
    let mut id = BTreeMap::new();
    id.insert(
        "planner".into(),
        format!(
            "agsteer {} revision {PLANNER_REVISION}",
            env!("CARGO_PKG_VERSION")
        ),
    );
    id.insert("kind".into(), format!("{:?}", planning.kind));
    let origin = origin.unwrap_or(planning.origin);
    id.insert("origin.lat_deg".into(), format!("{:?}", origin.lat_deg));
    id.insert("origin.lon_deg".into(), format!("{:?}", origin.lon_deg));
    match planning.kind {
        JobKind::Ab => {
            flatten_debug("ab", &format!("{:?}", planning.ab), &mut id);
            id.insert("line_order".into(), format!("{:?}", planning.line_order));
        }
        JobKind::Arcs => flatten_debug("arcs", &format!("{:?}", planning.arcs), &mut id),
        // The plan itself (its segments' checksum) stands for the field file, the loading
        // and the coverage parameters, and the map and manoeuvre parameters.
        JobKind::Field | JobKind::Maneuver => {}
    }
    match plan {
        JobPlan::Segments(s) => {
            id.insert(
                "plan.segments_crc32c".into(),
                format!("{:08x}", s.checksum()),
            );
            id.insert("plan.segments".into(), s.len().to_string());
        }
        JobPlan::Ab(ab) => {
            id.insert(
                "plan.blocks".into(),
                ab.block_count()
                    .map_or("unlimited".into(), |n| n.to_string()),
            );
        }
    }
    id
}
