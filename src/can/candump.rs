//! candump log lines (can-utils), read in the formats found in public logs and written in
//! `candump -L` form.
//!
//! Read:
//! - `(1502984866.421964) can0 09F112CC#FF725AFF7FFF7FFD` — `candump -L` / `-l` files;
//! - `can0 09F8027F#00FCFFFF` — the same without a time stamp (`cansend`'s argument);
//! - `can0  09F8027F   [8]  00 FC FF FF 00 00 FF FF` — candump's screen format, with an
//!   optional `(time)` before it;
//! - `<0x18eeff01> [8] 05 a0 be 1c 00 a0 a0 c0` — old candump versions' screen format.
//!
//! An identifier of more than 3 hex digits is a 29-bit extended one (candump prints 11-bit
//! identifiers with 3 digits).

use super::Frame;

/// One frame of a log.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogFrame {
    /// Time stamp, s, when the line has one.
    pub t: Option<f64>,
    /// A 29-bit identifier (else an 11-bit one).
    pub extended: bool,
    pub frame: Frame,
}

/// Hex digits only: `from_str_radix` would take a leading sign.
fn hex_digits(s: &str) -> bool {
    !s.is_empty() && s.bytes().all(|b| b.is_ascii_hexdigit())
}

fn hex_byte(s: &str) -> Option<u8> {
    if s.len() == 2 && hex_digits(s) {
        u8::from_str_radix(s, 16).ok()
    } else {
        None
    }
}

fn id_of(s: &str) -> Option<(u32, bool)> {
    let s = s.strip_prefix("0x").unwrap_or(s);
    if !hex_digits(s) || s.len() > 8 {
        return None;
    }
    let id = u32::from_str_radix(s, 16).ok()?;
    let extended = s.len() > 3;
    (id <= if extended { 0x1FFF_FFFF } else { 0x7FF }).then_some((id, extended))
}

/// Parse one line; `None` for anything that is not a classic CAN data frame (comments,
/// headers, CAN FD, remote frames, malformed lines).
pub fn parse_line(line: &str) -> Option<LogFrame> {
    let mut words = line.split_whitespace().peekable();
    let mut t = None;
    if let Some(ts) = words
        .peek()
        .and_then(|w| w.strip_prefix('(').and_then(|s| s.strip_suffix(')')))
    {
        t = Some(ts.parse::<f64>().ok().filter(|t| t.is_finite())?);
        words.next();
    }
    let first = words.next()?;
    // Old format: <0xID> [n] bytes...
    if let Some(id) = first.strip_prefix('<').and_then(|s| s.strip_suffix('>')) {
        let (id, extended) = id_of(id)?;
        return bracketed(t, id, extended, words);
    }
    let second = words.next()?;
    if let Some((id, hex)) = second.split_once('#') {
        // iface ID#HEX
        let (id, extended) = id_of(id)?;
        if hex.len() % 2 != 0 || hex.len() > 16 || hex.starts_with('#') || hex.starts_with('R') {
            return None;
        }
        let mut data = [0u8; 8];
        for (k, b) in data.iter_mut().enumerate().take(hex.len() / 2) {
            *b = hex_byte(hex.get(2 * k..2 * k + 2)?)?;
        }
        if words.next().is_some() {
            return None;
        }
        return Some(LogFrame {
            t,
            extended,
            frame: Frame::new(id, &data[..hex.len() / 2]),
        });
    }
    // iface ID [n] bytes...
    let (id, extended) = id_of(second)?;
    bracketed(t, id, extended, words)
}

fn bracketed<'a>(
    t: Option<f64>,
    id: u32,
    extended: bool,
    mut words: impl Iterator<Item = &'a str>,
) -> Option<LogFrame> {
    let len: usize = words
        .next()?
        .strip_prefix('[')?
        .strip_suffix(']')?
        .parse()
        .ok()?;
    if len > 8 {
        return None;
    }
    let mut data = [0u8; 8];
    for b in data.iter_mut().take(len) {
        *b = hex_byte(words.next()?)?;
    }
    Some(LogFrame {
        t,
        extended,
        frame: Frame::new(id, &data[..len]),
    })
}

/// `t` rounded to the whole microsecond a `candump -L` line keeps: a time taken through it is
/// written and read back exactly (`agsteerd` gives its node such times, so that a replay of its
/// bus log feeds the node the same values).
pub fn log_time(t: f64) -> f64 {
    (t * 1e6).round() / 1e6
}

/// `(t) iface ID#HEX`, as `candump -L` writes it (an extended identifier, 8 hex digits).
pub fn format_line(t: f64, iface: &str, frame: &Frame) -> String {
    format!("({t:.6}) {iface} {}", frame.to_candump())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_format_of_the_public_logs() {
        let l = parse_line("(1502984866.421964) slcan0 09F112CC#FF725AFF7FFF7FFD").unwrap();
        assert_eq!(l.t, Some(1502984866.421964));
        assert_eq!(l.frame.id, 0x09F112CC);
        assert!(l.extended);
        assert_eq!(
            l.frame.payload(),
            &[0xFF, 0x72, 0x5A, 0xFF, 0x7F, 0xFF, 0x7F, 0xFD]
        );
        let l = parse_line("  can0  09F8027F   [8]  00 FC FF FF 00 00 FF FF").unwrap();
        assert_eq!((l.t, l.frame.id, l.frame.len), (None, 0x09F8027F, 8));
        assert_eq!(l.frame.data[1], 0xFC);
        let l = parse_line("<0x18eeff01> [8] 05 a0 be 1c 00 a0 a0 c0 ").unwrap();
        assert_eq!((l.frame.id, l.frame.data[2]), (0x18EEFF01, 0xBE));
        let l = parse_line("can0 123#0102").unwrap();
        assert!(!l.extended);
        assert_eq!(l.frame.payload(), &[1, 2]);
        let l = parse_line("vcan0 0DF8051C#").unwrap();
        assert_eq!(l.frame.len, 0);
        for bad in [
            "# comment",
            "interface = can0, family = 29, type = 3, proto = 1",
            "can0 09F8027F#0",
            "can0 09F8027F#R",
            "can0 09F8027F##0112",
            "can0 09F8027F#0011223344556677AA",
            "can0 09F8027F [9] 00",
            "can0 09F8027F [3] 00 01",
            "can0 +9F8027F#00",
            "can0 09F8027F#+1",
            "can0 09F8027F [1] +1",
            "can0 09F8027F#é0",
            "(abc) can0 09F8027F#00",
            "",
        ] {
            assert_eq!(parse_line(bad), None, "{bad}");
        }
    }

    #[test]
    fn written_lines_read_back() {
        let f = Frame::new(0x0CFF2A2A, &[1, 2, 3, 0xFF]);
        let line = format_line(12.5, "can0", &f);
        assert_eq!(line, "(12.500000) can0 0CFF2A2A#010203FF");
        let l = parse_line(&line).unwrap();
        assert_eq!((l.t, l.frame), (Some(12.5), f));
        // A time rounded by log_time reads back bit for bit.
        for t in [0.1, 12.345_678_9, 86_399.999_999_6, 1.234_567_5e5] {
            let t = log_time(t);
            let back = parse_line(&format_line(t, "can0", &f)).unwrap().t.unwrap();
            assert_eq!(back.to_bits(), t.to_bits(), "{t}");
        }
    }
}
