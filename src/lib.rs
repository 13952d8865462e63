//! agsteer: automatic steering for tractors.
//!
//! Data flows one way through the control cycle:
//! `can` (bus + DBC codec) → [`estimate`] (lat/lon → ENU, antenna offset, latency
//! compensation) → [`guidance`] (job state machine, progress) → [`plan`] (global paths) →
//! [`track`] (local B-spline, pure pursuit) → `safety` (engage gating, limits, timeouts) →
//! `can`. [`control`] glues one cycle together; [`demo`] runs it closed-loop against the
//! [`sim`]ulator.
//!
//! Planning modules are pure functions of their inputs (no I/O, clocks or globals). I/O lives
//! only in `can`, [`daemon`] and the binaries.

pub mod can;
pub mod config;
pub mod control;
pub mod daemon;
pub mod demo;
pub mod envelope;
pub mod estimate;
pub mod field;
pub mod geo;
pub mod guidance;
pub mod input;
pub mod io;
pub mod plan;
pub mod safety;
pub mod sim;
pub mod track;
