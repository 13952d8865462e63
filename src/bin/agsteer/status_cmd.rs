//! `agsteer status`: ask the daemon's status socket, within an overall deadline and a reply
//! size limit (a peer that trickles a byte at a time or streams without end cannot hang or
//! grow the tool).

use anyhow::{bail, Context, Result};
use std::io::{ErrorKind, Read};
use std::os::unix::net::UnixStream;
use std::path::Path;
use std::time::{Duration, Instant};

/// The largest status reply read, bytes (a reply is a few kB).
pub const MAX_REPLY_BYTES: usize = 1024 * 1024;

/// Read the status JSON from `socket` and print it pretty. The whole exchange (connect and
/// read to the end) must finish within `timeout_s`; errors name the socket and the limit.
pub fn status(socket: &Path, timeout_s: f64) -> Result<u8> {
    let v = query(socket, timeout_s)?;
    println!("{}", serde_json::to_string_pretty(&v)?);
    Ok(0)
}

/// The status JSON from `socket`, within `timeout_s` (see [`status`]).
pub fn query(socket: &Path, timeout_s: f64) -> Result<serde_json::Value> {
    if !(timeout_s.is_finite() && timeout_s > 0.0 && timeout_s <= 3600.0) {
        bail!("--timeout-s {timeout_s}: must be in (0, 3600] s");
    }
    let timeout = Duration::from_secs_f64(timeout_s);
    let deadline = Instant::now() + timeout;
    let late = || {
        anyhow::anyhow!(
            "no complete status reply from {} within the deadline of {timeout_s} s (--timeout-s)",
            socket.display()
        )
    };
    let mut s = UnixStream::connect(socket)
        .with_context(|| format!("connecting to the status socket {}", socket.display()))?;
    let mut reply = Vec::new();
    let mut buf = [0u8; 8192];
    loop {
        let left = deadline
            .checked_duration_since(Instant::now())
            .filter(|d| !d.is_zero())
            .ok_or_else(late)?;
        s.set_read_timeout(Some(left))
            .with_context(|| format!("status socket {}", socket.display()))?;
        match s.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => {
                reply.extend_from_slice(buf.get(..n).unwrap_or_default());
                if reply.len() > MAX_REPLY_BYTES {
                    bail!(
                        "status reply from {} is over the limit of {MAX_REPLY_BYTES} bytes",
                        socket.display()
                    );
                }
            }
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
                return Err(late())
            }
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => {
                return Err(e)
                    .with_context(|| format!("reading the status socket {}", socket.display()))
            }
        }
    }
    let text = std::str::from_utf8(&reply)
        .with_context(|| format!("status reply from {} is not UTF-8", socket.display()))?;
    serde_json::from_str(text.trim())
        .with_context(|| format!("status reply from {} is not JSON", socket.display()))
}
