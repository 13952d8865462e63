//! Field input: GeoJSON and ISO 11783-10 TASKDATA boundaries (WGS-84) into a local
//! [`Field`](crate::plan::coverage::Field), with an ENU origin and boundary clean-up.
//!
//! Parsing works on strings; reading files is the binaries' job.
//!
//! - GeoJSON: a FeatureCollection, a Feature or a bare Polygon/MultiPolygon geometry, in
//!   WGS-84 (`[lon, lat]`). Exactly one boundary polygon; its holes become obstacles, and so do
//!   Features with the property `"obstacle": true`.
//! - ISO 11783-10 `TASKDATA.XML`: the first `PFD` (partfield) with a `PLN` of type `A="1"`
//!   (partfield boundary). Its `LSG A="1"` is the exterior, `LSG A="2"` rings are obstacles;
//!   `PLN`s of type 3 (water), 4 (building), 6 (obstacle) and 12 (windbreak) are obstacles too.
//!   Other polygon types (treatment zone, road, flag, headland, …) are ignored.
//!
//! Every ring is cleaned ([`clean_ring`]): closing and duplicate points dropped, collinear
//! points dropped, stretches of many short edges (arcs) replaced by straight segments fitted by
//! line regression (seed 001) within `boundary_tolerance_m`, orientation made CCW. The area
//! change is reported in [`CleanupReport`].

mod clean;
pub mod findings;
mod geojson;
pub mod output;
mod taskdata;

pub use clean::{clean_ring, RingCleanup};
pub use taskdata::{GuidanceKind, PartfieldInfo};

use crate::envelope;
use crate::geo::polygon::{contains_point, segments_intersect, signed_area};
use crate::geo::wgs84::{EnuFrame, LatLon};
use crate::geo::Vec2;
use crate::plan::coverage::Field;
use serde::Serialize;

/// Options for loading a field.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadOptions {
    /// ENU origin; `None` = the centre of the boundary's lat/lon bounding box.
    pub origin: Option<LatLon>,
    /// Largest distance of a dropped boundary point from the cleaned boundary, m.
    pub boundary_tolerance_m: f64,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            origin: None,
            boundary_tolerance_m: 0.1,
        }
    }
}

/// What boundary clean-up did, over all rings (boundary and obstacles).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct CleanupReport {
    /// Field area (boundary minus obstacles) before clean-up, m².
    pub area_before_m2: f64,
    /// Field area after clean-up, m².
    pub area_after_m2: f64,
    /// |after − before|, m².
    pub area_error_m2: f64,
    /// Area error as a percentage of the area before.
    pub area_error_pct: f64,
    /// Boundary tolerance used, m.
    pub tolerance_m: f64,
    pub vertices_before: usize,
    pub vertices_after: usize,
    /// Repeated (and closing) points dropped.
    pub duplicates_removed: usize,
    /// Points dropped because they lay on a straight line with their neighbours.
    pub collinear_removed: usize,
    /// Points dropped by fitting straight segments to stretches of short edges.
    pub fitted_removed: usize,
    /// Rings whose orientation was reversed.
    pub rings_reoriented: usize,
}

/// A field read from a file's text: local geometry, its origin and the clean-up report.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedField {
    /// Name from the input (GeoJSON `name` property, TASKDATA PFD designator), if any.
    pub name: Option<String>,
    /// The ENU origin of `field`.
    pub origin: LatLon,
    pub field: Field,
    pub cleanup: CleanupReport,
    /// Guidance patterns of the field (TASKDATA GGP/GPN), local metres.
    pub guidance: Vec<GuidanceLine>,
    /// What was skipped or changed while reading (unused PLN/LSG types, obstacles cut out of
    /// the boundary, …), one sentence each naming the element.
    pub warnings: Vec<String>,
}

/// A guidance pattern read with a field: an AB line (two points) or a reference curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GuidanceLine {
    /// The element it came from (PFD, GPN id and designator).
    pub name: String,
    pub kind: GuidanceKind,
    /// Points in order, local ENU metres.
    pub points: Vec<Vec2>,
}

impl GuidanceLine {
    /// Direction from the first to the last point, rad CCW from East.
    pub fn heading(&self) -> Option<f64> {
        let (a, b) = (self.points.first()?, self.points.last()?);
        let d = b - a;
        (d.norm() > 1e-6).then(|| d.y.atan2(d.x))
    }
}

impl LoadedField {
    /// The ENU frame of this field.
    pub fn frame(&self) -> EnuFrame {
        EnuFrame::new(self.origin)
    }
}

/// Why a field could not be read. `feature` names the offending input element (index and
/// name/id when present).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FieldError {
    #[error("not valid JSON: {0}")]
    Json(String),
    #[error("not valid XML: {0}")]
    Xml(String),
    #[error("input is neither GeoJSON (starts with '{{') nor TASKDATA XML (starts with '<')")]
    UnknownFormat,
    #[error("{feature}: not a polygon ({detail})")]
    NotAPolygon { feature: String, detail: String },
    #[error("{feature}: bad coordinates ({detail})")]
    BadCoordinates { feature: String, detail: String },
    #[error("{feature}: {ring} has {points} distinct points, at least 3 needed")]
    TooFewPoints {
        feature: String,
        ring: String,
        points: usize,
    },
    #[error("{feature}: {ring} intersects itself (edges {edge_a} and {edge_b})")]
    SelfIntersection {
        feature: String,
        ring: String,
        edge_a: usize,
        edge_b: usize,
    },
    #[error("{feature}: obstacle is not inside the field boundary")]
    ObstacleOutside { feature: String },
    #[error("{what}: {value}, over the limit of {limit} (input envelope)")]
    Envelope {
        what: String,
        value: String,
        limit: String,
    },
    #[error("no field boundary polygon found")]
    NoBoundary,
    #[error("{count} boundary polygons found ({features}); exactly one field boundary is supported (mark the others \"obstacle\": true or split the file)")]
    SeveralBoundaries { count: usize, features: String },
    #[error("{count} fields with a boundary in the file ({fields}); choose one by its id or name (agsteer plan --list shows them, --field-id chooses)")]
    SeveralFields { count: usize, fields: String },
    #[error("no field \"{wanted}\" in the file (by PFD id or name); the file holds: {available}")]
    NoSuchField { wanted: String, available: String },
    #[error("\"{wanted}\" is the name of several fields ({fields}); choose one by its PFD id (agsteer plan --list shows them, --field-id chooses)")]
    AmbiguousName { wanted: String, fields: String },
    #[error("no partfield with a boundary in the file ({partfields} partfield(s) (PFD), none with a boundary PLN A=\"1\"); agsteer plan --list shows them")]
    NoPartfield { partfields: usize },
    #[error("{field}: no field boundary polygon (a PLN A=\"1\" with an exterior LSG A=\"1\"); agsteer plan --list shows the file's fields")]
    PartfieldWithoutBoundary { field: String },
    #[error("text encoding: {0}")]
    Encoding(String),
    #[error("TASKDATA.XML names the external file {name}.XML (XFR), which is missing")]
    MissingExternal { name: String },
}

/// The text of a field file from its bytes: UTF-8 with or without a byte-order mark, or
/// UTF-16 (little or big endian, with a byte-order mark or starting with '<').
pub fn decode_text(bytes: &[u8]) -> Result<String, FieldError> {
    let utf16 = |body: &[u8], little: bool| -> Result<String, FieldError> {
        if body.len() % 2 != 0 {
            return Err(FieldError::Encoding(format!(
                "UTF-16 text of odd length ({} bytes)",
                body.len()
            )));
        }
        let units: Vec<u16> = body
            .chunks_exact(2)
            .map(|c| {
                if little {
                    u16::from_le_bytes([c[0], c[1]])
                } else {
                    u16::from_be_bytes([c[0], c[1]])
                }
            })
            .collect();
        String::from_utf16(&units).map_err(|e| FieldError::Encoding(format!("UTF-16: {e}")))
    };
    match bytes {
        [0xEF, 0xBB, 0xBF, rest @ ..] => std::str::from_utf8(rest)
            .map(str::to_string)
            .map_err(|e| FieldError::Encoding(format!("UTF-8: {e}"))),
        [0xFF, 0xFE, rest @ ..] => utf16(rest, true),
        [0xFE, 0xFF, rest @ ..] => utf16(rest, false),
        [b'<', 0, ..] => utf16(bytes, true),
        [0, b'<', ..] => utf16(bytes, false),
        _ => std::str::from_utf8(bytes)
            .map(str::to_string)
            .map_err(|e| FieldError::Encoding(format!("UTF-8: {e}"))),
    }
}

/// A map in local metres for manoeuvres: GeoJSON with `[x, y]` positions in metres (no
/// projection). Exactly one Polygon (or single-polygon MultiPolygon) without `"obstacle": true`
/// is the boundary: its exterior ring bounds the map and its holes are obstacles; every
/// Feature with `"obstacle": true` is an obstacle too. Obstacles may cross the boundary.
/// Rings are cleaned as field rings are (duplicates and collinear points dropped, CCW), with
/// no fitting of short edges.
pub fn load_local_map(text: &str) -> Result<Field, FieldError> {
    let parsed = geojson::parse_local(text)?;
    check_counts(&parsed)?;
    for p in parsed.boundaries.iter().chain(&parsed.obstacles) {
        for q in p.exterior.iter().chain(p.holes.iter().flatten()) {
            if q.x.abs() > envelope::MAX_LOCAL_COORD_M || q.y.abs() > envelope::MAX_LOCAL_COORD_M {
                return Err(FieldError::Envelope {
                    what: format!("{}: position ({}, {}) m", p.label, q.x, q.y),
                    value: "outside the local frame".into(),
                    limit: format!("±{} m", envelope::MAX_LOCAL_COORD_M),
                });
            }
        }
    }
    let boundary = single_boundary(parsed.boundaries)?;
    let clean = |ring: &[Vec2], feature: &str| -> Result<Vec<Vec2>, FieldError> {
        checked_ring(clean_ring(ring, 0.0), feature, "exterior ring").map(|c| c.ring)
    };
    let outer = clean(&boundary.exterior, &boundary.label)?;
    check_extent(&boundary.label, &outer)?;
    let mut obstacles = Vec::new();
    for (k, hole) in boundary.holes.iter().enumerate() {
        obstacles.push(clean(hole, &format!("{} (hole {k})", boundary.label))?);
    }
    for o in &parsed.obstacles {
        obstacles.push(clean(&o.exterior, &o.label)?);
    }
    check_clean_points(outer.len() + obstacles.iter().map(Vec::len).sum::<usize>())?;
    Ok(Field {
        boundary: outer,
        obstacles,
    })
}

/// A polygon as read, before projection: exterior plus holes in lat/lon, with a label for
/// error messages.
#[derive(Debug, Clone)]
pub(crate) struct RawPolygon<C = LatLon> {
    pub label: String,
    pub exterior: Vec<C>,
    pub holes: Vec<Vec<C>>,
}

/// A guidance pattern as read, before projection.
#[derive(Debug, Clone)]
pub(crate) struct RawGuidance {
    pub label: String,
    pub kind: GuidanceKind,
    pub points: Vec<LatLon>,
}

/// Load a field from GeoJSON or TASKDATA text, chosen by the first non-blank character (a
/// byte-order mark is skipped). A TASKDATA file must hold one field with a boundary; see
/// [`load_field_with`] for external files and for choosing one of several.
pub fn load_field(text: &str, options: &LoadOptions) -> Result<LoadedField, FieldError> {
    load_field_with(text, &[], None, options)
}

/// [`load_field`] with the external partfield files a TASKDATA.XML names
/// ([`external_partfield_files`]; (name, text) pairs, read by the caller) and the partfield to
/// read (its id or designator; `None` = the only one with a boundary).
pub fn load_field_with(
    text: &str,
    externals: &[(String, String)],
    select: Option<&str>,
    options: &LoadOptions,
) -> Result<LoadedField, FieldError> {
    let text = text.trim_start_matches('\u{feff}');
    match text.trim_start().chars().next() {
        Some('{') => load_geojson(text, options),
        Some('<') => {
            let parsed = taskdata::parse(text, externals, select)?;
            check_counts(&parsed)?;
            assemble(parsed, options)
        }
        _ => Err(FieldError::UnknownFormat),
    }
}

/// The external files (XFR, e.g. "PFD00000" for `PFD00000.XML`) of a TASKDATA.XML that hold
/// partfields; empty for GeoJSON.
pub fn external_partfield_files(text: &str) -> Result<Vec<String>, FieldError> {
    let text = text.trim_start_matches('\u{feff}');
    if text.trim_start().starts_with('<') {
        taskdata::external_partfield_files(text)
    } else {
        Ok(Vec::new())
    }
}

/// Every partfield of a TASKDATA file (and its external partfield files).
pub fn list_fields(
    text: &str,
    externals: &[(String, String)],
) -> Result<Vec<PartfieldInfo>, FieldError> {
    taskdata::list(text.trim_start_matches('\u{feff}'), externals)
}

/// Load a field from GeoJSON text (see the module docs).
pub fn load_geojson(text: &str, options: &LoadOptions) -> Result<LoadedField, FieldError> {
    let parsed = geojson::parse(text)?;
    check_counts(&parsed)?;
    assemble(parsed, options)
}

/// Load a field from ISO 11783-10 TASKDATA.XML text (see the module docs).
pub fn load_taskdata(text: &str, options: &LoadOptions) -> Result<LoadedField, FieldError> {
    let parsed = taskdata::parse(text, &[], None)?;
    check_counts(&parsed)?;
    assemble(parsed, options)
}

/// The input envelope's counts: positions as read, and obstacles (holes included).
fn check_counts<C>(parsed: &Parsed<C>) -> Result<(), FieldError> {
    let polys = || parsed.boundaries.iter().chain(&parsed.obstacles);
    let points: usize = polys()
        .map(|p| p.exterior.len() + p.holes.iter().map(Vec::len).sum::<usize>())
        .sum();
    if points > envelope::MAX_FIELD_POINTS {
        return Err(FieldError::Envelope {
            what: "positions in the file".into(),
            value: points.to_string(),
            limit: envelope::MAX_FIELD_POINTS.to_string(),
        });
    }
    let obstacles = parsed.obstacles.len()
        + parsed
            .boundaries
            .iter()
            .map(|b| b.holes.len())
            .sum::<usize>();
    if obstacles > envelope::MAX_OBSTACLES {
        return Err(FieldError::Envelope {
            what: "obstacles (holes and obstacle features)".into(),
            value: obstacles.to_string(),
            limit: envelope::MAX_OBSTACLES.to_string(),
        });
    }
    Ok(())
}

/// The boundary's extent (longer side of its bounding box) within the envelope.
fn check_extent(feature: &str, outer: &[Vec2]) -> Result<(), FieldError> {
    let (mut lo, mut hi) = (Vec2::repeat(f64::INFINITY), Vec2::repeat(f64::NEG_INFINITY));
    for p in outer {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let extent = (hi - lo).max();
    if extent > envelope::MAX_FIELD_EXTENT_M {
        return Err(FieldError::Envelope {
            what: format!("{feature}: extent"),
            value: format!("{extent:.0} m"),
            limit: format!("{} m", envelope::MAX_FIELD_EXTENT_M),
        });
    }
    Ok(())
}

/// Whether planning `loaded` with `params` stays in the envelope: the work path's points
/// (field area over working width and point spacing) at most [`envelope::MAX_PATH_POINTS`].
/// The planner and its metrics hold every point of the plan; beyond this they would not fit
/// the memory bound.
pub fn check_plan_size(
    loaded: &LoadedField,
    params: &crate::plan::coverage::CoverageParams,
) -> Result<(), FieldError> {
    let (w, r) = (params.line_width, params.r_min);
    let usable = |v: f64| v.is_finite() && v > 0.0;
    if !(usable(w) && usable(r) && usable(params.point_spacing)) {
        return Err(FieldError::Envelope {
            what: "working width, r_min and point spacing".into(),
            value: format!("{w} m, {r} m, {} m", params.point_spacing),
            limit: "finite and positive".into(),
        });
    }
    let block = 2.0 * (2.0 * r / w).ceil() + 1.0;
    if block > envelope::MAX_BLOCK_LINES as f64 {
        return Err(FieldError::Envelope {
            what: format!("lines per block 2·ceil(2·r_min/w) + 1 at r_min {r} m and w {w} m"),
            value: format!("{block}"),
            limit: envelope::MAX_BLOCK_LINES.to_string(),
        });
    }
    let area = loaded.cleanup.area_after_m2;
    let points = area / (w * params.point_spacing);
    if points.is_nan() || points > envelope::MAX_PATH_POINTS {
        return Err(FieldError::Envelope {
            what: format!(
                "work path of {:.0} ha at job.line_width_m = {} and guidance.point_spacing_m = {}",
                area / 1e4,
                params.line_width,
                params.point_spacing
            ),
            value: format!("{points:.2e} points"),
            limit: format!(
                "{:.0e} points (a wider working width or point spacing, or a smaller field)",
                envelope::MAX_PATH_POINTS
            ),
        });
    }
    Ok(())
}

fn check_clean_points(points: usize) -> Result<(), FieldError> {
    if points > envelope::MAX_CLEAN_POINTS {
        return Err(FieldError::Envelope {
            what: "points of all rings after clean-up".into(),
            value: points.to_string(),
            limit: envelope::MAX_CLEAN_POINTS.to_string(),
        });
    }
    Ok(())
}

pub(crate) struct Parsed<C = LatLon> {
    pub name: Option<String>,
    pub boundaries: Vec<RawPolygon<C>>,
    pub obstacles: Vec<RawPolygon<C>>,
    pub guidance: Vec<RawGuidance>,
    pub warnings: Vec<String>,
}

pub(crate) fn check_coordinate(feature: &str, lat: f64, lon: f64) -> Result<LatLon, FieldError> {
    crate::geo::wgs84::check_latitude(LatLon {
        lat_deg: lat,
        lon_deg: lon,
    })
    .map_err(|e| FieldError::BadCoordinates {
        feature: feature.to_string(),
        detail: e.to_string(),
    })
}

/// Every local position of a ring within [`envelope::MAX_LOCAL_COORD_M`] of the origin (a
/// configured origin far from the field would plan it on a plane tangent elsewhere).
fn check_near_origin(feature: &str, origin: LatLon, local: &[Vec2]) -> Result<(), FieldError> {
    let limit = envelope::MAX_LOCAL_COORD_M;
    match local
        .iter()
        .find(|p| !(p.x.abs() <= limit && p.y.abs() <= limit))
    {
        Some(p) => Err(FieldError::Envelope {
            what: format!(
                "{feature}: a point's distance from the ENU origin (lat {}, lon {})",
                origin.lat_deg, origin.lon_deg
            ),
            value: format!("{:.0} m East, {:.0} m North", p.x, p.y),
            limit: format!("±{limit} m (choose an origin at the field or field.origin = \"auto\")"),
        }),
        None => Ok(()),
    }
}

struct Accum {
    report: CleanupReport,
}

impl Accum {
    fn ring(
        &mut self,
        frame: &EnuFrame,
        ring: &[LatLon],
        feature: &str,
        ring_name: &str,
        tolerance: f64,
    ) -> Result<(Vec<Vec2>, f64, f64), FieldError> {
        let local: Vec<Vec2> = ring.iter().map(|p| frame.to_enu(*p)).collect();
        let cleaned = clean_ring(&local, tolerance);
        let r = &mut self.report;
        r.vertices_before += local.len();
        r.duplicates_removed += cleaned.duplicates_removed;
        let cleaned = checked_ring(cleaned, feature, ring_name)?;
        r.vertices_after += cleaned.ring.len();
        r.collinear_removed += cleaned.collinear_removed;
        r.fitted_removed += cleaned.fitted_removed;
        r.rings_reoriented += usize::from(cleaned.reoriented);
        Ok((cleaned.ring, cleaned.area_before_m2, cleaned.area_after_m2))
    }
}

/// The one boundary polygon of a file; none or several are errors naming the features.
fn single_boundary<C>(boundaries: Vec<RawPolygon<C>>) -> Result<RawPolygon<C>, FieldError> {
    if boundaries.len() > 1 {
        return Err(FieldError::SeveralBoundaries {
            count: boundaries.len(),
            features: boundaries
                .iter()
                .map(|b| b.label.clone())
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    boundaries.into_iter().next().ok_or(FieldError::NoBoundary)
}

/// A cleaned ring of `feature` that is still a polygon: at least three points enclosing an
/// area, and no self-intersection; else the error naming the feature and the ring.
fn checked_ring(
    cleaned: RingCleanup,
    feature: &str,
    ring_name: &str,
) -> Result<RingCleanup, FieldError> {
    if cleaned.ring.len() > envelope::MAX_RING_POINTS {
        return Err(FieldError::Envelope {
            what: format!("{feature}: {ring_name} points after simplification"),
            value: cleaned.ring.len().to_string(),
            limit: envelope::MAX_RING_POINTS.to_string(),
        });
    }
    if cleaned.ring.len() < 3 || cleaned.area_before_m2 < 1e-9 {
        return Err(FieldError::TooFewPoints {
            feature: feature.to_string(),
            ring: ring_name.to_string(),
            points: cleaned.distinct_points,
        });
    }
    if let Some((a, b)) = cleaned.self_intersection {
        return Err(FieldError::SelfIntersection {
            feature: feature.to_string(),
            ring: ring_name.to_string(),
            edge_a: a,
            edge_b: b,
        });
    }
    Ok(cleaned)
}

/// Whether ring `inner` lies inside ring `outer` (all vertices inside, no edges crossing).
fn ring_inside(inner: &[Vec2], outer: &[Vec2]) -> bool {
    if !inner.iter().all(|p| contains_point(outer, p)) {
        return false;
    }
    let n = inner.len();
    let m = outer.len();
    for i in 0..n {
        for j in 0..m {
            if segments_intersect(
                &inner[i],
                &inner[(i + 1) % n],
                &outer[j],
                &outer[(j + 1) % m],
            ) {
                return false;
            }
        }
    }
    true
}

fn assemble(parsed: Parsed, options: &LoadOptions) -> Result<LoadedField, FieldError> {
    let Parsed {
        name,
        boundaries,
        mut obstacles,
        guidance,
        mut warnings,
    } = parsed;
    let boundary = single_boundary(boundaries)?;
    let origin = match options.origin {
        Some(o) => o,
        None => crate::geo::wgs84::centre(&boundary.exterior).ok_or(FieldError::NoBoundary)?,
    };
    crate::geo::wgs84::check_latitude(origin).map_err(|e| FieldError::BadCoordinates {
        feature: "the ENU origin".into(),
        detail: e.to_string(),
    })?;
    let frame = EnuFrame::new(origin);
    let tol = options.boundary_tolerance_m.max(0.0);
    let mut acc = Accum {
        report: CleanupReport {
            tolerance_m: tol,
            ..Default::default()
        },
    };
    let (mut outer, a_before, a_after) = acc.ring(
        &frame,
        &boundary.exterior,
        &boundary.label,
        "exterior ring",
        tol,
    )?;
    check_extent(&boundary.label, &outer)?;
    check_near_origin(&boundary.label, origin, &outer)?;
    let (mut area_before, mut area_after) = (a_before, a_after);
    // Holes of the boundary become obstacles, labelled after the boundary feature.
    for (k, hole) in boundary.holes.iter().enumerate() {
        obstacles.push(RawPolygon {
            label: format!("{} (hole {k})", boundary.label),
            exterior: hole.clone(),
            holes: Vec::new(),
        });
    }
    let mut field_obstacles = Vec::new();
    for obstacle in &obstacles {
        let (ring, before, after) = acc.ring(
            &frame,
            &obstacle.exterior,
            &obstacle.label,
            "exterior ring",
            tol,
        )?;
        if !ring_inside(&ring, &outer) {
            // Parcels often exclude a pond or a farmyard that touches their edge: cut it out
            // of the boundary. One wholly outside is not the field's.
            match cut_out(&outer, &ring) {
                Some(cut) => {
                    let removed = signed_area(&outer) - signed_area(&cut);
                    warnings.push(format!(
                        "{}: obstacle touches or crosses the boundary; cut out of the field ({removed:.1} m²)",
                        obstacle.label
                    ));
                    area_before -= removed;
                    area_after -= removed;
                    outer = cut;
                }
                None => {
                    return Err(FieldError::ObstacleOutside {
                        feature: obstacle.label.clone(),
                    })
                }
            }
            continue;
        }
        area_before -= before;
        area_after -= after;
        field_obstacles.push(ring);
    }
    check_clean_points(outer.len() + field_obstacles.iter().map(Vec::len).sum::<usize>())?;
    if area_after > envelope::MAX_FIELD_AREA_M2 {
        return Err(FieldError::Envelope {
            what: format!("{}: area", boundary.label),
            value: format!("{:.0} ha", area_after / 1e4),
            limit: format!("{} ha", envelope::MAX_FIELD_AREA_M2 / 1e4),
        });
    }
    // A boundary cut after some obstacles were kept may now cross them: keep those inside.
    field_obstacles.retain(|o| ring_inside(o, &outer));
    let frame_guidance = |g: &RawGuidance| GuidanceLine {
        name: g.label.clone(),
        kind: g.kind,
        points: g.points.iter().map(|p| frame.to_enu(*p)).collect(),
    };
    let guidance: Vec<GuidanceLine> = guidance.iter().map(frame_guidance).collect();
    let mut report = acc.report;
    report.area_before_m2 = area_before;
    report.area_after_m2 = area_after;
    report.area_error_m2 = (area_after - area_before).abs();
    report.area_error_pct = if area_before > 0.0 {
        100.0 * report.area_error_m2 / area_before
    } else {
        0.0
    };
    debug_assert!(signed_area(&outer) > 0.0);
    Ok(LoadedField {
        name,
        origin,
        field: Field {
            boundary: outer,
            obstacles: field_obstacles,
        },
        cleanup: report,
        guidance,
        warnings,
    })
}

/// `outer` minus `cut` when they overlap: the largest remaining piece, CCW, without holes
/// (`None` when they do not overlap or nothing is left).
fn cut_out(outer: &[Vec2], cut: &[Vec2]) -> Option<Vec<Vec2>> {
    use crate::plan::coverage::geometry::{from_geo, to_geo};
    use geo::BooleanOps;
    let a = to_geo(&(outer.to_vec(), vec![]));
    let b = to_geo(&(cut.to_vec(), vec![]));
    if a.intersection(&b).0.is_empty() {
        return None;
    }
    let rest = from_geo(&a.difference(&b));
    rest.into_iter()
        .map(|(ring, _)| ring)
        .max_by(|x, y| signed_area(x).total_cmp(&signed_area(y)))
        .filter(|r| r.len() >= 3)
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_geodesy;
