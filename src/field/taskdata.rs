//! ISO 11783-10 `TASKDATA.XML` partfield reader (PFD → PLN → LSG → PNT; GGP → GPN → LSG),
//! as terminals and farm software write it: partfields in the main file or in external files
//! (`XFR A="PFD00000"` → `PFD00000.XML`, root `XFC`), several partfields in one file, types
//! this reader has no use for skipped with a warning naming them.
//!
//! Codes (ISO 11783-10 PLN A, LSG A, GPN C): PLN 1 partfield boundary, 2 treatment zone,
//! 3 water surface, 4 building, 5 road, 6 obstacle, 7 flag, 8 other, 9 mainfield, 10 headland,
//! 11 buffer zone, 12 windbreak; LSG 1 polygon exterior, 2 polygon interior, 3 tram line,
//! 4 sampling route, 5 guidance pattern, 6 drainage, 7 fence, 8 flag, 9 obstacle; GPN 1 AB,
//! 2 A+, 3 curve, 4 pivot, 5 spiral.

use super::{check_coordinate, FieldError, Parsed, RawGuidance, RawPolygon};
use crate::geo::wgs84::{EnuFrame, LatLon};
use roxmltree::{Document, Node};

/// PLN type A: partfield boundary.
const PLN_BOUNDARY: &str = "1";
/// PLN types that are obstacles to driving: 3 water, 4 building, 6 obstacle, 12 windbreak.
const PLN_OBSTACLES: [&str; 4] = ["3", "4", "6", "12"];
/// LSG type A: 1 polygon exterior, 2 polygon interior, 5 guidance pattern.
const LSG_EXTERIOR: &str = "1";
const LSG_INTERIOR: &str = "2";
const LSG_GUIDANCE: &str = "5";
const LSG_OBSTACLE: &str = "9";

/// First and last points of an obstacle LSG (type 9) at most this far apart make it a closed
/// ring, an area to keep off (CNH terminals write impassable areas so); farther, it is a line, m.
const CLOSED_RING_M: f64 = 0.1;

/// Is `ring` closed (its last point back on its first, within [`CLOSED_RING_M`]) round at
/// least three distinct points?
fn closed_area(ring: &[LatLon]) -> bool {
    let (Some(&first), Some(&last)) = (ring.first(), ring.last()) else {
        return false;
    };
    let frame = EnuFrame::new(first);
    let local: Vec<_> = ring.iter().map(|q| frame.to_enu(*q)).collect();
    let apart = |q: &&crate::geo::Vec2| q.norm() > 1e-3;
    let second = local.iter().find(apart);
    let third = second.and_then(|b| local.iter().filter(apart).find(|q| (*q - b).norm() > 1e-3));
    frame.to_enu(last).norm() <= CLOSED_RING_M && third.is_some()
}

/// An obstacle LSG (type 9) of `feature` as an area: its ring when closed ([`closed_area`]);
/// `None` when it is a line, with a warning that begins with `who` (the LSG named).
fn obstacle_area(
    feature: &str,
    who: &str,
    lsg: &Node,
    warnings: &mut Vec<String>,
) -> Result<Option<Vec<LatLon>>, FieldError> {
    let r = ring(feature, lsg)?;
    if closed_area(&r) {
        return Ok(Some(r));
    }
    warnings.push(format!(
        "{who} type 9 (obstacle) is a line, not a closed area: skipped (drive round it by hand)"
    ));
    Ok(None)
}

/// How a PLN or LSG is named in a warning: its id in the file (PLN E, LSG F) where it has one,
/// else its kind and place among its siblings.
fn element_name(node: &Node, tag: &str, id_attribute: &str, index: usize) -> String {
    match node.attribute(id_attribute).map(str::trim) {
        Some(id) if id.to_ascii_uppercase().starts_with(tag) => id.to_string(),
        Some(id) if !id.is_empty() => format!("{tag} {id}"),
        _ => format!("{tag} {index}"),
    }
}

fn pln_type_name(t: &str) -> &'static str {
    match t {
        "1" => "partfield boundary",
        "2" => "treatment zone",
        "3" => "water surface",
        "4" => "building",
        "5" => "road",
        "6" => "obstacle",
        "7" => "flag",
        "8" => "other",
        "9" => "mainfield",
        "10" => "headland",
        "11" => "buffer zone",
        "12" => "windbreak",
        _ => "unknown type",
    }
}

fn lsg_type_name(t: &str) -> &'static str {
    match t {
        "1" => "polygon exterior",
        "2" => "polygon interior",
        "3" => "tram line",
        "4" => "sampling route",
        "5" => "guidance pattern",
        "6" => "drainage",
        "7" => "fence",
        "8" => "flag",
        "9" => "obstacle",
        _ => "unknown type",
    }
}

/// Kind of a guidance pattern (GPN attribute C).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GuidanceKind {
    /// Type 1: a straight AB line.
    AbLine,
    /// Type 2: A plus a heading.
    APlus,
    /// Type 3: a reference curve.
    Curve,
    /// Type 4: a pivot.
    Pivot,
    /// Type 5: a spiral.
    Spiral,
    /// Anything else.
    Other,
}

impl GuidanceKind {
    fn from_code(code: Option<&str>) -> Self {
        match code.map(str::trim) {
            Some("1") => GuidanceKind::AbLine,
            Some("2") => GuidanceKind::APlus,
            Some("3") => GuidanceKind::Curve,
            Some("4") => GuidanceKind::Pivot,
            Some("5") => GuidanceKind::Spiral,
            _ => GuidanceKind::Other,
        }
    }
}

/// One partfield of a TASKDATA file, as `agsteer plan --list` shows it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PartfieldInfo {
    /// PFD attribute A (e.g. "PFD1").
    pub id: String,
    /// PFD attribute C, the name the farmer gave it.
    pub designator: Option<String>,
    /// PFD attribute D, the area the file states, m².
    pub stated_area_m2: Option<f64>,
    /// The file holding it ("TASKDATA.XML" or the external file's name).
    pub file: String,
    /// Boundary polygons (PLN type 1 with an exterior).
    pub boundaries: usize,
    /// Obstacle polygons (PLN types 3, 4, 6, 12 with an exterior).
    pub obstacles: usize,
    /// Guidance patterns (GPN).
    pub guidance_patterns: usize,
}

fn ring(feature: &str, lsg: &Node) -> Result<Vec<LatLon>, FieldError> {
    lsg.children()
        .filter(|n| n.has_tag_name("PNT"))
        .enumerate()
        .map(|(k, pnt)| {
            let get = |a: &str| {
                pnt.attribute(a)
                    .and_then(|v| v.trim().parse::<f64>().ok())
                    .ok_or_else(|| FieldError::BadCoordinates {
                        feature: feature.to_string(),
                        detail: format!("PNT {k} has no numeric attribute {a}"),
                    })
            };
            check_coordinate(feature, get("C")?, get("D")?)
        })
        .collect()
}

/// A PLN's exterior ring (if it has one) and its interior rings.
type PlnRings = (Option<Vec<LatLon>>, Vec<Vec<LatLon>>);

/// The rings of a PLN: its exterior and interior LSGs; in an obstacle PLN (`obstacle`) a
/// closed obstacle LSG (type 9) is its exterior when it has no type 1. Other LSG types, and
/// obstacle LSGs that are lines, are skipped with a warning naming them.
fn rings(
    feature: &str,
    pln: &Node,
    obstacle: bool,
    warnings: &mut Vec<String>,
) -> Result<PlnRings, FieldError> {
    let mut exterior = None;
    let mut obstacle_ring = None;
    let mut holes = Vec::new();
    for (k, lsg) in pln.children().filter(|n| n.has_tag_name("LSG")).enumerate() {
        let t = lsg.attribute("A").unwrap_or("").trim();
        let name = element_name(&lsg, "LSG", "F", k);
        match t {
            LSG_EXTERIOR if exterior.is_none() => exterior = Some(ring(feature, &lsg)?),
            LSG_EXTERIOR => {
                return Err(FieldError::NotAPolygon {
                    feature: feature.to_string(),
                    detail: "more than one exterior LSG".into(),
                })
            }
            LSG_INTERIOR => holes.push(ring(feature, &lsg)?),
            LSG_OBSTACLE if obstacle && obstacle_ring.is_none() => {
                let who = format!("{feature}: {name} of");
                obstacle_ring = obstacle_area(feature, &who, &lsg, warnings)?;
            }
            other => warnings.push(format!(
                "{feature}: {name} of type {other} ({}) skipped",
                lsg_type_name(other)
            )),
        }
    }
    Ok((exterior.or(obstacle_ring), holes))
}

fn pfd_label(pfd: &Node) -> String {
    let id = pfd.attribute("A").unwrap_or("?");
    let mut s = if id.to_ascii_uppercase().starts_with("PFD") {
        id.to_string()
    } else {
        format!("PFD {id}")
    };
    if let Some(name) = pfd.attribute("C") {
        s.push_str(&format!(" \"{name}\""));
    }
    s
}

/// Names of the external files (XFR attribute A, e.g. "PFD00000") that hold partfields; the
/// caller reads `NAME.XML` next to TASKDATA.XML and passes its text to [`parse`].
pub fn external_partfield_files(text: &str) -> Result<Vec<String>, FieldError> {
    let doc = Document::parse(text).map_err(|e| FieldError::Xml(e.to_string()))?;
    Ok(doc
        .root_element()
        .children()
        .filter(|n| n.has_tag_name("XFR"))
        .filter_map(|n| n.attribute("A"))
        .filter(|a| a.trim().to_ascii_uppercase().starts_with("PFD"))
        .map(|a| a.trim().to_string())
        .collect())
}

/// Every PFD of the main document and of the external files, with the name of its file.
fn documents<'a>(
    text: &'a str,
    externals: &'a [(String, String)],
) -> Result<Vec<(String, Document<'a>)>, FieldError> {
    let mut docs = vec![(
        "TASKDATA.XML".to_string(),
        Document::parse(text).map_err(|e| FieldError::Xml(e.to_string()))?,
    )];
    for (name, body) in externals {
        let doc = Document::parse(body)
            .map_err(|e| FieldError::Xml(format!("external file {name}.XML: {e}")))?;
        docs.push((format!("{name}.XML"), doc));
    }
    Ok(docs)
}

/// The partfields of a TASKDATA file and its external partfield files.
pub fn list(text: &str, externals: &[(String, String)]) -> Result<Vec<PartfieldInfo>, FieldError> {
    let docs = documents(text, externals)?;
    let mut out = Vec::new();
    for (file, doc) in &docs {
        for pfd in doc.descendants().filter(|n| n.has_tag_name("PFD")) {
            let plns: Vec<Node> = pfd.children().filter(|n| n.has_tag_name("PLN")).collect();
            // PLNs of `types` with an exterior: an LSG of type 1, or (`obstacle`) a closed one of
            // type 9, as `parse` reads them.
            let with_exterior = |types: &[&str], obstacle: bool| {
                let exterior = |l: &Node| {
                    let t = l.attribute("A").map(str::trim);
                    l.has_tag_name("LSG")
                        && (t == Some(LSG_EXTERIOR)
                            || (obstacle
                                && t == Some(LSG_OBSTACLE)
                                && ring("", l).is_ok_and(|r| closed_area(&r))))
                };
                plns.iter()
                    .filter(|p| types.contains(&p.attribute("A").unwrap_or("").trim()))
                    .filter(|p| p.children().any(|l| exterior(&l)))
                    .count()
            };
            out.push(PartfieldInfo {
                id: pfd.attribute("A").unwrap_or("").to_string(),
                designator: pfd.attribute("C").map(str::to_string),
                stated_area_m2: pfd.attribute("D").and_then(|d| d.trim().parse().ok()),
                file: file.clone(),
                boundaries: with_exterior(&[PLN_BOUNDARY], false),
                obstacles: with_exterior(&PLN_OBSTACLES, true),
                guidance_patterns: pfd.descendants().filter(|n| n.has_tag_name("GPN")).count()
                    + direct_guidance(&pfd).count(),
            });
        }
    }
    Ok(out)
}

/// Guidance lines written as LSGs of type 5 directly under the PFD, as ISO 11783-10 version 3
/// files have them (version 4 puts them in GGP → GPN).
fn direct_guidance<'a, 'input>(pfd: &Node<'a, 'input>) -> impl Iterator<Item = Node<'a, 'input>> {
    pfd.children()
        .filter(|n| n.has_tag_name("LSG") && n.attribute("A").map(str::trim) == Some(LSG_GUIDANCE))
}

fn guidance(pfd: &Node, label: &str) -> Result<Vec<RawGuidance>, FieldError> {
    let mut out = Vec::new();
    for gpn in pfd.descendants().filter(|n| n.has_tag_name("GPN")) {
        let name = format!(
            "{label} GPN {}{}",
            gpn.attribute("A").unwrap_or("?"),
            gpn.attribute("B")
                .map(|b| format!(" \"{b}\""))
                .unwrap_or_default()
        );
        let Some(lsg) = gpn.children().find(|n| {
            n.has_tag_name("LSG") && n.attribute("A").map(str::trim) == Some(LSG_GUIDANCE)
        }) else {
            continue;
        };
        let points = ring(&name, &lsg)?;
        if points.len() >= 2 {
            out.push(RawGuidance {
                label: name,
                kind: GuidanceKind::from_code(gpn.attribute("C")),
                points,
            });
        }
    }
    // Version 3: two points are an AB line, more a reference curve.
    for (k, lsg) in direct_guidance(pfd).enumerate() {
        let name = format!(
            "{label} {}{}",
            element_name(&lsg, "LSG", "F", k),
            lsg.attribute("B")
                .map(|b| format!(" \"{b}\""))
                .unwrap_or_default()
        );
        let points = ring(&name, &lsg)?;
        let kind = match points.len() {
            0 | 1 => continue,
            2 => GuidanceKind::AbLine,
            _ => GuidanceKind::Curve,
        };
        out.push(RawGuidance {
            label: name,
            kind,
            points,
        });
    }
    Ok(out)
}

/// Read the partfield `select` (its id, PFD attribute A, or its designator, attribute C) or,
/// without one, the only partfield that has a boundary.
pub(crate) fn parse(
    text: &str,
    externals: &[(String, String)],
    select: Option<&str>,
) -> Result<Parsed, FieldError> {
    let docs = documents(text, externals)?;
    let pfds: Vec<Node> = docs
        .iter()
        .flat_map(|(_, d)| d.descendants().filter(|n| n.has_tag_name("PFD")))
        .collect();
    let has_boundary = |pfd: &Node| {
        pfd.children()
            .any(|n| n.has_tag_name("PLN") && n.attribute("A").map(str::trim) == Some(PLN_BOUNDARY))
    };
    let names = |it: &mut dyn Iterator<Item = &Node>| -> String {
        it.map(pfd_label).collect::<Vec<_>>().join(", ")
    };
    let chosen = match select.map(str::trim) {
        Some(want) => match pfds
            .iter()
            .find(|p| p.attribute("A").map(str::trim) == Some(want))
        {
            Some(by_id) => by_id,
            None => {
                let named: Vec<&Node> = pfds
                    .iter()
                    .filter(|p| {
                        p.attribute("C")
                            .is_some_and(|c| c.trim().eq_ignore_ascii_case(want))
                    })
                    .collect();
                match named.as_slice() {
                    [] => {
                        return Err(FieldError::NoSuchField {
                            wanted: want.to_string(),
                            available: names(&mut pfds.iter()),
                        })
                    }
                    [one] => *one,
                    many => {
                        return Err(FieldError::AmbiguousName {
                            wanted: want.to_string(),
                            fields: names(&mut many.iter().copied()),
                        })
                    }
                }
            }
        },
        None => {
            let with: Vec<&Node> = pfds.iter().filter(|p| has_boundary(p)).collect();
            match with.as_slice() {
                [] => {
                    return Err(FieldError::NoPartfield {
                        partfields: pfds.len(),
                    })
                }
                [one] => *one,
                many => {
                    return Err(FieldError::SeveralFields {
                        count: many.len(),
                        fields: names(&mut many.iter().copied()),
                    })
                }
            }
        }
    };
    let label = pfd_label(chosen);
    let mut out = Parsed {
        name: chosen.attribute("C").map(str::to_string),
        boundaries: Vec::new(),
        obstacles: Vec::new(),
        guidance: guidance(chosen, &label)?,
        warnings: Vec::new(),
    };
    // Interiors written in boundary PLNs of their own, without an exterior (CNH terminals
    // write each hole so): (the PLN's name, the ring).
    let mut loose_holes: Vec<(String, Vec<LatLon>)> = Vec::new();
    // Each boundary's own name (PLN id), for the holes joined to it.
    let mut boundary_names: Vec<String> = Vec::new();
    for (j, pln) in chosen
        .children()
        .filter(|n| n.has_tag_name("PLN"))
        .enumerate()
    {
        let t = pln.attribute("A").unwrap_or("").trim();
        let pln_name = element_name(&pln, "PLN", "E", j);
        let mut feature = format!("{label} {pln_name} (type {t}, {})", pln_type_name(t));
        if let Some(name) = pln.attribute("B") {
            feature.push_str(&format!(" \"{name}\""));
        }
        let obstacle = PLN_OBSTACLES.contains(&t);
        if t != PLN_BOUNDARY && !obstacle {
            out.warnings.push(format!("{feature}: not used, skipped"));
            continue;
        }
        match rings(&feature, &pln, obstacle, &mut out.warnings)? {
            (Some(exterior), holes) => {
                let polygon = RawPolygon {
                    label: feature,
                    exterior,
                    holes,
                };
                if obstacle {
                    out.obstacles.push(polygon);
                } else {
                    out.boundaries.push(polygon);
                    boundary_names.push(pln_name);
                }
            }
            (None, holes) if !obstacle && !holes.is_empty() => {
                loose_holes.extend(holes.into_iter().map(|h| (pln_name.clone(), h)));
            }
            (None, _) => out.warnings.push(format!(
                "{feature}: no polygon exterior (LSG A=\"1\"{}), skipped",
                if obstacle {
                    ", or a closed obstacle LSG A=\"9\""
                } else {
                    ""
                }
            )),
        }
    }
    // LSGs directly under the PFD (version 3 files, CNH's impassable lines): guidance is read
    // above; a closed obstacle ring is an obstacle; anything else is named and skipped.
    for (k, lsg) in chosen
        .children()
        .filter(|n| n.has_tag_name("LSG"))
        .enumerate()
    {
        let t = lsg.attribute("A").unwrap_or("").trim();
        if t == LSG_GUIDANCE {
            continue;
        }
        let mut feature = format!("{label} {}", element_name(&lsg, "LSG", "F", k));
        if let Some(b) = lsg.attribute("B") {
            feature.push_str(&format!(" \"{b}\""));
        }
        if t != LSG_OBSTACLE {
            out.warnings.push(format!(
                "{feature}: type {t} ({}) skipped",
                lsg_type_name(t)
            ));
        } else if let Some(exterior) =
            obstacle_area(&feature, &format!("{feature}:"), &lsg, &mut out.warnings)?
        {
            out.obstacles.push(RawPolygon {
                label: feature,
                exterior,
                holes: Vec::new(),
            });
        }
    }
    // Each such interior is a hole of the boundary whose exterior holds it (tested on the plane
    // tangent at that boundary's centre, as the field is planned: across the antimeridian too).
    for (pln_name, hole) in loose_holes {
        let owner = out
            .boundaries
            .iter_mut()
            .zip(&boundary_names)
            .find(|(b, _)| {
                let Some(frame) = crate::geo::wgs84::centre(&b.exterior).map(EnuFrame::new) else {
                    return false;
                };
                let outer: Vec<_> = b.exterior.iter().map(|q| frame.to_enu(*q)).collect();
                hole.iter()
                    .all(|q| crate::geo::polygon::contains_point(&outer, &frame.to_enu(*q)))
            });
        match owner {
            Some((boundary, owner_name)) => {
                out.warnings.push(format!(
                    "{label} {pln_name}: an interior without an exterior, taken as a hole of {owner_name}"
                ));
                boundary.holes.push(hole);
            }
            None => out.warnings.push(format!(
                "{label} {pln_name}: a polygon interior (LSG A=\"2\") inside no boundary of the field, skipped"
            )),
        }
    }
    if out.boundaries.is_empty() {
        return Err(FieldError::PartfieldWithoutBoundary { field: label });
    }
    Ok(out)
}
