//! `[maneuver]`: manoeuvres with reversing in tight spaces (curve family, implement,
//! clearance, search budget).
//!
//! Owns the section's keys, their defaults and their range checks (the curve family's need of
//! `vehicle.max_curvature_rate_per_m2` included).

use super::check::{count, fmt_num, Checker};
use serde::{Deserialize, Serialize};

/// Which curves `[maneuver]` plans with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum CurveChoice {
    /// Continuous curvature: clothoid turns, CC Reeds-Shepp connections.
    #[default]
    Cc,
    /// Plain Reeds-Shepp: arcs and lines (curvature jumps where they meet).
    Rs,
}

/// `[maneuver]`: manoeuvres with reversing in tight spaces (`agsteer maneuver`; docs/METHODS.md,
/// Manoeuvres with reversing). The
/// vehicle rectangle is `vehicle.length_m` × `vehicle.width_m` with the rear axle
/// `vehicle.rear_axle_from_rear_m` ahead of its rear edge; the largest curvature is
/// 1 / `vehicle.r_min_m`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ManeuverConfig {
    /// Curve family: "cc" (continuous curvature, the default) or "rs" (plain Reeds-Shepp).
    pub curve: CurveChoice,
    /// Implement rigidly mounted behind the vehicle: length, m (0 = none), width, m, and
    /// distance of its front edge behind the rear axle, m.
    pub implement_length_m: f64,
    pub implement_width_m: f64,
    pub implement_hitch_m: f64,
    /// Clearance kept around the vehicle (and implement) rectangle, m. Must be at least half
    /// of `sample_tolerance_m` so that sampled checks cover the continuous sweep.
    pub clearance_m: f64,
    /// Largest distance any point of the vehicle moves between two collision samples, m.
    pub sample_tolerance_m: f64,
    /// Cell size of the collision broad-phase grid, m.
    pub grid_cell_m: f64,
    /// Straight-line expansion: leg length, m; join distance, m; most levels; most legs per
    /// tree.
    pub expansion_step_m: f64,
    pub expansion_join_m: f64,
    pub expansion_max_depth: usize,
    pub expansion_max_legs: usize,
    /// Reversing patterns tried at the goal, written for an arrival from the goal's left
    /// (mirrored l ↔ r for the right): curves l/r, `_`, directions p (forward) / n (reverse).
    /// Empty = no pattern stage.
    pub goal_patterns: Vec<String>,
    /// Search primitives: heading-change step, degrees; largest heading change, degrees;
    /// length of the straight primitive, m.
    pub heading_step_deg: f64,
    pub primitive_max_deg: f64,
    pub straight_step_m: f64,
    /// Cost factor on reverse driving (≥ 1) and cost of each change of direction, m.
    pub reverse_penalty: f64,
    pub cusp_penalty_m: f64,
    /// Duplicate-detection grid of the search: position cell, m; heading cell, degrees.
    pub xy_resolution_m: f64,
    pub heading_resolution_deg: f64,
    /// Most node expansions over all searches of one plan.
    pub max_expansions: usize,
    /// Most expansions of the search to one goal pattern's start (part of max_expansions).
    pub pattern_max_expansions: usize,
    /// Most expansions of the search straight to the goal (part of max_expansions; the rest is
    /// left for the fallback).
    pub search_max_expansions: usize,
    /// Try the analytic connection to the goal every this many expansions (1 = each).
    pub analytic_every: usize,
    /// Expansions spent after the first solution looking for a cheaper one.
    pub extra_expansions: usize,
    /// Points per leg tried by the fallback (search between the rough route's first and last
    /// legs).
    pub fallback_points: usize,
}

impl Default for ManeuverConfig {
    fn default() -> Self {
        ManeuverConfig {
            curve: CurveChoice::Cc,
            implement_length_m: 0.0,
            implement_width_m: 0.0,
            implement_hitch_m: 0.5,
            clearance_m: 0.15,
            sample_tolerance_m: 0.3,
            grid_cell_m: 2.0,
            expansion_step_m: 5.0,
            expansion_join_m: 0.5,
            expansion_max_depth: 8,
            expansion_max_legs: 200,
            goal_patterns: vec!["lrlr_pnpn".to_string(), "lr_pn".to_string()],
            heading_step_deg: 10.0,
            primitive_max_deg: 180.0,
            straight_step_m: 2.0,
            reverse_penalty: 1.5,
            cusp_penalty_m: 5.0,
            xy_resolution_m: 1.0,
            heading_resolution_deg: 10.0,
            max_expansions: 4000,
            pattern_max_expansions: 600,
            search_max_expansions: 2500,
            analytic_every: 1,
            extra_expansions: 40,
            fallback_points: 3,
        }
    }
}

impl ManeuverConfig {
    /// Range checks of `[maneuver]`, with the vehicle it is planned for.
    pub(crate) fn validate(&self, vehicle: &super::VehicleConfig, c: &mut Checker) {
        let m = self;
        if m.curve == CurveChoice::Cc && vehicle.max_curvature_rate_per_m2 <= 0.0 {
            c.push(
                "vehicle.max_curvature_rate_per_m2",
                fmt_num(vehicle.max_curvature_rate_per_m2),
                "must be > 0 for continuous-curvature manoeuvres (maneuver.curve = \"cc\")",
            );
        }
        c.range(
            "maneuver.implement_length_m",
            m.implement_length_m,
            0.0,
            40.0,
        );
        if m.implement_length_m > 0.0 {
            c.range("maneuver.implement_width_m", m.implement_width_m, 0.1, 60.0);
        }
        c.range("maneuver.implement_hitch_m", m.implement_hitch_m, 0.0, 20.0);
        c.range("maneuver.clearance_m", m.clearance_m, 0.0, 5.0);
        c.range(
            "maneuver.sample_tolerance_m",
            m.sample_tolerance_m,
            0.01,
            2.0,
        );
        if m.clearance_m.is_finite() && m.clearance_m < 0.5 * m.sample_tolerance_m {
            c.push(
                "maneuver.clearance_m",
                fmt_num(m.clearance_m),
                "must be at least half of maneuver.sample_tolerance_m, or sampled checks may miss a corner cut between samples",
            );
        }
        c.range("maneuver.grid_cell_m", m.grid_cell_m, 0.1, 1000.0);
        c.range("maneuver.expansion_step_m", m.expansion_step_m, 0.5, 100.0);
        c.range("maneuver.expansion_join_m", m.expansion_join_m, 0.0, 20.0);
        count(
            c,
            "maneuver.expansion_max_depth",
            m.expansion_max_depth,
            1,
            100,
        );
        count(
            c,
            "maneuver.expansion_max_legs",
            m.expansion_max_legs,
            2,
            100_000,
        );
        for (i, pat) in m.goal_patterns.iter().enumerate() {
            if crate::plan::maneuver::search::parse_pattern(pat).is_err() {
                c.push(
                    &format!("maneuver.goal_patterns[{i}]"),
                    format!("{pat:?}"),
                    "must be curves l/r, `_`, then as many directions p/n, e.g. \"lrlr_pnpn\"",
                );
            }
        }
        c.range("maneuver.heading_step_deg", m.heading_step_deg, 1.0, 90.0);
        c.range(
            "maneuver.primitive_max_deg",
            m.primitive_max_deg,
            0.0,
            180.0,
        );
        c.range("maneuver.straight_step_m", m.straight_step_m, 0.1, 50.0);
        c.range("maneuver.reverse_penalty", m.reverse_penalty, 1.0, 100.0);
        c.range("maneuver.cusp_penalty_m", m.cusp_penalty_m, 0.0, 1000.0);
        c.range("maneuver.xy_resolution_m", m.xy_resolution_m, 0.05, 50.0);
        c.range(
            "maneuver.heading_resolution_deg",
            m.heading_resolution_deg,
            1.0,
            90.0,
        );
        count(
            c,
            "maneuver.max_expansions",
            m.max_expansions,
            1,
            10_000_000,
        );
        count(
            c,
            "maneuver.pattern_max_expansions",
            m.pattern_max_expansions,
            0,
            10_000_000,
        );
        count(
            c,
            "maneuver.search_max_expansions",
            m.search_max_expansions,
            1,
            10_000_000,
        );
        count(c, "maneuver.analytic_every", m.analytic_every, 1, 10_000);
        count(
            c,
            "maneuver.extra_expansions",
            m.extra_expansions,
            0,
            10_000_000,
        );
        count(c, "maneuver.fallback_points", m.fallback_points, 1, 100);
    }
}
