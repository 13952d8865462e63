//! agsteer: automatic steering for tractors.
//!
//! Data flows one way through the control cycle: `can` (bus + DBC codec) or `io` (a GNSS
//! receiver's byte stream) → [`input`] (the seam: `Input` events) → [`control::node`] (source
//! selection, lat/lon → ENU) → [`estimate`] (antenna offset, latency compensation) →
//! [`guidance`] (job state machine, progress) → [`plan`] (global paths) → [`track`] (local
//! B-spline, steering laws) → `safety` (engage gating, limits, timeouts) → `can`. [`control`]
//! glues one cycle together; [`demo`] runs it closed-loop against the [`sim`]ulator. The design
//! is written down in docs/ARCHITECTURE.md, Layers (and One control cycle, Where I/O lives).
//!
//! Planning modules are pure functions of their inputs (no I/O, clocks or globals). The
//! configuration is read once and resolved into each consumer's parameters ([`config`]); the
//! [`job`] layer sets the job up (and resumes it) the same way for the daemon, the demo and the
//! tools. I/O lives only in the adapters (`can`, `io`), [`store`], [`daemon`] and the
//! binaries. `docs/layers.txt` declares the layer order, which `tests/binaries/layering.rs` enforces.

pub mod calibrate;
pub mod can;
pub mod config;
pub mod control;
pub mod daemon;
pub mod demo;
pub mod envelope;
pub mod estimate;
pub mod exit;
pub mod field;
pub mod geo;
pub mod guidance;
pub mod input;
pub mod io;
pub mod job;
pub mod plan;
pub mod safety;
pub mod sim;
pub mod store;
pub mod track;
