//! `agsteer maneuver`: plan a manoeuvre with reversing between two poses (docs/METHODS.md,
//! Manoeuvres with reversing) on a map in local metres, print the result (text or JSON), optionally
//! draw it as SVG; or plan a batch of pose pairs from a JSON-lines file.

use agsteer::config::{Config, CurveChoice};
use agsteer::envelope;
use agsteer::field::load_local_map;
use agsteer::geo::{Direction, Pose, Vec2};
use agsteer::job::maneuver::{plan_configured, pose_of};
use agsteer::plan::maneuver::collision::CollisionMap;
use agsteer::plan::maneuver::search::{ManeuverError, ManeuverResult, Method};
use anyhow::{anyhow, bail, Context, Result};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// Options of one run.
pub struct ManeuverArgs<'a> {
    pub map: Option<&'a Path>,
    pub from: Option<&'a str>,
    pub to: Option<&'a str>,
    pub curve: Option<CurveChoice>,
    pub svg: Option<&'a Path>,
    pub json: bool,
    pub batch: Option<&'a Path>,
}

/// Parse `x,y,heading_deg` (local metres, degrees CCW from East) into a pose.
pub fn parse_pose(s: &str) -> Result<Pose> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        bail!("pose `{s}`: expected x,y,heading_deg");
    }
    let v: Vec<f64> = parts
        .iter()
        .map(|p| p.parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| anyhow!("pose `{s}`: {e}"))?;
    if v.iter().any(|x| !x.is_finite()) {
        bail!("pose `{s}`: every number must be finite");
    }
    Ok(pose_of([v[0], v[1], v[2]]))
}

/// A start and goal inside the input envelope: finite, within ±`MAX_LOCAL_COORD_M` and at most
/// `MAX_MANEUVER_DISTANCE_M` apart; else the error names the value and the limit.
pub fn check_request(from: [f64; 3], to: [f64; 3]) -> Result<()> {
    for (name, p) in [("from", from), ("to", to)] {
        if p.iter().any(|x| !x.is_finite()) {
            bail!("{name} {p:?}: every number must be finite");
        }
        if p[0].abs() > envelope::MAX_LOCAL_COORD_M || p[1].abs() > envelope::MAX_LOCAL_COORD_M {
            bail!(
                "{name} ({}, {}) m: outside the local frame's ±{} m (envelope)",
                p[0],
                p[1],
                envelope::MAX_LOCAL_COORD_M
            );
        }
    }
    let d = (to[0] - from[0]).hypot(to[1] - from[1]);
    if d > envelope::MAX_MANEUVER_DISTANCE_M {
        bail!(
            "start and goal {d:.0} m apart: a manoeuvre is at most {} m long (envelope); drive it as a line or a field job",
            envelope::MAX_MANEUVER_DISTANCE_M
        );
    }
    Ok(())
}

#[derive(Serialize)]
struct SegmentOut {
    kind: agsteer::plan::maneuver::path::CurveKind,
    direction: Direction,
    length_m: f64,
}

/// The JSON of one result.
#[derive(Serialize)]
struct ResultOut {
    found: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    method: Option<String>,
    length_m: f64,
    cusps: usize,
    reverse_length_m: f64,
    segments: Vec<SegmentOut>,
    /// 1/m.
    max_curvature: f64,
    /// 1/m².
    max_curvature_rate: f64,
    expansions: usize,
    plan_time_ms: f64,
    /// What each planner stage did.
    stages: Vec<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    failure: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<String>,
}

fn method_name(m: &Method) -> String {
    match m {
        Method::Direct => "direct".into(),
        Method::Pattern(p) => format!("pattern {p}"),
        Method::Search => "search".into(),
        Method::Fallback => "fallback".into(),
    }
}

fn result_out(r: &Result<ManeuverResult, ManeuverError>, ms: f64) -> ResultOut {
    let mut out = ResultOut {
        found: false,
        method: None,
        length_m: 0.0,
        cusps: 0,
        reverse_length_m: 0.0,
        segments: Vec::new(),
        max_curvature: 0.0,
        max_curvature_rate: 0.0,
        expansions: 0,
        plan_time_ms: ms,
        stages: Vec::new(),
        failure: None,
        error: None,
    };
    match r {
        Err(e) => out.error = Some(e.to_string()),
        Ok(res) => {
            out.expansions = res.expansions;
            out.stages = res.stages.clone();
            out.failure = res.failure.clone();
            out.method = res.method.as_ref().map(method_name);
            if let Some(p) = &res.path {
                out.found = true;
                out.length_m = p.length();
                out.cusps = p.cusps();
                // + 0.0: an empty float sum is -0.0.
                out.reverse_length_m = p.reverse_length() + 0.0;
                out.max_curvature = p.max_curvature();
                out.max_curvature_rate = p.max_curvature_rate();
                out.segments = p
                    .segments
                    .iter()
                    .map(|s| SegmentOut {
                        kind: s.kind,
                        direction: s.direction,
                        length_m: s.length,
                    })
                    .collect();
            }
        }
    }
    out
}

fn plan_one(
    map: &CollisionMap,
    cfg: &Config,
    curve: CurveChoice,
    from: &Pose,
    to: &Pose,
) -> (Result<ManeuverResult, ManeuverError>, f64) {
    let t0 = Instant::now();
    let r = plan_configured(&cfg.planning().maneuver, map, curve, from, to);
    (r, t0.elapsed().as_secs_f64() * 1e3)
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct BatchLine {
    from: [f64; 3],
    to: [f64; 3],
}

/// `agsteer maneuver`. Exit status: 0 found (or a batch ran), 3 no path found.
pub fn run(cfg: &Config, a: &ManeuverArgs) -> Result<u8> {
    let (map, field) = match a.map {
        Some(path) => {
            let text = envelope::read_text(path, envelope::FileKind::Map)?;
            let field = load_local_map(&text).with_context(|| format!("map {}", path.display()))?;
            let map = CollisionMap::new(
                Some(field.boundary.clone()),
                field.obstacles.clone(),
                cfg.maneuver.grid_cell_m,
            )
            .with_context(|| format!("map {}", path.display()))?;
            (map, Some(field))
        }
        None => (CollisionMap::free(), None),
    };
    let curve = a.curve.unwrap_or(cfg.maneuver.curve);
    if let Some(batch) = a.batch {
        let text = envelope::read_text(batch, envelope::FileKind::Batch)?;
        for (n, line) in text.lines().enumerate() {
            if line.trim().is_empty() {
                continue;
            }
            let req: BatchLine = serde_json::from_str(line)
                .with_context(|| format!("{} line {}", batch.display(), n + 1))?;
            check_request(req.from, req.to)
                .with_context(|| format!("{} line {}", batch.display(), n + 1))?;
            let (r, ms) = plan_one(&map, cfg, curve, &pose_of(req.from), &pose_of(req.to));
            if !say(&serde_json::to_string(&result_out(&r, ms))?)? {
                return Ok(0);
            }
        }
        return Ok(0);
    }
    let from = parse_pose(a.from.ok_or_else(|| anyhow!("--from is required"))?)?;
    let to = parse_pose(a.to.ok_or_else(|| anyhow!("--to is required"))?)?;
    let xyh = |p: &Pose| [p.pos.x, p.pos.y, p.heading];
    check_request(xyh(&from), xyh(&to))?;
    let (r, ms) = plan_one(&map, cfg, curve, &from, &to);
    let res = r.clone().context("planning the manoeuvre")?;
    let out = result_out(&r, ms);
    if let Some(svg) = a.svg {
        let spacing = cfg.maneuver.sample_tolerance_m.max(0.05);
        std::fs::write(
            svg,
            maneuver_svg(cfg, field.as_ref(), &res, &from, &to, spacing),
        )
        .with_context(|| format!("writing {}", svg.display()))?;
    }
    if a.json {
        say(&serde_json::to_string_pretty(&out)?)?;
    } else if out.found {
        say(&format!(
            "found ({}): {:.1} m, {} cusps, {:.1} m in reverse, {} segments, max curvature {:.3} 1/m, max curvature rate {:.3} 1/m²; {} expansions, {:.1} ms",
            out.method.as_deref().unwrap_or("?"),
            out.length_m,
            out.cusps,
            out.reverse_length_m,
            out.segments.len(),
            out.max_curvature,
            out.max_curvature_rate,
            out.expansions,
            out.plan_time_ms
        ))?;
    } else {
        say(&format!(
            "no path: {} ({:.1} ms)",
            out.failure.as_deref().unwrap_or("not found"),
            out.plan_time_ms
        ))?;
    }
    Ok(if out.found {
        agsteer::exit::Exit::Success
    } else {
        agsteer::exit::Exit::NoPath
    }
    .code())
}

/// Print a line on stdout. `Ok(false)` when the reader has gone (broken pipe, e.g. `| head`):
/// stop quietly instead of panicking like `println!`.
fn say(line: &str) -> Result<bool> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match writeln!(out, "{line}").and_then(|()| out.flush()) {
        Ok(()) => Ok(true),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(false),
        Err(e) => Err(e.into()),
    }
}

fn svg_points(pts: &[Vec2]) -> String {
    pts.iter()
        .map(|p| format!("{:.2},{:.2}", p.x, -p.y))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The map, the rough route (dashed green), the path coloured by direction (forward blue,
/// reverse red), vehicle outlines every ~3 m, cusps as circles, start and goal outlines.
fn maneuver_svg(
    cfg: &Config,
    field: Option<&agsteer::plan::coverage::Field>,
    res: &ManeuverResult,
    from: &Pose,
    to: &Pose,
    spacing: f64,
) -> String {
    let fp = cfg.maneuver_params().footprint;
    let mut samples = Vec::new();
    if let Some(p) = &res.path {
        p.sample(spacing, &mut samples);
    }
    let mut all: Vec<Vec2> = samples.iter().map(|s| s.pose.pos).collect();
    all.push(from.pos);
    all.push(to.pos);
    if let Some(f) = field {
        all.extend(f.boundary.iter().copied());
    }
    let (min, max) = agsteer::geo::polygon::bbox(all.iter())
        .unwrap_or((Vec2::new(0.0, 0.0), Vec2::new(1.0, 1.0)));
    let pad = 6.0;
    let (w, h) = (max.x - min.x + 2.0 * pad, max.y - min.y + 2.0 * pad);
    let width_px = (w * 12.0).min(1600.0);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="{:.2} {:.2} {:.2} {:.2}" width="{:.0}" height="{:.0}">"#,
        min.x - pad,
        -max.y - pad,
        w,
        h,
        width_px,
        width_px * h / w
    );
    if let Some(f) = field {
        let _ = writeln!(
            s,
            r##"<polygon points="{}" fill="#eef5e6" stroke="#555" stroke-width="0.15"/>"##,
            svg_points(&f.boundary)
        );
        for o in &f.obstacles {
            let _ = writeln!(
                s,
                r##"<polygon points="{}" fill="#777" stroke="#333" stroke-width="0.1"/>"##,
                svg_points(o)
            );
        }
    }
    // The rough route of the straight-line expansion, dashed.
    if res.rough_route.len() >= 2 {
        let _ = writeln!(
            s,
            r##"<polyline points="{}" fill="none" stroke="#8a6" stroke-width="0.08" stroke-dasharray="0.5 0.3"/>"##,
            svg_points(&res.rough_route)
        );
    }
    // Vehicle outlines every ~3 m.
    let mut next = 0.0;
    for smp in &samples {
        if smp.s + 1e-9 >= next {
            for r in fp.rectangles(&smp.pose) {
                let _ = writeln!(
                    s,
                    r##"<polygon points="{}" fill="none" stroke="#999" stroke-width="0.05"/>"##,
                    svg_points(&r)
                );
            }
            next = smp.s + 3.0;
        }
    }
    for (pose, colour) in [(from, "#2a7"), (to, "#c80")] {
        for r in fp.rectangles(pose) {
            let _ = writeln!(
                s,
                r#"<polygon points="{}" fill="none" stroke="{colour}" stroke-width="0.15"/>"#,
                svg_points(&r)
            );
        }
    }
    // Path runs by direction.
    let mut k = 0;
    while k + 1 < samples.len() {
        let dir = samples[k + 1].direction;
        let mut run = vec![samples[k].pose.pos];
        while k + 1 < samples.len() && samples[k + 1].direction == dir {
            k += 1;
            run.push(samples[k].pose.pos);
        }
        let colour = match dir {
            Direction::Forward => "#1f5fd0",
            Direction::Reverse => "#d02020",
        };
        let _ = writeln!(
            s,
            r#"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="0.12"/>"#,
            svg_points(&run)
        );
        if k + 1 < samples.len() {
            let c = samples[k].pose.pos;
            let _ = writeln!(
                s,
                r##"<circle cx="{:.2}" cy="{:.2}" r="0.4" fill="none" stroke="#000" stroke-width="0.1"/>"##,
                c.x, -c.y
            );
        }
    }
    let status = match &res.path {
        Some(p) => format!(
            "{:.1} m, {} cusps, {:.1} m reverse",
            p.length(),
            p.cusps(),
            p.reverse_length() + 0.0
        ),
        None => format!("no path: {}", res.failure.as_deref().unwrap_or("not found")),
    };
    let _ = writeln!(
        s,
        r#"<text x="{:.2}" y="{:.2}" font-size="1.5" font-family="sans-serif">{status}</text>"#,
        min.x - pad + 0.5,
        -max.y - pad + 2.0
    );
    s.push_str("</svg>\n");
    s
}
