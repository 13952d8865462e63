//! `agsteer sim --gnss-pty LINK` / `--gnss-udp ADDR`: the simulator as a serial or UDP GNSS
//! receiver. Its GNSS measurements leave as NMEA 0183 sentences or UBX messages
//! ([`GnssStreamEncoder`]) on a pseudo-terminal (the link names its slave device, which
//! agsteerd opens as `gnss.device`) or in UDP datagrams (one per epoch, as an AgOpenGPS board
//! sends them), instead of NMEA 2000 frames on the bus; wheel angle, speed and steering stay
//! on CAN.

use agsteer::can::bus::monotonic_s;
use agsteer::geo::wgs84::EnuFrame;
use agsteer::io::pty::Pty;
use agsteer::sim::can_node::SimNode;
use agsteer::sim::gnss_stream::{GnssStreamEncoder, GnssStreamParams, StreamMessage};
use agsteer::sim::GnssMeasurement;
use anyhow::{Context, Result};
use std::io::Write;
use std::net::{SocketAddr, UdpSocket};
use std::path::{Path, PathBuf};

/// The GNSS options of `agsteer sim`.
#[derive(Debug, Clone, Default)]
pub struct SimGnssArgs {
    pub pty: Option<PathBuf>,
    pub udp: Option<SocketAddr>,
    /// An epoch's messages, in sending order.
    pub messages: Vec<StreamMessage>,
    pub log: Option<PathBuf>,
}

impl SimGnssArgs {
    /// The sink chosen (`None`: GNSS as NMEA 2000 frames on the bus).
    pub fn sink(&self) -> Result<Option<GnssSink>> {
        match (&self.pty, self.udp) {
            (Some(link), None) => GnssSink::pty(link).map(Some),
            (None, Some(to)) => GnssSink::udp(to).map(Some),
            (None, None) => Ok(None),
            (Some(_), Some(_)) => anyhow::bail!("--gnss-pty and --gnss-udp: choose one"),
        }
    }
}

/// Where the simulated receiver's bytes go.
pub enum GnssSink {
    /// A pseudo-terminal; `link` is a symbolic link to its slave device.
    Pty { pty: Pty, link: PathBuf },
    /// Datagrams to `to`.
    Udp { socket: UdpSocket, to: SocketAddr },
}

impl GnssSink {
    /// A new pseudo-terminal behind the symbolic link `link` (an earlier link there is
    /// replaced; any other file is left alone and is an error).
    pub fn pty(link: &Path) -> Result<GnssSink> {
        let pty = Pty::open().context("opening a pseudo-terminal")?;
        pty.set_nonblocking()
            .context("making the pseudo-terminal non-blocking")?;
        if std::fs::symlink_metadata(link).is_ok_and(|m| m.file_type().is_symlink()) {
            std::fs::remove_file(link).with_context(|| format!("removing {}", link.display()))?;
        }
        std::os::unix::fs::symlink(pty.path(), link).with_context(|| {
            format!(
                "linking {} to the pseudo-terminal {}",
                link.display(),
                pty.path().display()
            )
        })?;
        tracing::info!(
            "simulated GNSS receiver on {} ({})",
            link.display(),
            pty.path().display()
        );
        Ok(GnssSink::Pty {
            pty,
            link: link.to_path_buf(),
        })
    }

    /// A UDP sender to `to`.
    pub fn udp(to: SocketAddr) -> Result<GnssSink> {
        let bind: SocketAddr = if to.is_ipv4() {
            ([0, 0, 0, 0], 0).into()
        } else {
            (std::net::Ipv6Addr::UNSPECIFIED, 0).into()
        };
        let socket = UdpSocket::bind(bind).context("binding a UDP socket")?;
        socket.set_nonblocking(true)?;
        socket.set_broadcast(true)?;
        tracing::info!("simulated GNSS receiver sending UDP to {to}");
        Ok(GnssSink::Udp { socket, to })
    }

    /// Write one epoch's bytes; false if they were not taken (nobody reading a full pty,
    /// nobody listening on the port).
    fn send(&mut self, bytes: &[u8]) -> bool {
        match self {
            GnssSink::Pty { pty, .. } => {
                let mut m = pty.master();
                m.write_all(bytes).is_ok()
            }
            GnssSink::Udp { socket, to } => socket.send_to(bytes, *to).is_ok(),
        }
    }
}

impl Drop for GnssSink {
    fn drop(&mut self) {
        if let GnssSink::Pty { link, .. } = self {
            let _ = std::fs::remove_file(link);
        }
    }
}

/// The simulator's GNSS leaving on a [`GnssSink`].
pub struct GnssOut {
    sink: GnssSink,
    encoder: GnssStreamEncoder,
    measurements: Vec<GnssMeasurement>,
    bytes: Vec<u8>,
    /// `--gnss-log`: each epoch's write time (UTC s, the clock of candump's timestamps), taken
    /// just before the write.
    log: Option<std::io::BufWriter<std::fs::File>>,
    pub epochs: u64,
    pub unsent: u64,
}

/// UTC now, s since 1970-01-01.
fn utc_now() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

impl GnssOut {
    /// `t0`: the monotonic time that is the simulator's time 0; UTC is stamped from the host
    /// clock at that moment.
    pub fn new(
        sink: GnssSink,
        messages: Vec<StreamMessage>,
        enu: EnuFrame,
        t0: f64,
        log: Option<&Path>,
    ) -> Result<GnssOut> {
        let utc_at_zero = utc_now() - (monotonic_s() - t0);
        let log = match log {
            Some(p) => {
                let mut f = std::io::BufWriter::new(
                    std::fs::File::create(p)
                        .with_context(|| format!("creating {}", p.display()))?,
                );
                writeln!(f, "utc_s,t_measured_s")?;
                Some(f)
            }
            None => None,
        };
        Ok(GnssOut {
            sink,
            encoder: GnssStreamEncoder::new(GnssStreamParams::new(messages, utc_at_zero), enu),
            measurements: Vec::with_capacity(8),
            bytes: Vec::with_capacity(1024),
            log,
            epochs: 0,
            unsent: 0,
        })
    }

    /// Send the measurements the node has delivered since the last call.
    pub fn pump(&mut self, node: &mut SimNode) -> Result<()> {
        self.measurements.clear();
        node.drain_gnss(&mut self.measurements);
        for m in &self.measurements {
            self.bytes.clear();
            self.encoder.encode(m, &mut self.bytes);
            self.epochs += 1;
            // Stamped before the write: the reader may have the epoch before this thread goes
            // on (as a position frame's candump time is its send's).
            let sent = utc_now();
            if !self.sink.send(&self.bytes) {
                self.unsent += 1;
            }
            if let Some(f) = self.log.as_mut() {
                writeln!(f, "{sent:.6},{:.3}", m.t_measured)?;
            }
        }
        if !self.measurements.is_empty() {
            if let Some(f) = self.log.as_mut() {
                f.flush()?;
            }
        }
        Ok(())
    }
}
