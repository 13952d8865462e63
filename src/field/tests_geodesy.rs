//! Fields anywhere a tractor drives: across the antimeridian, in both hemispheres, up to the
//! latitude limit — planned at their place with their geodesic area. The reference is
//! geographiclib (Karney 2013) through the `geo` crate's `Geodesic` and `GeodesicArea`, code
//! this project did not write.

use super::*;
use geo::{Destination, Geodesic, GeodesicArea, Point};

/// A pentagon of about 1.2 km × 0.8 km with its first corner at (lat, lon), walked along
/// geodesics (lon/lat pairs, not closed).
fn pentagon(lat: f64, lon: f64) -> Vec<(f64, f64)> {
    let mut p = Point::new(lon, lat);
    let mut out = vec![(p.x(), p.y())];
    for &(bearing, d) in &[
        (95.0, 1_200.0),
        (10.0, 700.0),
        (300.0, 600.0),
        (230.0, 500.0),
    ] {
        p = Geodesic.destination(p, bearing, d);
        out.push((p.x(), p.y()));
    }
    out
}

fn geojson(ring: &[(f64, f64)]) -> String {
    let mut closed = ring.to_vec();
    closed.push(ring[0]);
    let pts: Vec<String> = closed
        .iter()
        .map(|(lon, lat)| format!("[{lon:.10},{lat:.10}]"))
        .collect();
    format!(
        r#"{{"type":"Feature","properties":{{}},"geometry":{{"type":"Polygon","coordinates":[[{}]]}}}}"#,
        pts.join(",")
    )
}

fn geodesic_area(ring: &[(f64, f64)]) -> f64 {
    let poly = geo::Polygon::new(geo::LineString::from(ring.to_vec()), vec![]);
    poly.geodesic_area_unsigned()
}

fn exact() -> LoadOptions {
    LoadOptions {
        origin: None,
        boundary_tolerance_m: 0.0,
    }
}

/// (lat, lon) of the first corner: the issue's field across the antimeridian at 52° N, the
/// same in the south, both hemispheres East and West, the equator, the latitude limit.
const PLACES: [(f64, f64); 8] = [
    (52.0, 179.99),
    (-52.0, 179.995),
    (52.0, 5.0),
    (-34.6, -58.4),
    (41.9, -93.6),
    (-0.004, 36.8),
    (83.98, -40.0),
    (-83.99, 179.99),
];

#[test]
fn fields_are_planned_in_place_with_their_geodesic_area() {
    for &(lat, lon) in &PLACES {
        let ring = pentagon(lat, lon);
        let f =
            load_field(&geojson(&ring), &exact()).unwrap_or_else(|e| panic!("{lat},{lon}: {e}"));
        // At the right place: the origin is inside the field's box, and every boundary point
        // maps back to its input position within a millimetre.
        let back: Vec<LatLon> = f
            .field
            .boundary
            .iter()
            .map(|p| f.frame().to_latlon(*p))
            .collect();
        for (lon_in, lat_in) in &ring {
            let near = back.iter().any(|b| {
                let d = f.frame().to_enu(*b)
                    - f.frame().to_enu(LatLon {
                        lat_deg: *lat_in,
                        lon_deg: *lon_in,
                    });
                d.norm() < 1e-3
                    && (b.lat_deg - lat_in).abs() < 1e-7
                    && crate::geo::wgs84::wrap_lon_deg(b.lon_deg - lon_in).abs() < 1e-6
            });
            assert!(
                near,
                "{lat},{lon}: corner ({lat_in}, {lon_in}) not in the plan's boundary {back:?}"
            );
        }
        // The origin at the field (the box centre is under a kilometre from the first corner;
        // the issue's antimeridian field was planned 1 600 km away).
        let from_corner = {
            use geo::Distance;
            Geodesic.distance(
                Point::new(lon, lat),
                Point::new(f.origin.lon_deg, f.origin.lat_deg),
            )
        };
        assert!(
            from_corner < 1_000.0,
            "{lat},{lon}: origin {:?} {from_corner} m away",
            f.origin
        );
        // The right area: within 0.1 % of the geodesic area (it is within 1e-5 here).
        let reference = geodesic_area(&ring);
        let planar = signed_area(&f.field.boundary);
        let rel = (planar - reference).abs() / reference;
        assert!(
            rel < 1e-3,
            "{lat},{lon}: area {planar} vs geodesic {reference} ({rel:e})"
        );
        assert!(rel < 1e-5, "{lat},{lon}: {rel:e}");
        assert!((f.cleanup.area_after_m2 - planar).abs() < 1e-6 * planar);
    }
}

#[test]
fn a_field_beyond_the_latitude_limit_is_refused_naming_it() {
    for &(lat, lon) in &[(84.05, 10.0), (-86.0, -120.0)] {
        let e = load_field(&geojson(&pentagon(lat, lon)), &exact())
            .unwrap_err()
            .to_string();
        assert!(e.contains("84") && e.contains("beyond"), "{e}");
    }
    // And a configured origin beyond it.
    let e = load_field(
        &geojson(&pentagon(83.0, 10.0)),
        &LoadOptions {
            origin: Some(LatLon {
                lat_deg: 84.5,
                lon_deg: 10.0,
            }),
            boundary_tolerance_m: 0.0,
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("ENU origin") && e.contains("84.5"), "{e}");
}

#[test]
fn a_configured_origin_far_from_the_field_is_refused() {
    // The issue's moved origin: a field at 52° N, 179.99° E planned about 52° N, 5° E.
    let e = load_field(
        &geojson(&pentagon(52.0, 179.99)),
        &LoadOptions {
            origin: Some(LatLon {
                lat_deg: 52.0,
                lon_deg: 5.0,
            }),
            boundary_tolerance_m: 0.0,
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("ENU origin") && e.contains("50000"), "{e}");
    // An origin 10 km away is fine.
    let near = load_field(
        &geojson(&pentagon(52.0, 179.99)),
        &LoadOptions {
            origin: Some(LatLon {
                lat_deg: 52.09,
                lon_deg: -179.95,
            }),
            boundary_tolerance_m: 0.0,
        },
    );
    assert!(near.is_ok(), "{near:?}");
}
