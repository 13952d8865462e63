//! NMEA 2000 PGN 129029 GNSS Position Data: the payload carried by fast-packet frames
//! (layout as documented by canboat), and edge conversions of GNSS angles.

/// Positioning method (high nibble of byte 31).
pub const METHOD_RTK_FIXED: u8 = 4;
pub const METHOD_RTK_FLOAT: u8 = 5;

/// One differential reference station of a 129029 message.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ReferenceStation {
    /// Type of the station's system (as `gnss_type`).
    pub station_type: Option<u8>,
    /// Station id (12 bits).
    pub id: Option<u16>,
    /// Age of its differential corrections, s.
    pub age_s: Option<f64>,
}

/// Reference stations kept per message (a message may list more; they are counted).
pub const MAX_STATIONS: usize = 4;

/// The decoded 129029 payload, in edge units as the PGN defines them. Every field the sender
/// may mark not available (see [`n2k_unsigned`], [`n2k_signed`]) is an `Option`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssPosition {
    pub sid: Option<u8>,
    /// Days since 1970-01-01.
    pub date_days: Option<u16>,
    /// Seconds since midnight.
    pub time_s: Option<f64>,
    /// WGS-84 degrees; `None` when not available or outside ±90 / ±180.
    pub latitude_deg: Option<f64>,
    pub longitude_deg: Option<f64>,
    /// Height above the ellipsoid, m.
    pub altitude_m: Option<f64>,
    /// GNSS type (low nibble of byte 31): 0 GPS, 1 GLONASS, 2 GPS+GLONASS, 3 GPS+SBAS,
    /// 4 GPS+SBAS+GLONASS, 5 Chayka, 6 integrated, 7 surveyed, 8 Galileo.
    pub gnss_type: Option<u8>,
    /// Method (high nibble of byte 31): 0 no GNSS, 1 GNSS fix, 2 DGNSS, 3 precise GNSS,
    /// 4 RTK fixed, 5 RTK float, 6 estimated (dead reckoning), 7 manual input, 8 simulated.
    pub method: Option<u8>,
    /// Integrity (2 bits): 0 no checking, 1 safe, 2 caution.
    pub integrity: Option<u8>,
    pub satellites: Option<u8>,
    pub hdop: Option<f64>,
    pub pdop: Option<f64>,
    /// Geoidal separation, m.
    pub geoidal_separation_m: Option<f64>,
    /// Number of reference stations the message lists.
    pub reference_stations: Option<u8>,
    /// The first [`MAX_STATIONS`] of them.
    pub stations: [Option<ReferenceStation>; MAX_STATIONS],
}

impl GnssPosition {
    /// The first station's correction age, s.
    pub fn correction_age_s(&self) -> Option<f64> {
        self.stations[0].and_then(|s| s.age_s)
    }
}

/// Payload length with one reference station, bytes.
pub const PAYLOAD_LEN: usize = 47;
/// Minimum payload length (no reference station), bytes.
pub const MIN_LEN: usize = 43;

#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum GnssError {
    #[error("129029 payload of {0} bytes is shorter than {MIN_LEN}")]
    Short(usize),
}

/// Number of top codes NMEA 2000 reserves in a field of `bits` bits (not available, out of
/// range, reserved), as canboat reads the standard (analyzer/fieldtype.c
/// `reservedCountForSize`): 3 from 8 bits up, 2 for 4–7 bits, 1 for 2–3 bits.
fn reserved_count(bits: u32) -> u64 {
    match bits {
        8.. => 3,
        4..=7 => 2,
        2..=3 => 1,
        _ => 0,
    }
}

/// An unsigned NMEA 2000 field of `bits` bits: `None` for its reserved top codes.
pub fn n2k_unsigned(raw: u64, bits: u32) -> Option<u64> {
    let max = if bits >= 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    };
    (raw <= max - reserved_count(bits)).then_some(raw)
}

/// A signed NMEA 2000 field of `bits` bits (sign-extended): `None` for the reserved top
/// positive codes.
pub fn n2k_signed(value: i64, bits: u32) -> Option<i64> {
    let max = ((1u64 << (bits - 1)) - 1) as i64;
    (value <= max - reserved_count(bits) as i64).then_some(value)
}

fn le<const N: usize>(p: &[u8], at: usize) -> [u8; N] {
    let mut b = [0u8; N];
    b.copy_from_slice(&p[at..at + N]);
    b
}

impl GnssPosition {
    /// Decode a reassembled payload (byte layout as canboat documents 129029).
    pub fn decode(p: &[u8]) -> Result<GnssPosition, GnssError> {
        if p.len() < MIN_LEN {
            return Err(GnssError::Short(p.len()));
        }
        let u8f = |at: usize| n2k_unsigned(p[at] as u64, 8).map(|v| v as u8);
        let i64f = |at: usize, scale: f64| {
            n2k_signed(i64::from_le_bytes(le(p, at)), 64).map(|v| v as f64 * scale)
        };
        // A dilution of precision is positive by definition: a negative one is a receiver
        // writing "not available" as unsigned (a Garmin GPS 17x sends 0xFFFF, canboat's
        // candumpSample1), so it is absent too.
        let dop = |at: usize| {
            n2k_signed(i16::from_le_bytes(le(p, at)) as i64, 16)
                .filter(|&v| v >= 0)
                .map(|v| v as f64 * 0.01)
        };
        let nibble = |v: u8| n2k_unsigned(v as u64, 4).map(|v| v as u8);
        let lat = i64f(7, 1e-16).filter(|l| l.abs() <= 90.0);
        let lon = i64f(15, 1e-16).filter(|l| l.abs() <= 180.0);
        let count = u8f(42);
        let mut stations = [None; MAX_STATIONS];
        for (k, slot) in stations
            .iter_mut()
            .enumerate()
            .take(count.unwrap_or(0) as usize)
        {
            let at = MIN_LEN + 4 * k;
            if p.len() < at + 4 {
                break;
            }
            let w = u16::from_le_bytes(le(p, at));
            let a = u16::from_le_bytes(le(p, at + 2));
            *slot = Some(ReferenceStation {
                station_type: nibble((w & 0x0F) as u8),
                id: n2k_unsigned((w >> 4) as u64, 12).map(|v| v as u16),
                age_s: n2k_unsigned(a as u64, 16).map(|v| v as f64 * 0.01),
            });
        }
        Ok(GnssPosition {
            sid: u8f(0),
            date_days: n2k_unsigned(u16::from_le_bytes(le(p, 1)) as u64, 16).map(|v| v as u16),
            time_s: n2k_unsigned(u32::from_le_bytes(le(p, 3)) as u64, 32).map(|v| v as f64 * 1e-4),
            latitude_deg: lat,
            longitude_deg: lon,
            altitude_m: i64f(23, 1e-6),
            gnss_type: nibble(p[31] & 0x0F),
            method: nibble(p[31] >> 4),
            integrity: n2k_unsigned((p[32] & 0x03) as u64, 2).map(|v| v as u8),
            satellites: u8f(33),
            hdop: dop(34),
            pdop: dop(36),
            geoidal_separation_m: n2k_signed(i32::from_le_bytes(le(p, 38)) as i64, 32)
                .map(|v| v as f64 * 0.01),
            reference_stations: count,
            stations,
        })
    }

    /// Encode with the first reference station (47 bytes); absent fields are sent as not
    /// available.
    pub fn encode(&self) -> [u8; PAYLOAD_LEN] {
        let mut p = [0xFFu8; PAYLOAD_LEN];
        p[0] = self.sid.unwrap_or(0xFF);
        p[1..3].copy_from_slice(&self.date_days.unwrap_or(u16::MAX).to_le_bytes());
        let time = self
            .time_s
            .map(|t| (t / 1e-4).round() as u32)
            .unwrap_or(u32::MAX);
        p[3..7].copy_from_slice(&time.to_le_bytes());
        let i64v = |v: Option<f64>, scale: f64| v.map(|x| (x / scale).round() as i64);
        let deg = |v: Option<f64>| v.map(|x| (x * 1e16).round() as i64).unwrap_or(i64::MAX);
        p[7..15].copy_from_slice(&deg(self.latitude_deg).to_le_bytes());
        p[15..23].copy_from_slice(&deg(self.longitude_deg).to_le_bytes());
        p[23..31].copy_from_slice(
            &i64v(self.altitude_m, 1e-6)
                .unwrap_or(i64::MAX)
                .to_le_bytes(),
        );
        p[31] = (self.gnss_type.unwrap_or(0x0F) & 0x0F) | (self.method.unwrap_or(0x0F) << 4);
        p[32] = (self.integrity.unwrap_or(3) & 0x03) | 0xFC;
        p[33] = self.satellites.unwrap_or(0xFF);
        let i16v = |v: Option<f64>| v.map(|x| (x / 0.01).round() as i16).unwrap_or(i16::MAX);
        p[34..36].copy_from_slice(&i16v(self.hdop).to_le_bytes());
        p[36..38].copy_from_slice(&i16v(self.pdop).to_le_bytes());
        let sep = self
            .geoidal_separation_m
            .map(|x| (x / 0.01).round() as i32)
            .unwrap_or(i32::MAX);
        p[38..42].copy_from_slice(&sep.to_le_bytes());
        p[42] = 1;
        let st = self.stations[0].unwrap_or_default();
        let w = (st.id.unwrap_or(0x0FFF) << 4) | (st.station_type.unwrap_or(0x0F) as u16 & 0x0F);
        p[43..45].copy_from_slice(&w.to_le_bytes());
        let age = st
            .age_s
            .map(|a| (a / 0.01).round().clamp(0.0, 65532.0) as u16)
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

/// A 129029 message with the usual fields of a receiver's fix (one reference station).
pub fn fix_message(sid: u8, lat_deg: f64, lon_deg: f64, method: u8) -> GnssPosition {
    GnssPosition {
        sid: Some(sid),
        date_days: Some(20_000),
        time_s: Some(0.0),
        latitude_deg: Some(lat_deg),
        longitude_deg: Some(lon_deg),
        altitude_m: Some(0.0),
        gnss_type: Some(4),
        method: Some(method),
        integrity: Some(0),
        satellites: Some(12),
        hdop: Some(1.0),
        pdop: Some(1.0),
        geoidal_separation_m: Some(0.0),
        reference_stations: Some(1),
        stations: [
            Some(ReferenceStation {
                station_type: Some(0),
                id: Some(1),
                age_s: Some(1.0),
            }),
            None,
            None,
            None,
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> GnssPosition {
        GnssPosition {
            sid: Some(7),
            date_days: Some(20_000),
            time_s: Some(43_210.5),
            latitude_deg: Some(52.123_456_789_012_3),
            longitude_deg: Some(-5.987_654_321_098_7),
            altitude_m: Some(12.345_678),
            gnss_type: Some(4),
            method: Some(METHOD_RTK_FIXED),
            integrity: Some(1),
            satellites: Some(21),
            hdop: Some(0.71),
            pdop: Some(1.3),
            geoidal_separation_m: Some(46.12),
            reference_stations: Some(1),
            stations: [
                Some(ReferenceStation {
                    station_type: Some(0),
                    id: Some(123),
                    age_s: Some(1.25),
                }),
                None,
                None,
                None,
            ],
        }
    }

    #[test]
    fn round_trip_keeps_nanodegrees_and_every_field() {
        let s = sample();
        let d = GnssPosition::decode(&s.encode()).unwrap();
        assert!((d.latitude_deg.unwrap() - s.latitude_deg.unwrap()).abs() < 1e-13);
        assert!((d.longitude_deg.unwrap() - s.longitude_deg.unwrap()).abs() < 1e-13);
        assert_eq!(
            GnssPosition {
                latitude_deg: s.latitude_deg,
                longitude_deg: s.longitude_deg,
                ..d
            },
            s
        );
        assert_eq!(d.correction_age_s(), Some(1.25));
    }

    #[test]
    fn short_is_an_error_and_sentinels_are_absent() {
        assert_eq!(GnssPosition::decode(&[0u8; 20]), Err(GnssError::Short(20)));
        // A receiver without a fix: everything not available, method 0.
        let none = GnssPosition {
            sid: None,
            date_days: None,
            time_s: None,
            latitude_deg: None,
            longitude_deg: None,
            altitude_m: None,
            gnss_type: None,
            method: Some(0),
            integrity: None,
            satellites: None,
            hdop: None,
            pdop: None,
            geoidal_separation_m: None,
            reference_stations: Some(1),
            stations: [Some(ReferenceStation::default()), None, None, None],
        };
        assert_eq!(GnssPosition::decode(&none.encode()), Ok(none));
        // The codes just below "not available" (out of range, reserved) are absent too.
        let mut p = sample().encode();
        p[7..15].copy_from_slice(&(i64::MAX - 1).to_le_bytes());
        p[15..23].copy_from_slice(&(i64::MAX - 2).to_le_bytes());
        p[33] = 0xFD;
        p[34..36].copy_from_slice(&(i16::MAX - 1).to_le_bytes());
        p[38..42].copy_from_slice(&(i32::MAX - 2).to_le_bytes());
        p[45..47].copy_from_slice(&0xFFFEu16.to_le_bytes());
        let d = GnssPosition::decode(&p).unwrap();
        assert_eq!((d.latitude_deg, d.longitude_deg), (None, None));
        assert_eq!(
            (d.satellites, d.hdop, d.geoidal_separation_m),
            (None, None, None)
        );
        assert_eq!(d.correction_age_s(), None);
        assert_eq!(d.pdop, Some(1.3), "the next field is still read");
        // The largest values that are data.
        p[33] = 0xFC;
        p[34..36].copy_from_slice(&(i16::MAX - 3).to_le_bytes());
        let d = GnssPosition::decode(&p).unwrap();
        assert_eq!(d.satellites, Some(252));
        assert_eq!(d.hdop, Some(327.64));
    }

    #[test]
    fn several_reference_stations_are_read() {
        let mut p = sample().encode().to_vec();
        p[42] = 3;
        p.extend_from_slice(&((77u16 << 4) | 1).to_le_bytes());
        p.extend_from_slice(&250u16.to_le_bytes());
        p.extend_from_slice(&0xFFFFu16.to_le_bytes());
        p.extend_from_slice(&0xFFFFu16.to_le_bytes());
        let d = GnssPosition::decode(&p).unwrap();
        assert_eq!(d.reference_stations, Some(3));
        assert_eq!(
            d.stations[1],
            Some(ReferenceStation {
                station_type: Some(1),
                id: Some(77),
                age_s: Some(2.5)
            })
        );
        assert_eq!(d.stations[2], Some(ReferenceStation::default()));
        assert_eq!(d.stations[3], None);
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
