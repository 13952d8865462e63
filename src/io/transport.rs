//! Byte-stream transports of a GNSS receiver: a serial device or USB CDC-ACM device (both
//! ttys: 8N1 at the configured baud rate, no flow control), UDP (a local port, optionally only
//! from one sender) and a TCP client. One task per stream reads, stamps each chunk on
//! receipt, decodes it ([`GnssDecoder`]) and passes the [`Input`]s on a bounded channel; RTCM
//! corrections from the NTRIP client are written back to the same device or socket
//! concurrently, so a slow write never delays a read.
//!
//! The task never ends by itself: when the device disappears (unplugged USB receiver, closed
//! socket, read error) or goes silent for `silence_timeout_s`, it closes it, drops any partial
//! frame, waits (back-off doubling from `backoff_min_s` to `backoff_max_s`) and opens it
//! again, counting reconnects. A serial device's input buffer is flushed on open: bytes queued
//! before the (re)open are old. Counters and the connection state are published in a
//! [`StreamStatus`] for `agsteer status`.
//!
//! Serial ports are opened and configured with `tokio-serial` (`serialport` under it) with
//! default features off: no libudev, nothing but Rust and libc to build; they are read by
//! [`super::tty`], which never reads an empty tty (that read waits for a kernel worker).

use super::decoder::{DecoderParams, GnssDecoder, StreamCounters};
use super::ntrip::GgaSource;
use crate::input::nmea0183::clock::Receipt;
use crate::input::{FixQuality, Input};
use serde::Serialize;
use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt};
use tokio::sync::{mpsc, watch};

/// Where the receiver's bytes come from.
#[derive(Debug, Clone, PartialEq)]
pub enum Transport {
    /// A serial port or USB CDC-ACM device (`/dev/ttyUSB0`, `/dev/ttyACM0`, or better its
    /// stable `/dev/serial/by-id/...` link), 8N1.
    Serial { device: PathBuf, baud: u32 },
    /// Datagrams to a local port. `source`: accept only this sender's address. `rtcm_to`:
    /// where corrections go (an AgOpenGPS board listens on its own port), if anywhere.
    Udp {
        bind: SocketAddr,
        source: Option<IpAddr>,
        rtcm_to: Option<SocketAddr>,
    },
    /// A TCP server the receiver (or a serial-to-network bridge) runs.
    Tcp { host: String, port: u16 },
}

impl std::fmt::Display for Transport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Transport::Serial { device, baud } => {
                write!(f, "serial {} at {baud} Bd", device.display())
            }
            Transport::Udp { bind, source, .. } => match source {
                Some(s) => write!(f, "udp {bind} from {s}"),
                None => write!(f, "udp {bind}"),
            },
            Transport::Tcp { host, port } => write!(f, "tcp {host}:{port}"),
        }
    }
}

/// How one stream runs.
#[derive(Debug, Clone, PartialEq)]
pub struct StreamConfig {
    pub transport: Transport,
    pub decoder: DecoderParams,
    /// No byte for this long: the device is reopened (serial, TCP), s.
    pub silence_timeout_s: f64,
    pub backoff_min_s: f64,
    pub backoff_max_s: f64,
    /// Bytes per second taken at most; more (a flood) is dropped and counted.
    pub max_rate_bytes_s: f64,
    /// Stamp receipts with the host's UTC too (for the latency rule; only meaningful when
    /// the host clock is disciplined).
    pub host_utc: bool,
}

/// The state of one stream, for `agsteer status`.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct StreamStatus {
    pub transport: String,
    pub connected: bool,
    /// Times the device or socket was lost and reopened.
    pub reconnects: u64,
    pub last_error: Option<String>,
    #[serde(flatten)]
    pub counters: StreamCounters,
    /// Checksum and CRC failures of every kind.
    pub checksum_errors: u64,
    /// UDP datagrams from another sender than the configured one.
    pub filtered_datagrams: u64,
    /// Bytes dropped above `max_rate_bytes_s`.
    pub dropped_bytes: u64,
    /// Inputs dropped because the controller's queue was full.
    pub dropped_inputs: u64,
    /// RTCM bytes written to the receiver.
    pub rtcm_bytes_out: u64,
    /// Monotonic time of the last byte received, s.
    pub last_byte_t: Option<f64>,
}

/// Shared handle to a stream's status.
pub type SharedStatus = Arc<Mutex<StreamStatus>>;

/// What a stream task is connected to.
pub struct StreamPorts {
    /// Decoded inputs, to the controller.
    pub inputs: mpsc::Sender<Input>,
    /// RTCM corrections to write to the receiver (from the NTRIP client).
    pub rtcm: Option<mpsc::Receiver<Vec<u8>>>,
    /// Monotonic time of the NTRIP client's last RTCM frame, s (the link's age of corrections
    /// feeds the decoder's correction-age cap).
    pub last_rtcm: Option<watch::Receiver<Option<f64>>>,
    /// The receiver's latest position, for the NTRIP client's GGA.
    pub position: Option<watch::Sender<Option<GgaSource>>>,
    pub status: SharedStatus,
}

/// Receipt stamp now.
pub fn receipt_now(host_utc: bool) -> Receipt {
    let t = crate::can::bus::monotonic_s();
    let utc_s = host_utc
        .then(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .ok()
        })
        .flatten()
        .map(|d| d.as_secs_f64());
    Receipt { t, utc_s }
}

fn set_status(status: &SharedStatus, f: impl FnOnce(&mut StreamStatus)) {
    if let Ok(mut s) = status.lock() {
        f(&mut s);
    }
}

/// An open transport.
enum Conn {
    Stream(
        Box<dyn AsyncRead + Unpin + Send>,
        Box<dyn AsyncWrite + Unpin + Send>,
    ),
    Udp(tokio::net::UdpSocket),
}

async fn open(t: &Transport) -> std::io::Result<Conn> {
    match t {
        Transport::Serial { device, baud } => {
            // Never a read of an empty tty on the control loop's thread (super::tty).
            let (r, w) = super::tty::open(device, *baud)?;
            Ok(Conn::Stream(Box::new(r), Box::new(w)))
        }
        Transport::Tcp { host, port } => {
            let s = tokio::net::TcpStream::connect((host.as_str(), *port)).await?;
            s.set_nodelay(true)?;
            let (r, w) = s.into_split();
            Ok(Conn::Stream(Box::new(r), Box::new(w)))
        }
        Transport::Udp { bind, rtcm_to, .. } => {
            let s = tokio::net::UdpSocket::bind(bind).await?;
            if rtcm_to.is_some() {
                s.set_broadcast(true)?;
            }
            Ok(Conn::Udp(s))
        }
    }
}

/// A token bucket on received bytes (flood protection).
struct RateLimit {
    rate: f64,
    tokens: f64,
    last_t: f64,
}

impl RateLimit {
    fn new(rate: f64, t: f64) -> Self {
        RateLimit {
            rate,
            tokens: rate,
            last_t: t,
        }
    }
    /// Whether `n` bytes received at `t` may be taken.
    fn take(&mut self, n: usize, t: f64) -> bool {
        self.tokens = (self.tokens + self.rate * (t - self.last_t).max(0.0)).min(self.rate);
        self.last_t = t;
        if self.tokens >= n as f64 {
            self.tokens -= n as f64;
            true
        } else {
            false
        }
    }
}

/// Decode one chunk and publish it.
struct Sink<'a> {
    cfg: &'a StreamConfig,
    decoder: GnssDecoder,
    ports: &'a mut StreamPorts,
    limit: RateLimit,
    /// The latest quality report, for GGA.
    quality: (FixQuality, u8, f64),
    /// One chunk's inputs, in the order they go to the controller (reused: no allocation).
    pending: Vec<Input>,
}

/// Inputs per chunk kept without reallocating (a 4 kB chunk of short sentences is ~60).
const PENDING_INPUTS: usize = 64;

/// Put each heading of a chunk before the position it follows, when that position had no
/// heading before it (since the previous position, or the chunk's start). The controller
/// makes a fix of a position and the newest heading when the position arrives; most receivers
/// send an epoch's heading after its position (u-blox and Unicore: GGA before HDT;
/// NAV-HPPOSLLH before NAV-RELPOSNED), so without this the fix would carry the previous
/// epoch's heading, one GNSS period old. An epoch read in one chunk (a UDP datagram, a pty,
/// a USB CDC read) gets its own heading; a heading-first stream is left as it is; an epoch
/// split across reads keeps the arrival order.
fn heading_with_its_position(inputs: &mut [Input]) {
    let mut open_position = None;
    let mut unclaimed_heading = false;
    for k in 0..inputs.len() {
        match inputs.get(k) {
            Some(Input::Position(_)) => {
                open_position = (!unclaimed_heading).then_some(k);
                unclaimed_heading = false;
            }
            Some(Input::Heading(_)) => match open_position.take() {
                Some(p) => {
                    if let Some(run) = inputs.get_mut(p..=k) {
                        run.rotate_right(1);
                    }
                }
                None => unclaimed_heading = true,
            },
            _ => {}
        }
    }
}

impl Sink<'_> {
    fn chunk(&mut self, data: &[u8]) {
        let receipt = receipt_now(self.cfg.host_utc);
        if !self.limit.take(data.len(), receipt.t) {
            set_status(&self.ports.status, |s| s.dropped_bytes += data.len() as u64);
            return;
        }
        let age = self
            .ports
            .last_rtcm
            .as_ref()
            .and_then(|a| *a.borrow())
            .map(|last| (receipt.t - last).max(0.0));
        self.decoder.set_link_correction_age(age);
        let mut dropped = 0u64;
        let inputs = &self.ports.inputs;
        let position = &self.ports.position;
        let quality = &mut self.quality;
        let pending = &mut self.pending;
        pending.clear();
        self.decoder
            .push(data, &receipt, &mut |i| pending.push(i), &mut |_| {});
        heading_with_its_position(pending);
        for i in pending.drain(..) {
            match &i {
                Input::Quality(q) => {
                    *quality = (q.quality, q.satellites.unwrap_or(0), q.hdop.unwrap_or(1.0));
                }
                Input::Position(p) => {
                    if let Some(tx) = position {
                        tx.send_replace(Some(GgaSource {
                            lat_deg: p.lat_deg,
                            lon_deg: p.lon_deg,
                            altitude_m: p.altitude_m.unwrap_or(0.0),
                            quality: p.quality.unwrap_or(quality.0),
                            satellites: quality.1,
                            hdop: quality.2,
                        }));
                    }
                }
                _ => {}
            }
            if inputs.try_send(i).is_err() {
                dropped += 1;
            }
        }
        // A burst larger than usual (a buffer flushed after a stall) must not keep its
        // memory for ever.
        pending.shrink_to(PENDING_INPUTS);
        let counters = self.decoder.counters();
        set_status(&self.ports.status, |s| {
            s.counters = counters;
            s.checksum_errors = counters.checksum_errors();
            s.dropped_inputs += dropped;
            s.last_byte_t = Some(receipt.t);
        });
    }
}

/// Write the NTRIP corrections to a separate serial port (`gnss.rtcm_device`: a receiver's
/// second UART) for ever: reopened with back-off when it fails or disappears; frames queued
/// while it was away are dropped on reopening (old corrections are of no use). Bytes written
/// count in `status.rtcm_bytes_out`.
pub async fn run_rtcm_serial(
    device: PathBuf,
    baud: u32,
    mut rtcm: mpsc::Receiver<Vec<u8>>,
    status: SharedStatus,
    backoff_min_s: f64,
    backoff_max_s: f64,
) {
    let transport = Transport::Serial { device, baud };
    let mut backoff = backoff_min_s;
    let mut last_error = String::new();
    loop {
        let reason = match open(&transport).await {
            Ok(Conn::Stream(_, mut w)) => {
                tracing::info!("RTCM to {transport}: open");
                backoff = backoff_min_s;
                while rtcm.try_recv().is_ok() {}
                loop {
                    let Some(data) = rtcm.recv().await else {
                        return;
                    };
                    if let Err(e) = w.write_all(&data).await {
                        break format!("write error: {e}");
                    }
                    set_status(&status, |s| s.rtcm_bytes_out += data.len() as u64);
                }
            }
            Ok(Conn::Udp(_)) => return,
            Err(e) => format!("cannot open: {e}"),
        };
        if reason != last_error {
            tracing::warn!("RTCM to {transport}: {reason}; retrying");
            last_error = reason;
        }
        tokio::time::sleep(Duration::from_secs_f64(backoff)).await;
        backoff = (backoff * 2.0).min(backoff_max_s);
    }
}

/// Run one stream for ever (see the module doc).
pub async fn run_stream(cfg: StreamConfig, mut ports: StreamPorts) {
    let name = cfg.transport.to_string();
    set_status(&ports.status, |s| s.transport = name.clone());
    let mut sink = Sink {
        cfg: &cfg,
        decoder: GnssDecoder::new(cfg.decoder),
        limit: RateLimit::new(cfg.max_rate_bytes_s, crate::can::bus::monotonic_s()),
        ports: &mut ports,
        quality: (FixQuality::None, 0, 1.0),
        pending: Vec::with_capacity(PENDING_INPUTS),
    };
    let mut rtcm = sink.ports.rtcm.take();
    let mut backoff = cfg.backoff_min_s;
    let mut buf = vec![0u8; 4096];
    loop {
        let started = tokio::time::Instant::now();
        let reason = match open(&cfg.transport).await {
            Ok(conn) => {
                tracing::info!("GNSS stream {name}: open");
                set_status(&sink.ports.status, |s| s.connected = true);
                sink.decoder.reset();
                let reason = session(conn, &mut sink, &mut buf, &mut rtcm).await;
                set_status(&sink.ports.status, |s| {
                    s.connected = false;
                    s.reconnects += 1;
                });
                reason
            }
            Err(e) => format!("cannot open: {e}"),
        };
        let changed = sink
            .ports
            .status
            .lock()
            .map(|s| s.last_error.as_deref() != Some(reason.as_str()))
            .unwrap_or(true);
        if changed {
            tracing::warn!("GNSS stream {name}: {reason}; retrying");
        }
        set_status(&sink.ports.status, |s| s.last_error = Some(reason));
        // A session that lasted resets the back-off.
        if started.elapsed() > Duration::from_secs(10) {
            backoff = cfg.backoff_min_s;
        }
        tokio::time::sleep(Duration::from_secs_f64(backoff)).await;
        backoff = (backoff * 2.0).min(cfg.backoff_max_s);
    }
}

/// Read and write until the connection fails; the reason it ended.
async fn session(
    conn: Conn,
    sink: &mut Sink<'_>,
    buf: &mut [u8],
    rtcm: &mut Option<mpsc::Receiver<Vec<u8>>>,
) -> String {
    let silence = Duration::from_secs_f64(sink.cfg.silence_timeout_s);
    let status = sink.ports.status.clone();
    match conn {
        Conn::Stream(mut r, mut w) => {
            let reader = async {
                loop {
                    match tokio::time::timeout(silence, r.read(buf)).await {
                        Err(_) => return format!("no data for {:.1} s", silence.as_secs_f64()),
                        Ok(Ok(0)) => return "closed (end of stream)".to_string(),
                        Ok(Ok(n)) => sink.chunk(buf.get(..n).unwrap_or(&[])),
                        Ok(Err(e)) => return format!("read error: {e}"),
                    }
                }
            };
            let writer = async {
                let Some(rx) = rtcm.as_mut() else {
                    return std::future::pending::<String>().await;
                };
                while let Some(data) = rx.recv().await {
                    if let Err(e) = w.write_all(&data).await {
                        return format!("write error: {e}");
                    }
                    set_status(&status, |s| s.rtcm_bytes_out += data.len() as u64);
                }
                std::future::pending::<String>().await
            };
            tokio::select! {
                r = reader => r,
                w = writer => w,
            }
        }
        Conn::Udp(sock) => {
            let (filter, rtcm_to) = match &sink.cfg.transport {
                Transport::Udp {
                    source, rtcm_to, ..
                } => (*source, *rtcm_to),
                _ => (None, None),
            };
            let reader = async {
                loop {
                    match sock.recv_from(buf).await {
                        Ok((n, from)) => {
                            if filter.is_some_and(|ip| ip != from.ip()) {
                                set_status(&status, |s| s.filtered_datagrams += 1);
                            } else {
                                sink.chunk(buf.get(..n).unwrap_or(&[]));
                            }
                            // A flood must not starve the control loop on this thread.
                            tokio::task::coop::consume_budget().await;
                        }
                        Err(e) => return format!("receive error: {e}"),
                    }
                }
            };
            let writer = async {
                let (Some(rx), Some(to)) = (rtcm.as_mut(), rtcm_to) else {
                    return std::future::pending::<String>().await;
                };
                while let Some(data) = rx.recv().await {
                    match sock.send_to(&data, to).await {
                        Ok(n) => set_status(&status, |s| s.rtcm_bytes_out += n as u64),
                        Err(e) => tracing::debug!("RTCM to {to}: {e}"),
                    }
                }
                std::future::pending::<String>().await
            };
            tokio::select! {
                r = reader => r,
                w = writer => w,
            }
        }
    }
}

#[cfg(test)]
mod order_tests {
    use super::heading_with_its_position;
    use crate::input::{HeadingInput, HeadingReference, Input, PositionInput, SourceId};

    fn position(k: u8) -> Input {
        Input::Position(PositionInput {
            t: 0.0,
            source: SourceId::Stream(0),
            lat_deg: k as f64,
            lon_deg: 0.0,
            altitude_m: None,
            latency_s: None,
            quality: None,
        })
    }
    fn heading(k: u8) -> Input {
        Input::Heading(HeadingInput {
            t: 0.0,
            source: SourceId::Stream(0),
            heading: k as f64,
            reference: HeadingReference::True,
            variation: None,
        })
    }
    /// "P1" / "H1" for a position / heading of epoch 1.
    fn names(inputs: &[Input]) -> Vec<String> {
        inputs
            .iter()
            .map(|i| match i {
                Input::Position(p) => format!("P{}", p.lat_deg),
                Input::Heading(h) => format!("H{}", h.heading),
                _ => "?".into(),
            })
            .collect()
    }

    #[test]
    fn each_heading_goes_before_the_position_it_follows() {
        // GGA (position), RMC, HDT of epoch 1, then epoch 2; a chunk ending after a position.
        let mut v = vec![
            position(1),
            heading(1),
            position(2),
            heading(2),
            position(3),
        ];
        heading_with_its_position(&mut v);
        assert_eq!(names(&v), ["H1", "P1", "H2", "P2", "P3"]);
        // A heading that starts the chunk (the end of an epoch split across reads): the
        // arrival order is kept (it cannot be told from a heading-first stream).
        let mut v = vec![heading(0), position(1), heading(1)];
        heading_with_its_position(&mut v);
        assert_eq!(names(&v), ["H0", "P1", "H1"]);
        // Heading-first receivers are left as they are.
        let mut v = vec![heading(1), position(1), heading(2), position(2)];
        heading_with_its_position(&mut v);
        assert_eq!(names(&v), ["H1", "P1", "H2", "P2"]);
    }
}
