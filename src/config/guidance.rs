//! `[guidance]`: how the job is broken into lines, blocks and turns, and how cusps and
//! approach paths are handled.
//!
//! Owns the section's keys, their defaults and their range checks.

use super::check::Checker;
use serde::{Deserialize, Serialize};

/// `[guidance]`: how the job is broken into lines, blocks and turns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GuidanceConfig {
    /// The seed's `a` in N = 2·ceil(2·r_min/line_width) + a, an integer ≥ 1.
    pub a: i64,
    /// Spacing of global path points, m.
    pub point_spacing_m: f64,
    /// Angular step between turn-arc points, degrees.
    pub turn_arc_step_deg: f64,
    /// Two turn arcs whose ends are closer than this are merged into one, m.
    pub turn_merge_distance_m: f64,
    /// Cap on the number of points of a turn's straight part.
    pub turn_max_points: usize,
    /// The path counts as "near its end" within this distance of its last point, m.
    pub end_distance_m: f64,
    /// Before a cusp (a change of driving direction) the daemon asks the tractor to stop
    /// when the remaining distance is within the stopping distance at this deceleration, m/s².
    pub cusp_decel_mps2: f64,
    /// Below this speed the vehicle counts as stopped (for a change of direction), m/s.
    pub stopped_speed_mps: f64,
    /// A vehicle stopped within this distance of a cusp moves on to the next segment, m.
    pub cusp_capture_m: f64,
    /// Approach paths: when the operator engages too far from the path to engage (at the
    /// job's start, or resuming it after a restart, a pause or a manual drive) (|XTE| ≥ `safety.max_engage_xte_m` or heading error ≥
    /// `safety.max_engage_heading_error_deg`), plan a continuous-curvature path (reversing
    /// where shorter, κ_max = 1/`vehicle.r_min_m`, σ_max = `vehicle.max_curvature_rate_per_m2`)
    /// from the vehicle to the line start (on a line partly worked: where its work stopped),
    /// inside the field when the job has one, and drive
    /// it first. false = refuse to engage there, as without approach paths.
    pub approach_paths: bool,
    /// One step of the operator's nudge (OperatorCommand nudge): the job's lines shift by
    /// this many metres per step, left of A→B for steps > 0, m.
    pub nudge_step_m: f64,
}

impl Default for GuidanceConfig {
    fn default() -> Self {
        GuidanceConfig {
            a: 1,
            point_spacing_m: 1.0,
            turn_arc_step_deg: 5.0,
            turn_merge_distance_m: 0.05,
            turn_max_points: 500,
            end_distance_m: 0.3,
            cusp_decel_mps2: 0.5,
            stopped_speed_mps: 0.05,
            cusp_capture_m: 1.0,
            approach_paths: true,
            nudge_step_m: 0.02,
        }
    }
}

impl GuidanceConfig {
    /// Range checks of `[guidance]`.
    pub(crate) fn validate(&self, c: &mut Checker) {
        let g = self;
        if g.a < 1 {
            c.push("guidance.a", g.a.to_string(), "must be an integer >= 1");
        }
        c.range("guidance.point_spacing_m", g.point_spacing_m, 0.05, 10.0);
        c.range("guidance.turn_arc_step_deg", g.turn_arc_step_deg, 0.1, 10.0);
        c.range(
            "guidance.turn_merge_distance_m",
            g.turn_merge_distance_m,
            0.0,
            5.0,
        );
        if g.turn_max_points < 2 {
            c.push(
                "guidance.turn_max_points",
                g.turn_max_points.to_string(),
                "must be an integer >= 2",
            );
        }
        c.range("guidance.end_distance_m", g.end_distance_m, 0.0, 10.0);
        c.range("guidance.nudge_step_m", g.nudge_step_m, 0.001, 1.0);
        c.range("guidance.cusp_decel_mps2", g.cusp_decel_mps2, 0.05, 5.0);
        c.range(
            "guidance.stopped_speed_mps",
            g.stopped_speed_mps,
            0.001,
            1.0,
        );
        c.range("guidance.cusp_capture_m", g.cusp_capture_m, 0.05, 10.0);
    }
}
