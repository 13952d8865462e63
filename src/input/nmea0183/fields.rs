//! Field-level decoding of NMEA 0183 sentences: comma-separated ASCII fields, read in place
//! (no allocation), each number checked (finite, in its range).
//!
//! Formats follow NMEA 0183 as gpsd documents it ("NMEA 0183 revealed"): latitude `ddmm.mmmm`
//! with `N`/`S`, longitude `dddmm.mmmm` with `E`/`W`, time `hhmmss.sss` (UTC), date `ddmmyy`.

/// Why a field could not be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BadField;

/// The fields of one sentence body (between the address field and `*`), read left to right.
pub struct Fields<'a> {
    rest: Option<&'a [u8]>,
    /// 1-based number of the next field (field 0 is the address, `GPGGA`).
    next: u8,
}

impl<'a> Fields<'a> {
    /// `body` is everything after the address field's comma, up to (not including) `*`.
    pub fn new(body: &'a [u8]) -> Self {
        Fields {
            rest: Some(body),
            next: 1,
        }
    }

    /// Number of the field the next [`Fields::next_field`] returns (1-based, as the NMEA
    /// references count).
    pub fn number(&self) -> u8 {
        self.next
    }

    /// The next field; an empty slice once the sentence has no more fields (a missing trailing
    /// field reads as an empty, i.e. null, one).
    pub fn next_field(&mut self) -> &'a [u8] {
        self.next = self.next.saturating_add(1);
        match self.rest {
            None => &[],
            Some(r) => match r.iter().position(|&b| b == b',') {
                Some(i) => {
                    self.rest = r.get(i + 1..);
                    r.get(..i).unwrap_or(&[])
                }
                None => {
                    self.rest = None;
                    r
                }
            },
        }
    }

    /// Skip `n` fields.
    pub fn skip(&mut self, n: usize) {
        for _ in 0..n {
            self.next_field();
        }
    }

    /// Whether the sentence has fields left.
    pub fn has_more(&self) -> bool {
        self.rest.is_some()
    }
}

/// Exact powers of ten (10^22 is the largest exactly representable in an f64).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// A decimal number; empty → `None`. Plain decimals (`-12.345`) take a fast path: the digits
/// as an integer below 2^53 divided by an exact power of ten, which IEEE division rounds
/// correctly (Clinger's fast path), so the result is the same as `f64::from_str`'s. Anything
/// else (exponents, 16+ significant digits) goes through `f64::from_str`. Non-finite values
/// (`inf`, `NaN`) are rejected.
pub fn f64_opt(f: &[u8]) -> Result<Option<f64>, BadField> {
    let (neg, digits) = match f {
        [] => return Ok(None),
        [b'-', rest @ ..] => (true, rest),
        [b'+', rest @ ..] => (false, rest),
        _ => (false, f),
    };
    let mut mantissa: u64 = 0;
    let mut frac_digits = 0usize;
    let mut any_digit = false;
    let mut point = false;
    for &b in digits {
        match b {
            b'0'..=b'9' => {
                any_digit = true;
                mantissa = match mantissa
                    .checked_mul(10)
                    .and_then(|m| m.checked_add(u64::from(b - b'0')))
                {
                    Some(m) if m < 1 << 53 => m,
                    _ => return slow_f64(f),
                };
                frac_digits += usize::from(point);
            }
            b'.' if !point => point = true,
            b'e' | b'E' => return slow_f64(f),
            _ => return Err(BadField),
        }
    }
    if !any_digit {
        return Err(BadField);
    }
    let Some(&p) = POW10.get(frac_digits) else {
        return slow_f64(f);
    };
    let v = mantissa as f64 / p;
    Ok(Some(if neg { -v } else { v }))
}

/// `f64::from_str` for what the fast path does not take (only the characters of a decimal
/// number: `from_str` would also take "inf" and "NaN").
fn slow_f64(f: &[u8]) -> Result<Option<f64>, BadField> {
    if !f
        .iter()
        .all(|&b| b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E'))
    {
        return Err(BadField);
    }
    let s = std::str::from_utf8(f).map_err(|_| BadField)?;
    let v: f64 = s.parse().map_err(|_| BadField)?;
    if v.is_finite() {
        Ok(Some(v))
    } else {
        Err(BadField)
    }
}

/// A decimal number within `[lo, hi]`; empty → `None`.
pub fn f64_in(f: &[u8], lo: f64, hi: f64) -> Result<Option<f64>, BadField> {
    match f64_opt(f)? {
        Some(v) if (lo..=hi).contains(&v) => Ok(Some(v)),
        Some(_) => Err(BadField),
        None => Ok(None),
    }
}

/// An unsigned integer of at most 9 digits; empty → `None`.
pub fn u32_opt(f: &[u8]) -> Result<Option<u32>, BadField> {
    if f.is_empty() {
        return Ok(None);
    }
    if f.len() > 9 || !f.iter().all(u8::is_ascii_digit) {
        return Err(BadField);
    }
    Ok(Some(
        f.iter().fold(0u32, |a, &d| a * 10 + u32::from(d - b'0')),
    ))
}

/// An unsigned integer no greater than `max`; empty → `None`. A decimal fraction of zero
/// (`"08.0"`, some receivers' satellite count) is accepted.
pub fn uint_max(f: &[u8], max: u32) -> Result<Option<u32>, BadField> {
    let digits = match f.iter().position(|&b| b == b'.') {
        Some(i) => {
            let (int, frac) = f.split_at(i);
            if !frac.iter().skip(1).all(|&b| b == b'0') {
                return Err(BadField);
            }
            int
        }
        None => f,
    };
    match u32_opt(digits)? {
        Some(v) if v <= max => Ok(Some(v)),
        Some(_) => Err(BadField),
        None => Ok(None),
    }
}

fn digits2(f: &[u8], at: usize) -> Result<u32, BadField> {
    match (f.get(at), f.get(at + 1)) {
        (Some(a), Some(b)) if a.is_ascii_digit() && b.is_ascii_digit() => {
            Ok(u32::from(a - b'0') * 10 + u32::from(b - b'0'))
        }
        _ => Err(BadField),
    }
}

/// UTC time of day `hhmmss[.sss]` → seconds since midnight; empty → `None`.
pub fn time_of_day(f: &[u8]) -> Result<Option<f64>, BadField> {
    if f.is_empty() {
        return Ok(None);
    }
    let h = digits2(f, 0)?;
    let m = digits2(f, 2)?;
    let s = f64_in(f.get(4..).unwrap_or(&[]), 0.0, 61.0)?.ok_or(BadField)?;
    if h > 23
        || m > 59
        || f.get(4..6)
            .is_none_or(|d| !d.iter().all(u8::is_ascii_digit))
    {
        return Err(BadField);
    }
    Ok(Some(f64::from(h * 3600 + m * 60) + s))
}

/// Days since 1970-01-01 of a proleptic Gregorian date (the civil-from-days inverse in
/// Howard Hinnant's "chrono-compatible low-level date algorithms").
pub fn days_from_civil(year: i32, month: u32, day: u32) -> i64 {
    let y = i64::from(year) - i64::from(month <= 2);
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let m = i64::from(month);
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + i64::from(day) - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

fn days_in_month(year: i32, month: u32) -> u32 {
    match month {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        _ if (year % 4 == 0 && year % 100 != 0) || year % 400 == 0 => 29,
        _ => 28,
    }
}

/// A checked calendar date → days since 1970-01-01.
pub fn checked_days(year: i32, month: u32, day: u32) -> Result<i64, BadField> {
    if !(1..=12).contains(&month) || day == 0 || day > days_in_month(year, month) {
        return Err(BadField);
    }
    Ok(days_from_civil(year, month, day))
}

/// Date `ddmmyy` → days since 1970-01-01; two-digit years are 1980–2079 (GPS time began in
/// 1980). Empty → `None`.
pub fn date_ddmmyy(f: &[u8]) -> Result<Option<i64>, BadField> {
    if f.is_empty() {
        return Ok(None);
    }
    if f.len() != 6 {
        return Err(BadField);
    }
    let d = digits2(f, 0)?;
    let m = digits2(f, 2)?;
    let y = digits2(f, 4)? as i32;
    let year = if y >= 80 { 1900 + y } else { 2000 + y };
    checked_days(year, m, d).map(Some)
}

/// Latitude or longitude `[d]ddmm.mmmm` and its hemisphere letter → signed degrees.
/// `max_deg` is 90 for latitude, 180 for longitude; `pos`/`neg` the hemisphere letters.
/// Both empty → `None`.
pub fn angle_dm(
    value: &[u8],
    hemi: &[u8],
    max_deg: f64,
    pos: u8,
    neg: u8,
) -> Result<Option<f64>, BadField> {
    if value.is_empty() && hemi.is_empty() {
        return Ok(None);
    }
    let sign = match hemi {
        [h] if *h == pos => 1.0,
        [h] if *h == neg => -1.0,
        _ => return Err(BadField),
    };
    // Degrees are the digits before the last two of the integer part.
    let int_len = value.iter().position(|&b| b == b'.').unwrap_or(value.len());
    if !(3..=5).contains(&int_len) {
        return Err(BadField);
    }
    let (deg, min) = value.split_at(int_len - 2);
    let deg = u32_opt(deg)?.ok_or(BadField)?;
    let min = f64_in(min, 0.0, 60.0)?.ok_or(BadField)?;
    if min >= 60.0 || min.is_sign_negative() || !min_is_plain(value, int_len) {
        return Err(BadField);
    }
    let v = f64::from(deg) + min / 60.0;
    if v > max_deg {
        return Err(BadField);
    }
    Ok(Some(sign * v))
}

/// The minutes part holds only digits and one point (no sign or exponent).
fn min_is_plain(value: &[u8], int_len: usize) -> bool {
    value.get(int_len.saturating_sub(2)..).is_some_and(|m| {
        m.iter().all(|&b| b.is_ascii_digit() || b == b'.')
            && m.iter().filter(|&&b| b == b'.').count() <= 1
    })
}

/// A single-letter status or mode field; empty → `None`.
pub fn letter(f: &[u8]) -> Result<Option<u8>, BadField> {
    match f {
        [] => Ok(None),
        [c] if c.is_ascii_alphabetic() => Ok(Some(*c)),
        _ => Err(BadField),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_split_and_pad() {
        let mut f = Fields::new(b"a,,bc");
        assert_eq!(f.next_field(), b"a");
        assert_eq!(f.next_field(), b"");
        assert_eq!(f.number(), 3);
        assert_eq!(f.next_field(), b"bc");
        assert!(!f.has_more());
        assert_eq!(f.next_field(), b"", "missing trailing fields read as null");
    }

    #[test]
    fn numbers() {
        assert_eq!(f64_opt(b"").unwrap(), None);
        assert_eq!(f64_opt(b"-1.5").unwrap(), Some(-1.5));
        assert!(f64_opt(b"inf").is_err());
        assert!(f64_opt(b"NaN").is_err());
        assert!(f64_opt(b"1.2.3").is_err());
        assert!(f64_opt(b"1e999").is_err(), "overflows to infinity");
        assert!(f64_opt(b".").is_err() && f64_opt(b"-").is_err() && f64_opt(b"1-2").is_err());
        assert_eq!(f64_opt(b"1.5e2").unwrap(), Some(150.0));
        assert_eq!(f64_opt(b"+.5").unwrap(), Some(0.5));
        assert_eq!(
            f64_opt(b"-0").unwrap().map(f64::is_sign_negative),
            Some(true)
        );
        // The fast path gives exactly what f64::from_str gives.
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..100_000 {
            let int: u64 = rng.gen_range(0..100_000_000);
            let frac_len = rng.gen_range(0..12);
            let frac: String = (0..frac_len)
                .map(|_| char::from(b'0' + rng.gen_range(0..10u8)))
                .collect();
            let text = if frac_len > 0 {
                format!("{int}.{frac}")
            } else {
                format!("{int}")
            };
            assert_eq!(
                f64_opt(text.as_bytes()).unwrap(),
                Some(text.parse::<f64>().unwrap()),
                "{text}"
            );
        }
        assert_eq!(
            f64_opt(b"12345678901234567.5").unwrap(),
            Some(12345678901234567.5_f64),
            "beyond 2^53: the slow path"
        );
        assert_eq!(uint_max(b"08", 99).unwrap(), Some(8));
        assert_eq!(uint_max(b"08.0", 99).unwrap(), Some(8));
        assert!(uint_max(b"8.5", 99).is_err());
        assert!(uint_max(b"100", 99).is_err());
        assert!(u32_opt(b"9999999999").is_err());
    }

    #[test]
    fn time_and_date() {
        assert_eq!(time_of_day(b"123519").unwrap(), Some(45319.0));
        assert_eq!(time_of_day(b"000000.50").unwrap(), Some(0.5));
        assert!(time_of_day(b"245959").is_err());
        assert!(time_of_day(b"12").is_err());
        assert!(time_of_day(b"1235-1").is_err());
        assert_eq!(days_from_civil(1970, 1, 1), 0);
        assert_eq!(days_from_civil(2000, 3, 1), 11017);
        assert_eq!(
            date_ddmmyy(b"230394").unwrap(),
            Some(days_from_civil(1994, 3, 23))
        );
        assert_eq!(
            date_ddmmyy(b"180320").unwrap(),
            Some(days_from_civil(2020, 3, 18))
        );
        assert!(date_ddmmyy(b"300221").is_err(), "30 February");
        assert!(date_ddmmyy(b"2902").is_err());
    }

    #[test]
    fn latitude_longitude() {
        let lat = angle_dm(b"4807.038", b"N", 90.0, b'N', b'S')
            .unwrap()
            .unwrap();
        assert!((lat - (48.0 + 7.038 / 60.0)).abs() < 1e-12);
        let lon = angle_dm(b"01131.000", b"W", 180.0, b'E', b'W')
            .unwrap()
            .unwrap();
        assert!((lon + (11.0 + 31.0 / 60.0)).abs() < 1e-12);
        assert_eq!(angle_dm(b"", b"", 90.0, b'N', b'S').unwrap(), None);
        assert!(angle_dm(b"4807.038", b"E", 90.0, b'N', b'S').is_err());
        assert!(angle_dm(b"9107.038", b"N", 90.0, b'N', b'S').is_err());
        assert!(angle_dm(b"4867.038", b"N", 90.0, b'N', b'S').is_err());
        assert!(angle_dm(b"48-7.038", b"N", 90.0, b'N', b'S').is_err());
        assert!(angle_dm(b"4807.038", b"", 90.0, b'N', b'S').is_err());
    }
}
