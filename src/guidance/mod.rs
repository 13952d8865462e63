//! Guidance: the job state machine and its progress.
//!
//! [`Guidance`] drives a [`JobPlan`] (from [`crate::plan::job`]) every control period: it
//! holds the current global path (a work line, a turn, a segment, an approach path) and the
//! local B-spline path, finds the nearest points, moves on at the end of a path and emits
//! [`Event`]s. [`progress`] is the job's position as it survives power loss (a pure,
//! checksummed encoding; the file is [`crate::store`]'s).
//!
//! Contract: inputs are the plan, the job's definition, [`GuidanceParams`] and poses; outputs
//! the paths, the errors to the path and progress snapshots. No I/O, no configuration, no
//! allocation per cycle (path buffers are reused).

pub mod machine;
pub mod progress;
#[cfg(test)]
mod tests_approach;

pub use crate::plan::job::JobPlan;
pub use machine::{Event, Guidance, GuidanceError, GuidanceParams};
