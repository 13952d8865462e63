//! Guidance: the job state machine and its progress.

pub mod progress;
