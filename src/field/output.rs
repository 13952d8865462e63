//! Plan writers (pure, return strings): `plan.geojson` in WGS-84 and `plan.svg`; the plan
//! summary of `metrics.json` and of the demo report.

use super::findings::{violation_phrases, PlanFindings, PlanGround};
use super::{CleanupReport, LoadedField};
use crate::geo::svg::SvgCanvas;
use crate::geo::wgs84::{EnuFrame, LatLon};
use crate::geo::{Direction, Vec2};
use crate::plan::coverage::metrics::PlanMetrics;
use crate::plan::coverage::{Field, FieldPlan, SegmentKind};
use geo::MultiPolygon;
use serde::Serialize;
use serde_json::{json, Value};
use std::time::Duration;

/// A plan's summary: `agsteer plan`'s `metrics.json` and the `plan` object of the demo
/// report. Lengths m, areas m², fractions 0–1, times ms (measured by the caller).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanSummary {
    pub field: Option<String>,
    pub origin: LatLon,
    pub cleanup: CleanupReport,
    pub cells: usize,
    pub swaths: usize,
    pub swath_angles_deg: Vec<f64>,
    pub work_length_m: f64,
    pub turn_length_m: f64,
    pub transit_length_m: f64,
    pub total_length_m: f64,
    pub turns: usize,
    pub reversals: usize,
    /// The whole field worked (footprints of every working pass over the field area).
    pub covered_fraction: f64,
    /// The working area (inside the headland) covered by the swaths.
    pub working_area_covered_fraction: f64,
    pub unworked_area_m2: f64,
    pub overlap_fraction: f64,
    /// Sections of the implement the plan was made for (`field.sections`): above 1 the
    /// overlap counts each section where it is on.
    pub sections: usize,
    /// Overlap of neighbouring passes the plan was made with (`field.overlap_m`), m.
    pub pass_overlap_m: f64,
    pub outside_area_m2: f64,
    pub outside_length_m: f64,
    pub obstacle_intrusions: usize,
    pub obstacle_length_m: f64,
    pub obstacle_footprint_m2: f64,
    pub max_curvature: f64,
    pub turn_points_outside: usize,
    pub plan_time_ms: f64,
    pub metrics_time_ms: f64,
    /// Violations, unreachable ground and warnings.
    #[serde(flatten)]
    pub findings: PlanFindings,
}

impl PlanSummary {
    pub fn new(
        loaded: &LoadedField,
        plan: &FieldPlan,
        m: &PlanMetrics,
        findings: &PlanFindings,
        plan_time: Duration,
        metrics_time: Duration,
    ) -> PlanSummary {
        PlanSummary {
            field: loaded.name.clone(),
            origin: loaded.origin,
            cleanup: loaded.cleanup,
            cells: plan.cells,
            swaths: plan.swaths,
            swath_angles_deg: plan.swath_angles.iter().map(|a| a.to_degrees()).collect(),
            work_length_m: m.work_length_m,
            turn_length_m: m.turn_length_m,
            transit_length_m: m.transit_length_m,
            total_length_m: m.total_length_m,
            turns: m.turns,
            reversals: m.reversals,
            covered_fraction: m.covered_fraction,
            working_area_covered_fraction: m.working_area_covered_fraction,
            unworked_area_m2: m.unworked_area_m2,
            overlap_fraction: m.overlap_fraction,
            sections: plan.sections.max(1),
            pass_overlap_m: plan.pass_overlap_m,
            outside_area_m2: m.outside_area_m2,
            outside_length_m: m.outside_length_m,
            obstacle_intrusions: m.obstacle_intrusions,
            obstacle_length_m: m.obstacle_length_m,
            obstacle_footprint_m2: m.obstacle_footprint_m2,
            max_curvature: m.max_curvature,
            turn_points_outside: m.turn_points_outside,
            plan_time_ms: plan_time.as_secs_f64() * 1e3,
            metrics_time_ms: metrics_time.as_secs_f64() * 1e3,
            findings: findings.clone(),
        }
    }
}

/// What the overlap figure counts, after it: "" for an implement without sections whose passes
/// meet exactly, else " (with N sections, passes X m over each other)" or either part
/// ([`FieldPlan::sections`], [`FieldPlan::pass_overlap_m`]).
pub fn overlap_note(plan: &FieldPlan) -> String {
    let mut parts = Vec::new();
    if plan.sections > 1 {
        parts.push(format!("with {} sections", plan.sections));
    }
    if plan.pass_overlap_m > 0.0 {
        parts.push(format!(
            "passes {:.2} m over each other",
            plan.pass_overlap_m
        ));
    }
    if parts.is_empty() {
        String::new()
    } else {
        format!(" ({})", parts.join(", "))
    }
}

/// Colour of unworked ground in the SVG.
pub const UNWORKED: &str = "#e41a1c";
/// Colour of the hatching of unreachable ground in the SVG, and of its background.
pub const UNREACHABLE: &str = "#222222";
const UNREACHABLE_BG: &str = "#fdd0a2";
/// Characters per footer line of the SVG.
const FOOTER_CHARS: usize = 150;

/// The rings of a multipolygon (outer rings and holes), local metres.
fn rings(mp: &MultiPolygon<f64>) -> Vec<Vec<Vec2>> {
    mp.0.iter()
        .flat_map(|p| std::iter::once(p.exterior()).chain(p.interiors()))
        .map(|r| r.coords().map(|c| Vec2::new(c.x, c.y)).collect())
        .collect()
}

/// `text` cut at spaces into lines of at most `width` characters (a longer word stays whole);
/// the continuation lines indented.
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for word in text.split(' ') {
        if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > width {
            lines.push(std::mem::take(&mut line));
            line.push_str("    ");
        } else if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.trim().is_empty() {
        lines.push(line);
    }
    lines
}

fn kind_name(k: SegmentKind) -> &'static str {
    match k {
        SegmentKind::Work => "work",
        SegmentKind::Turn => "turn",
        SegmentKind::Headland => "headland",
        SegmentKind::Detour => "detour",
        SegmentKind::Transit => "transit",
    }
}

fn direction_name(d: Direction) -> &'static str {
    match d {
        Direction::Forward => "forward",
        Direction::Reverse => "reverse",
    }
}

/// Colour of a segment kind in the SVG.
pub fn kind_colour(k: SegmentKind) -> &'static str {
    match k {
        SegmentKind::Work => "#1a9850",
        SegmentKind::Turn => "#4575b4",
        SegmentKind::Headland => "#984ea3",
        SegmentKind::Detour => "#f46d43",
        SegmentKind::Transit => "#999999",
    }
}

fn position(frame: &EnuFrame, p: &Vec2) -> Value {
    let ll = frame.to_latlon(*p);
    let r = |v: f64| (v * 1e9).round() / 1e9;
    json!([r(ll.lon_deg), r(ll.lat_deg)])
}

fn ring(frame: &EnuFrame, pts: &[Vec2]) -> Value {
    let mut v: Vec<Value> = pts.iter().map(|p| position(frame, p)).collect();
    if let Some(first) = v.first().cloned() {
        v.push(first);
    }
    Value::Array(v)
}

fn polygon_feature(frame: &EnuFrame, outer: &[Vec2], holes: &[Vec<Vec2>], props: Value) -> Value {
    let mut rings = vec![ring(frame, outer)];
    rings.extend(holes.iter().map(|h| {
        // RFC 7946: holes clockwise.
        let mut h = h.clone();
        h.reverse();
        ring(frame, &h)
    }));
    json!({"type": "Feature", "properties": props,
           "geometry": {"type": "Polygon", "coordinates": rings}})
}

/// `plan.geojson`: a FeatureCollection in WGS-84 holding the field (`role` "field", with the
/// ENU origin), obstacles, working area and headland polygons, then every plan segment as a
/// LineString in driving order with `kind`, `direction`, `index` and `cell`. The origin is
/// also a top-level member `origin`.
pub fn plan_geojson(
    field: &Field,
    plan: &FieldPlan,
    origin: LatLon,
    metrics: Option<&PlanMetrics>,
) -> String {
    let frame = EnuFrame::new(origin);
    let origin_json = json!({"lat_deg": origin.lat_deg, "lon_deg": origin.lon_deg});
    let mut features = vec![polygon_feature(
        &frame,
        &field.boundary,
        &field.obstacles,
        json!({"role": "field", "origin": origin_json}),
    )];
    for (i, o) in field.obstacles.iter().enumerate() {
        features.push(polygon_feature(
            &frame,
            o,
            &[],
            json!({"role": "obstacle", "obstacle": true, "index": i}),
        ));
    }
    for (i, (outer, holes)) in plan.working_area.iter().enumerate() {
        features.push(polygon_feature(
            &frame,
            outer,
            holes,
            json!({"role": "working_area", "index": i}),
        ));
    }
    // The headland: the field inside its boundary and outside the working area.
    let working_outlines: Vec<Vec<Vec2>> = plan
        .working_area
        .iter()
        .map(|(outer, _)| outer.clone())
        .collect();
    if !working_outlines.is_empty() {
        features.push(polygon_feature(
            &frame,
            &field.boundary,
            &working_outlines,
            json!({"role": "headland_area"}),
        ));
    }
    for s in &plan.segments {
        let coords: Vec<Value> = s.points.iter().map(|p| position(&frame, p)).collect();
        features.push(json!({
            "type": "Feature",
            "properties": {"kind": kind_name(s.kind), "direction": direction_name(s.direction),
                           "index": s.index, "cell": s.cell},
            "geometry": {"type": "LineString", "coordinates": coords},
        }));
    }
    let mut doc = json!({"type": "FeatureCollection", "origin": origin_json, "features": features});
    if let (Some(m), Some(obj)) = (metrics, doc.as_object_mut()) {
        obj.insert("metrics".into(), json!(m));
    }
    serde_json::to_string_pretty(&doc).unwrap_or_default()
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `TASKDATA.XML` (ISO 11783-10, version 4.3) for a terminal: one partfield (PFD1) with the
/// field boundary (PLN type 1: LSG type 1 exterior, LSG type 2 for each obstacle) and one
/// guidance group holding the plan's lines in driving order: every work swath as an AB line
/// (GPN type 1, points A and B) and every headland pass as a curve (GPN type 3), each as an
/// LSG type 5. Coordinates WGS-84 degrees with 9 decimals (0.1 mm).
pub fn plan_taskdata(field: &Field, plan: &FieldPlan, origin: LatLon, name: &str) -> String {
    use std::fmt::Write;
    let frame = EnuFrame::new(origin);
    let pnt = |out: &mut String, kind: u8, p: &Vec2| {
        let ll = frame.to_latlon(*p);
        let _ = write!(
            out,
            r#"<PNT A="{kind}" C="{:.9}" D="{:.9}"/>"#,
            ll.lat_deg, ll.lon_deg
        );
    };
    let ring = |out: &mut String, lsg_type: u8, pts: &[Vec2]| {
        let _ = write!(out, r#"<LSG A="{lsg_type}">"#);
        for p in pts.iter().chain(pts.first()) {
            pnt(out, 2, p);
        }
        out.push_str("</LSG>");
    };
    let area = crate::geo::polygon::signed_area(&field.boundary)
        - field
            .obstacles
            .iter()
            .map(|o| crate::geo::polygon::signed_area(o).abs())
            .sum::<f64>();
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        r#"<ISO11783_TaskData VersionMajor="4" VersionMinor="3" ManagementSoftwareManufacturer="agsteer" ManagementSoftwareVersion="{}" DataTransferOrigin="1">"#,
        env!("CARGO_PKG_VERSION")
    );
    let _ = write!(
        x,
        r#"<PFD A="PFD1" C="{}" D="{}">"#,
        xml_escape(name),
        area.max(0.0).round() as u64
    );
    x.push_str(r#"<PLN A="1" B="boundary">"#);
    ring(&mut x, 1, &field.boundary);
    for o in &field.obstacles {
        ring(&mut x, 2, o);
    }
    x.push_str("</PLN>\n");
    x.push_str(r#"<GGP A="GGP1" B="agsteer plan">"#);
    let mut n = 0;
    for s in &plan.segments {
        let (kind, label) = match s.kind {
            SegmentKind::Work => (1, "swath"),
            SegmentKind::Headland => (3, "headland pass"),
            _ => continue,
        };
        let (Some(first), Some(last)) = (s.points.first(), s.points.last()) else {
            continue;
        };
        n += 1;
        let _ = write!(
            x,
            r#"<GPN A="GPN{n}" B="{label} {n} (segment {})" C="{kind}"><LSG A="5">"#,
            s.index
        );
        if kind == 1 {
            pnt(&mut x, 6, first);
            pnt(&mut x, 7, last);
        } else {
            let k = s.points.len();
            for (i, p) in s.points.iter().enumerate() {
                let t = match i {
                    0 => 6,
                    _ if i + 1 == k => 7,
                    _ => 9,
                };
                pnt(&mut x, t, p);
            }
        }
        x.push_str("</LSG></GPN>\n");
    }
    x.push_str("</GGP></PFD>\n</ISO11783_TaskData>\n");
    x
}

/// `plan.svg`: field, obstacles, headland area, working area, segments coloured by kind with
/// their driving-order index at each segment start and an arrow dot at each work segment's
/// end, a legend, key figures, a scale bar and a north arrow.
pub fn plan_svg(
    field: &Field,
    plan: &FieldPlan,
    origin: LatLon,
    metrics: Option<&PlanMetrics>,
    checked: Option<(&PlanFindings, &PlanGround)>,
    title: &str,
) -> String {
    let extent = field
        .boundary
        .iter()
        .chain(plan.segments.iter().flat_map(|s| s.points.iter()));
    // Footer lines below the figures: the violations and every warning, wrapped.
    let notes: Vec<(String, &str)> = checked
        .map(|(f, _)| {
            let mut lines = vec![if f.violations.is_empty() {
                ("violations: none".to_string(), "#000")
            } else {
                (
                    format!(
                        "VIOLATIONS {} (must not be driven): {}",
                        f.violations.len(),
                        violation_phrases(&f.violations).join("; ")
                    ),
                    "#b00",
                )
            }];
            lines.extend(f.warnings.iter().map(|w| (format!("warning: {w}"), "#a50")));
            lines
                .iter()
                .flat_map(|(l, colour)| wrap(l, FOOTER_CHARS).into_iter().map(|l| (l, *colour)))
                .collect()
        })
        .unwrap_or_default();
    let mut c = SvgCanvas::fit(extent, 1000.0).with_taller_footer(if notes.is_empty() {
        0.0
    } else {
        16.0 * notes.len() as f64 + 20.0
    });
    c.polygon(
        &field.boundary,
        r##"fill="#f3efe0" stroke="#333" stroke-width="1.5""##,
    );
    for (outer, holes) in &plan.working_area {
        c.polygon(
            outer,
            r##"fill="#e3f1dc" stroke="#7a7" stroke-width="0.8""##,
        );
        for h in holes {
            c.polygon(h, r##"fill="#f3efe0" stroke="#7a7" stroke-width="0.8""##);
        }
    }
    for o in &field.obstacles {
        c.polygon(o, r##"fill="#8c6d46" stroke="#333" stroke-width="1""##);
    }
    if let Some((_, ground)) = checked {
        // Unworked ground red (stroked too, so thin strips show at any scale); unreachable
        // ground hatched over it.
        c.area(
            rings(&ground.unworked).iter(),
            &format!(
                r#"fill="{UNWORKED}" fill-opacity="0.6" stroke="{UNWORKED}" stroke-width="1""#
            ),
        );
        c.raw(&format!(
            r#"<defs><pattern id="unreachable" width="6" height="6" patternUnits="userSpaceOnUse" patternTransform="rotate(45)"><rect width="6" height="6" fill="{UNREACHABLE_BG}"/><line x1="0" y1="0" x2="0" y2="6" stroke="{UNREACHABLE}" stroke-width="2.5"/></pattern></defs>"#
        ));
        c.area(
            rings(&ground.unreachable).iter(),
            &format!(r#"fill="url(#unreachable)" stroke="{UNREACHABLE}" stroke-width="1""#),
        );
    }
    let label_every = (plan.segments.len() / 150).max(1);
    for s in &plan.segments {
        let style = match s.kind {
            SegmentKind::Transit | SegmentKind::Turn => format!(
                r#"stroke="{}" stroke-width="1.2" stroke-dasharray="4 2""#,
                kind_colour(s.kind)
            ),
            _ => format!(r#"stroke="{}" stroke-width="1.5""#, kind_colour(s.kind)),
        };
        c.polyline(&s.points, &style);
        if matches!(s.kind, SegmentKind::Work | SegmentKind::Headland) {
            if let Some(end) = s.points.last() {
                c.dot(end, 2.0, "#000");
            }
            if s.index % label_every == 0 {
                if let Some(start) = s.points.first() {
                    c.label(start, &s.index.to_string(), 9.0);
                }
            }
        }
    }
    let kinds = [
        SegmentKind::Work,
        SegmentKind::Headland,
        SegmentKind::Turn,
        SegmentKind::Detour,
        SegmentKind::Transit,
    ];
    for (i, k) in kinds.iter().enumerate() {
        c.footer_swatch(
            10.0 + 110.0 * i as f64,
            20.0,
            kind_colour(*k),
            kind_name(*k),
        );
    }
    if checked.is_some() {
        c.footer_swatch(
            10.0 + 110.0 * kinds.len() as f64,
            20.0,
            UNWORKED,
            "unworked",
        );
        c.footer_swatch(
            10.0 + 110.0 * (kinds.len() + 1) as f64,
            20.0,
            UNREACHABLE,
            "unreachable (hatched)",
        );
    }
    c.footer_text(
        10.0,
        42.0,
        "numbers: driving order at segment start; black dot: segment end",
        11.0,
        "#444",
    );
    let figures = match metrics {
        Some(m) => format!(
            "{} cells, {} swaths, field worked {:.2} % (working area {:.2} %), unworked {:.0} m², overlap {:.2} %{}, outside {:.3} m², total {:.0} m; origin {:.7}°, {:.7}°",
            plan.cells,
            plan.swaths,
            100.0 * m.covered_fraction,
            100.0 * m.working_area_covered_fraction,
            m.unworked_area_m2,
            100.0 * m.overlap_fraction,
            overlap_note(plan),
            m.outside_area_m2,
            m.total_length_m,
            origin.lat_deg,
            origin.lon_deg
        ),
        None => format!(
            "{} cells, {} swaths; origin {:.7}°, {:.7}°",
            plan.cells, plan.swaths, origin.lat_deg, origin.lon_deg
        ),
    };
    c.footer_text(10.0, 62.0, &figures, 12.0, "#000");
    for (i, (line, colour)) in notes.iter().enumerate() {
        c.footer_text(10.0, 80.0 + 16.0 * i as f64, line, 11.0, colour);
    }
    c.scale_bar_and_north();
    c.finish(title)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::{load_geojson, LoadOptions};
    use crate::geo::v2;
    use crate::plan::coverage::PlanSegment;

    fn sample() -> (Field, FieldPlan, LatLon) {
        let origin = LatLon {
            lat_deg: 52.0,
            lon_deg: 5.0,
        };
        let field = Field {
            boundary: vec![v2(0.0, 0.0), v2(100.0, 0.0), v2(100.0, 50.0), v2(0.0, 50.0)],
            obstacles: vec![vec![v2(40.0, 20.0), v2(50.0, 20.0), v2(50.0, 30.0)]],
        };
        let seg = |kind, index, direction, pts: Vec<Vec2>| PlanSegment {
            kind,
            direction,
            index,
            cell: 0,
            points: pts,
        };
        let plan = FieldPlan {
            segments: vec![
                seg(
                    SegmentKind::Work,
                    0,
                    Direction::Forward,
                    vec![v2(5.0, 5.0), v2(95.0, 5.0)],
                ),
                seg(
                    SegmentKind::Turn,
                    1,
                    Direction::Reverse,
                    vec![v2(95.0, 5.0), v2(95.0, 15.0)],
                ),
            ],
            working_area: vec![(field.boundary.clone(), vec![])],
            cells: 1,
            swath_angles: vec![0.0],
            swaths: 1,
            ..FieldPlan::default()
        };
        (field, plan, origin)
    }

    #[test]
    fn geojson_round_trips_segments_and_origin() {
        let (field, plan, origin) = sample();
        let text = plan_geojson(&field, &plan, origin, None);
        let doc: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(doc["origin"]["lat_deg"], 52.0);
        let feats = doc["features"].as_array().unwrap();
        let lines: Vec<&Value> = feats
            .iter()
            .filter(|f| f["geometry"]["type"] == "LineString")
            .collect();
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[1]["properties"]["kind"], "turn");
        assert_eq!(lines[1]["properties"]["direction"], "reverse");
        assert_eq!(lines[1]["properties"]["index"], 1);
        // Back to ENU: the first work point is where it was (0.1 mm rounding).
        let frame = EnuFrame::new(origin);
        let c = &lines[0]["geometry"]["coordinates"][0];
        let p = frame.to_enu(LatLon {
            lat_deg: c[1].as_f64().unwrap(),
            lon_deg: c[0].as_f64().unwrap(),
        });
        assert!((p - v2(5.0, 5.0)).norm() < 1e-3);
        // The field polygon (with the obstacle as a hole) reads back as the same field.
        let field_only = json!({"type": "FeatureCollection", "features": [feats[0].clone()]});
        let back = load_geojson(
            &field_only.to_string(),
            &LoadOptions {
                origin: Some(origin),
                boundary_tolerance_m: 0.0,
            },
        )
        .unwrap();
        assert_eq!(back.field.obstacles.len(), 1);
        assert!((back.cleanup.area_after_m2 - (5000.0 - 50.0)).abs() < 0.01);
        // The headland polygon: the boundary with each working area's outline as a hole.
        let headland: Vec<&Value> = feats
            .iter()
            .filter(|f| f["properties"]["role"] == "headland_area")
            .collect();
        assert_eq!(headland.len(), usize::from(!plan.working_area.is_empty()));
        if let Some(h) = headland.first() {
            let rings = h["geometry"]["coordinates"].as_array().unwrap();
            assert_eq!(rings.len(), 1 + plan.working_area.len());
        }
    }

    #[test]
    fn svg_draws_unworked_ground_red_unreachable_hatched_and_names_each_finding() {
        let (field, plan, origin) = sample();
        let loaded = LoadedField {
            name: None,
            origin,
            field: field.clone(),
            cleanup: CleanupReport::default(),
            guidance: vec![],
            warnings: vec!["LSG 1 of type 7 (fence) skipped".into()],
        };
        let m = crate::plan::coverage::metrics::plan_metrics(&field, &plan, 6.0);
        let (f, ground) = crate::field::findings::plan_findings(&loaded, &plan, &m, 6.0, 5.0, &[]);
        let svg = plan_svg(&field, &plan, origin, Some(&m), Some((&f, &ground)), "t");
        // The turn (95, 5) → (95, 15) is 2.7 m from the edge: no violation; one swath of a
        // 6 m implement leaves most of the field unworked.
        assert!(f.violations.is_empty(), "{:?}", f.violations);
        let red = format!(r#"fill="{UNWORKED}" fill-opacity"#);
        assert_eq!(svg.matches(&red).count(), 1, "one unworked area");
        assert!(svg.contains(r#"fill="url(#unreachable)""#));
        assert!(svg.contains("<pattern id=\"unreachable\""));
        assert!(svg.contains(">unworked</text>") && svg.contains(">unreachable (hatched)</text>"));
        assert!(svg.contains(">violations: none</text>"), "{svg}");
        assert!(svg.contains("warning: LSG 1 of type 7 (fence) skipped"));
        assert!(svg.contains("warning: field worked"));
        assert!(svg.contains("cannot be reached turning at r_min 5 m"));
        // Without findings, none of it.
        let bare = plan_svg(&field, &plan, origin, Some(&m), None, "t");
        assert!(!bare.contains(&red) && !bare.contains("unreachable"));
    }

    #[test]
    fn long_footer_lines_are_wrapped_at_spaces() {
        let text = "a ".repeat(100) + "end";
        let lines = wrap(&text, 50);
        assert!(lines.iter().all(|l| l.chars().count() <= 50), "{lines:?}");
        assert_eq!(lines.concat().split_whitespace().count(), 101);
        assert!(lines[1].starts_with("    "));
    }

    #[test]
    fn svg_has_every_kind_colour_and_labels() {
        let (field, plan, origin) = sample();
        let svg = plan_svg(&field, &plan, origin, None, None, "t");
        assert!(svg.starts_with("<svg"));
        assert!(svg.contains(kind_colour(SegmentKind::Work)));
        assert!(svg.contains(kind_colour(SegmentKind::Turn)));
        assert!(svg.contains(">0</text>"));
        assert!(svg.contains(" m</text>"));
    }
}
