//! TEMPORARY stand-in for the CC Reeds-Shepp connection being written in branch `curves`.
//! Deleted when it is merged; only `steering.rs` uses it.

use super::path::{CurveParams, CurvePath};
use crate::geo::Pose;

pub fn cc_reeds_shepp_shortest(
    _start: &Pose,
    _goal: &Pose,
    _params: &CurveParams,
) -> Option<CurvePath> {
    None
}
