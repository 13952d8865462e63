//! `AGSTEER_FIX_TRACE=FILE`: each GNSS fix's times in the daemon, one CSV line per fix, for
//! the VM's latency tests to split a fix's arrival → command time into the kernel's part and
//! the daemon's. Off unless the variable is set. The control loop hands a fixed-size record to
//! a writer thread through a bounded channel (no allocation, never waits: a full channel drops
//! the record); times are on the realtime clock (UTC s), as candump's and the simulator's.

use std::io::Write;
use std::sync::mpsc;

/// One fix's times, monotonic s: read (the frame or chunk received), taken by the loop,
/// its period's frames ready, handed to the socket.
#[derive(Debug, Clone, Copy)]
pub struct FixRecord {
    pub read: f64,
    pub taken: f64,
    pub ready: f64,
    pub left: f64,
    /// Realtime − monotonic at `left`, s.
    pub utc_offset: f64,
}

/// The writer's end, when tracing is on.
pub struct FixTrace {
    tx: mpsc::SyncSender<FixRecord>,
}

impl FixTrace {
    /// From `AGSTEER_FIX_TRACE`; `None` when unset or the file cannot be made.
    pub fn from_env() -> Option<FixTrace> {
        let path = std::env::var_os("AGSTEER_FIX_TRACE")?;
        let file = std::fs::File::create(&path)
            .map_err(|e| tracing::warn!("AGSTEER_FIX_TRACE: {e}"))
            .ok()?;
        let (tx, rx) = mpsc::sync_channel::<FixRecord>(256);
        std::thread::Builder::new()
            .name("agsteer-fixtrace".into())
            .spawn(move || {
                let mut f = std::io::BufWriter::new(file);
                let _ = writeln!(f, "read_utc,taken_utc,ready_utc,left_utc");
                for r in rx {
                    let o = r.utc_offset;
                    let _ = writeln!(
                        f,
                        "{:.6},{:.6},{:.6},{:.6}",
                        r.read + o,
                        r.taken + o,
                        r.ready + o,
                        r.left + o
                    );
                    let _ = f.flush();
                }
            })
            .ok()?;
        tracing::info!("fix trace to {}", std::path::Path::new(&path).display());
        Some(FixTrace { tx })
    }

    pub fn record(&self, r: FixRecord) {
        let _ = self.tx.try_send(r);
    }
}

/// Realtime − monotonic now, s.
pub fn utc_offset() -> f64 {
    let utc = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0);
    utc - crate::can::bus::monotonic_s()
}
