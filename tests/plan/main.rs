//! Integration tests of the planners on their own: curves, manoeuvre scenarios, field plans
//! and their guarantees, TASKDATA in and out.
//!
//! The integration tests are a few test binaries (tests/<group>/main.rs, one module per former
//! tests/<name>.rs) rather than one per file: each binary links the library and optimises its
//! generics once, which cut the release build of all targets (docs/CONVENTIONS.md, Tests). Run
//! one file's tests by module: `cargo test --release --test <group> <name>::` (or
//! `cargo nextest run --release -E 'test(/^<name>::/)'`).

mod cc_paths;
mod field_plans;
mod isoxml_export;
mod maneuver_scenarios;
mod plan_guarantees;
mod taskdata_files;
