//! The input envelope's checks of a configuration ([`crate::envelope`]): sizes that cross
//! sections (a job's path points, a block's lines), list lengths, and every float finite.
//!
//! Each section's `validate` checks its keys' ranges; this pass adds what makes a valid-looking
//! configuration eat the machine (an AB line 1e9 m long, 100 000 sequential lines, 1 000 arcs
//! of 10 km, a turn radius 1 000 times the working width) and, over the whole resolved tree,
//! that no float is NaN or infinite, so a key whose range check is missing or conditional
//! still cannot carry one.

use super::check::{fmt_num, Checker};
use super::{Config, JobKind, LineOrder};
use crate::envelope as env;

/// The envelope checks, after the sections' own.
pub(crate) fn validate(cfg: &Config, c: &mut Checker) {
    let j = &cfg.job;
    for (key, p) in [
        ("job.point_a_m", j.point_a_m),
        ("job.point_b_m", j.point_b_m),
    ] {
        if p.iter()
            .any(|v| v.is_finite() && v.abs() > env::MAX_LOCAL_COORD_M)
        {
            c.push(
                key,
                format!("{p:?}"),
                &format!(
                    "must be within ±{} m of the origin (input envelope; move job.origin_* instead)",
                    fmt_num(env::MAX_LOCAL_COORD_M)
                ),
            );
        }
    }
    let ab = (j.point_b_m[0] - j.point_a_m[0]).hypot(j.point_b_m[1] - j.point_a_m[1]);
    if ab.is_finite() && ab > env::MAX_LINE_LENGTH_M {
        c.push(
            "job.point_b_m",
            format!("{:?}", j.point_b_m),
            &format!(
                "must be at most {} m from job.point_a_m (input envelope; the line is {} m)",
                fmt_num(env::MAX_LINE_LENGTH_M),
                fmt_num(ab.round())
            ),
        );
    }
    let spacing = cfg.guidance.point_spacing_m;
    let width = j.line_width_m;
    let usable = |v: f64| v.is_finite() && v > 0.0;
    match j.kind {
        JobKind::Ab => {
            if j.line_num > env::MAX_LINES {
                c.push(
                    "job.line_num",
                    j.line_num.to_string(),
                    &format!(
                        "must be at most {} (input envelope; 0 = unlimited)",
                        env::MAX_LINES
                    ),
                );
            } else if j.line_order == LineOrder::Sequential && usable(spacing) && ab.is_finite() {
                // Planned whole at start: every line and a turn of about π·r_min each.
                let per_line = ab + std::f64::consts::PI * cfg.vehicle.r_min_m.max(0.0);
                path_points(
                    c,
                    "job.line_num",
                    j.line_num,
                    per_line * j.line_num as f64 / spacing,
                );
            }
        }
        JobKind::Arcs if j.line_num <= env::MAX_ARCS && usable(spacing) && usable(width) => {
            let n = j.line_num as f64;
            let sweep = j.arc_sweep_deg.to_radians();
            // Σ (r + i·w)·sweep over i < n.
            let length = sweep * (n * j.arc_radius_m + width * n * (n - 1.0) / 2.0);
            path_points(c, "job.line_num", j.line_num, length / spacing);
            let outer = j.arc_radius_m + width * (n - 1.0);
            if outer > env::MAX_LOCAL_COORD_M {
                c.push(
                    "job.line_num",
                    j.line_num.to_string(),
                    &format!(
                        "the outer arc's radius {} m is beyond {} m (input envelope)",
                        fmt_num(outer.round()),
                        fmt_num(env::MAX_LOCAL_COORD_M)
                    ),
                );
            }
        }
        JobKind::Maneuver => {
            for (key, p) in [
                ("job.maneuver_from", j.maneuver_from),
                ("job.maneuver_to", j.maneuver_to),
            ] {
                if p[..2]
                    .iter()
                    .any(|v| v.is_finite() && v.abs() > env::MAX_LOCAL_COORD_M)
                {
                    c.push(
                        key,
                        format!("{p:?}"),
                        &format!(
                            "must be within ±{} m of the origin (input envelope)",
                            fmt_num(env::MAX_LOCAL_COORD_M)
                        ),
                    );
                }
            }
            let (f, t) = (j.maneuver_from, j.maneuver_to);
            let d = (t[0] - f[0]).hypot(t[1] - f[1]);
            if d.is_finite() && d > env::MAX_MANEUVER_DISTANCE_M {
                c.push(
                    "job.maneuver_to",
                    format!("{t:?}"),
                    &format!(
                        "must be at most {} m from job.maneuver_from (input envelope; it is {} m)",
                        fmt_num(env::MAX_MANEUVER_DISTANCE_M),
                        fmt_num(d.round())
                    ),
                );
            }
        }
        _ => {}
    }
    let a = cfg.guidance.a;
    if a > env::MAX_BLOCK_EXTRA {
        c.push(
            "guidance.a",
            a.to_string(),
            &format!("must be at most {} (input envelope)", env::MAX_BLOCK_EXTRA),
        );
    } else if a >= 1 && usable(width) {
        let r = cfg.turn_radius();
        let ratio = (2.0 * r / width).ceil();
        if ratio.is_finite() {
            let lines = 2.0 * ratio + a as f64;
            if lines > env::MAX_BLOCK_LINES as f64 {
                c.push(
                    "job.line_width_m",
                    fmt_num(width),
                    &format!(
                        "lines per block 2·ceil(2·r/w) + a = {} with the turn radius r = {} m (vehicle.r_min_m, or v²/(0.8·safety.a_lat_max_m_s2)) must be at most {} (input envelope)",
                        fmt_num(lines),
                        fmt_num((r * 100.0).round() / 100.0),
                        env::MAX_BLOCK_LINES
                    ),
                );
            }
        }
    }
    if cfg.guidance.turn_max_points > 100_000 {
        c.push(
            "guidance.turn_max_points",
            cfg.guidance.turn_max_points.to_string(),
            "must be at most 100000 (input envelope)",
        );
    }
    let lists = [
        (
            "sim.gnss_float_windows_s",
            cfg.sim.gnss_float_windows_s.len(),
            env::MAX_FLOAT_WINDOWS,
        ),
        (
            "maneuver.goal_patterns",
            cfg.maneuver.goal_patterns.len(),
            env::MAX_CONFIG_LIST,
        ),
    ];
    for (key, n, max) in lists {
        if n > max {
            c.push(
                key,
                format!("{n} entries"),
                &format!("must have at most {max} entries (input envelope)"),
            );
        }
    }
    every_float_finite(cfg, c);
}

fn path_points(c: &mut Checker, key: &str, line_num: u64, points: f64) {
    if points > env::MAX_PATH_POINTS {
        c.push(
            key,
            line_num.to_string(),
            &format!(
                "the job's path would hold {points:.2e} points at guidance.point_spacing_m, over the limit of {:.0e} (input envelope)",
                env::MAX_PATH_POINTS
            ),
        );
    }
}

/// Every float of the resolved configuration is finite; a key already reported is not
/// reported again.
fn every_float_finite(cfg: &Config, c: &mut Checker) {
    let Ok(tree) = toml::Table::try_from(cfg) else {
        return;
    };
    let mut bad = Vec::new();
    for (section, v) in &tree {
        walk(section, v, &mut bad);
    }
    for (key, value) in bad {
        let root = key.split('[').next().unwrap_or(&key).to_string();
        if !c.problems.iter().any(|p| p.key.starts_with(&root)) {
            c.push(&key, value, "must be a finite number");
        }
    }
}

fn walk(key: &str, v: &toml::Value, bad: &mut Vec<(String, String)>) {
    match v {
        toml::Value::Float(f) if !f.is_finite() => bad.push((key.to_string(), format!("{f}"))),
        toml::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                walk(&format!("{key}[{i}]"), x, bad);
            }
        }
        toml::Value::Table(t) => {
            for (k, x) in t {
                walk(&format!("{key}.{k}"), x, bad);
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every float key of the configuration (from the resolved default), as `--set` paths.
    fn float_keys() -> Vec<String> {
        let tree = toml::Table::try_from(Config::default()).unwrap();
        let mut keys = Vec::new();
        fn collect(key: &str, v: &toml::Value, keys: &mut Vec<String>) {
            match v {
                toml::Value::Float(_) => keys.push(key.to_string()),
                toml::Value::Table(t) => {
                    for (k, x) in t {
                        collect(&format!("{key}.{k}"), x, keys);
                    }
                }
                _ => {}
            }
        }
        for (s, v) in &tree {
            collect(s, v, &mut keys);
        }
        keys
    }

    #[test]
    fn every_float_key_refuses_nan_and_infinity_by_name() {
        let keys = float_keys();
        assert!(keys.len() > 100, "{}", keys.len());
        for key in keys {
            for v in ["nan", "inf", "-inf"] {
                let cfg = Config::parse_with("", &[format!("{key}={v}")]).unwrap();
                let problems = cfg.validate();
                assert!(
                    problems.iter().any(|p| p.key == key),
                    "{key} = {v} accepted: {problems:?}"
                );
            }
        }
    }

    #[test]
    fn float_arrays_refuse_nan_by_index() {
        let cfg = Config::parse_with("[sim]\ngnss_float_windows_s = [[1.0, nan]]\n", &[]).unwrap();
        assert!(cfg
            .validate()
            .iter()
            .any(|p| p.key.starts_with("sim.gnss_float_windows_s")));
        let cfg = Config::parse_with(
            "[job]\nkind = \"maneuver\"\nmaneuver_to = [nan, 0.0, 0.0]\n",
            &[],
        )
        .unwrap();
        assert!(cfg.validate().iter().any(|p| p.key == "job.maneuver_to"));
    }

    fn problems(set: &[&str]) -> Vec<String> {
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        Config::parse_with("", &set)
            .unwrap()
            .validate()
            .iter()
            .map(|p| p.to_string())
            .collect()
    }

    #[test]
    fn sizes_beyond_the_envelope_are_problems_naming_key_value_and_limit() {
        let p = problems(&["guidance.a=4294967297"]);
        assert!(
            p.iter()
                .any(|m| m.starts_with("guidance.a = 4294967297: must be at most 100")),
            "{p:?}"
        );
        let p = problems(&["job.point_b_m=[0.0, 1e9]"]);
        assert!(
            p.iter()
                .any(|m| m.starts_with("job.point_b_m") && m.contains("at most 20000 m")),
            "{p:?}"
        );
        let p = problems(&["job.point_a_m=[1e15, 0.0]"]);
        assert!(
            p.iter()
                .any(|m| m.starts_with("job.point_a_m") && m.contains("50000")),
            "{p:?}"
        );
        let p = problems(&["job.line_num=9223372036854775807"]);
        assert!(
            p.iter()
                .any(|m| m.starts_with("job.line_num = 9223372036854775807")),
            "{p:?}"
        );
        let p = problems(&[
            "job.line_order=\"sequential\"",
            "job.line_num=10000",
            "job.point_b_m=[0.0, 5000.0]",
        ]);
        assert!(
            p.iter()
                .any(|m| m.starts_with("job.line_num = 10000") && m.contains("points")),
            "{p:?}"
        );
        let p = problems(&[
            "job.kind=\"arcs\"",
            "job.line_num=1000",
            "job.arc_radius_m=10000",
        ]);
        assert!(
            p.iter()
                .any(|m| m.starts_with("job.line_num = 1000") && m.contains("points")),
            "{p:?}"
        );
        let p = problems(&["vehicle.r_min_m=100", "job.line_width_m=0.1"]);
        assert!(p.iter().any(|m| m.contains("lines per block")), "{p:?}");
        let p = problems(&["job.kind=\"maneuver\"", "job.maneuver_to=[1e9, 0.0, 0.0]"]);
        assert!(p.iter().any(|m| m.starts_with("job.maneuver_to")), "{p:?}");
    }

    #[test]
    fn the_defaults_and_large_legitimate_jobs_are_inside() {
        assert!(problems(&[]).is_empty());
        // 1 000 arcs of 30 m plus 3 m each: 2.4e3 km of path at 1 m would be too many; 200 are not.
        assert!(problems(&["job.kind=\"arcs\"", "job.line_num=200"]).is_empty());
        assert!(problems(&[
            "job.line_order=\"sequential\"",
            "job.line_num=1000",
            "job.point_b_m=[0.0, 2000.0]"
        ])
        .is_empty());
        assert!(problems(&["job.line_num=0"]).is_empty());
    }
}
