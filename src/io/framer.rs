//! A streaming framer for what GNSS receivers put on one byte stream: NMEA 0183 sentences,
//! UBX frames and RTCM 3 frames, interleaved, in chunks cut anywhere, with line noise and
//! binary garbage in between.
//!
//! Every frame is checked before it is believed: a UBX frame by its Fletcher checksum, an RTCM
//! 3 frame by its CRC-24Q (and its six reserved length bits being zero), an NMEA line by being
//! printable ASCII from `$` to its end of line within [`MAX_LINE`] bytes (the sentence's own
//! checksum is the parser's job). When a candidate fails, only its first byte is dropped and
//! the search resumes right after it, so a false start inside garbage never swallows the good
//! frames that follow. Bytes that belong to no frame are counted as garbage.
//!
//! One buffer of [`BUFFER`] bytes is allocated at construction; frames are handed out as
//! slices of it. Nothing is allocated per frame.

/// Longest NMEA line (from `$`, without the line end), bytes.
pub const MAX_LINE: usize = 256;
/// Largest UBX payload framed (a NAV-SAT or RXM-RAWX of a multi-band receiver stays below).
pub const MAX_UBX_PAYLOAD: usize = 4096;
/// Largest RTCM 3 frame: 3 header + 1023 payload + 3 CRC bytes.
pub const MAX_RTCM_FRAME: usize = 1029;
/// The buffer: room for the largest frame plus a chunk.
pub const BUFFER: usize = 16 * 1024;

/// CRC-24Q of RTCM 3 (poly 0x864CFB, init 0, not reflected: the catalogue's CRC-24/LTE-A).
static CRC24Q: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_24_LTE_A);

/// A frame found in the stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Frame<'a> {
    /// An NMEA 0183 line from `$` to before its `\r\n` (checksum not yet verified).
    Nmea(&'a [u8]),
    /// A text line starting with `#` (Unicore/NovAtel ASCII logs): not used, not garbage.
    Text(&'a [u8]),
    /// A UBX frame whose checksum holds.
    Ubx {
        class: u8,
        id: u8,
        payload: &'a [u8],
    },
    /// A whole RTCM 3 frame (header, payload, CRC) whose CRC holds.
    Rtcm(&'a [u8]),
}

/// What the framer saw.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct FramerCounters {
    pub bytes: u64,
    pub nmea_lines: u64,
    pub text_lines: u64,
    pub ubx_frames: u64,
    pub rtcm_frames: u64,
    /// UBX frames whose Fletcher checksum failed.
    pub ubx_checksum_errors: u64,
    /// RTCM frames whose CRC-24Q failed.
    pub rtcm_crc_errors: u64,
    /// Bytes that belonged to no frame (noise, truncated sentences, unknown data).
    pub garbage_bytes: u64,
}

enum Scan {
    /// A frame of this many bytes (and this many more to drop after it).
    Frame(usize),
    /// Not a frame: drop one byte.
    NotFrame,
    /// Could still be a frame: wait for more bytes.
    NeedMore,
}

/// The streaming framer (see the module doc).
pub struct Framer {
    buf: Vec<u8>,
    start: usize,
    end: usize,
    /// A line ended with `\r` at the end of a chunk: drop a `\n` that starts the next one.
    skip_lf: bool,
    pub counters: FramerCounters,
}

impl Default for Framer {
    fn default() -> Self {
        Self::new()
    }
}

fn is_sync(b: u8) -> bool {
    matches!(b, b'$' | b'#' | 0xB5 | 0xD3)
}

/// An NMEA or `#` line at the start of `a`: its length up to the line end, and the bytes of
/// the line end consumed.
fn scan_line(a: &[u8]) -> (Scan, usize) {
    for (i, &b) in a.iter().enumerate().skip(1) {
        match b {
            b'\n' => return (Scan::Frame(i), 1),
            b'\r' => {
                return match a.get(i + 1) {
                    Some(b'\n') => (Scan::Frame(i), 2),
                    _ => (Scan::Frame(i), 1),
                };
            }
            b'$' | b'#' => return (Scan::NotFrame, 0),
            0x20..=0x7E if i < MAX_LINE => {}
            _ => return (Scan::NotFrame, 0),
        }
    }
    (Scan::NeedMore, 0)
}

/// UBX message classes u-blox documents (NAV, RXM, INF, ACK, CFG, UPD, MON, AID, TIM, ESF,
/// MGA, LOG, SEC, HNR, NAV2): a sync pair followed by another class is not a frame.
fn ubx_class(c: u8) -> bool {
    matches!(
        c,
        0x01 | 0x02
            | 0x04
            | 0x05
            | 0x06
            | 0x09
            | 0x0A
            | 0x0B
            | 0x0D
            | 0x10
            | 0x13
            | 0x21
            | 0x27
            | 0x28
            | 0x29
    )
}

fn scan_ubx(a: &[u8]) -> Scan {
    if a.get(1).is_some_and(|&s2| s2 != 0x62) || a.get(2).is_some_and(|&c| !ubx_class(c)) {
        return Scan::NotFrame;
    }
    let (Some(&l0), Some(&l1)) = (a.get(4), a.get(5)) else {
        return Scan::NeedMore;
    };
    let len = usize::from(u16::from_le_bytes([l0, l1]));
    if len > MAX_UBX_PAYLOAD {
        return Scan::NotFrame;
    }
    match a.get(..len + 8) {
        None => Scan::NeedMore,
        Some(f) => {
            let (ck_a, ck_b) = crate::input::ubx::fletcher8(f.get(2..len + 6).unwrap_or(&[]));
            if f.get(len + 6..) == Some(&[ck_a, ck_b][..]) {
                Scan::Frame(len + 8)
            } else {
                Scan::NotFrame
            }
        }
    }
}

fn scan_rtcm(a: &[u8]) -> Scan {
    let (Some(&h1), Some(&h2)) = (a.get(1), a.get(2)) else {
        return match a.get(1) {
            Some(&h1) if h1 & 0xFC != 0 => Scan::NotFrame,
            _ => Scan::NeedMore,
        };
    };
    if h1 & 0xFC != 0 {
        return Scan::NotFrame;
    }
    let len = usize::from(u16::from(h1 & 0x03) << 8 | u16::from(h2));
    match a.get(..len + 6) {
        None => Scan::NeedMore,
        Some(f) => {
            let crc = CRC24Q.checksum(f.get(..len + 3).unwrap_or(&[]));
            let sent = f.get(len + 3..).map_or(u32::MAX, |c| {
                c.iter().fold(0u32, |a, &b| a << 8 | u32::from(b))
            });
            if crc == sent {
                Scan::Frame(len + 6)
            } else {
                Scan::NotFrame
            }
        }
    }
}

impl Framer {
    pub fn new() -> Self {
        Framer {
            buf: vec![0; BUFFER],
            start: 0,
            end: 0,
            skip_lf: false,
            counters: FramerCounters::default(),
        }
    }

    /// Bytes held waiting for the rest of a frame.
    pub fn pending(&self) -> usize {
        self.end - self.start
    }

    /// Forget a partial frame (the stream was closed and reopened: what follows does not
    /// continue it). Its bytes count as garbage.
    pub fn reset(&mut self) {
        self.counters.garbage_bytes += self.pending() as u64;
        self.start = 0;
        self.end = 0;
        self.skip_lf = false;
    }

    /// Take the next chunk of the stream; each complete frame goes to `on_frame`.
    pub fn push(&mut self, mut data: &[u8], on_frame: &mut dyn FnMut(Frame<'_>)) {
        self.counters.bytes += data.len() as u64;
        while !data.is_empty() {
            if self.end == self.buf.len() {
                self.compact();
            }
            let room = self.buf.len() - self.end;
            let n = room.min(data.len());
            let (now, later) = data.split_at(n);
            if let Some(dst) = self.buf.get_mut(self.end..self.end + n) {
                dst.copy_from_slice(now);
            }
            self.end += n;
            data = later;
            self.scan(on_frame);
            if self.end == self.buf.len() && self.start == 0 {
                // Full of a frame that never completes (cannot happen with BUFFER above the
                // largest frame, kept so that nothing can wedge the framer).
                self.drop_bytes(1);
            }
        }
    }

    fn compact(&mut self) {
        self.buf.copy_within(self.start..self.end, 0);
        self.end -= self.start;
        self.start = 0;
    }

    fn drop_bytes(&mut self, n: usize) {
        let n = n.min(self.end - self.start);
        self.start += n;
        self.counters.garbage_bytes += n as u64;
    }

    fn scan(&mut self, on_frame: &mut dyn FnMut(Frame<'_>)) {
        loop {
            let Some(a) = self.buf.get(self.start..self.end) else {
                return;
            };
            let Some(&first) = a.first() else {
                self.start = 0;
                self.end = 0;
                return;
            };
            if self.skip_lf {
                self.skip_lf = false;
                if first == b'\n' {
                    self.start += 1;
                    continue;
                }
            }
            let (scan, tail) = match first {
                b'$' | b'#' => scan_line(a),
                0xB5 => (scan_ubx(a), 0),
                0xD3 => (scan_rtcm(a), 0),
                _ => {
                    // Skip to the next byte that could start a frame.
                    let n = a.iter().position(|&b| is_sync(b)).unwrap_or(a.len());
                    self.drop_bytes(n);
                    continue;
                }
            };
            match scan {
                Scan::NeedMore => return,
                Scan::NotFrame => {
                    if first == 0xB5 && a.get(1) == Some(&0x62) && a.len() >= 8 {
                        self.counters.ubx_checksum_errors += u64::from(scan_ubx_len_ok(a));
                    }
                    if first == 0xD3 && a.len() >= 6 {
                        self.counters.rtcm_crc_errors += u64::from(scan_rtcm_len_ok(a));
                    }
                    self.drop_bytes(1);
                }
                Scan::Frame(len) => {
                    let f = a.get(..len).unwrap_or(&[]);
                    let frame = match first {
                        b'$' => {
                            self.counters.nmea_lines += 1;
                            Frame::Nmea(f)
                        }
                        b'#' => {
                            self.counters.text_lines += 1;
                            Frame::Text(f)
                        }
                        0xB5 => {
                            self.counters.ubx_frames += 1;
                            Frame::Ubx {
                                class: f.get(2).copied().unwrap_or(0),
                                id: f.get(3).copied().unwrap_or(0),
                                payload: f.get(6..len.saturating_sub(2)).unwrap_or(&[]),
                            }
                        }
                        _ => {
                            self.counters.rtcm_frames += 1;
                            Frame::Rtcm(f)
                        }
                    };
                    on_frame(frame);
                    let consumed = len + tail;
                    // A line that ended with a lone '\r' at the chunk's end may be followed
                    // by its '\n' in the next chunk.
                    if matches!(first, b'$' | b'#') && tail == 1 && a.get(len) == Some(&b'\r') {
                        self.skip_lf = a.len() == len + 1;
                    }
                    self.start += consumed;
                }
            }
        }
    }
}

/// A UBX candidate that was complete (length plausible, all bytes there) but failed its
/// checksum: counted as a checksum error rather than silently as garbage.
fn scan_ubx_len_ok(a: &[u8]) -> bool {
    match (a.get(4), a.get(5)) {
        (Some(&l0), Some(&l1)) => {
            let len = usize::from(u16::from_le_bytes([l0, l1]));
            len <= MAX_UBX_PAYLOAD && a.len() >= len + 8
        }
        _ => false,
    }
}

fn scan_rtcm_len_ok(a: &[u8]) -> bool {
    match (a.get(1), a.get(2)) {
        (Some(&h1), Some(&h2)) if h1 & 0xFC == 0 => {
            let len = usize::from(u16::from(h1 & 0x03) << 8 | u16::from(h2));
            a.len() >= len + 6
        }
        _ => false,
    }
}

/// An RTCM 3 frame around `payload` (for the simulator and the tests). Allocates.
pub fn rtcm_frame(payload: &[u8]) -> Vec<u8> {
    let len = payload.len().min(1023);
    let mut f = Vec::with_capacity(len + 6);
    f.push(0xD3);
    f.push((len >> 8) as u8 & 0x03);
    f.push(len as u8);
    f.extend_from_slice(payload.get(..len).unwrap_or(&[]));
    let crc = CRC24Q.checksum(&f);
    f.extend_from_slice(&crc.to_be_bytes()[1..]);
    f
}

/// The message number of an RTCM 3 frame (the payload's first 12 bits).
pub fn rtcm_message_type(frame: &[u8]) -> Option<u16> {
    match (frame.get(3), frame.get(4)) {
        (Some(&a), Some(&b)) => Some(u16::from(a) << 4 | u16::from(b) >> 4),
        _ => None,
    }
}
