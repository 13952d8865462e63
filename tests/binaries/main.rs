//! Integration tests of the binaries and the repository: agsteer and agsteerd as a user runs
//! them (CLI, exit codes, --check, status, plan outputs, replay, bad input), crash safety of the
//! state files, and the layering and file-size checks.
//!
//! The integration tests are a few test binaries (tests/<group>/main.rs, one module per former
//! tests/<name>.rs) rather than one per file: each binary links the library and optimises its
//! generics once, which cut the release build of all targets (docs/CONVENTIONS.md, Tests). Run
//! one file's tests by module: `cargo test --release --test <group> <name>::` (or
//! `cargo nextest run --release -E 'test(/^<name>::/)'`).

mod bad_input;
mod check;
mod cli;
mod exit_codes;
mod layering;
mod plan_outputs;
mod replay;
mod state_files;
mod status_cmd;
