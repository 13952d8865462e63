//! Manoeuvres with reversing (docs/METHODS.md, Manoeuvres with reversing; seed 004):
//! continuous-curvature (clothoid) paths with cusps, plain and CC Reeds-Shepp connections, vehicle
//! collision checks and a hybrid-A*-style search with analytic connection.
//!
//! Paths are lists of [`CurveSegment`](path::CurveSegment)s from a start
//! [`Pose`](crate::geo::Pose); they can be sampled at any spacing.

pub mod approach;
pub mod cc_reeds_shepp;
pub mod cc_turn;
pub mod drive;
pub mod fresnel;
pub mod path;
pub mod reeds_shepp;

pub mod collision;
pub mod expansion;
pub mod search;
pub mod steering;
