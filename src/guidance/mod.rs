//! Guidance: the job state machine and its progress.

pub mod progress;
pub mod machine;

pub use machine::{Event, Guidance, GuidanceError, GuidanceParams};
