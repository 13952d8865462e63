//! GeoJSON field reader: RFC 7946 (WGS-84 `[lon, lat]`) for fields, or local metres `[x, y]`
//! for manoeuvre maps (the same structure, another coordinate check).

use super::{check_coordinate, FieldError, Parsed, RawPolygon};
use crate::geo::Vec2;
use serde_json::Value;

fn label(index: Option<usize>, feature: &Value) -> String {
    let mut s = match index {
        Some(i) => format!("feature {i}"),
        None => "geometry".to_string(),
    };
    let props = feature.get("properties");
    let name = props
        .and_then(|p| p.get("name"))
        .and_then(Value::as_str)
        .map(str::to_string);
    let id = feature.get("id").map(|v| match v {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    });
    if let Some(name) = name {
        s.push_str(&format!(" \"{name}\""));
    }
    if let Some(id) = id {
        s.push_str(&format!(" (id {id})"));
    }
    s
}

/// Turns a position's two numbers into a coordinate, or says why not.
type Coord<C> = fn(&str, f64, f64) -> Result<C, FieldError>;

fn ring<C>(feature: &str, value: &Value, coord: Coord<C>) -> Result<Vec<C>, FieldError> {
    let bad = |detail: String| FieldError::BadCoordinates {
        feature: feature.to_string(),
        detail,
    };
    let points = value
        .as_array()
        .ok_or_else(|| bad("a ring is not an array of positions".into()))?;
    points
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let pos = p.as_array().filter(|a| a.len() >= 2);
            let (first, second) = match pos.map(|a| (a[0].as_f64(), a[1].as_f64())) {
                Some((Some(a), Some(b))) => (a, b),
                _ => return Err(bad(format!("position {k} is not two numbers: {p}"))),
            };
            coord(feature, first, second)
        })
        .collect()
}

fn polygon<C>(feature: &str, rings: &Value, coord: Coord<C>) -> Result<RawPolygon<C>, FieldError> {
    let rings = rings.as_array().ok_or_else(|| FieldError::BadCoordinates {
        feature: feature.to_string(),
        detail: "polygon coordinates are not an array of rings".into(),
    })?;
    let mut it = rings.iter();
    let exterior = match it.next() {
        Some(r) => ring(feature, r, coord)?,
        None => {
            return Err(FieldError::TooFewPoints {
                feature: feature.to_string(),
                ring: "exterior ring".into(),
                points: 0,
            })
        }
    };
    let holes = it
        .map(|r| ring(feature, r, coord))
        .collect::<Result<_, _>>()?;
    Ok(RawPolygon {
        label: feature.to_string(),
        exterior,
        holes,
    })
}

/// Polygons of one geometry object.
fn geometry<C>(
    feature: &str,
    geom: &Value,
    coord: Coord<C>,
) -> Result<Vec<RawPolygon<C>>, FieldError> {
    let kind = geom.get("type").and_then(Value::as_str).unwrap_or("");
    let coords = geom.get("coordinates");
    match (kind, coords) {
        ("Polygon", Some(c)) => Ok(vec![polygon(feature, c, coord)?]),
        ("MultiPolygon", Some(Value::Array(polys))) => {
            let many = polys.len() > 1;
            polys
                .iter()
                .enumerate()
                .map(|(k, c)| {
                    let name = if many {
                        format!("{feature} polygon {k}")
                    } else {
                        feature.to_string()
                    };
                    polygon(&name, c, coord)
                })
                .collect()
        }
        ("Polygon" | "MultiPolygon", _) => Err(FieldError::BadCoordinates {
            feature: feature.to_string(),
            detail: format!("{kind} without valid \"coordinates\""),
        }),
        ("", _) => Err(FieldError::NotAPolygon {
            feature: feature.to_string(),
            detail: "no geometry type".into(),
        }),
        (other, _) => Err(FieldError::NotAPolygon {
            feature: feature.to_string(),
            detail: format!("geometry type {other}"),
        }),
    }
}

fn is_obstacle(feature: &Value) -> bool {
    feature
        .get("properties")
        .and_then(|p| p.get("obstacle"))
        .and_then(Value::as_bool)
        .unwrap_or(false)
}

fn feature_name(feature: &Value) -> Option<String> {
    feature
        .get("properties")
        .and_then(|p| p.get("name"))
        .and_then(Value::as_str)
        .map(str::to_string)
}

/// A WGS-84 GeoJSON document (`[lon, lat]` positions).
pub(crate) fn parse(text: &str) -> Result<Parsed, FieldError> {
    parse_with(text, |feature, lon, lat| {
        check_coordinate(feature, lat, lon)
    })
}

/// A GeoJSON document in local metres (`[x, y]` positions, any finite numbers).
pub(crate) fn parse_local(text: &str) -> Result<Parsed<Vec2>, FieldError> {
    parse_with(text, |feature, x, y| {
        if x.is_finite() && y.is_finite() {
            Ok(Vec2::new(x, y))
        } else {
            Err(FieldError::BadCoordinates {
                feature: feature.to_string(),
                detail: format!("[{x}, {y}] is not finite"),
            })
        }
    })
}

fn parse_with<C>(text: &str, coord: Coord<C>) -> Result<Parsed<C>, FieldError> {
    let root: Value = serde_json::from_str(text).map_err(|e| FieldError::Json(e.to_string()))?;
    let mut out = Parsed {
        name: None,
        boundaries: Vec::new(),
        obstacles: Vec::new(),
        guidance: Vec::new(),
        warnings: Vec::new(),
    };
    let mut add = |index: Option<usize>, feature: &Value, geom: Option<&Value>| {
        let name = label(index, feature);
        let geom = geom.ok_or_else(|| FieldError::NotAPolygon {
            feature: name.clone(),
            detail: "feature without geometry".into(),
        })?;
        let polys = geometry(&name, geom, coord)?;
        if is_obstacle(feature) {
            out.obstacles.extend(polys);
        } else {
            if out.name.is_none() {
                out.name = feature_name(feature);
            }
            out.boundaries.extend(polys);
        }
        Ok::<(), FieldError>(())
    };
    match root.get("type").and_then(Value::as_str) {
        Some("FeatureCollection") => {
            let features = root
                .get("features")
                .and_then(Value::as_array)
                .ok_or_else(|| FieldError::NotAPolygon {
                    feature: "FeatureCollection".into(),
                    detail: "no \"features\" array".into(),
                })?;
            for (i, f) in features.iter().enumerate() {
                add(Some(i), f, f.get("geometry"))?;
            }
        }
        Some("Feature") => add(Some(0), &root, root.get("geometry"))?,
        Some(_) => add(None, &root, Some(&root))?,
        None => {
            return Err(FieldError::NotAPolygon {
                feature: "document".into(),
                detail: "no GeoJSON \"type\"".into(),
            })
        }
    }
    if out.name.is_none() {
        out.name = feature_name(&root);
    }
    Ok(out)
}
