//! The curve family the manoeuvre search steers with: continuous-curvature (clothoid) turns and
//! CC Reeds-Shepp connections (docs/METHODS.md, Curves), or plain arcs and Reeds-Shepp connections.

use super::cc_reeds_shepp::cc_reeds_shepp_shortest;
use super::cc_turn::cc_turn;
pub use super::path::CurveParams;
use super::path::CurvePath;
use super::path::CurveSegment;
use super::reeds_shepp::{reeds_shepp_length, reeds_shepp_shortest};
use crate::geo::{Direction, Pose};

/// What the search needs from a curve family.
pub trait Steering {
    /// The shortest analytic connection `from` → `to` (any forward/reverse labelling), if any.
    fn connect(&self, from: &Pose, to: &Pose) -> Option<CurvePath>;
    /// A primitive turn: segments changing the heading by `heading_change_rad` (+ = left),
    /// driven in `direction`, starting and ending at curvature 0. A change of 0 gives a straight
    /// line of `straight_m`.
    fn turn(
        &self,
        heading_change_rad: f64,
        direction: Direction,
        straight_m: f64,
    ) -> Vec<CurveSegment>;
    /// A distance for the search heuristic: the plain Reeds-Shepp length with the same
    /// minimum radius, m.
    fn distance(&self, from: &Pose, to: &Pose) -> f64;
    /// Largest curvature of any path, 1/m.
    fn kappa_max(&self) -> f64;
}

fn rs_distance(from: &Pose, to: &Pose, r_min: f64) -> f64 {
    let euclid = (to.pos - from.pos).norm();
    reeds_shepp_length(from, to, r_min).map_or(euclid, |l| l.max(euclid))
}

/// Continuous-curvature steering (Fraichard & Scheuer, seed 004): clothoid turns and CC
/// Reeds-Shepp connections.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CcSteering {
    pub params: CurveParams,
}

impl Steering for CcSteering {
    fn connect(&self, from: &Pose, to: &Pose) -> Option<CurvePath> {
        cc_reeds_shepp_shortest(from, to, &self.params)
    }
    fn turn(&self, delta: f64, direction: Direction, straight_m: f64) -> Vec<CurveSegment> {
        if delta.abs() < 1e-9 {
            vec![CurveSegment::line(direction, straight_m)]
        } else {
            cc_turn(delta, direction, &self.params)
        }
    }
    fn distance(&self, from: &Pose, to: &Pose) -> f64 {
        rs_distance(from, to, 1.0 / self.params.kappa_max)
    }
    fn kappa_max(&self) -> f64 {
        self.params.kappa_max
    }
}

/// Plain Reeds-Shepp steering: arcs of the minimum radius and lines (curvature jumps at the
/// joints).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RsSteering {
    pub r_min_m: f64,
}

impl Steering for RsSteering {
    fn connect(&self, from: &Pose, to: &Pose) -> Option<CurvePath> {
        reeds_shepp_shortest(from, to, self.r_min_m)
    }
    fn turn(&self, delta: f64, direction: Direction, straight_m: f64) -> Vec<CurveSegment> {
        if delta.abs() < 1e-9 {
            return vec![CurveSegment::line(direction, straight_m)];
        }
        let sign = match direction {
            Direction::Forward => 1.0,
            Direction::Reverse => -1.0,
        };
        let kappa = delta.signum() * sign / self.r_min_m;
        vec![CurveSegment::arc(
            direction,
            delta.abs() * self.r_min_m,
            kappa,
        )]
    }
    fn distance(&self, from: &Pose, to: &Pose) -> f64 {
        rs_distance(from, to, self.r_min_m)
    }
    fn kappa_max(&self) -> f64 {
        1.0 / self.r_min_m
    }
}
