//! `[job]`: what to drive (the job kind, its lines or field or manoeuvre, the ENU origin).
//!
//! Owns the section's keys, their defaults and their range checks; turns nothing into
//! parameters (the job layer does that).

use super::check::Checker;
use serde::{Deserialize, Serialize};

/// The kind of job the guidance runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum JobKind {
    /// Parallel AB lines (docs/METHODS.md, AB-line work).
    #[default]
    Ab,
    /// A field coverage plan (docs/METHODS.md, Coverage of a field) made from the field at
    /// `job.field_path`.
    Field,
    /// Concentric circular work lines about `job.point_a_m` (the curved lines of the accuracy
    /// suite): `job.line_num` arcs from radius `job.arc_radius_m` outwards, `job.line_width_m`
    /// apart, each sweeping `job.arc_sweep_deg`, joined by headland turns.
    Arcs,
    /// A manoeuvre with reversing (docs/METHODS.md, Manoeuvres with reversing) from
    /// `job.maneuver_from` to `job.maneuver_to` on the map at `job.maneuver_map_path`, planned at
    /// start-up with `[maneuver]`.
    Maneuver,
}

/// In which order the lines of an AB job are driven.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum LineOrder {
    /// The seed-000 order: blocks of `N = 2·ceil(2·r_min/line_width) + a` lines driven in a
    /// skip order so that every turn is a forward pi turn (docs/METHODS.md, Blocks and the skip
    /// order).
    #[default]
    Blocks,
    /// Adjacent lines in turn. Lines closer than `2·r_min` are joined by a fishtail turn with
    /// a reversal (continuous-curvature when `vehicle.max_curvature_rate_per_m2` > 0). Needs a
    /// finite `line_num`.
    Sequential,
}

/// Side of A→B on which the following lines are laid (the AB planner's type).
pub use crate::plan::types::Side as LineSide;

/// `[job]`: what to drive.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct JobConfig {
    /// Job kind: "ab" (parallel lines from A and B) or "field" (a coverage plan of the field
    /// at `field_path`).
    pub kind: JobKind,
    /// For `kind = "field"`: the field, a GeoJSON (WGS-84) or ISO 11783-10 TASKDATA.XML file.
    /// A relative path is taken from the working directory (as every path in the
    /// configuration), not from the configuration file's directory. Read and planned once
    /// when agsteerd or `agsteer demo` starts.
    pub field_path: String,
    /// For `kind = "maneuver"`: the map, GeoJSON in local metres (boundary polygon, holes and
    /// `"obstacle": true` features are obstacles; see `agsteer maneuver`); empty = free space.
    pub maneuver_map_path: String,
    /// For `kind = "maneuver"`: start pose [x m, y m, heading degrees CCW from East], local
    /// ENU about `job.origin_*`.
    pub maneuver_from: [f64; 3],
    /// For `kind = "maneuver"`: goal pose [x m, y m, heading degrees].
    pub maneuver_to: [f64; 3],
    /// Point A of the first work line, local ENU [east, north], m.
    pub point_a_m: [f64; 2],
    /// Point B of the first work line, local ENU [east, north], m.
    pub point_b_m: [f64; 2],
    /// Spacing between adjacent work lines (implement working width), m.
    pub line_width_m: f64,
    /// Number of work lines; 0 = unlimited (until the operator stops).
    pub line_num: u64,
    /// Side of A→B on which further lines are laid: "left" or "right".
    pub side: LineSide,
    /// For `kind = "ab"`: "blocks" (the seed-000 skip order, forward turns only) or
    /// "sequential" (adjacent lines in turn, fishtail turns with a reversal where the lines
    /// are closer than 2·r_min; needs `line_num` ≥ 1).
    pub line_order: LineOrder,
    /// WGS-84 latitude of the local ENU origin, degrees.
    pub origin_lat_deg: f64,
    /// WGS-84 longitude of the local ENU origin, degrees.
    pub origin_lon_deg: f64,
    /// For `kind = "arcs"`: radius of the first (innermost) line, m.
    pub arc_radius_m: f64,
    /// For `kind = "arcs"`: sweep of every line, degrees (the first starts due South of the
    /// centre, heading East, and runs counter-clockwise).
    pub arc_sweep_deg: f64,
}

impl Default for JobConfig {
    fn default() -> Self {
        JobConfig {
            kind: JobKind::Ab,
            field_path: String::new(),
            maneuver_map_path: String::new(),
            maneuver_from: [0.0, 0.0, 0.0],
            maneuver_to: [20.0, 0.0, 0.0],
            point_a_m: [0.0, 0.0],
            point_b_m: [0.0, 150.0],
            line_width_m: 3.0,
            line_num: 12,
            side: LineSide::Right,
            line_order: LineOrder::Blocks,
            origin_lat_deg: 52.0,
            origin_lon_deg: 5.0,
            arc_radius_m: 30.0,
            arc_sweep_deg: 270.0,
        }
    }
}

impl JobConfig {
    /// Range and consistency checks of `[job]`.
    pub(crate) fn validate(&self, c: &mut Checker) {
        let j = self;
        c.finite2("job.point_a_m", j.point_a_m);
        c.finite2("job.point_b_m", j.point_b_m);
        let ab = ((j.point_b_m[0] - j.point_a_m[0]).powi(2)
            + (j.point_b_m[1] - j.point_a_m[1]).powi(2))
        .sqrt();
        if ab.is_finite() && ab < 1.0 {
            c.push(
                "job.point_b_m",
                format!("{:?}", j.point_b_m),
                "must be at least 1 m from job.point_a_m",
            );
        }
        c.range("job.line_width_m", j.line_width_m, 0.1, 100.0);
        if j.kind == JobKind::Ab && j.line_order == LineOrder::Sequential && j.line_num == 0 {
            c.push(
                "job.line_num",
                "0".to_string(),
                "must be at least 1 when job.line_order = \"sequential\" (the whole job is planned at start)",
            );
        }
        for (key, pose) in [
            ("job.maneuver_from", j.maneuver_from),
            ("job.maneuver_to", j.maneuver_to),
        ] {
            if pose.iter().any(|v| !v.is_finite()) {
                c.push(
                    key,
                    format!("{pose:?}"),
                    "must be [x m, y m, heading degrees], all finite",
                );
            }
        }
        if j.kind == JobKind::Field && j.field_path.trim().is_empty() {
            c.push(
                "job.field_path",
                format!("{:?}", j.field_path),
                "must name a GeoJSON or TASKDATA.XML file when job.kind = \"field\"",
            );
        }
        c.range("job.arc_radius_m", j.arc_radius_m, 1.0, 10_000.0);
        c.range("job.arc_sweep_deg", j.arc_sweep_deg, 1.0, 359.0);
        if j.kind == JobKind::Arcs && !(1..=1000).contains(&j.line_num) {
            c.push(
                "job.line_num",
                j.line_num.to_string(),
                "must be in 1..=1000 when job.kind = \"arcs\"",
            );
        }
        c.range(
            "job.origin_lat_deg",
            j.origin_lat_deg,
            -crate::geo::wgs84::MAX_ABS_LAT_DEG,
            crate::geo::wgs84::MAX_ABS_LAT_DEG,
        );
        c.range("job.origin_lon_deg", j.origin_lon_deg, -180.0, 180.0);
    }
}
