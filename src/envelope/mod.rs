//! The input envelope: how large and how strange an input agsteer accepts, in one place.
//!
//! Every limit that protects the machine from an input (a field, a configuration, a log, a
//! request) is a documented constant here, so the README's envelope table, the checks where
//! input enters and the bad-input suite (`tests/binaries/bad_input.rs`) all name the same figure.
//! Inside the envelope agsteer works (large work shows progress and stays under the memory
//! bound quoted in the README); beyond it the input is refused with an error naming the key or
//! file, the value and the limit. Never an out-of-memory, a hang or a panic.
//!
//! The figures are generous for real farm work (the largest single fields are a few hundred
//! hectares; a 10 000 ha farm block is far beyond any one job) and tight enough that the work
//! they allow fits a 2-core, few-GB controller.
//!
//! This module is the lowest layer: it imports nothing from the crate, so every layer may use
//! it. [`file`] is the bounded file reader every file input goes through.

pub mod file;

pub use file::{open_stream, read_bytes, read_text, FileError, FileKind};

/// Largest field area (boundary minus obstacles), m²: 10 000 ha.
pub const MAX_FIELD_AREA_M2: f64 = 1.0e8;

/// Largest extent of a field or manoeuvre map (longer side of the boundary's bounding box in
/// the local frame), m.
pub const MAX_FIELD_EXTENT_M: f64 = 20_000.0;

/// Most positions in one field or map file, all rings together, as read (before clean-up).
/// Beyond it the file is refused before any geometry is built.
pub const MAX_FIELD_POINTS: usize = 100_000;

/// A ring with more distinct points than this is simplified within `field.boundary_tolerance_m`
/// (Douglas–Peucker) before its quadratic checks (self-intersection, containment).
pub const SIMPLIFY_ABOVE_POINTS: usize = 4_000;

/// Most points of one ring after clean-up (and simplification): the ring checks are quadratic
/// in it. A ring that does not simplify below it within the tolerance is refused.
pub const MAX_RING_POINTS: usize = 10_000;

/// Most points of all rings of a field or map after clean-up (containment checks are the
/// product of an obstacle's points and the boundary's).
pub const MAX_CLEAN_POINTS: usize = 20_000;

/// Tolerance of the simplification of a large ring of a manoeuvre map (whose rings are
/// otherwise not simplified), m.
pub const MAP_SIMPLIFY_TOLERANCE_M: f64 = 0.01;

/// Most obstacles (holes and obstacle features) in one field or map.
pub const MAX_OBSTACLES: usize = 200;

/// Largest |coordinate| of a local position given in metres (AB points, manoeuvre poses, map
/// positions), m. The local ENU frame is a flat-earth approximation about its origin; beyond a
/// few tens of kilometres it is no longer a good one.
pub const MAX_LOCAL_COORD_M: f64 = 50_000.0;

/// Longest AB line (|B − A|), m; also the longest arc (`job.arc_radius_m` plus the widths of
/// the lines outside it, times the sweep) of an arcs job.
pub const MAX_LINE_LENGTH_M: f64 = 20_000.0;

/// Most work lines of a job (`job.line_num`; 0 = unlimited stays allowed for the blocks order,
/// which plans one block at a time).
pub const MAX_LINES: u64 = 10_000;

/// Most arcs of an arcs job (`job.line_num` when `job.kind = "arcs"`).
pub const MAX_ARCS: u64 = 1_000;

/// Most global-path points a job planned whole at start-up may hold: the job's total path
/// length over `guidance.point_spacing_m` (sequential AB jobs, arcs jobs, field plans).
pub const MAX_PATH_POINTS: f64 = 4.0e6;

/// Most lines in one block of the skip order, 2·ceil(2·r_min/w) + a (`vehicle.r_min_m`,
/// `job.line_width_m`, `guidance.a`): a turn radius far larger than the working width makes
/// blocks of thousands of lines.
pub const MAX_BLOCK_LINES: u64 = 1_000;

/// Largest `guidance.a`, the extra lines of a block.
pub const MAX_BLOCK_EXTRA: i64 = 100;

/// Most RTK-float windows of the simulator (`sim.gnss_float_windows_s`).
pub const MAX_FLOAT_WINDOWS: usize = 1_000;

/// Most entries of any other list in the configuration (goal patterns, scenario faults).
pub const MAX_CONFIG_LIST: usize = 1_000;

/// Largest distance between a manoeuvre's start and goal, m. The search grows with the area
/// between them; a manoeuvre is a local move (a headland turn, into a bay, through a gate).
pub const MAX_MANEUVER_DISTANCE_M: f64 = 2_000.0;

/// Longest line read from a candump log (streamed, so only its lines are bounded), bytes. A
/// longer line is reported and skipped, never held whole.
pub const MAX_LINE_BYTES: usize = 64 * 1024;

/// The README's envelope table (Markdown), from [`table`].
pub fn markdown_table() -> String {
    let mut s = String::from("| input | limit | checked by |\n|---|---|---|\n");
    for (what, limit, by) in table() {
        s.push_str(&format!("| {what} | {limit} | {by} |\n"));
    }
    s
}

/// The rows of the README's envelope table: (what, limit, where it is checked).
pub fn table() -> Vec<(&'static str, String, &'static str)> {
    let mib = |b: u64| format!("{} MiB", b / (1024 * 1024));
    let mut rows = vec![
        (
            "field area",
            format!("{} ha", MAX_FIELD_AREA_M2 / 1e4),
            "field reader",
        ),
        (
            "field / map extent",
            format!("{} km", MAX_FIELD_EXTENT_M / 1e3),
            "field reader",
        ),
        (
            "positions per field or map file",
            MAX_FIELD_POINTS.to_string(),
            "field reader",
        ),
        (
            "ring simplified (within field.boundary_tolerance_m) above",
            format!("{SIMPLIFY_ABOVE_POINTS} points"),
            "field reader",
        ),
        (
            "points of one ring / all rings after clean-up",
            format!("{MAX_RING_POINTS} / {MAX_CLEAN_POINTS}"),
            "field reader",
        ),
        (
            "obstacles per field or map",
            MAX_OBSTACLES.to_string(),
            "field reader",
        ),
        (
            "local coordinates (AB points, poses, map)",
            format!("±{} km", MAX_LOCAL_COORD_M / 1e3),
            "config, map reader, CLI",
        ),
        (
            "AB line length |B − A|",
            format!("{} km", MAX_LINE_LENGTH_M / 1e3),
            "config",
        ),
        ("job.line_num (AB)", MAX_LINES.to_string(), "config"),
        ("job.line_num (arcs)", MAX_ARCS.to_string(), "config"),
        ("guidance.a", MAX_BLOCK_EXTRA.to_string(), "config"),
        (
            "lines per block 2·ceil(2·r_min/w)+a",
            MAX_BLOCK_LINES.to_string(),
            "config, field planner",
        ),
        (
            "global-path points of a job planned whole",
            format!("{:.0e}", MAX_PATH_POINTS),
            "config, field planner",
        ),
        (
            "sim.gnss_float_windows_s entries",
            MAX_FLOAT_WINDOWS.to_string(),
            "config",
        ),
        (
            "manoeuvre start–goal distance",
            format!("{} km", MAX_MANEUVER_DISTANCE_M / 1e3),
            "config, CLI",
        ),
        (
            "line of a candump log",
            format!("{} KiB", MAX_LINE_BYTES / 1024),
            "dbc decode",
        ),
    ];
    for kind in FileKind::ALL {
        rows.push((kind.what(), mib(kind.max_bytes()), "bounded file reader"));
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_names_every_file_kind() {
        let t = table();
        for kind in FileKind::ALL {
            assert!(t.iter().any(|(what, _, _)| *what == kind.what()));
        }
    }
}
