//! NMEA 2000 PGN 129029 GNSS Position Data: the payload carried by fast-packet frames
//! (layout as documented by canboat), and edge conversions of GNSS angles.

/// Positioning method (high nibble of byte 31).
pub const METHOD_RTK_FIXED: u8 = 4;
pub const METHOD_RTK_FLOAT: u8 = 5;

/// The decoded 129029 payload, in edge units as the PGN defines them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssPosition {
    pub sid: u8,
    /// Days since 1970-01-01.
    pub date_days: u16,
    /// Seconds since midnight.
    pub time_s: f64,
    pub latitude_deg: f64,
    pub longitude_deg: f64,
    pub altitude_m: f64,
    /// GNSS type (low nibble): 0 GPS, … 4 GNSS.
    pub gnss_type: u8,
    /// Method: 0 none, 1 GNSS fix, 2 DGNSS, 4 RTK fixed, 5 RTK float, …
    pub method: u8,
    pub integrity: u8,
    pub satellites: u8,
    pub hdop: Option<f64>,
    pub pdop: Option<f64>,
    pub geoidal_separation_m: f64,
    pub reference_stations: u8,
    pub reference_station_id: u16,
    /// Age of the differential corrections, s.
    pub correction_age_s: Option<f64>,
}

/// Payload length with one reference station, bytes.
pub const PAYLOAD_LEN: usize = 47;
/// Minimum payload length (no reference station), bytes.
pub const MIN_LEN: usize = 43;

#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum GnssError {
    #[error("129029 payload of {0} bytes is shorter than {MIN_LEN}")]
    Short(usize),
    #[error("129029 latitude or longitude not available or out of range")]
    NoPosition,
}

fn le<const N: usize>(p: &[u8], at: usize) -> [u8; N] {
    let mut b = [0u8; N];
    b.copy_from_slice(&p[at..at + N]);
    b
}

impl GnssPosition {
    /// Decode a reassembled payload.
    pub fn decode(p: &[u8]) -> Result<GnssPosition, GnssError> {
        if p.len() < MIN_LEN {
            return Err(GnssError::Short(p.len()));
        }
        let lat = i64::from_le_bytes(le(p, 7));
        let lon = i64::from_le_bytes(le(p, 15));
        if lat == i64::MAX || lon == i64::MAX {
            return Err(GnssError::NoPosition);
        }
        let (lat, lon) = (lat as f64 * 1e-16, lon as f64 * 1e-16);
        if lat.abs() > 90.0 || lon.abs() > 180.0 {
            return Err(GnssError::NoPosition);
        }
        let i16_opt = |at: usize| {
            let v = i16::from_le_bytes(le(p, at));
            (v != i16::MAX).then_some(v as f64 * 0.01)
        };
        let (station, age) = if p.len() >= PAYLOAD_LEN && p[42] >= 1 {
            let w = u16::from_le_bytes(le(p, 43));
            let a = u16::from_le_bytes(le(p, 45));
            (w >> 4, (a != u16::MAX).then_some(a as f64 * 0.01))
        } else {
            (0, None)
        };
        Ok(GnssPosition {
            sid: p[0],
            date_days: u16::from_le_bytes(le(p, 1)),
            time_s: u32::from_le_bytes(le(p, 3)) as f64 * 1e-4,
            latitude_deg: lat,
            longitude_deg: lon,
            altitude_m: i64::from_le_bytes(le(p, 23)) as f64 * 1e-6,
            gnss_type: p[31] & 0x0F,
            method: p[31] >> 4,
            integrity: p[32] & 0x03,
            satellites: p[33],
            hdop: i16_opt(34),
            pdop: i16_opt(36),
            geoidal_separation_m: i32::from_le_bytes(le(p, 38)) as f64 * 0.01,
            reference_stations: p[42],
            reference_station_id: station,
            correction_age_s: age,
        })
    }

    /// Encode with one reference station (47 bytes).
    pub fn encode(&self) -> [u8; PAYLOAD_LEN] {
        let mut p = [0xFFu8; PAYLOAD_LEN];
        p[0] = self.sid;
        p[1..3].copy_from_slice(&self.date_days.to_le_bytes());
        p[3..7].copy_from_slice(&((self.time_s / 1e-4).round() as u32).to_le_bytes());
        p[7..15].copy_from_slice(&((self.latitude_deg * 1e16).round() as i64).to_le_bytes());
        p[15..23].copy_from_slice(&((self.longitude_deg * 1e16).round() as i64).to_le_bytes());
        p[23..31].copy_from_slice(&((self.altitude_m * 1e6).round() as i64).to_le_bytes());
        p[31] = (self.gnss_type & 0x0F) | (self.method << 4);
        p[32] = (self.integrity & 0x03) | 0xFC;
        p[33] = self.satellites;
        let i16v = |v: Option<f64>| v.map(|x| (x / 0.01).round() as i16).unwrap_or(i16::MAX);
        p[34..36].copy_from_slice(&i16v(self.hdop).to_le_bytes());
        p[36..38].copy_from_slice(&i16v(self.pdop).to_le_bytes());
        p[38..42]
            .copy_from_slice(&((self.geoidal_separation_m / 0.01).round() as i32).to_le_bytes());
        p[42] = 1;
        p[43..45].copy_from_slice(&(self.reference_station_id << 4).to_le_bytes());
        let age = self
            .correction_age_s
            .map(|a| (a / 0.01).round().clamp(0.0, 65534.0) as u16)
            .unwrap_or(u16::MAX);
        p[45..47].copy_from_slice(&age.to_le_bytes());
        p
    }
}

/// GNSS course/heading (clockwise from north, rad) → yaw (counter-clockwise from east, rad).
pub fn yaw_from_north_cw(north_cw: f64) -> f64 {
    crate::geo::wrap_angle(std::f64::consts::FRAC_PI_2 - north_cw)
}

/// Yaw (counter-clockwise from east) → GNSS course/heading (clockwise from north) in [0, 2π).
pub fn north_cw_from_yaw(yaw: f64) -> f64 {
    (std::f64::consts::FRAC_PI_2 - yaw).rem_euclid(std::f64::consts::TAU)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> GnssPosition {
        GnssPosition {
            sid: 7,
            date_days: 20_000,
            time_s: 43_210.5,
            latitude_deg: 52.123_456_789_012_3,
            longitude_deg: -5.987_654_321_098_7,
            altitude_m: 12.345_678,
            gnss_type: 4,
            method: METHOD_RTK_FIXED,
            integrity: 1,
            satellites: 21,
            hdop: Some(0.71),
            pdop: Some(1.3),
            geoidal_separation_m: 46.12,
            reference_stations: 1,
            reference_station_id: 123,
            correction_age_s: Some(1.25),
        }
    }

    #[test]
    fn round_trip_keeps_nanodegrees() {
        let s = sample();
        let d = GnssPosition::decode(&s.encode()).unwrap();
        assert!((d.latitude_deg - s.latitude_deg).abs() < 1e-13);
        assert!((d.longitude_deg - s.longitude_deg).abs() < 1e-13);
        assert_eq!(d.method, METHOD_RTK_FIXED);
        assert_eq!(d.satellites, 21);
        assert_eq!(d.hdop, Some(0.71));
        assert_eq!(d.correction_age_s, Some(1.25));
        assert_eq!(d.reference_station_id, 123);
    }

    #[test]
    fn short_and_unavailable_are_errors() {
        assert_eq!(GnssPosition::decode(&[0u8; 20]), Err(GnssError::Short(20)));
        let mut p = sample().encode();
        p[7..15].copy_from_slice(&i64::MAX.to_le_bytes());
        assert_eq!(GnssPosition::decode(&p), Err(GnssError::NoPosition));
    }

    #[test]
    fn heading_conventions() {
        use std::f64::consts::{FRAC_PI_2, PI};
        assert!((yaw_from_north_cw(0.0) - FRAC_PI_2).abs() < 1e-12, "north");
        assert!(yaw_from_north_cw(FRAC_PI_2).abs() < 1e-12, "east");
        assert!(
            (north_cw_from_yaw(PI) - 3.0 * FRAC_PI_2).abs() < 1e-12,
            "west"
        );
    }
}
