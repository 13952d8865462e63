//! Guidance: the job state machine and its progress.

pub mod machine;
pub mod progress;
pub mod segments;

pub use machine::{Event, Guidance, GuidanceError, GuidanceParams, JobPlan};
