//! NMEA 0183 sentences as GNSS receivers for autosteer send them: GGA, RMC, VTG, HDT, GST and
//! GNS (any talker), AgOpenGPS's `$PANDA` and `$PAOGI`, and Unicore/ComNav's `$KSXT`.
//!
//! [`parse`] takes one sentence (from `$` to the end of the line, with or without `\r\n`),
//! verifies its checksum and decodes it into a [`Sentence`] in the sentence's own units
//! (degrees, knots, ...). It is pure, never allocates and never panics, whatever the bytes.
//! [`convert`] turns sentences into the seam's [`Input`](crate::input::Input) events (SI units,
//! yaw counter-clockwise from East), with the per-stream state that needs (epochs, staleness,
//! latency).
//!
//! Checksums: the standard one is the XOR of every byte between `$` and `*`, as two hex digits.
//! `$KSXT` sentences from Unicore receivers carry eight hex digits instead: the CRC-32 that
//! Unicore (like NovAtel) uses for its own logs — reflected polynomial 0xEDB88320, initial
//! value 0, no final XOR — over the same bytes (checked against a real UM982 sentence in the
//! tests).
//!
//! Why not the `nmea` crate (v0.8, evaluated for this): its GGA drops the age of corrections
//! and the reference station (fields 13–14), which the RTK gating needs; it has none of the
//! proprietary sentences (`PANDA`, `PAOGI`, `KSXT`) and rejects sentences over 102 bytes (a
//! `PAOGI` or `KSXT` is often longer); it parses `&str` (a UTF-8 pass on every line first) and
//! needs Rust 1.87 where this crate declares 1.85. The six standard sentences here are a few
//! dozen lines each on the shared field readers (`fields`).

pub mod clock;
pub mod convert;
pub mod fields;
mod proprietary;
mod standard;
#[cfg(test)]
pub(crate) mod tests;

pub use proprietary::{AgOpenGps, Ksxt};
pub use standard::{Gga, Gns, Gst, Hdt, Rmc, Vtg};

/// Longest sentence accepted, bytes from `$` to the checksum (NMEA says 82; `$KSXT` lines run
/// to ~180, and some receivers exceed the standard).
pub const MAX_SENTENCE_LEN: usize = 254;

/// Why a sentence was not decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum NmeaError {
    #[error("not a sentence (no '$' or no address field)")]
    NotASentence,
    #[error("sentence of {0} bytes is longer than {MAX_SENTENCE_LEN}")]
    TooLong(usize),
    #[error("no checksum ('*hh' missing)")]
    NoChecksum,
    #[error("checksum {found:X} but the sentence sums to {computed:X}")]
    Checksum { found: u32, computed: u32 },
    #[error("{sentence} field {field}: not a valid value")]
    Field { sentence: &'static str, field: u8 },
    #[error("sentence not used by agsteer")]
    Unsupported,
}

impl NmeaError {
    /// A transmission error (bad or missing checksum, malformed frame), as opposed to a
    /// well-formed sentence agsteer does not use or could not make sense of.
    pub fn is_checksum(&self) -> bool {
        matches!(self, NmeaError::Checksum { .. } | NmeaError::NoChecksum)
    }
}

/// A decoded sentence, in the sentence's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sentence {
    Gga(Gga),
    Rmc(Rmc),
    Vtg(Vtg),
    Hdt(Hdt),
    Gst(Gst),
    Gns(Gns),
    /// AgOpenGPS single antenna (+ IMU).
    Panda(AgOpenGps),
    /// AgOpenGPS dual antenna.
    Paogi(AgOpenGps),
    Ksxt(Ksxt),
}

impl Sentence {
    /// Short name for counters and logs (`"GGA"`, `"PANDA"`, ...).
    pub fn name(&self) -> &'static str {
        match self {
            Sentence::Gga(_) => "GGA",
            Sentence::Rmc(_) => "RMC",
            Sentence::Vtg(_) => "VTG",
            Sentence::Hdt(_) => "HDT",
            Sentence::Gst(_) => "GST",
            Sentence::Gns(_) => "GNS",
            Sentence::Panda(_) => "PANDA",
            Sentence::Paogi(_) => "PAOGI",
            Sentence::Ksxt(_) => "KSXT",
        }
    }
}

/// XOR of the bytes (the NMEA checksum of the bytes between `$` and `*`).
pub fn xor_checksum(bytes: &[u8]) -> u8 {
    bytes.iter().fold(0, |a, &b| a ^ b)
}

/// The CRC-32 of Unicore's (and NovAtel's) logs: reflected 0xEDB88320, init 0, no final XOR.
pub const UNICORE_CRC32: crc::Algorithm<u32> = crc::Algorithm {
    width: 32,
    poly: 0x04C1_1DB7,
    init: 0,
    refin: true,
    refout: true,
    xorout: 0,
    check: 0x2DFD_2D88,
    residue: 0,
};
static UNICORE: crc::Crc<u32, crc::Table<16>> =
    crc::Crc::<u32, crc::Table<16>>::new(&UNICORE_CRC32);

fn hex_value(digits: &[u8]) -> Option<u32> {
    if digits.is_empty() || digits.len() > 8 {
        return None;
    }
    digits.iter().try_fold(0u32, |a, &d| {
        let v = (d as char).to_digit(16)?;
        Some(a << 4 | v)
    })
}

/// Split a line into (address + fields between `$` and `*`) after verifying its checksum.
fn checked_body(line: &[u8]) -> Result<&[u8], NmeaError> {
    let line = line.trim_ascii_end();
    if line.len() > MAX_SENTENCE_LEN + 1 {
        return Err(NmeaError::TooLong(line.len()));
    }
    let Some(rest) = line.strip_prefix(b"$") else {
        return Err(NmeaError::NotASentence);
    };
    let star = rest
        .iter()
        .rposition(|&b| b == b'*')
        .ok_or(NmeaError::NoChecksum)?;
    let (body, sum) = rest.split_at(star);
    let digits = sum.get(1..).unwrap_or(&[]);
    let found = hex_value(digits).ok_or(NmeaError::NoChecksum)?;
    let computed = match digits.len() {
        2 => u32::from(xor_checksum(body)),
        8 => UNICORE.checksum(body),
        _ => return Err(NmeaError::NoChecksum),
    };
    if found != computed {
        return Err(NmeaError::Checksum { found, computed });
    }
    Ok(body)
}

/// Verify and decode one sentence.
pub fn parse(line: &[u8]) -> Result<Sentence, NmeaError> {
    let body = checked_body(line)?;
    let comma = body
        .iter()
        .position(|&b| b == b',')
        .ok_or(NmeaError::NotASentence)?;
    let (address, fields) = body.split_at(comma);
    let fields = fields.get(1..).unwrap_or(&[]);
    match address {
        b"PANDA" => proprietary::agopengps(fields, "PANDA").map(Sentence::Panda),
        b"PAOGI" => proprietary::agopengps(fields, "PAOGI").map(Sentence::Paogi),
        b"KSXT" => proprietary::ksxt(fields).map(Sentence::Ksxt),
        // Standard sentences: a two-letter talker (GP, GN, GL, GA, GB, BD, HE, ...) and a
        // three-letter formatter.
        [t1, t2, f @ ..] if t1.is_ascii_uppercase() && t2.is_ascii_uppercase() && *t1 != b'P' => {
            match f {
                b"GGA" => standard::gga(fields).map(Sentence::Gga),
                b"RMC" => standard::rmc(fields).map(Sentence::Rmc),
                b"VTG" => standard::vtg(fields).map(Sentence::Vtg),
                b"HDT" => standard::hdt(fields).map(Sentence::Hdt),
                b"GST" => standard::gst(fields).map(Sentence::Gst),
                b"GNS" => standard::gns(fields).map(Sentence::Gns),
                _ => Err(NmeaError::Unsupported),
            }
        }
        _ => Err(NmeaError::Unsupported),
    }
}

/// The error for field `n` of `sentence`.
pub(crate) fn bad(sentence: &'static str, field: u8) -> NmeaError {
    NmeaError::Field { sentence, field }
}
