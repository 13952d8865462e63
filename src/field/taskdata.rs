//! ISO 11783-10 `TASKDATA.XML` partfield reader (PFD → PLN → LSG → PNT).

use super::{check_coordinate, FieldError, Parsed, RawPolygon};
use crate::geo::wgs84::LatLon;
use roxmltree::{Document, Node};

/// PLN type A: partfield boundary.
const PLN_BOUNDARY: &str = "1";
/// PLN types that are obstacles to driving: 3 water, 4 building, 6 obstacle, 12 windbreak.
const PLN_OBSTACLES: [&str; 4] = ["3", "4", "6", "12"];
/// LSG type A: 1 polygon exterior, 2 polygon interior.
const LSG_EXTERIOR: &str = "1";
const LSG_INTERIOR: &str = "2";

fn node_label(node: &Node, what: &str, index: usize) -> String {
    let mut s = format!("{what} {index}");
    if let Some(id) = node.attribute("A").filter(|_| what == "PFD") {
        s.push_str(&format!(" (id {id})"));
    }
    if let Some(name) = node.attribute("B").filter(|_| what == "PLN") {
        s.push_str(&format!(" \"{name}\""));
    }
    if let Some(name) = node.attribute("C").filter(|_| what == "PFD") {
        s.push_str(&format!(" \"{name}\""));
    }
    s
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

fn polygon(feature: &str, pln: &Node) -> Result<RawPolygon, FieldError> {
    let mut exterior = None;
    let mut holes = Vec::new();
    for lsg in pln.children().filter(|n| n.has_tag_name("LSG")) {
        match lsg.attribute("A") {
            Some(LSG_EXTERIOR) if exterior.is_none() => exterior = Some(ring(feature, &lsg)?),
            Some(LSG_EXTERIOR) => {
                return Err(FieldError::NotAPolygon {
                    feature: feature.to_string(),
                    detail: "more than one exterior LSG".into(),
                })
            }
            Some(LSG_INTERIOR) => holes.push(ring(feature, &lsg)?),
            _ => {}
        }
    }
    let exterior = exterior.ok_or_else(|| FieldError::NotAPolygon {
        feature: feature.to_string(),
        detail: "PLN without an exterior LSG (A=\"1\")".into(),
    })?;
    Ok(RawPolygon {
        label: feature.to_string(),
        exterior,
        holes,
    })
}

pub(crate) fn parse(text: &str) -> Result<Parsed, FieldError> {
    let doc = Document::parse(text).map_err(|e| FieldError::Xml(e.to_string()))?;
    let mut out = Parsed {
        name: None,
        boundaries: Vec::new(),
        obstacles: Vec::new(),
    };
    let pfds = doc.descendants().filter(|n| n.has_tag_name("PFD"));
    for (i, pfd) in pfds.enumerate() {
        let pfd_label = node_label(&pfd, "PFD", i);
        let mut boundaries = Vec::new();
        let mut obstacles = Vec::new();
        for (j, pln) in pfd.children().filter(|n| n.has_tag_name("PLN")).enumerate() {
            let label = format!("{pfd_label} {}", node_label(&pln, "PLN", j));
            match pln.attribute("A") {
                Some(PLN_BOUNDARY) => boundaries.push(polygon(&label, &pln)?),
                Some(t) if PLN_OBSTACLES.contains(&t) => obstacles.push(polygon(&label, &pln)?),
                _ => {}
            }
        }
        if !boundaries.is_empty() {
            out.name = pfd.attribute("C").map(str::to_string);
            out.boundaries = boundaries;
            out.obstacles = obstacles;
            break;
        }
    }
    Ok(out)
}
