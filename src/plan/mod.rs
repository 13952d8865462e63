//! Global path planning. Every planner here is a pure function of its inputs.

pub mod abline;
pub mod turns;
