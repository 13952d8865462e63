//! The standard sentences (field layouts as in NMEA 0183 v4.11 and gpsd's "NMEA 0183
//! revealed"): GGA, RMC, VTG, HDT, GST, GNS.

use super::fields::{self as f, Fields};
use super::{bad, NmeaError};

/// GGA: fix data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gga {
    /// UTC seconds since midnight.
    pub time_s: Option<f64>,
    pub lat_deg: Option<f64>,
    pub lon_deg: Option<f64>,
    /// Quality indicator: 0 invalid, 1 GNSS, 2 DGNSS, 3 PPS, 4 RTK fixed, 5 RTK float,
    /// 6 estimated (dead reckoning), 7 manual, 8 simulator.
    pub quality: u8,
    pub satellites: Option<u8>,
    pub hdop: Option<f64>,
    /// Antenna height above mean sea level (geoid), m.
    pub altitude_msl_m: Option<f64>,
    /// Geoid height above the WGS-84 ellipsoid, m.
    pub geoid_separation_m: Option<f64>,
    /// Age of the differential corrections, s.
    pub correction_age_s: Option<f64>,
    pub station_id: Option<u16>,
}

/// RMC: recommended minimum data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rmc {
    pub time_s: Option<f64>,
    /// Status `A` (valid); `V` is a warning (no fix).
    pub valid: bool,
    pub lat_deg: Option<f64>,
    pub lon_deg: Option<f64>,
    pub speed_knots: Option<f64>,
    /// Course over ground, degrees clockwise from true North.
    pub course_deg: Option<f64>,
    /// Days since 1970-01-01.
    pub date_days: Option<i64>,
    /// Magnetic variation, degrees, positive East.
    pub variation_deg: Option<f64>,
    /// FAA mode indicator (NMEA 2.3+): A, D, E, F (RTK float), M, N, P, R (RTK fixed), S.
    pub mode: Option<u8>,
}

/// VTG: course and speed over ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vtg {
    /// Course over ground, degrees clockwise from true North.
    pub course_true_deg: Option<f64>,
    pub course_magnetic_deg: Option<f64>,
    pub speed_knots: Option<f64>,
    pub speed_kmh: Option<f64>,
    pub mode: Option<u8>,
}

/// HDT: true heading (dual-antenna receivers, gyrocompasses).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hdt {
    /// Degrees clockwise from true North.
    pub heading_deg: Option<f64>,
}

/// GST: pseudorange error statistics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gst {
    pub time_s: Option<f64>,
    /// RMS of the pseudorange residuals, m.
    pub rms_m: Option<f64>,
    /// 1-σ error along the error ellipse's semi-major and semi-minor axes, m.
    pub sigma_major_m: Option<f64>,
    pub sigma_minor_m: Option<f64>,
    /// 1-σ latitude, longitude and altitude errors, m.
    pub sigma_lat_m: Option<f64>,
    pub sigma_lon_m: Option<f64>,
    pub sigma_alt_m: Option<f64>,
}

/// GNS: fix data with a mode letter per constellation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gns {
    pub time_s: Option<f64>,
    pub lat_deg: Option<f64>,
    pub lon_deg: Option<f64>,
    /// Mode letters (GPS, GLONASS, Galileo, BeiDou, ...), unused slots 0: N no fix,
    /// A autonomous, D differential, P precise, R RTK fixed, F RTK float, E estimated,
    /// M manual, S simulator.
    pub modes: [u8; 6],
    pub satellites: Option<u8>,
    pub hdop: Option<f64>,
    pub altitude_msl_m: Option<f64>,
    pub geoid_separation_m: Option<f64>,
    pub correction_age_s: Option<f64>,
    pub station_id: Option<u16>,
}

/// Latitude then longitude, four fields.
pub(super) fn lat_lon(
    fs: &mut Fields<'_>,
    name: &'static str,
) -> Result<(Option<f64>, Option<f64>), NmeaError> {
    let n = fs.number();
    let (lat, ns) = (fs.next_field(), fs.next_field());
    let lat = f::angle_dm(lat, ns, 90.0, b'N', b'S').map_err(|_| bad(name, n))?;
    let (lon, ew) = (fs.next_field(), fs.next_field());
    let lon = f::angle_dm(lon, ew, 180.0, b'E', b'W').map_err(|_| bad(name, n + 2))?;
    // Half a position is no position.
    Ok(match (lat, lon) {
        (Some(a), Some(o)) => (Some(a), Some(o)),
        _ => (None, None),
    })
}

/// Read the next field with `read`, naming it in the error.
pub(super) fn field<T>(
    fs: &mut Fields<'_>,
    name: &'static str,
    read: impl FnOnce(&[u8]) -> Result<T, f::BadField>,
) -> Result<T, NmeaError> {
    let n = fs.number();
    read(fs.next_field()).map_err(|_| bad(name, n))
}

/// Satellites (0–99), HDOP, altitude (with its `M`), geoid separation (with its `M`).
#[allow(clippy::type_complexity)]
fn sats_hdop_alt_sep(
    fs: &mut Fields<'_>,
    name: &'static str,
    with_units: bool,
) -> Result<(Option<u8>, Option<f64>, Option<f64>, Option<f64>), NmeaError> {
    let sats = field(fs, name, |x| f::uint_max(x, 255))?.map(|v| v as u8);
    let hdop = field(fs, name, |x| f::f64_in(x, 0.0, 100.0))?;
    let alt = field(fs, name, |x| f::f64_in(x, -10_000.0, 100_000.0))?;
    if with_units {
        fs.next_field();
    }
    let sep = field(fs, name, |x| f::f64_in(x, -200.0, 200.0))?;
    if with_units {
        fs.next_field();
    }
    Ok((sats, hdop, alt, sep))
}

/// Age of corrections (s) and reference station id (0–4095).
fn age_station(
    fs: &mut Fields<'_>,
    name: &'static str,
) -> Result<(Option<f64>, Option<u16>), NmeaError> {
    let age = field(fs, name, |x| f::f64_in(x, 0.0, 1e6))?;
    let station = field(fs, name, |x| f::uint_max(x, 4095))?.map(|v| v as u16);
    Ok((age, station))
}

pub(super) fn gga(body: &[u8]) -> Result<Gga, NmeaError> {
    const N: &str = "GGA";
    let mut fs = Fields::new(body);
    let time_s = field(&mut fs, N, f::time_of_day)?;
    let (lat_deg, lon_deg) = lat_lon(&mut fs, N)?;
    let quality = field(&mut fs, N, |x| f::uint_max(x, 9))?.ok_or(bad(N, 6))? as u8;
    let (satellites, hdop, altitude_msl_m, geoid_separation_m) =
        sats_hdop_alt_sep(&mut fs, N, true)?;
    let (correction_age_s, station_id) = age_station(&mut fs, N)?;
    Ok(Gga {
        time_s,
        lat_deg,
        lon_deg,
        quality,
        satellites,
        hdop,
        altitude_msl_m,
        geoid_separation_m,
        correction_age_s,
        station_id,
    })
}

pub(super) fn rmc(body: &[u8]) -> Result<Rmc, NmeaError> {
    const N: &str = "RMC";
    let mut fs = Fields::new(body);
    let time_s = field(&mut fs, N, f::time_of_day)?;
    let valid = match fs.next_field() {
        b"A" => true,
        b"V" | b"" => false,
        _ => return Err(bad(N, 2)),
    };
    let (lat_deg, lon_deg) = lat_lon(&mut fs, N)?;
    let speed_knots = field(&mut fs, N, |x| f::f64_in(x, 0.0, 10_000.0))?;
    let course_deg = field(&mut fs, N, |x| f::f64_in(x, -360.0, 360.0))?;
    let date_days = field(&mut fs, N, f::date_ddmmyy)?;
    let var = field(&mut fs, N, |x| f::f64_in(x, 0.0, 180.0))?;
    let variation_deg = match (var, fs.next_field()) {
        (Some(v), b"E") => Some(v),
        (Some(v), b"W") => Some(-v),
        (None, _) => None,
        (Some(_), _) => return Err(bad(N, 11)),
    };
    let mode = field(&mut fs, N, f::letter)?;
    Ok(Rmc {
        time_s,
        valid,
        lat_deg,
        lon_deg,
        speed_knots,
        course_deg,
        date_days,
        variation_deg,
        mode,
    })
}

pub(super) fn vtg(body: &[u8]) -> Result<Vtg, NmeaError> {
    const N: &str = "VTG";
    let mut fs = Fields::new(body);
    let course = |x: &[u8]| f::f64_in(x, -360.0, 360.0);
    let speed = |x: &[u8]| f::f64_in(x, 0.0, 20_000.0);
    let course_true_deg = field(&mut fs, N, course)?;
    let unit_t = fs.next_field();
    if !matches!(unit_t, b"T" | b"") {
        // The pre-2.0 form without unit letters: course true, magnetic, knots, km/h.
        let mut fs = Fields::new(body);
        fs.skip(1);
        let m = field(&mut fs, N, course)?;
        let kn = field(&mut fs, N, speed)?;
        let kmh = field(&mut fs, N, speed)?;
        return Ok(Vtg {
            course_true_deg,
            course_magnetic_deg: m,
            speed_knots: kn,
            speed_kmh: kmh,
            mode: None,
        });
    }
    let course_magnetic_deg = field(&mut fs, N, course)?;
    fs.next_field();
    let speed_knots = field(&mut fs, N, speed)?;
    fs.next_field();
    let speed_kmh = field(&mut fs, N, speed)?;
    fs.next_field();
    let mode = field(&mut fs, N, f::letter)?;
    Ok(Vtg {
        course_true_deg,
        course_magnetic_deg,
        speed_knots,
        speed_kmh,
        mode,
    })
}

pub(super) fn hdt(body: &[u8]) -> Result<Hdt, NmeaError> {
    const N: &str = "HDT";
    let mut fs = Fields::new(body);
    let heading_deg = field(&mut fs, N, |x| f::f64_in(x, -360.0, 360.0))?;
    match fs.next_field() {
        b"T" | b"" => Ok(Hdt { heading_deg }),
        _ => Err(bad(N, 2)),
    }
}

pub(super) fn gst(body: &[u8]) -> Result<Gst, NmeaError> {
    const N: &str = "GST";
    let mut fs = Fields::new(body);
    let sigma = |x: &[u8]| f::f64_in(x, 0.0, 1e7);
    let time_s = field(&mut fs, N, f::time_of_day)?;
    let rms_m = field(&mut fs, N, sigma)?;
    let sigma_major_m = field(&mut fs, N, sigma)?;
    let sigma_minor_m = field(&mut fs, N, sigma)?;
    field(&mut fs, N, |x| f::f64_in(x, -360.0, 360.0))?;
    let sigma_lat_m = field(&mut fs, N, sigma)?;
    let sigma_lon_m = field(&mut fs, N, sigma)?;
    let sigma_alt_m = field(&mut fs, N, sigma)?;
    Ok(Gst {
        time_s,
        rms_m,
        sigma_major_m,
        sigma_minor_m,
        sigma_lat_m,
        sigma_lon_m,
        sigma_alt_m,
    })
}

pub(super) fn gns(body: &[u8]) -> Result<Gns, NmeaError> {
    const N: &str = "GNS";
    let mut fs = Fields::new(body);
    let time_s = field(&mut fs, N, f::time_of_day)?;
    let (lat_deg, lon_deg) = lat_lon(&mut fs, N)?;
    let mode_field = fs.next_field();
    let mut modes = [0u8; 6];
    if mode_field.len() > modes.len() + 2 || !mode_field.iter().all(u8::is_ascii_uppercase) {
        return Err(bad(N, 6));
    }
    for (slot, &m) in modes.iter_mut().zip(mode_field) {
        *slot = m;
    }
    let (satellites, hdop, altitude_msl_m, geoid_separation_m) =
        sats_hdop_alt_sep(&mut fs, N, false)?;
    let (correction_age_s, station_id) = age_station(&mut fs, N)?;
    Ok(Gns {
        time_s,
        lat_deg,
        lon_deg,
        modes,
        satellites,
        hdop,
        altitude_msl_m,
        geoid_separation_m,
        correction_age_s,
        station_id,
    })
}
