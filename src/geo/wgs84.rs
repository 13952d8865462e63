//! WGS-84 latitude/longitude ↔ local ENU (tangent plane at an origin).
//!
//! Exact ECEF-based conversion: lat/lon/height → ECEF → ENU about the origin. At field scale
//! (a few km) the result is consistent to well under a millimetre both ways.

use super::{v2, Vec2};
use serde::{Deserialize, Serialize};

const A: f64 = 6_378_137.0;
const F: f64 = 1.0 / 298.257_223_563;
const E2: f64 = F * (2.0 - F);

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
}
