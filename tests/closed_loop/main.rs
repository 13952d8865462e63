//! Closed-loop integration tests in process: the controller node and the simulator on an
//! in-memory bus (jobs, manoeuvres, accuracy, faults, safety properties, calibration, ISOBUS).
//!
//! The integration tests are a few test binaries (tests/<group>/main.rs, one module per former
//! tests/<name>.rs) rather than one per file: each binary links the library and optimises its
//! generics once, which cut the release build of all targets (docs/CONVENTIONS.md, Tests). Run
//! one file's tests by module: `cargo test --release --test <group> <name>::` (or
//! `cargo nextest run --release -E 'test(/^<name>::/)'`).

mod ab_sequential;
mod accuracy;
mod approach;
mod calibrate;
mod demo_closed_loop;
mod demo_maneuver;
mod disturbances;
mod envelope_subset;
mod faults;
mod field_job_closed_loop;
mod heading_fault;
mod inputs;
mod isobus;
mod operator_commands;
mod reverse_driving;
mod safety_properties;
mod tracking_faults;
