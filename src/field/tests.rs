use super::*;
use crate::geo::polygon::point_segment_distance;
use crate::geo::{rect, v2};

const ORIGIN: LatLon = LatLon {
    lat_deg: 52.0,
    lon_deg: 5.0,
};

/// GeoJSON ring text (`[[lon, lat], …]`, closed) from local metres about [`ORIGIN`].
fn ring_json(points: &[Vec2]) -> String {
    let frame = EnuFrame::new(ORIGIN);
    let mut closed = points.to_vec();
    closed.push(points[0]);
    let items: Vec<String> = closed
        .iter()
        .map(|p| {
            let ll = frame.to_latlon(*p);
            format!("[{:.10},{:.10}]", ll.lon_deg, ll.lat_deg)
        })
        .collect();
    format!("[{}]", items.join(","))
}

fn feature(rings: &[&[Vec2]], props: &str) -> String {
    let rings: Vec<String> = rings.iter().map(|r| ring_json(r)).collect();
    format!(
        r#"{{"type":"Feature","properties":{{{props}}},"geometry":{{"type":"Polygon","coordinates":[{}]}}}}"#,
        rings.join(",")
    )
}

fn collection(features: &[String]) -> String {
    format!(
        r#"{{"type":"FeatureCollection","features":[{}]}}"#,
        features.join(",")
    )
}

fn opts() -> LoadOptions {
    LoadOptions {
        origin: Some(ORIGIN),
        boundary_tolerance_m: 0.1,
    }
}

#[test]
fn rectangle_round_trips_with_given_and_automatic_origin() {
    let text = collection(&[feature(&[&rect(0.0, 0.0, 300.0, 200.0)], r#""name":"R""#)]);
    let f = load_field(&text, &opts()).unwrap();
    assert_eq!(f.name.as_deref(), Some("R"));
    assert_eq!(f.origin, ORIGIN);
    assert_eq!(f.field.boundary.len(), 4);
    assert!((signed_area(&f.field.boundary) - 60_000.0).abs() < 0.5);
    assert!((f.field.boundary[0] - v2(0.0, 0.0)).norm() < 1e-3);

    let auto = load_field(&text, &LoadOptions::default()).unwrap();
    // Automatic origin: bounding-box centre, so the field is centred on (0, 0).
    let (lo, hi) = crate::geo::polygon::bbox(&auto.field.boundary).unwrap();
    assert!((lo + hi).norm() < 0.05, "{lo} {hi}");
    assert!((auto.origin.lat_deg - ORIGIN.lat_deg).abs() > 1e-5);
}

#[test]
fn clockwise_duplicates_and_collinear_points_are_cleaned() {
    let mut pts = vec![
        v2(0.0, 0.0),
        v2(0.0, 100.0),
        v2(0.0, 100.0),
        v2(50.0, 100.0), // collinear
        v2(100.0, 100.0),
        v2(100.0, 0.0),
    ];
    pts.push(pts[0]); // explicit closing point inside the ring too
    let text = feature(&[&pts], "");
    let f = load_geojson(&text, &opts()).unwrap();
    assert_eq!(f.field.boundary.len(), 4);
    assert!(signed_area(&f.field.boundary) > 0.0);
    assert_eq!(f.cleanup.rings_reoriented, 1);
    assert_eq!(f.cleanup.collinear_removed, 1);
    assert!(f.cleanup.duplicates_removed >= 2);
    assert!(f.cleanup.area_error_m2 < 1.0);
}

fn arc_field() -> Vec<Vec2> {
    // 400 m wide, straight sides, a circular arc (radius 300 m) of 400 short edges on top.
    let mut pts = vec![v2(0.0, 0.0), v2(400.0, 0.0)];
    let r = 300.0_f64;
    let half = (200.0 / r).asin();
    let cy = 200.0 - r * half.cos();
    for k in 0..=400 {
        let a = half - 2.0 * half * k as f64 / 400.0;
        pts.push(v2(200.0 + r * a.sin(), cy + r * a.cos() + 100.0));
    }
    pts
}

#[test]
fn arcs_are_fitted_with_bounded_reported_area_error() {
    let pts = arc_field();
    let text = feature(&[&pts], "");
    let f = load_geojson(&text, &opts()).unwrap();
    let ring = &f.field.boundary;
    assert!(ring.len() < 60, "{} vertices", ring.len());
    assert!(f.cleanup.fitted_removed > 300);
    let before = signed_area(&pts).abs();
    assert!((f.cleanup.area_before_m2 - before).abs() < 1.0);
    assert!((f.cleanup.area_after_m2 - signed_area(ring)).abs() < 1e-6);
    let perimeter: f64 = (0..pts.len())
        .map(|i| (pts[(i + 1) % pts.len()] - pts[i]).norm())
        .sum();
    assert!(f.cleanup.area_error_m2 <= 0.1 * perimeter);
    assert!(f.cleanup.area_error_pct < 0.1);
    // Every input point stays within twice the tolerance of the cleaned ring.
    for p in &pts {
        let d = (0..ring.len())
            .map(|i| point_segment_distance(p, &ring[i], &ring[(i + 1) % ring.len()]))
            .fold(f64::MAX, f64::min);
        assert!(d < 0.2 + 1e-3, "point {p} is {d} m off");
    }
}

#[test]
fn regression_fit_beats_chords_on_arc_area() {
    let pts = arc_field();
    let fitted = clean_ring(&pts, 0.1);
    // Chords of a convex arc always cut area off; the regression lines straddle the arc.
    let chord_only_error = {
        let keep = super::clean::tests_support::dp(&pts, 0.1);
        (signed_area(&keep).abs() - signed_area(&pts).abs()).abs()
    };
    let fit_error = (fitted.area_after_m2 - fitted.area_before_m2).abs();
    assert!(
        fit_error < chord_only_error,
        "{fit_error} vs {chord_only_error}"
    );
}

#[test]
fn holes_and_obstacle_features_become_obstacles() {
    let outer = rect(0.0, 0.0, 400.0, 300.0);
    let hole = rect(50.0, 50.0, 80.0, 90.0);
    let obst = rect(200.0, 100.0, 220.0, 110.0);
    let text = collection(&[
        feature(&[&outer, &hole], r#""name":"F""#),
        feature(&[&obst], r#""obstacle":true"#),
    ]);
    let f = load_field(&text, &opts()).unwrap();
    assert_eq!(f.field.obstacles.len(), 2);
    for o in &f.field.obstacles {
        assert!(signed_area(o) > 0.0);
    }
    let area = 400.0 * 300.0 - 30.0 * 40.0 - 20.0 * 10.0;
    assert!((f.cleanup.area_after_m2 - area).abs() < 1.0);
}

fn err(text: &str) -> String {
    load_field(text, &opts()).unwrap_err().to_string()
}

#[test]
fn invalid_input_gives_errors_naming_the_feature() {
    let bow = vec![
        v2(0.0, 0.0),
        v2(100.0, 100.0),
        v2(100.0, 0.0),
        v2(0.0, 100.0),
    ];
    let e = err(&collection(&[feature(&[&bow], r#""name":"bow""#)]));
    assert!(
        e.contains("feature 0 \"bow\"") && e.contains("intersects itself"),
        "{e}"
    );

    let two = vec![v2(0.0, 0.0), v2(100.0, 0.0), v2(0.0, 0.0)];
    let e = err(&collection(&[feature(&[&two], "")]));
    assert!(e.contains("feature 0") && e.contains("at least 3"), "{e}");

    // An obstacle across the boundary is cut out of the field, with a warning naming it;
    // one wholly outside is an error.
    let outer = rect(0.0, 0.0, 100.0, 100.0);
    let across = rect(90.0, 90.0, 150.0, 120.0);
    let f = load_field(
        &collection(&[
            feature(&[&outer], ""),
            feature(&[&across], r#""obstacle":true,"name":"barn""#),
        ]),
        &opts(),
    )
    .unwrap();
    assert!(f.field.obstacles.is_empty());
    assert!((f.cleanup.area_after_m2 - 9900.0).abs() < 0.01);
    assert!(f.warnings[0].contains("feature 1 \"barn\"") && f.warnings[0].contains("cut out"));
    let outside = rect(190.0, 190.0, 250.0, 220.0);
    let e = err(&collection(&[
        feature(&[&outer], ""),
        feature(&[&outside], r#""obstacle":true,"name":"barn""#),
    ]));
    assert!(
        e.contains("feature 1 \"barn\"") && e.contains("not inside"),
        "{e}"
    );

    let line = r#"{"type":"FeatureCollection","features":[{"type":"Feature","id":7,"properties":{},"geometry":{"type":"LineString","coordinates":[[5,52],[5.1,52]]}}]}"#;
    let e = err(line);
    assert!(
        e.contains("feature 0 (id 7)") && e.contains("LineString"),
        "{e}"
    );

    let bad = r#"{"type":"Polygon","coordinates":[[[5,52],[5.1,952],[5.1,52.1],[5,52]]]}"#;
    let e = err(bad);
    assert!(e.contains("bad coordinates") && e.contains("952"), "{e}");

    let e = err(&collection(&[
        feature(&[&outer], ""),
        feature(&[&rect(200.0, 0.0, 300.0, 100.0)], ""),
    ]));
    assert!(e.contains("2 boundary polygons"), "{e}");

    assert!(err("{not json").contains("JSON"));
    assert!(err("hello").contains("neither"));
    assert!(err(r#"{"type":"FeatureCollection","features":[]}"#).contains("no field boundary"));
}

fn pnts(points: &[Vec2]) -> String {
    let frame = EnuFrame::new(ORIGIN);
    points
        .iter()
        .map(|p| {
            let ll = frame.to_latlon(*p);
            format!(
                r#"<PNT A="2" C="{:.9}" D="{:.9}"/>"#,
                ll.lat_deg, ll.lon_deg
            )
        })
        .collect()
}

#[test]
fn taskdata_boundary_interior_ring_and_obstacle_polygon() {
    let outer = vec![
        v2(0.0, 0.0),
        v2(300.0, 0.0),
        v2(380.0, 200.0),
        v2(150.0, 320.0),
        v2(-60.0, 180.0),
    ];
    let hole = rect(100.0, 100.0, 130.0, 120.0);
    let pond = rect(200.0, 50.0, 230.0, 80.0);
    let xml = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<ISO11783_TaskData VersionMajor="4" VersionMinor="0" DataTransferOrigin="1">
<PFD A="PFD1" C="Pentagon" D="0">
<PLN A="1" B="boundary"><LSG A="1">{}</LSG><LSG A="2">{}</LSG></PLN>
<PLN A="6" B="pond"><LSG A="1">{}</LSG></PLN>
<PLN A="2" B="zone"><LSG A="1">{}</LSG></PLN>
</PFD></ISO11783_TaskData>"#,
        pnts(&outer),
        pnts(&hole),
        pnts(&pond),
        pnts(&rect(0.0, 0.0, 10.0, 10.0)),
    );
    let f = load_field(&xml, &opts()).unwrap();
    assert_eq!(f.name.as_deref(), Some("Pentagon"));
    assert_eq!(f.field.boundary.len(), 5);
    assert_eq!(f.field.obstacles.len(), 2);
    let area = signed_area(&outer) - 600.0 - 900.0;
    assert!((f.cleanup.area_after_m2 - area).abs() < 1.0);

    let broken = xml
        .replace(r#"C="Pentagon""#, r#"C="P""#)
        .replacen("C=\"5", "C=\"x5", 1);
    let e = load_field(&broken, &opts()).unwrap_err().to_string();
    assert!(e.contains("PFD1 \"P\" PLN 0") && e.contains("PNT 0"), "{e}");
}

#[test]
fn local_map_reads_metres_holes_and_obstacle_features() {
    // Coordinates far outside lat/lon ranges are fine in metres; the boundary is clockwise
    // and gets reoriented; a hole and an obstacle Feature (crossing the boundary) are kept.
    let text = r#"{"type":"FeatureCollection","features":[
      {"type":"Feature","properties":{"name":"yard"},"geometry":{"type":"Polygon","coordinates":[
        [[0,0],[0,300],[500,300],[500,0],[0,0]],
        [[10,10],[20,10],[20,20],[10,20],[10,10]]]}},
      {"type":"Feature","properties":{"obstacle":true},"geometry":{"type":"Polygon","coordinates":[
        [[490,100],[510,100],[510,120],[490,120],[490,100]]]}}]}"#;
    let f = load_local_map(text).unwrap();
    assert_eq!(f.boundary.len(), 4);
    assert!(signed_area(&f.boundary) > 0.0);
    assert!((signed_area(&f.boundary) - 150_000.0).abs() < 1e-6);
    assert_eq!(f.obstacles.len(), 2);
    assert!(f.obstacles.iter().any(|o| o.contains(&v2(510.0, 120.0))));
    // Errors name the feature.
    let two = r#"{"type":"FeatureCollection","features":[
      {"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[0,0],[1,0],[1,1],[0,0]]]}},
      {"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[5,0],[6,0],[6,1],[5,0]]]}}]}"#;
    assert!(matches!(
        load_local_map(two),
        Err(FieldError::SeveralBoundaries { count: 2, .. })
    ));
    let bad = r#"{"type":"Polygon","coordinates":[[[0,0],[1,"x"],[1,1],[0,0]]]}"#;
    assert!(load_local_map(bad)
        .unwrap_err()
        .to_string()
        .contains("position 1"));
}
