//! Guidance: the job state machine and its progress.

pub mod machine;
pub mod progress;

pub use crate::plan::job::JobPlan;
pub use machine::{Event, Guidance, GuidanceError, GuidanceParams};
