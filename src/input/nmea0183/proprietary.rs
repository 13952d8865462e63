//! Proprietary sentences autosteer receivers send.
//!
//! `$PANDA` and `$PAOGI` are AgOpenGPS's, built by its AiO boards' firmware from the receiver's
//! GGA and VTG plus an IMU (PANDA) or a u-blox moving-base heading (PAOGI); layout from
//! AgOpenGPS's `AgIO` (`NMEA.Designer.cs`, `ParsePANDA`/`ParseOGI`) and the boards' firmware
//! (`zHandlers.ino`, `BuildNmea`): fields 1–10 are GGA's time, position, quality, satellites,
//! HDOP, altitude and age; 11 speed in knots; 12–15 heading, roll, pitch, yaw rate. In PANDA
//! those four come from the IMU as integers in tenths of a degree (heading 65535 = no IMU); in
//! PAOGI heading and roll are the dual-antenna values in degrees (pitch and yaw rate empty).
//!
//! `$KSXT` is Unicore's (UM98x) and ComNav's combined position/heading sentence; layout from
//! AgOpenGPS's UDP simulator notes and ArduPilot's NMEA driver: 1 date-time
//! `YYYYMMDDhhmmss.ss` (UTC), 2 longitude and 3 latitude in decimal degrees, 4 height,
//! 5 heading of the antenna baseline, 6 its pitch, 7 course over ground, 8 speed km/h, 9 roll,
//! 10 position status (0 invalid, 1 single, 2 RTK float, 3 RTK fixed), 11 heading status (same
//! codes), 12–13 satellites (heading, position), 14–19 ENU offsets and velocities, 20 age of
//! corrections, 21 base satellites.

use super::fields::{self as f, Fields};
use super::standard::{field, lat_lon};
use super::{bad, NmeaError};

/// `$PANDA` / `$PAOGI`, scaled to degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AgOpenGps {
    pub time_s: Option<f64>,
    pub lat_deg: Option<f64>,
    pub lon_deg: Option<f64>,
    /// GGA quality indicator.
    pub quality: u8,
    pub satellites: Option<u8>,
    pub hdop: Option<f64>,
    /// Above mean sea level, m.
    pub altitude_msl_m: Option<f64>,
    pub correction_age_s: Option<f64>,
    pub speed_knots: Option<f64>,
    /// Degrees clockwise from North: the IMU's yaw (PANDA; its zero is wherever the IMU
    /// started unless it has a magnetometer) or the dual-antenna heading (PAOGI).
    pub heading_deg: Option<f64>,
    /// Degrees, positive with the right side down.
    pub roll_deg: Option<f64>,
    /// Degrees, positive nose up.
    pub pitch_deg: Option<f64>,
    pub yaw_rate_deg_s: Option<f64>,
}

/// PANDA's IMU heading when the board has no IMU.
const NO_IMU: f64 = 65535.0;

pub(super) fn agopengps(body: &[u8], name: &'static str) -> Result<AgOpenGps, NmeaError> {
    let mut fs = Fields::new(body);
    let time_s = field(&mut fs, name, f::time_of_day)?;
    let (lat_deg, lon_deg) = lat_lon(&mut fs, name)?;
    let quality = field(&mut fs, name, |x| f::uint_max(x, 9))?.ok_or(bad(name, 6))? as u8;
    let satellites = field(&mut fs, name, |x| f::uint_max(x, 255))?.map(|v| v as u8);
    let hdop = field(&mut fs, name, |x| f::f64_in(x, 0.0, 100.0))?;
    let altitude_msl_m = field(&mut fs, name, |x| f::f64_in(x, -10_000.0, 100_000.0))?;
    let correction_age_s = field(&mut fs, name, |x| f::f64_in(x, 0.0, 1e6))?;
    let speed_knots = field(&mut fs, name, |x| f::f64_in(x, -10_000.0, 10_000.0))?;
    let num = |x: &[u8]| f::f64_in(x, -1e6, 1e6);
    let heading = field(&mut fs, name, num)?;
    let roll = field(&mut fs, name, num)?;
    let pitch = field(&mut fs, name, num)?;
    let yaw_rate = field(&mut fs, name, num)?;
    let panda = name == "PANDA";
    let (heading_deg, roll_deg, pitch_deg, yaw_rate_deg_s) = if panda {
        if heading == Some(NO_IMU) {
            (None, None, None, None)
        } else {
            let tenth = |v: Option<f64>| v.map(|x| x / 10.0);
            (tenth(heading), tenth(roll), tenth(pitch), tenth(yaw_rate))
        }
    } else {
        (heading, roll, pitch, yaw_rate)
    };
    let angle_ok = |v: Option<f64>, lim: f64| v.is_none_or(|x| x.abs() <= lim);
    if !angle_ok(heading_deg, 360.0) {
        return Err(bad(name, 12));
    }
    if !angle_ok(roll_deg, 90.0) {
        return Err(bad(name, 13));
    }
    if !angle_ok(pitch_deg, 90.0) {
        return Err(bad(name, 14));
    }
    Ok(AgOpenGps {
        time_s,
        lat_deg,
        lon_deg,
        quality,
        satellites,
        hdop,
        altitude_msl_m,
        correction_age_s,
        // PAOGI's doc allows a signed speed (reversing); the magnitude is what GNSS measures.
        speed_knots: speed_knots.map(f64::abs),
        heading_deg,
        roll_deg,
        pitch_deg,
        yaw_rate_deg_s,
    })
}

/// `$KSXT`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ksxt {
    /// UTC, seconds since 1970-01-01.
    pub utc_s: Option<f64>,
    pub lat_deg: Option<f64>,
    pub lon_deg: Option<f64>,
    pub height_m: Option<f64>,
    /// Heading of the antenna baseline, degrees clockwise from true North.
    pub heading_deg: Option<f64>,
    /// Pitch of the antenna baseline, degrees.
    pub baseline_pitch_deg: Option<f64>,
    /// Course over ground, degrees clockwise from true North.
    pub course_deg: Option<f64>,
    pub speed_kmh: Option<f64>,
    /// Roll (the baseline's tilt about its own axis), degrees.
    pub roll_deg: Option<f64>,
    /// 0 invalid, 1 single point, 2 RTK float, 3 RTK fixed.
    pub position_status: u8,
    /// Same codes, for the heading.
    pub heading_status: u8,
    pub satellites: Option<u8>,
    pub correction_age_s: Option<f64>,
}

/// `YYYYMMDDhhmmss.ss` → seconds since 1970-01-01.
fn date_time(x: &[u8]) -> Result<Option<f64>, f::BadField> {
    if x.is_empty() {
        return Ok(None);
    }
    let year = x.get(..4).ok_or(f::BadField)?;
    let year = f::u32_opt(year)?.ok_or(f::BadField)? as i32;
    let md = x.get(4..8).ok_or(f::BadField)?;
    let month = f::u32_opt(md.get(..2).unwrap_or(&[]))?.ok_or(f::BadField)?;
    let day = f::u32_opt(md.get(2..).unwrap_or(&[]))?.ok_or(f::BadField)?;
    let days = f::checked_days(year, month, day)?;
    let tod = f::time_of_day(x.get(8..).unwrap_or(&[]))?.ok_or(f::BadField)?;
    Ok(Some(days as f64 * 86_400.0 + tod))
}

pub(super) fn ksxt(body: &[u8]) -> Result<Ksxt, NmeaError> {
    const N: &str = "KSXT";
    let mut fs = Fields::new(body);
    let utc_s = field(&mut fs, N, date_time)?;
    let lon = field(&mut fs, N, |x| f::f64_in(x, -180.0, 180.0))?;
    let lat = field(&mut fs, N, |x| f::f64_in(x, -90.0, 90.0))?;
    let height_m = field(&mut fs, N, |x| f::f64_in(x, -10_000.0, 100_000.0))?;
    let angle = |x: &[u8]| f::f64_in(x, -360.0, 360.0);
    let tilt = |x: &[u8]| f::f64_in(x, -90.0, 90.0);
    let heading_deg = field(&mut fs, N, angle)?;
    let baseline_pitch_deg = field(&mut fs, N, tilt)?;
    let course_deg = field(&mut fs, N, angle)?;
    let speed_kmh = field(&mut fs, N, |x| f::f64_in(x, 0.0, 20_000.0))?;
    let roll_deg = field(&mut fs, N, tilt)?;
    let status = |x: &[u8]| f::uint_max(x, 3);
    let position_status = field(&mut fs, N, status)?.unwrap_or(0) as u8;
    let heading_status = field(&mut fs, N, status)?.unwrap_or(0) as u8;
    field(&mut fs, N, |x| f::uint_max(x, 255))?;
    let satellites = field(&mut fs, N, |x| f::uint_max(x, 255))?.map(|v| v as u8);
    fs.skip(6);
    let correction_age_s = field(&mut fs, N, |x| f::f64_in(x, 0.0, 1e6))?;
    let (lat_deg, lon_deg) = match (lat, lon) {
        (Some(a), Some(o)) => (Some(a), Some(o)),
        _ => (None, None),
    };
    Ok(Ksxt {
        utc_s,
        lat_deg,
        lon_deg,
        height_m,
        heading_deg,
        baseline_pitch_deg,
        course_deg,
        speed_kmh,
        roll_deg,
        position_status,
        heading_status,
        satellites,
        correction_age_s,
    })
}
