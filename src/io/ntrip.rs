//! NTRIP client (revisions 1 and 2): fetches a caster's RTCM 3 corrections for one
//! mountpoint, sends the receiver's position back as GGA every `gga_interval_s` (VRS and
//! nearest-base casters need it), and hands every RTCM frame to the receiver's stream.
//!
//! Protocol (NTRIP 1.0, RTCM 10410.0; NTRIP 2.0, RTCM 10410.1), as AgOpenGPS's AgIO and
//! RTKLIB's `stream.c` speak it:
//! - request `GET /MOUNT HTTP/1.0` (rev 1) or `HTTP/1.1` with `Host` and
//!   `Ntrip-Version: Ntrip/2.0` (rev 2), `User-Agent: NTRIP ...`, HTTP Basic authorization;
//! - answers: `ICY 200 OK` (rev 1; data follows at once), `HTTP/1.x 200 OK` then headers
//!   (rev 2; the body may be `Transfer-Encoding: chunked`), `SOURCETABLE 200 OK` or
//!   `404` (no such mountpoint), `401` or `ERROR - Bad Password` (wrong user or password);
//! - GGA goes up the same connection (in rev 2 chunked bodies too, plain lines).
//!
//! Only CRC-checked RTCM 3 frames are forwarded (through the [`Framer`]): a caster's HTTP
//! noise or a broken frame never reaches the receiver. The client reconnects with back-off
//! when the caster refuses, closes, or sends nothing for `timeout_s`; its [`NtripStatus`]
//! (state, age of corrections, bytes/s, reconnects) goes to `agsteer status`, and the time
//! of the last frame goes to the stream decoders (their correction-age cap, see
//! [`decoder`](super::decoder)).
//!
//! Written by hand rather than on an HTTP client crate: revision 1 answers are not HTTP
//! (`ICY 200 OK`), and the whole exchange is a request line, a few headers and an optional
//! chunked body. Base64 (for the authorization header) is the 20-line RFC 4648 encoder
//! below.

use super::framer::{rtcm_message_type, Frame, Framer};
use crate::can::bus::monotonic_s;
use crate::input::FixQuality;
use serde::Serialize;
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;
use tokio::sync::{mpsc, watch};

/// Protocol revision.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
pub enum NtripVersion {
    #[serde(rename = "1")]
    V1,
    #[serde(rename = "2")]
    V2,
}

/// How to reach the caster.
#[derive(Clone, PartialEq)]
pub struct NtripConfig {
    pub host: String,
    pub port: u16,
    pub mountpoint: String,
    pub user: String,
    pub password: String,
    pub version: NtripVersion,
    /// Send the position as GGA this often, s (0: never).
    pub gga_interval_s: f64,
    /// No data for this long: reconnect, s.
    pub timeout_s: f64,
    pub backoff_min_s: f64,
    pub backoff_max_s: f64,
}

impl std::fmt::Debug for NtripConfig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // Never the password.
        write!(
            f,
            "NtripConfig {{ {}:{}/{} user {:?} {:?} }}",
            self.host, self.port, self.mountpoint, self.user, self.version
        )
    }
}

/// What the client is doing.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum CasterState {
    #[default]
    Connecting,
    /// Receiving corrections.
    Streaming,
    /// The caster refused the user or password.
    Unauthorized,
    /// The caster has no such mountpoint (it answered with its source table or 404).
    UnknownMountpoint,
    /// Anything else (connection refused, closed, timed out, unexpected answer).
    Error,
}

/// The client's state for `agsteer status`.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct NtripStatus {
    pub caster: String,
    pub state: CasterState,
    pub last_error: Option<String>,
    pub reconnects: u64,
    pub bytes: u64,
    pub rtcm_frames: u64,
    /// Bytes/s over the last 10 s.
    pub bytes_per_s: f64,
    /// Monotonic time of the last RTCM frame, s.
    pub last_rtcm_t: Option<f64>,
    pub gga_sent: u64,
    pub crc_errors: u64,
    /// Message types seen (the latest few distinct ones).
    pub message_types: Vec<u16>,
}

impl NtripStatus {
    /// Age of the corrections at `now`, s.
    pub fn correction_age_s(&self, now: f64) -> Option<f64> {
        self.last_rtcm_t.map(|t| (now - t).max(0.0))
    }
}

/// The receiver's position, for GGA.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GgaSource {
    pub lat_deg: f64,
    pub lon_deg: f64,
    /// Height above the ellipsoid (sent as altitude with a zero geoid separation), m.
    pub altitude_m: f64,
    pub quality: FixQuality,
    pub satellites: u8,
    pub hdop: f64,
}

/// What the client is connected to.
pub struct NtripPorts {
    /// RTCM frames to the receiver's stream (a full queue drops the frame).
    pub rtcm: Vec<mpsc::Sender<Vec<u8>>>,
    /// Monotonic time of the last RTCM frame, for the stream decoders.
    pub last_rtcm: watch::Sender<Option<f64>>,
    /// The receiver's latest position.
    pub position: watch::Receiver<Option<GgaSource>>,
    pub status: Arc<Mutex<NtripStatus>>,
}

/// RFC 4648 base64.
pub fn base64(input: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(input.len().div_ceil(3) * 4);
    for c in input.chunks(3) {
        let b = [
            c.first().copied().unwrap_or(0),
            c.get(1).copied().unwrap_or(0),
            c.get(2).copied().unwrap_or(0),
        ];
        let n = u32::from(b[0]) << 16 | u32::from(b[1]) << 8 | u32::from(b[2]);
        for k in 0..4 {
            if k <= c.len() {
                out.push(char::from(A[(n >> (18 - 6 * k) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// The request for `cfg` (with the first GGA as a header in rev 2, if known).
pub fn request(cfg: &NtripConfig, gga: Option<&str>) -> String {
    let auth = base64(format!("{}:{}", cfg.user, cfg.password).as_bytes());
    let mount = cfg.mountpoint.trim_start_matches('/');
    let agent = concat!("NTRIP agsteer/", env!("CARGO_PKG_VERSION"));
    match cfg.version {
        NtripVersion::V1 => format!(
            "GET /{mount} HTTP/1.0\r\nUser-Agent: {agent}\r\nAccept: */*\r\nAuthorization: Basic {auth}\r\n\r\n"
        ),
        NtripVersion::V2 => {
            let gga = gga.map(|g| format!("Ntrip-GGA: {g}\r\n")).unwrap_or_default();
            format!(
                "GET /{mount} HTTP/1.1\r\nHost: {}:{}\r\nNtrip-Version: Ntrip/2.0\r\nUser-Agent: {agent}\r\nAuthorization: Basic {auth}\r\n{gga}Connection: close\r\n\r\n",
                cfg.host, cfg.port
            )
        }
    }
}

/// A GGA sentence for `p` at UTC time of day `tod_s` (what casters use to pick or compute a
/// base).
pub fn gga_sentence(p: &GgaSource, tod_s: f64) -> String {
    let dm = |v: f64, deg_digits: usize| {
        let a = v.abs();
        let d = a.floor();
        let m = (a - d) * 60.0;
        format!("{:0w$}{:08.5}", d as u32, m, w = deg_digits)
    };
    let q = match p.quality {
        FixQuality::RtkFixed => 4,
        FixQuality::RtkFloat => 5,
        FixQuality::Other => 1,
        FixQuality::None => 0,
    };
    let tod = tod_s.rem_euclid(86_400.0);
    let body = format!(
        "GPGGA,{:02}{:02}{:05.2},{},{},{},{},{},{:02},{:.1},{:.3},M,0.000,M,,",
        (tod / 3600.0) as u32,
        ((tod % 3600.0) / 60.0) as u32,
        tod % 60.0,
        dm(p.lat_deg, 2),
        if p.lat_deg < 0.0 { 'S' } else { 'N' },
        dm(p.lon_deg, 3),
        if p.lon_deg < 0.0 { 'W' } else { 'E' },
        q,
        p.satellites,
        p.hdop,
        p.altitude_m
    );
    format!(
        "${body}*{:02X}",
        crate::input::nmea0183::xor_checksum(body.as_bytes())
    )
}

/// Why a session ended.
#[derive(Debug, Clone, PartialEq)]
pub enum SessionEnd {
    Unauthorized(String),
    UnknownMountpoint(String),
    Error(String),
}

impl SessionEnd {
    fn state(&self) -> CasterState {
        match self {
            SessionEnd::Unauthorized(_) => CasterState::Unauthorized,
            SessionEnd::UnknownMountpoint(_) => CasterState::UnknownMountpoint,
            SessionEnd::Error(_) => CasterState::Error,
        }
    }
    fn message(&self) -> &str {
        match self {
            SessionEnd::Unauthorized(m)
            | SessionEnd::UnknownMountpoint(m)
            | SessionEnd::Error(m) => m,
        }
    }
}

/// How the caster answered the request.
#[derive(Debug, Clone, PartialEq)]
pub enum Answer {
    /// Data follows (`chunked`: rev 2 chunked transfer encoding); `header_len` bytes were
    /// the answer's head.
    Ok {
        chunked: bool,
        header_len: usize,
    },
    Refused(SessionEnd),
    /// Not all of the head is there yet.
    Incomplete,
}

/// Read the caster's answer from the start of `buf`.
pub fn parse_answer(buf: &[u8]) -> Answer {
    let Some(line_end) = buf.windows(2).position(|w| w == b"\r\n") else {
        return if buf.len() > 4096 {
            Answer::Refused(SessionEnd::Error("answer without a line end".into()))
        } else {
            Answer::Incomplete
        };
    };
    let status = String::from_utf8_lossy(buf.get(..line_end).unwrap_or(&[])).to_string();
    if status.starts_with("ICY 200") {
        // Rev 1: data follows the status line (some casters add a blank line).
        let mut len = line_end + 2;
        if buf.get(len..len + 2) == Some(b"\r\n") {
            len += 2;
        }
        return Answer::Ok {
            chunked: false,
            header_len: len,
        };
    }
    if status.starts_with("SOURCETABLE") {
        return Answer::Refused(SessionEnd::UnknownMountpoint(
            "the caster answered with its source table: no such mountpoint".into(),
        ));
    }
    if status.starts_with("ERROR") {
        let m = status.to_ascii_lowercase();
        return Answer::Refused(if m.contains("password") || m.contains("pasword") {
            SessionEnd::Unauthorized(status)
        } else if m.contains("mountpoint") {
            SessionEnd::UnknownMountpoint(status)
        } else {
            SessionEnd::Error(status)
        });
    }
    if status.starts_with("HTTP/") {
        let code: u16 = status
            .split_whitespace()
            .nth(1)
            .and_then(|c| c.parse().ok())
            .unwrap_or(0);
        let head_end = buf.windows(4).position(|w| w == b"\r\n\r\n");
        return match code {
            200 => match head_end {
                None => Answer::Incomplete,
                Some(e) => {
                    let head =
                        String::from_utf8_lossy(buf.get(..e).unwrap_or(&[])).to_ascii_lowercase();
                    if head.contains("content-type: gnss/sourcetable") {
                        return Answer::Refused(SessionEnd::UnknownMountpoint(
                            "the caster answered with its source table: no such mountpoint".into(),
                        ));
                    }
                    Answer::Ok {
                        chunked: head.contains("transfer-encoding: chunked"),
                        header_len: e + 4,
                    }
                }
            },
            401 | 403 => Answer::Refused(SessionEnd::Unauthorized(status)),
            404 => Answer::Refused(SessionEnd::UnknownMountpoint(status)),
            _ => Answer::Refused(SessionEnd::Error(status)),
        };
    }
    Answer::Refused(SessionEnd::Error(format!("unexpected answer {status:?}")))
}

/// Streaming decoder of HTTP/1.1 chunked transfer encoding (NTRIP rev 2 bodies).
#[derive(Debug, Default)]
pub struct Dechunker {
    /// Bytes left in the current chunk's data.
    left: usize,
    /// A chunk-size line being read.
    line: Vec<u8>,
    /// The CR LF after a chunk's data is still to come.
    trailer: u8,
    /// The terminating zero-size chunk was seen.
    pub done: bool,
}

impl Dechunker {
    /// Feed body bytes; the data bytes go to `out`. Errors on a malformed size line.
    pub fn push(&mut self, mut data: &[u8], out: &mut dyn FnMut(&[u8])) -> Result<(), String> {
        while !data.is_empty() && !self.done {
            if self.left > 0 {
                let n = self.left.min(data.len());
                let (now, rest) = data.split_at(n);
                out(now);
                self.left -= n;
                if self.left == 0 {
                    self.trailer = 2;
                }
                data = rest;
            } else if self.trailer > 0 {
                self.trailer -= 1;
                data = data.get(1..).unwrap_or(&[]);
            } else {
                let Some((&b, rest)) = data.split_first() else {
                    break;
                };
                data = rest;
                if b == b'\n' {
                    let line = String::from_utf8_lossy(&self.line).to_string();
                    self.line.clear();
                    let size = line.trim().split(';').next().unwrap_or("").trim();
                    let n = usize::from_str_radix(size, 16)
                        .map_err(|_| format!("bad chunk size line {line:?}"))?;
                    if n == 0 {
                        self.done = true;
                    }
                    self.left = n;
                } else if self.line.len() < 256 {
                    self.line.push(b);
                } else {
                    return Err("chunk size line too long".into());
                }
            }
        }
        Ok(())
    }
}

fn update(status: &Arc<Mutex<NtripStatus>>, f: impl FnOnce(&mut NtripStatus)) {
    if let Ok(mut s) = status.lock() {
        f(&mut s);
    }
}

/// Run the client for ever (see the module doc).
pub async fn run_ntrip(cfg: NtripConfig, ports: NtripPorts) {
    let caster = format!(
        "{}:{}/{}",
        cfg.host,
        cfg.port,
        cfg.mountpoint.trim_start_matches('/')
    );
    update(&ports.status, |s| s.caster = caster.clone());
    let mut backoff = cfg.backoff_min_s;
    let mut framer = Framer::new();
    loop {
        update(&ports.status, |s| s.state = CasterState::Connecting);
        let started = tokio::time::Instant::now();
        let end = session(&cfg, &ports, &mut framer).await;
        let msg = end.message().to_string();
        let repeated = ports
            .status
            .lock()
            .map(|s| s.last_error.as_deref() == Some(msg.as_str()))
            .unwrap_or(false);
        if !repeated {
            tracing::warn!("NTRIP {caster}: {msg}; retrying");
        }
        update(&ports.status, |s| {
            s.state = end.state();
            s.last_error = Some(msg);
            s.reconnects += 1;
            s.bytes_per_s = 0.0;
        });
        if started.elapsed() > Duration::from_secs(30) {
            backoff = cfg.backoff_min_s;
        }
        // A refusal will not go away by itself soon: wait the longest.
        let wait = match end {
            SessionEnd::Error(_) => backoff,
            _ => cfg.backoff_max_s,
        };
        tokio::time::sleep(Duration::from_secs_f64(wait)).await;
        backoff = (backoff * 2.0).min(cfg.backoff_max_s);
    }
}

fn utc_time_of_day() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64().rem_euclid(86_400.0))
        .unwrap_or(0.0)
}

async fn session(cfg: &NtripConfig, ports: &NtripPorts, framer: &mut Framer) -> SessionEnd {
    let timeout = Duration::from_secs_f64(cfg.timeout_s);
    let connect = tokio::time::timeout(timeout, TcpStream::connect((cfg.host.as_str(), cfg.port)));
    let mut sock = match connect.await {
        Ok(Ok(s)) => s,
        Ok(Err(e)) => return SessionEnd::Error(format!("cannot connect: {e}")),
        Err(_) => return SessionEnd::Error("connect timed out".into()),
    };
    let gga_now = || (*ports.position.borrow()).map(|p| gga_sentence(&p, utc_time_of_day()));
    let first_gga = gga_now();
    if let Err(e) = sock
        .write_all(request(cfg, first_gga.as_deref()).as_bytes())
        .await
    {
        return SessionEnd::Error(format!("cannot send the request: {e}"));
    }
    // The answer's head.
    let mut head = Vec::with_capacity(1024);
    let mut buf = vec![0u8; 4096];
    let (chunked, body_start) = loop {
        match parse_answer(&head) {
            Answer::Ok {
                chunked,
                header_len,
            } => break (chunked, header_len),
            Answer::Refused(end) => return end,
            Answer::Incomplete => {}
        }
        match tokio::time::timeout(timeout, sock.read(&mut buf)).await {
            Err(_) => return SessionEnd::Error("no answer from the caster".into()),
            Ok(Ok(0)) => {
                return match parse_answer(&head) {
                    Answer::Refused(end) => end,
                    _ => SessionEnd::Error(
                        "the caster closed the connection without answering".into(),
                    ),
                }
            }
            Ok(Ok(n)) => head.extend_from_slice(buf.get(..n).unwrap_or(&[])),
            Ok(Err(e)) => return SessionEnd::Error(format!("read error: {e}")),
        }
    };
    tracing::info!(
        "NTRIP {}:{}/{}: streaming",
        cfg.host,
        cfg.port,
        cfg.mountpoint
    );
    update(&ports.status, |s| {
        s.state = CasterState::Streaming;
        s.last_error = None;
    });
    framer.reset();
    let mut dechunker = chunked.then(Dechunker::default);
    // Bytes/s over a sliding window of 1 s buckets.
    let mut window = [0u64; 10];
    let mut window_start = monotonic_s().floor();
    let mut body = |data: &[u8], framer: &mut Framer| {
        let t = monotonic_s();
        let bucket = t.floor();
        while window_start < bucket {
            window_start += 1.0;
            window.rotate_left(1);
            if let Some(last) = window.last_mut() {
                *last = 0;
            }
        }
        if let Some(last) = window.last_mut() {
            *last += data.len() as u64;
        }
        let mut frames = 0u64;
        let mut types = Vec::new();
        framer.push(data, &mut |f| {
            if let Frame::Rtcm(r) = f {
                frames += 1;
                if let Some(ty) = rtcm_message_type(r) {
                    types.push(ty);
                }
                for tx in &ports.rtcm {
                    let _ = tx.try_send(r.to_vec());
                }
            }
        });
        if frames > 0 {
            ports.last_rtcm.send_replace(Some(t));
        }
        let crc = framer.counters.rtcm_crc_errors;
        let rate = window.iter().sum::<u64>() as f64 / window.len() as f64;
        update(&ports.status, |s| {
            s.bytes += data.len() as u64;
            s.rtcm_frames += frames;
            s.crc_errors = crc;
            s.bytes_per_s = rate;
            if frames > 0 {
                s.last_rtcm_t = Some(t);
            }
            for ty in types {
                if !s.message_types.contains(&ty) {
                    if s.message_types.len() >= 16 {
                        s.message_types.remove(0);
                    }
                    s.message_types.push(ty);
                }
            }
        });
    };
    let mut feed = |data: &[u8],
                    framer: &mut Framer,
                    dechunker: &mut Option<Dechunker>|
     -> Result<(), String> {
        match dechunker {
            Some(d) => d.push(data, &mut |b| body(b, framer)),
            None => {
                body(data, framer);
                Ok(())
            }
        }
    };
    if let Err(e) = feed(
        head.get(body_start..).unwrap_or(&[]),
        framer,
        &mut dechunker,
    ) {
        return SessionEnd::Error(e);
    }
    let (mut rd, mut wr) = sock.into_split();
    let gga_every = (cfg.gga_interval_s > 0.0).then(|| Duration::from_secs_f64(cfg.gga_interval_s));
    let mut gga_timer = tokio::time::interval(gga_every.unwrap_or(Duration::from_secs(3600)));
    gga_timer.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    // The first tick is now; rev 2 already sent the position in the request.
    if first_gga.is_some() && cfg.version == NtripVersion::V2 {
        gga_timer.tick().await;
    }
    loop {
        tokio::select! {
            r = tokio::time::timeout(timeout, rd.read(&mut buf)) => match r {
                Err(_) => return SessionEnd::Error(format!("no data for {:.0} s", timeout.as_secs_f64())),
                Ok(Ok(0)) => return SessionEnd::Error("the caster closed the connection".into()),
                Ok(Ok(n)) => {
                    if let Err(e) = feed(buf.get(..n).unwrap_or(&[]), framer, &mut dechunker) {
                        return SessionEnd::Error(e);
                    }
                    if dechunker.as_ref().is_some_and(|d| d.done) {
                        return SessionEnd::Error("the caster ended the stream".into());
                    }
                }
                Ok(Err(e)) => return SessionEnd::Error(format!("read error: {e}")),
            },
            _ = gga_timer.tick(), if gga_every.is_some() => {
                if let Some(g) = gga_now() {
                    if let Err(e) = wr.write_all(format!("{g}\r\n").as_bytes()).await {
                        return SessionEnd::Error(format!("cannot send GGA: {e}"));
                    }
                    update(&ports.status, |s| s.gga_sent += 1);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_vectors() {
        // RFC 4648 §10.
        for (i, o) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(i.as_bytes()), o);
        }
    }

    #[test]
    fn answers() {
        assert_eq!(
            parse_answer(b"ICY 200 OK\r\n\xD3\x00"),
            Answer::Ok {
                chunked: false,
                header_len: 12
            }
        );
        assert_eq!(parse_answer(b"ICY 200"), Answer::Incomplete);
        assert!(matches!(
            parse_answer(b"HTTP/1.0 401 Unauthorized\r\n"),
            Answer::Refused(SessionEnd::Unauthorized(_))
        ));
        assert!(matches!(
            parse_answer(b"ERROR - Bad Pasword\r\n"),
            Answer::Refused(SessionEnd::Unauthorized(_))
        ));
        assert!(matches!(
            parse_answer(b"SOURCETABLE 200 OK\r\nSTR;X;\r\nENDSOURCETABLE\r\n"),
            Answer::Refused(SessionEnd::UnknownMountpoint(_))
        ));
        assert!(matches!(
            parse_answer(b"HTTP/1.1 404 Not Found\r\n\r\n"),
            Answer::Refused(SessionEnd::UnknownMountpoint(_))
        ));
        let v2 = b"HTTP/1.1 200 OK\r\nNtrip-Version: Ntrip/2.0\r\nContent-Type: gnss/data\r\nTransfer-Encoding: chunked\r\n\r\n5\r\n";
        assert_eq!(
            parse_answer(v2),
            Answer::Ok {
                chunked: true,
                header_len: v2.len() - 3
            }
        );
        assert_eq!(
            parse_answer(b"HTTP/1.1 200 OK\r\nServer: x\r\n"),
            Answer::Incomplete
        );
        let table = b"HTTP/1.1 200 OK\r\nContent-Type: gnss/sourcetable\r\n\r\nSTR;";
        assert!(matches!(
            parse_answer(table),
            Answer::Refused(SessionEnd::UnknownMountpoint(_))
        ));
    }

    #[test]
    fn dechunking_in_any_split() {
        let body = b"4\r\nabcd\r\n3;ext=1\r\nefg\r\n0\r\n\r\n";
        for split in 0..body.len() {
            let mut d = Dechunker::default();
            let mut out = Vec::new();
            let (a, b) = body.split_at(split);
            d.push(a, &mut |x| out.extend_from_slice(x)).unwrap();
            d.push(b, &mut |x| out.extend_from_slice(x)).unwrap();
            assert_eq!(out, b"abcdefg", "split {split}");
            assert!(d.done);
        }
        assert!(Dechunker::default().push(b"zz\r\n", &mut |_| {}).is_err());
    }

    #[test]
    fn requests_and_gga() {
        let cfg = NtripConfig {
            host: "127.0.0.1".into(),
            port: 2101,
            mountpoint: "/RTCM3".into(),
            user: "farmer".into(),
            password: "secret".into(),
            version: NtripVersion::V1,
            gga_interval_s: 10.0,
            timeout_s: 10.0,
            backoff_min_s: 1.0,
            backoff_max_s: 30.0,
        };
        let r = request(&cfg, None);
        assert!(r.starts_with("GET /RTCM3 HTTP/1.0\r\n"), "{r}");
        assert!(r.contains(&format!(
            "Authorization: Basic {}\r\n",
            base64(b"farmer:secret")
        )));
        assert!(r.contains("User-Agent: NTRIP "));
        assert!(!format!("{cfg:?}").contains("secret"));
        let g = gga_sentence(
            &GgaSource {
                lat_deg: -45.5,
                lon_deg: 170.25,
                altitude_m: 29.3,
                quality: FixQuality::RtkFloat,
                satellites: 7,
                hdop: 0.9,
            },
            3600.0 * 13.0 + 5.5,
        );
        let parsed = crate::input::nmea0183::parse(g.as_bytes()).unwrap();
        let crate::input::nmea0183::Sentence::Gga(gga) = parsed else {
            panic!("{g}")
        };
        assert!(
            (gga.lat_deg.unwrap() + 45.5).abs() < 1e-7
                && (gga.lon_deg.unwrap() - 170.25).abs() < 1e-7,
            "{g}"
        );
        assert_eq!(
            (gga.quality, gga.satellites, gga.time_s),
            (5, Some(7), Some(46805.5))
        );
        let v2 = request(
            &NtripConfig {
                version: NtripVersion::V2,
                ..cfg
            },
            Some(&g),
        );
        assert!(
            v2.contains("Ntrip-Version: Ntrip/2.0\r\n") && v2.contains("Host: 127.0.0.1:2101\r\n")
        );
        assert!(v2.contains(&format!("Ntrip-GGA: {g}\r\n")));
    }
}
