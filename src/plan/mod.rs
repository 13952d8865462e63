//! Global path planning. Every planner here is a pure function of its inputs: no I/O, no
//! clocks, no globals, no configuration (planners take their own parameter structs, filled by
//! the configuration layer).
//!
//! Inner layers (lowest first, as `docs/layers.txt` lists them; each imports only earlier
//! ones):
//! * [`types`]: the shared types ([`PlanError`], [`types::Field`], [`types::PlanSegment`],
//!   [`types::SegmentKind`], [`types::Side`]);
//! * [`maneuver`]: continuous-curvature paths, Reeds-Shepp, collision checks, the manoeuvre
//!   search, approach paths;
//! * [`turns`]: turns between parallel lines and the one turn selector, with the
//!   canonical-frame turn cache;
//! * [`skip_order`]: the seed-000 block skip order;
//! * the planners [`abline`], [`arcs`] and [`coverage`] (peers: none imports another);
//! * [`job`]: what the guidance drives ([`job::JobPlan`], [`job::SegmentJob`]).

pub mod abline;
pub mod arcs;
pub mod coverage;
pub mod job;
pub mod maneuver;
pub mod skip_order;
pub mod turns;
pub mod types;

pub use types::PlanError;
