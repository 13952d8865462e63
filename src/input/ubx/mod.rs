//! u-blox UBX messages agsteer uses: NAV-PVT (position, velocity, time, fix and carrier
//! solution), NAV-HPPOSLLH (the same position to 0.1 mm) and NAV-RELPOSNED (moving-base
//! heading of a dual-receiver set-up such as two ZED-F9Ps).
//!
//! Layouts from the u-blox interface descriptions (u-blox 8/M8 protocol 15–23.01 for
//! RELPOSNED version 0; ZED-F9P HPG 1.13/1.32 interface description for RELPOSNED version 1,
//! NAV-PVT's `flags3.lastCorrectionAge` and NAV-HPPOSLLH's `flags.invalidLlh`). All fields are
//! little-endian. A frame is `B5 62`, class, id, payload length (u16), payload, and the two
//! bytes of an 8-bit Fletcher checksum over class, id, length and payload ([`fletcher8`]).
//!
//! [`decode`] is pure, never allocates and never panics: a payload shorter than its message's
//! fixed part is an error, not an index out of bounds.
//!
//! Why not the `ublox` crate (v0.10, evaluated): decoding three fixed-layout messages is a
//! hundred lines here, whereas the crate brings a proc-macro derive, `bitflags` and `chrono`,
//! and needs Rust 1.88 (this crate declares 1.85); its stream parser takes any `0xD3` as the
//! start of an RTCM frame without checking the frame's CRC, so a stray byte in line noise can
//! swallow up to a kilobyte of good sentences. The framer in [`crate::io::framer`] checks the
//! RTCM CRC-24Q before it believes a frame.

pub mod convert;
#[cfg(test)]
mod tests;

/// Class of the navigation messages.
pub const CLASS_NAV: u8 = 0x01;
pub const ID_NAV_PVT: u8 = 0x07;
pub const ID_NAV_HPPOSLLH: u8 = 0x14;
pub const ID_NAV_RELPOSNED: u8 = 0x3C;

/// Why a UBX message was not decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum UbxError {
    #[error("UBX {class:02X}-{id:02X}: payload of {len} bytes, at least {min} needed")]
    Short {
        class: u8,
        id: u8,
        len: usize,
        min: usize,
    },
    #[error("UBX {class:02X}-{id:02X}: version {version} not known")]
    Version { class: u8, id: u8, version: u8 },
    #[error("UBX message not used by agsteer")]
    Unsupported,
}

/// The UBX 8-bit Fletcher checksum (CK_A, CK_B) of `bytes` (class, id, length, payload).
pub fn fletcher8(bytes: &[u8]) -> (u8, u8) {
    bytes.iter().fold((0u8, 0u8), |(a, b), &x| {
        let a = a.wrapping_add(x);
        (a, b.wrapping_add(a))
    })
}

/// Little-endian readers over a payload whose length was checked by the caller.
struct Le<'a>(&'a [u8]);

impl Le<'_> {
    fn bytes<const N: usize>(&self, at: usize) -> [u8; N] {
        let mut b = [0u8; N];
        if let Some(s) = self.0.get(at..at + N) {
            b.copy_from_slice(s);
        }
        b
    }
    fn u8(&self, at: usize) -> u8 {
        self.0.get(at).copied().unwrap_or(0)
    }
    fn i8(&self, at: usize) -> i8 {
        self.u8(at) as i8
    }
    fn u16(&self, at: usize) -> u16 {
        u16::from_le_bytes(self.bytes(at))
    }
    fn u32(&self, at: usize) -> u32 {
        u32::from_le_bytes(self.bytes(at))
    }
    fn i32(&self, at: usize) -> i32 {
        i32::from_le_bytes(self.bytes(at))
    }
}

/// NAV-PVT, scaled to SI units and degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavPvt {
    /// GPS time of week, ms.
    pub itow_ms: u32,
    /// UTC (s since 1970-01-01) when the receiver marks date and time valid.
    pub utc_s: Option<f64>,
    /// 0 no fix, 1 dead reckoning only, 2 2-D, 3 3-D, 4 GNSS + dead reckoning, 5 time only.
    pub fix_type: u8,
    /// A valid fix within the receiver's accuracy masks (`flags.gnssFixOK`).
    pub gnss_fix_ok: bool,
    pub diff_soln: bool,
    /// Carrier-phase solution: 0 none, 1 float, 2 fixed.
    pub carr_soln: u8,
    pub satellites: u8,
    pub lat_deg: f64,
    pub lon_deg: f64,
    /// Height above the ellipsoid, m.
    pub height_m: f64,
    /// Horizontal accuracy estimate, m.
    pub h_acc_m: f64,
    /// Ground speed, m/s.
    pub ground_speed_mps: f64,
    /// Heading of motion, degrees clockwise from North.
    pub head_motion_deg: f64,
    pub pdop: f64,
    /// `flags3.invalidLlh`: latitude, longitude and height are not valid.
    pub invalid_llh: bool,
    /// Age of the last correction, s: the upper bound of the receiver's age class
    /// (`flags3.lastCorrectionAge`), `None` when not available.
    pub correction_age_s: Option<f64>,
    /// Vehicle heading (degrees clockwise from North) when the receiver marks it valid
    /// (dead-reckoning products).
    pub head_vehicle_deg: Option<f64>,
}

/// NAV-HPPOSLLH, high-precision position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavHpPosLlh {
    pub itow_ms: u32,
    pub invalid_llh: bool,
    pub lat_deg: f64,
    pub lon_deg: f64,
    /// Height above the ellipsoid, m.
    pub height_m: f64,
    /// Horizontal accuracy estimate, m.
    pub h_acc_m: f64,
}

/// NAV-RELPOSNED: the rover antenna relative to the (moving) base antenna.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavRelPosNed {
    pub version: u8,
    pub itow_ms: u32,
    /// Baseline north, east, down components, m.
    pub north_m: f64,
    pub east_m: f64,
    pub down_m: f64,
    /// Heading of the baseline (base → rover), degrees clockwise from North: the message's
    /// own (version 1, when `relPosHeadingValid`) or computed from north and east (version 0).
    pub heading_deg: Option<f64>,
    pub gnss_fix_ok: bool,
    pub rel_pos_valid: bool,
    /// Carrier-phase solution: 0 none, 1 float, 2 fixed.
    pub carr_soln: u8,
}

/// A decoded message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum UbxMessage {
    NavPvt(NavPvt),
    NavHpPosLlh(NavHpPosLlh),
    NavRelPosNed(NavRelPosNed),
}

/// Upper bound of NAV-PVT's `lastCorrectionAge` classes, s (index 0: not available; 12 and
/// above: 120 s or more).
const CORRECTION_AGE_S: [f64; 12] = [
    0.0, 1.0, 2.0, 5.0, 10.0, 15.0, 20.0, 30.0, 45.0, 60.0, 90.0, 120.0,
];

fn need(class: u8, id: u8, p: &[u8], min: usize) -> Result<(), UbxError> {
    if p.len() < min {
        Err(UbxError::Short {
            class,
            id,
            len: p.len(),
            min,
        })
    } else {
        Ok(())
    }
}

/// UTC of NAV-PVT's date and time fields, when valid and in range.
fn pvt_utc(l: &Le<'_>) -> Option<f64> {
    let valid = l.u8(11);
    if valid & 0x03 != 0x03 {
        return None;
    }
    let (year, month, day) = (l.u16(4), l.u8(6), l.u8(7));
    let (hour, min, sec) = (l.u8(8), l.u8(9), l.u8(10));
    if hour > 23 || min > 59 || sec > 60 {
        return None;
    }
    let days = crate::input::nmea0183::fields::checked_days(
        i32::from(year),
        u32::from(month),
        u32::from(day),
    )
    .ok()?;
    let nano = f64::from(l.i32(16)) / 1e9;
    Some(
        days as f64 * 86_400.0
            + f64::from(u32::from(hour) * 3600 + u32::from(min) * 60 + u32::from(sec))
            + nano,
    )
}

fn nav_pvt(p: &[u8]) -> Result<NavPvt, UbxError> {
    // 84 bytes before protocol 15 (no headVeh), 92 after.
    need(CLASS_NAV, ID_NAV_PVT, p, 84)?;
    let l = Le(p);
    let flags = l.u8(21);
    let flags3 = l.u8(78);
    let age_class = usize::from((flags3 >> 1) & 0x0F);
    let head_veh_valid = p.len() >= 92 && flags & 0x20 != 0;
    Ok(NavPvt {
        itow_ms: l.u32(0),
        utc_s: pvt_utc(&l),
        fix_type: l.u8(20),
        gnss_fix_ok: flags & 0x01 != 0,
        diff_soln: flags & 0x02 != 0,
        carr_soln: flags >> 6,
        satellites: l.u8(23),
        lon_deg: f64::from(l.i32(24)) / 1e7,
        lat_deg: f64::from(l.i32(28)) / 1e7,
        height_m: f64::from(l.i32(32)) / 1e3,
        h_acc_m: f64::from(l.u32(40)) / 1e3,
        ground_speed_mps: f64::from(l.i32(60)) / 1e3,
        head_motion_deg: f64::from(l.i32(64)) / 1e5,
        pdop: f64::from(l.u16(76)) / 100.0,
        invalid_llh: flags3 & 0x01 != 0,
        correction_age_s: match age_class {
            0 => None,
            c => Some(CORRECTION_AGE_S.get(c).copied().unwrap_or(120.0)),
        },
        head_vehicle_deg: head_veh_valid.then(|| f64::from(l.i32(84)) / 1e5),
    })
}

fn nav_hpposllh(p: &[u8]) -> Result<NavHpPosLlh, UbxError> {
    need(CLASS_NAV, ID_NAV_HPPOSLLH, p, 36)?;
    let l = Le(p);
    let deg = |at: usize, hp: usize| (f64::from(l.i32(at)) * 100.0 + f64::from(l.i8(hp))) / 1e9;
    Ok(NavHpPosLlh {
        itow_ms: l.u32(4),
        invalid_llh: l.u8(3) & 0x01 != 0,
        lon_deg: deg(8, 24),
        lat_deg: deg(12, 25),
        height_m: (f64::from(l.i32(16)) * 10.0 + f64::from(l.i8(26))) / 1e4,
        h_acc_m: f64::from(l.u32(28)) / 1e4,
    })
}

fn nav_relposned(p: &[u8]) -> Result<NavRelPosNed, UbxError> {
    const ID: u8 = ID_NAV_RELPOSNED;
    need(CLASS_NAV, ID, p, 40)?;
    let l = Le(p);
    let version = l.u8(0);
    // Component in cm plus its high-precision part in 0.1 mm → m.
    let comp = |cm: usize, hp: usize| (f64::from(l.i32(cm)) * 100.0 + f64::from(l.i8(hp))) / 1e4;
    let (north_m, east_m, down_m, flags, heading) = match version {
        0 => {
            let (n, e) = (comp(8, 20), comp(12, 21));
            let heading = n.hypot(e) > 0.0;
            (
                n,
                e,
                comp(16, 22),
                l.u32(36),
                heading.then(|| e.atan2(n).to_degrees().rem_euclid(360.0)),
            )
        }
        1 => {
            need(CLASS_NAV, ID, p, 64)?;
            let flags = l.u32(60);
            let valid = flags & 0x100 != 0;
            let heading = valid.then(|| f64::from(l.i32(24)) / 1e5);
            (comp(8, 32), comp(12, 33), comp(16, 34), flags, heading)
        }
        v => {
            return Err(UbxError::Version {
                class: CLASS_NAV,
                id: ID,
                version: v,
            })
        }
    };
    Ok(NavRelPosNed {
        version,
        itow_ms: l.u32(4),
        north_m,
        east_m,
        down_m,
        heading_deg: heading,
        gnss_fix_ok: flags & 0x01 != 0,
        rel_pos_valid: flags & 0x04 != 0,
        carr_soln: ((flags >> 3) & 0x03) as u8,
    })
}

/// Decode a checked frame's payload.
pub fn decode(class: u8, id: u8, payload: &[u8]) -> Result<UbxMessage, UbxError> {
    match (class, id) {
        (CLASS_NAV, ID_NAV_PVT) => nav_pvt(payload).map(UbxMessage::NavPvt),
        (CLASS_NAV, ID_NAV_HPPOSLLH) => nav_hpposllh(payload).map(UbxMessage::NavHpPosLlh),
        (CLASS_NAV, ID_NAV_RELPOSNED) => nav_relposned(payload).map(UbxMessage::NavRelPosNed),
        _ => Err(UbxError::Unsupported),
    }
}

/// A whole frame (sync, header, payload, checksum) for `class`/`id`/`payload`: what a
/// receiver sends, for the simulator and the tests. Allocates: not for the hot path.
pub fn frame(class: u8, id: u8, payload: &[u8]) -> Vec<u8> {
    let mut f = Vec::with_capacity(payload.len() + 8);
    f.extend_from_slice(&[0xB5, 0x62, class, id]);
    f.extend_from_slice(&(payload.len() as u16).to_le_bytes());
    f.extend_from_slice(payload);
    let (a, b) = fletcher8(f.get(2..).unwrap_or(&[]));
    f.extend_from_slice(&[a, b]);
    f
}

/// Encoders of the three messages (the simulator speaks UBX with them; the tests build
/// frames with them). Inputs in the messages' units.
pub mod encode {
    /// NAV-PVT (92 bytes) from its main fields.
    pub fn nav_pvt(p: &super::NavPvt) -> [u8; 92] {
        let mut b = [0u8; 92];
        let mut put = |at: usize, v: &[u8]| {
            if let Some(s) = b.get_mut(at..at + v.len()) {
                s.copy_from_slice(v);
            }
        };
        put(0, &p.itow_ms.to_le_bytes());
        if let Some(utc) = p.utc_s {
            let days = (utc / 86_400.0).floor();
            let tod = utc - days * 86_400.0;
            let (y, m, d) = civil_from_days(days as i64);
            put(4, &(y as u16).to_le_bytes());
            put(6, &[m as u8, d as u8]);
            let s = tod.floor();
            put(
                8,
                &[
                    (s / 3600.0) as u8,
                    ((s % 3600.0) / 60.0) as u8,
                    (s % 60.0) as u8,
                    0x07,
                ],
            );
            put(16, &(((tod - s) * 1e9).round() as i32).to_le_bytes());
        }
        let flags = u8::from(p.gnss_fix_ok)
            | u8::from(p.diff_soln) << 1
            | u8::from(p.head_vehicle_deg.is_some()) << 5
            | (p.carr_soln & 0x03) << 6;
        put(20, &[p.fix_type, flags, 0, p.satellites]);
        let e7 = |v: f64| ((v * 1e7).round() as i32).to_le_bytes();
        put(24, &e7(p.lon_deg));
        put(28, &e7(p.lat_deg));
        put(32, &(((p.height_m * 1e3).round()) as i32).to_le_bytes());
        put(40, &(((p.h_acc_m * 1e3).round()) as u32).to_le_bytes());
        put(
            60,
            &(((p.ground_speed_mps * 1e3).round()) as i32).to_le_bytes(),
        );
        put(
            64,
            &(((p.head_motion_deg * 1e5).round()) as i32).to_le_bytes(),
        );
        put(76, &(((p.pdop * 100.0).round()) as u16).to_le_bytes());
        let age_class = p.correction_age_s.map_or(0u8, |a| {
            super::CORRECTION_AGE_S
                .iter()
                .position(|&ub| a <= ub)
                .map_or(12, |c| c.max(1) as u8)
        });
        put(78, &[u8::from(p.invalid_llh) | age_class << 1]);
        if let Some(h) = p.head_vehicle_deg {
            put(84, &(((h * 1e5).round()) as i32).to_le_bytes());
        }
        b
    }

    /// NAV-RELPOSNED version 1 (64 bytes).
    pub fn nav_relposned(r: &super::NavRelPosNed) -> [u8; 64] {
        let mut b = [0u8; 64];
        let mut put = |at: usize, v: &[u8]| {
            if let Some(s) = b.get_mut(at..at + v.len()) {
                s.copy_from_slice(v);
            }
        };
        put(0, &[1]);
        put(4, &r.itow_ms.to_le_bytes());
        let mut comp = |m: f64, cm_at: usize, hp_at: usize| {
            let tenth_mm = (m * 1e4).round() as i64;
            let cm = tenth_mm / 100;
            put(cm_at, &(cm as i32).to_le_bytes());
            put(hp_at, &[((tenth_mm - cm * 100) as i8) as u8]);
        };
        comp(r.north_m, 8, 32);
        comp(r.east_m, 12, 33);
        comp(r.down_m, 16, 34);
        let len = (r.north_m.powi(2) + r.east_m.powi(2) + r.down_m.powi(2)).sqrt();
        put(20, &(((len * 100.0).round()) as i32).to_le_bytes());
        if let Some(h) = r.heading_deg {
            put(24, &(((h * 1e5).round()) as i32).to_le_bytes());
        }
        let flags = u32::from(r.gnss_fix_ok)
            | 1 << 1
            | u32::from(r.rel_pos_valid) << 2
            | u32::from(r.carr_soln & 0x03) << 3
            | 1 << 5
            | u32::from(r.heading_deg.is_some()) << 8;
        put(60, &flags.to_le_bytes());
        b
    }

    /// NAV-HPPOSLLH (36 bytes).
    pub fn nav_hpposllh(h: &super::NavHpPosLlh) -> [u8; 36] {
        let mut b = [0u8; 36];
        let mut put = |at: usize, v: &[u8]| {
            if let Some(s) = b.get_mut(at..at + v.len()) {
                s.copy_from_slice(v);
            }
        };
        put(3, &[u8::from(h.invalid_llh)]);
        put(4, &h.itow_ms.to_le_bytes());
        let mut deg = |v: f64, at: usize, hp_at: usize| {
            let e9 = (v * 1e9).round() as i64;
            let e7 = e9.div_euclid(100);
            let hp = e9 - e7 * 100;
            put(at, &(e7 as i32).to_le_bytes());
            put(hp_at, &[(hp as i8) as u8]);
        };
        deg(h.lon_deg, 8, 24);
        deg(h.lat_deg, 12, 25);
        let tenth_mm = (h.height_m * 1e4).round() as i64;
        let mm = tenth_mm.div_euclid(10);
        put(16, &(mm as i32).to_le_bytes());
        put(26, &[((tenth_mm - mm * 10) as i8) as u8]);
        put(28, &(((h.h_acc_m * 1e4).round()) as u32).to_le_bytes());
        b
    }

    /// Civil date of a day number (days since 1970-01-01), Hinnant's algorithm.
    pub fn civil_from_days(z: i64) -> (i64, u32, u32) {
        let z = z + 719_468;
        let era = z.div_euclid(146_097);
        let doe = z - era * 146_097;
        let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
        let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
        let mp = (5 * doy + 2) / 153;
        let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
        let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
        (yoe + era * 400 + i64::from(m <= 2), m, d)
    }
}
