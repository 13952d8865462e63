//! WGS-84 latitude/longitude ↔ local ENU (tangent plane at an origin).
//!
//! Exact ECEF-based conversion: lat/lon/height → ECEF → ENU about the origin. At field scale
//! (a few km) the result is consistent to well under a millimetre both ways.
//!
//! Where it holds (tested below against geographiclib through the `geo` crate's geodesics):
//! - **Anywhere in longitude.** The conversion goes through ECEF, so a field across the
//!   antimeridian (179.99° and −179.99°) is as good as one at 5° E. Only the choice of an origin
//!   must not average longitudes naively: [`centre`] unwraps them about the first point.
//! - **Up to [`MAX_ABS_LAT_DEG`] north or south** ([`check_latitude`]). The plane itself stays
//!   exact towards the pole, but a heading from a GNSS receiver is measured from the local
//!   meridian, which turns away from the plane's North by the meridian convergence
//!   γ ≈ (x / R) · tan φ at x metres East of the origin: 2.0 mrad at 52° and 10 km, 21 mrad
//!   (1.2°) at 84° and 14 km (the envelope's farthest corner), growing without bound at the
//!   pole. Beyond 84° (the limit of UTM, past which mapping changes to polar projections; no
//!   cropland lies there) a field is refused.
//! - **Scale over the field's extent.** The local plane is the tangent plane at the origin: a
//!   distance d from the origin is kept along circles and shrunk by cos(d / R) ≈ 1 − d²/2R²
//!   radially, so a segment's length is off by at most 1.2 × 10⁻⁶ at 10 km from the origin
//!   (3.7 µm on a 3 m swath spacing) and an area by the same fraction; the envelope's field
//!   (20 km across, ≤ 14.2 km from a centred origin) stays under 2.6 × 10⁻⁶ (the meridian's
//!   radius of curvature is 6 335 km at the equator). A point's own
//!   distance from the origin comes out shorter by d³/6R² (12 mm at 14.2 km), which moves
//!   nothing: GNSS fixes and the plan go through the same frame both ways. Heights are taken
//!   on the ellipsoid: a field at height h is larger than planned by h / R (1.6 × 10⁻⁴ at
//!   1 000 m).

use super::{v2, Vec2};
use serde::{Deserialize, Serialize};

const A: f64 = 6_378_137.0;
const F: f64 = 1.0 / 298.257_223_563;
const E2: f64 = F * (2.0 - F);

/// The largest |latitude| at which a field is planned or an origin accepted, degrees (see the
/// module documentation for why).
pub const MAX_ABS_LAT_DEG: f64 = 84.0;

/// Why a position cannot be used for planning.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GeoError {
    #[error("latitude {lat_deg}° is beyond ±{MAX_ABS_LAT_DEG}°, the limit of the local plane (the meridian convergence near the pole would turn GNSS headings away from the plan's North)")]
    TooNearPole { lat_deg: f64 },
    #[error("lat {lat_deg}, lon {lon_deg} is not a position (lat within ±90°, lon within ±180°, finite)")]
    OutOfRange { lat_deg: f64, lon_deg: f64 },
}

/// A position that can be planned about: finite, lon within ±180°, |lat| ≤ [`MAX_ABS_LAT_DEG`].
pub fn check_latitude(p: LatLon) -> Result<LatLon, GeoError> {
    if !p.lat_deg.is_finite()
        || !p.lon_deg.is_finite()
        || p.lat_deg.abs() > 90.0
        || p.lon_deg.abs() > 180.0
    {
        return Err(GeoError::OutOfRange {
            lat_deg: p.lat_deg,
            lon_deg: p.lon_deg,
        });
    }
    if p.lat_deg.abs() > MAX_ABS_LAT_DEG {
        return Err(GeoError::TooNearPole { lat_deg: p.lat_deg });
    }
    Ok(p)
}

/// A longitude wrapped to [-180°, 180°).
pub fn wrap_lon_deg(lon: f64) -> f64 {
    (lon + 180.0).rem_euclid(360.0) - 180.0
}

/// The centre of the lat/lon bounding box of `points`, with longitudes unwrapped about the
/// first point (each taken within 180° of it), so a field across the antimeridian has its
/// centre there and not half a world away. `None` when empty.
pub fn centre(points: &[LatLon]) -> Option<LatLon> {
    let first = points.first()?;
    let (mut lat0, mut lat1, mut lon0, mut lon1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in points {
        // Moved by a whole turn only when the short way round crosses the antimeridian, so a
        // field elsewhere keeps its longitudes to the last bit.
        let d = p.lon_deg - first.lon_deg;
        let lon = if d > 180.0 {
            p.lon_deg - 360.0
        } else if d < -180.0 {
            p.lon_deg + 360.0
        } else {
            p.lon_deg
        };
        lat0 = lat0.min(p.lat_deg);
        lat1 = lat1.max(p.lat_deg);
        lon0 = lon0.min(lon);
        lon1 = lon1.max(lon);
    }
    let lon = 0.5 * (lon0 + lon1);
    Some(LatLon {
        lat_deg: 0.5 * (lat0 + lat1),
        lon_deg: if (-180.0..=180.0).contains(&lon) {
            lon
        } else {
            wrap_lon_deg(lon)
        },
    })
}

/// A WGS-84 geodetic position in degrees (edge unit) and metres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LatLon {
    pub lat_deg: f64,
    pub lon_deg: f64,
}

/// A local tangent-plane frame about an origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnuFrame {
    origin: LatLon,
    origin_ecef: [f64; 3],
    sin_lat: f64,
    cos_lat: f64,
    sin_lon: f64,
    cos_lon: f64,
}

fn ecef(lat: f64, lon: f64, h: f64) -> [f64; 3] {
    let (sl, cl) = lat.sin_cos();
    let (so, co) = lon.sin_cos();
    let n = A / (1.0 - E2 * sl * sl).sqrt();
    [
        (n + h) * cl * co,
        (n + h) * cl * so,
        (n * (1.0 - E2) + h) * sl,
    ]
}

impl EnuFrame {
    pub fn new(origin: LatLon) -> Self {
        let lat = origin.lat_deg.to_radians();
        let lon = origin.lon_deg.to_radians();
        EnuFrame {
            origin,
            origin_ecef: ecef(lat, lon, 0.0),
            sin_lat: lat.sin(),
            cos_lat: lat.cos(),
            sin_lon: lon.sin(),
            cos_lon: lon.cos(),
        }
    }

    pub fn origin(&self) -> LatLon {
        self.origin
    }

    /// Geodetic → local East/North, metres (height taken as 0 on the ellipsoid).
    pub fn to_enu(&self, p: LatLon) -> Vec2 {
        let e = ecef(p.lat_deg.to_radians(), p.lon_deg.to_radians(), 0.0);
        let d = [
            e[0] - self.origin_ecef[0],
            e[1] - self.origin_ecef[1],
            e[2] - self.origin_ecef[2],
        ];
        let east = -self.sin_lon * d[0] + self.cos_lon * d[1];
        let north = -self.sin_lat * self.cos_lon * d[0] - self.sin_lat * self.sin_lon * d[1]
            + self.cos_lat * d[2];
        v2(east, north)
    }

    /// Local East/North → geodetic (on the ellipsoid surface under the point).
    pub fn to_latlon(&self, p: Vec2) -> LatLon {
        // Up component chosen so the point lies near the ellipsoid: for field distances the
        // tangent-plane drop is d²/2R; include it so round trips stay sub-millimetre.
        let r2 = p.x * p.x + p.y * p.y;
        let up = -r2 / (2.0 * A);
        let x = -self.sin_lon * p.x - self.sin_lat * self.cos_lon * p.y
            + self.cos_lat * self.cos_lon * up
            + self.origin_ecef[0];
        let y = self.cos_lon * p.x - self.sin_lat * self.sin_lon * p.y
            + self.cos_lat * self.sin_lon * up
            + self.origin_ecef[1];
        let z = self.cos_lat * p.y + self.sin_lat * up + self.origin_ecef[2];
        // Bowring-style iteration for latitude.
        let lon = y.atan2(x);
        let pxy = (x * x + y * y).sqrt();
        let mut lat = z.atan2(pxy * (1.0 - E2));
        for _ in 0..5 {
            let sl = lat.sin();
            let n = A / (1.0 - E2 * sl * sl).sqrt();
            let h = pxy / lat.cos() - n;
            lat = z.atan2(pxy * (1.0 - E2 * n / (n + h)));
        }
        LatLon {
            lat_deg: lat.to_degrees(),
            lon_deg: lon.to_degrees(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_submillimetre() {
        let f = EnuFrame::new(LatLon {
            lat_deg: 52.2,
            lon_deg: 5.1,
        });
        for &(x, y) in &[
            (0.0, 0.0),
            (100.0, -50.0),
            (2500.0, 3100.0),
            (-4000.0, 10.0),
        ] {
            let ll = f.to_latlon(v2(x, y));
            let back = f.to_enu(ll);
            assert!((back - v2(x, y)).norm() < 1e-3, "{x},{y} -> {back:?}");
        }
    }

    #[test]
    fn one_microdegree_north_is_about_11_cm() {
        let f = EnuFrame::new(LatLon {
            lat_deg: 45.0,
            lon_deg: 0.0,
        });
        let p = f.to_enu(LatLon {
            lat_deg: 45.000001,
            lon_deg: 0.0,
        });
        assert!((p.y - 0.1111).abs() < 0.001, "{p:?}");
        assert!(p.x.abs() < 1e-6);
    }

    /// geographiclib (Karney 2013, through the `geo` crate) as the reference.
    fn geodesic_point(from: LatLon, bearing_deg: f64, distance_m: f64) -> LatLon {
        use geo::{Destination, Geodesic, Point};
        let p = Geodesic.destination(
            Point::new(from.lon_deg, from.lat_deg),
            bearing_deg,
            distance_m,
        );
        LatLon {
            lat_deg: p.y(),
            lon_deg: p.x(),
        }
    }

    fn geodesic_distance(a: LatLon, b: LatLon) -> f64 {
        use geo::{Distance, Geodesic, Point};
        Geodesic.distance(
            Point::new(a.lon_deg, a.lat_deg),
            Point::new(b.lon_deg, b.lat_deg),
        )
    }

    /// Origins in both hemispheres, on both sides of the antimeridian and at the limit.
    const ORIGINS: [(f64, f64); 6] = [
        (52.0, 5.0),
        (-33.9, -60.5),
        (0.5, 179.999),
        (-45.0, -179.995),
        (65.0, -179.99),
        (84.0, 30.0),
    ];

    #[test]
    fn swath_lengths_match_geodesics_across_the_envelope() {
        // 3 m segments at up to 14.2 km from the origin (the envelope's 20 km field's corner)
        // in eight directions: the plane's length within 2.6e-6 of the geodesic's.
        let mut worst = 0.0f64;
        for &(lat, lon) in &ORIGINS {
            let o = LatLon {
                lat_deg: lat,
                lon_deg: lon,
            };
            let f = EnuFrame::new(o);
            for k in 0..8 {
                let bearing = 45.0 * k as f64;
                for &d in &[1_000.0, 5_000.0, 14_200.0] {
                    let a = geodesic_point(o, bearing, d);
                    for &along in &[bearing, bearing + 90.0] {
                        let b = geodesic_point(a, along, 3.0);
                        let plane = (f.to_enu(b) - f.to_enu(a)).norm();
                        let rel = (plane - geodesic_distance(a, b)).abs() / 3.0;
                        worst = worst.max(rel);
                        assert!(
                            rel < 2.6e-6,
                            "origin {o:?} bearing {bearing} at {d} m: {rel:e}"
                        );
                    }
                }
            }
        }
        // The bound is near what the tangent plane gives (1 − cos(d/R) at 14.2 km: 2.5e-6).
        assert!(worst > 1e-6, "{worst:e}");
    }

    #[test]
    fn antimeridian_is_continuous_and_round_trips() {
        let f = EnuFrame::new(LatLon {
            lat_deg: -45.0,
            lon_deg: 179.995,
        });
        // 0.01° of longitude further East is across the antimeridian, ~787 m East.
        let p = f.to_enu(LatLon {
            lat_deg: -45.0,
            lon_deg: -179.995,
        });
        let expected = geodesic_distance(
            LatLon {
                lat_deg: -45.0,
                lon_deg: 179.995,
            },
            LatLon {
                lat_deg: -45.0,
                lon_deg: -179.995,
            },
        );
        assert!(
            (p.x - expected).abs() < 0.01 && p.y.abs() < 0.1,
            "{p:?} vs {expected}"
        );
        for &(x, y) in &[(2000.0, 300.0), (-7000.0, -6000.0), (9000.0, 9000.0)] {
            let ll = f.to_latlon(v2(x, y));
            assert!(ll.lon_deg.abs() <= 180.0);
            assert!((f.to_enu(ll) - v2(x, y)).norm() < 1e-3, "{x},{y} -> {ll:?}");
        }
    }

    #[test]
    fn centre_unwraps_longitudes() {
        let pts = |lons: &[f64]| -> Vec<LatLon> {
            lons.iter()
                .map(|&lon_deg| LatLon {
                    lat_deg: 52.0,
                    lon_deg,
                })
                .collect()
        };
        // 179.99 … 180.03 unwrapped: the centre is 180.01, i.e. -179.99.
        let c = centre(&pts(&[179.99, -179.99, -179.97])).unwrap();
        assert!((c.lon_deg + 179.99).abs() < 1e-9, "{c:?}");
        let c = centre(&pts(&[-179.99, 179.97, 179.99])).unwrap();
        assert!((c.lon_deg - 179.99).abs() < 1e-9, "{c:?}");
        let c = centre(&pts(&[4.0, 6.0])).unwrap();
        assert!((c.lon_deg - 5.0).abs() < 1e-12 && c.lat_deg == 52.0);
        assert_eq!(centre(&[]), None);
    }

    #[test]
    fn latitude_limit() {
        let at = |lat_deg| LatLon {
            lat_deg,
            lon_deg: 10.0,
        };
        assert!(check_latitude(at(84.0)).is_ok());
        assert!(check_latitude(at(-84.0)).is_ok());
        assert!(matches!(
            check_latitude(at(84.01)),
            Err(GeoError::TooNearPole { .. })
        ));
        assert!(matches!(
            check_latitude(at(-89.0)),
            Err(GeoError::TooNearPole { .. })
        ));
        assert!(matches!(
            check_latitude(at(f64::NAN)),
            Err(GeoError::OutOfRange { .. })
        ));
        let msg = check_latitude(at(86.5)).unwrap_err().to_string();
        assert!(msg.contains("86.5") && msg.contains("84"), "{msg}");
    }

    /// The meridian convergence the module documents: the angle between the plane's North and
    /// the local meridian at x metres East of the origin.
    #[test]
    fn meridian_convergence_figures() {
        let convergence = |lat: f64, x: f64| {
            let o = LatLon {
                lat_deg: lat,
                lon_deg: 0.0,
            };
            let f = EnuFrame::new(o);
            let p = geodesic_point(o, 90.0, x);
            let north = geodesic_point(p, 0.0, 1.0);
            let d = f.to_enu(north) - f.to_enu(p);
            d.x.atan2(d.y).abs()
        };
        let g52 = convergence(52.0, 10_000.0);
        assert!((g52 - 2.0e-3).abs() < 0.1e-3, "{g52}");
        let g84 = convergence(84.0, 14_200.0);
        assert!((g84 - 21e-3).abs() < 1e-3, "{g84}");
    }
}
