//! `agsteerd --bus-log FILE`: every frame in and out, in `candump -L` form
//! (`(t) iface ID#HEX`), which `agsteer replay`, `canplayer` and `agsteer dbc decode` read.
//!
//! The control loop never waits on the disk: it hands each frame (a `Copy` value, no
//! allocation) to a writer thread through a bounded channel with `try_send`; a full channel
//! drops the frame and counts it ([`BusLogStats::dropped`], shown by `agsteer status`). The
//! writer formats and writes through a buffer, flushes when the channel runs dry, and rotates
//! by size: when the next line would take `FILE` past the size limit, `FILE.{n-2}` →
//! `FILE.{n-1}`, …, `FILE` → `FILE.1` and a new `FILE` is started, so at most `files` files of
//! at most the size limit each are kept (the oldest is deleted). A non-empty `FILE` left by an
//! earlier run is rotated away at start, so each file holds one run of the daemon.
//!
//! Time stamps are the seconds the node saw (the receive time of a frame, the control period's
//! time of a command), written with 6 decimals; the daemon rounds its times to whole
//! microseconds so that a replay feeds the node exactly the same values.

use crate::can::candump::format_line;
use crate::can::Frame;
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError, SyncSender, TrySendError};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// Frames the channel holds before new ones are dropped (about 4 s of a busy 250 kbit/s bus).
pub const CHANNEL_FRAMES: usize = 8192;

/// Where and how much to log.
#[derive(Debug, Clone, PartialEq)]
pub struct BusLogParams {
    pub path: PathBuf,
    /// Interface name written on every line.
    pub interface: String,
    /// A file is rotated before it would exceed this many bytes (at least one line is written).
    pub max_bytes: u64,
    /// Files kept, the current one included (at least 1).
    pub files: u32,
}

/// Counters for `agsteer status`.
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct BusLogStats {
    pub path: String,
    /// Lines written.
    pub lines: u64,
    /// Frames dropped because the writer was behind (channel full) or the file failed.
    pub dropped: u64,
    pub rotations: u64,
    /// The last write error, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

#[derive(Default)]
struct Shared {
    lines: AtomicU64,
    dropped: AtomicU64,
    rotations: AtomicU64,
    failing: AtomicBool,
    error: Mutex<Option<String>>,
}

#[derive(Debug, Clone, Copy)]
struct Entry {
    t: f64,
    frame: Frame,
}

/// The logging side, held by the control loop.
pub struct BusLog {
    tx: SyncSender<Entry>,
    shared: Arc<Shared>,
    path: String,
}

/// Errors opening the log at start-up.
#[derive(Debug, thiserror::Error)]
pub enum BusLogError {
    #[error("--bus-log {path}: {source}")]
    Open {
        path: String,
        source: std::io::Error,
    },
}

/// `FILE.k` (k ≥ 1).
fn numbered(path: &Path, k: u32) -> PathBuf {
    let mut s = path.as_os_str().to_owned();
    s.push(format!(".{k}"));
    PathBuf::from(s)
}

/// Shift `FILE` → `FILE.1` → … keeping `files` files in all.
fn rotate(path: &Path, files: u32) -> std::io::Result<()> {
    if files <= 1 {
        return match std::fs::remove_file(path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e),
            _ => Ok(()),
        };
    }
    let _ = std::fs::remove_file(numbered(path, files - 1));
    for k in (1..files - 1).rev() {
        let from = numbered(path, k);
        if from.exists() {
            std::fs::rename(&from, numbered(path, k + 1))?;
        }
    }
    std::fs::rename(path, numbered(path, 1))
}

fn open(path: &Path) -> std::io::Result<std::io::BufWriter<std::fs::File>> {
    let f = std::fs::OpenOptions::new()
        .create(true)
        .write(true)
        .truncate(true)
        .open(path)?;
    Ok(std::io::BufWriter::with_capacity(64 * 1024, f))
}

impl BusLog {
    /// Open `params.path` (rotating a non-empty one away) and start the writer thread.
    pub fn start(params: BusLogParams) -> Result<BusLog, BusLogError> {
        let shown = params.path.display().to_string();
        let err = |source| BusLogError::Open {
            path: shown.clone(),
            source,
        };
        if let Some(dir) = params.path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(err)?;
        }
        if std::fs::metadata(&params.path).is_ok_and(|m| m.len() > 0) {
            rotate(&params.path, params.files.max(1)).map_err(err)?;
        }
        let file = open(&params.path).map_err(err)?;
        let (tx, rx) = mpsc::sync_channel::<Entry>(CHANNEL_FRAMES);
        let shared = Arc::new(Shared::default());
        let path = shown.clone();
        let writer = Writer {
            params,
            shared: shared.clone(),
            file: Some(file),
            bytes: 0,
        };
        std::thread::Builder::new()
            .name("agsteer-buslog".into())
            .spawn(move || writer.run(rx))
            .map_err(err)?;
        Ok(BusLog { tx, shared, path })
    }

    /// Log one frame seen or sent at `t` (s). Never blocks: a full channel drops it.
    pub fn record(&self, t: f64, frame: &Frame) {
        match self.tx.try_send(Entry { t, frame: *frame }) {
            Ok(()) => {}
            Err(TrySendError::Full(_)) | Err(TrySendError::Disconnected(_)) => {
                self.shared.dropped.fetch_add(1, Ordering::Relaxed);
            }
        }
    }

    pub fn stats(&self) -> BusLogStats {
        BusLogStats {
            path: self.path.clone(),
            lines: self.shared.lines.load(Ordering::Relaxed),
            dropped: self.shared.dropped.load(Ordering::Relaxed),
            rotations: self.shared.rotations.load(Ordering::Relaxed),
            error: self.shared.error.lock().ok().and_then(|e| e.clone()),
        }
    }

    /// Stop logging: the frames queued are written and the file flushed before this returns.
    pub fn finish(self, timeout: Duration) {
        let BusLog { tx, shared, .. } = self;
        drop(tx);
        let end = std::time::Instant::now() + timeout;
        while Arc::strong_count(&shared) > 1 && std::time::Instant::now() < end {
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

struct Writer {
    params: BusLogParams,
    shared: Arc<Shared>,
    file: Option<std::io::BufWriter<std::fs::File>>,
    bytes: u64,
}

impl Writer {
    fn run(mut self, rx: mpsc::Receiver<Entry>) {
        let mut line = String::with_capacity(64);
        loop {
            match rx.recv_timeout(Duration::from_millis(200)) {
                Ok(e) => {
                    line.clear();
                    line.push_str(&format_line(e.t, &self.params.interface, &e.frame));
                    line.push('\n');
                    self.write(&line);
                }
                Err(RecvTimeoutError::Timeout) => self.flush(),
                Err(RecvTimeoutError::Disconnected) => break,
            }
        }
        self.flush();
    }

    fn fail(&mut self, what: &str, e: std::io::Error) {
        if !self.shared.failing.swap(true, Ordering::Relaxed) {
            tracing::error!("bus log {}: {what}: {e}", self.params.path.display());
        }
        if let Ok(mut slot) = self.shared.error.lock() {
            *slot = Some(format!("{what}: {e}"));
        }
    }

    fn write(&mut self, line: &str) {
        let len = line.len() as u64;
        if self.bytes > 0 && self.bytes + len > self.params.max_bytes {
            self.flush();
            self.file = None;
            match rotate(&self.params.path, self.params.files.max(1)) {
                Ok(()) => {
                    self.shared.rotations.fetch_add(1, Ordering::Relaxed);
                }
                Err(e) => self.fail("rotating", e),
            }
            self.bytes = 0;
        }
        if self.file.is_none() {
            // Reopened after a rotation, or retried after a failure (at the next size step).
            match open(&self.params.path) {
                Ok(f) => self.file = Some(f),
                Err(e) => self.fail("opening", e),
            }
        }
        let Some(f) = self.file.as_mut() else {
            self.shared.dropped.fetch_add(1, Ordering::Relaxed);
            // Retry opening after as many bytes as would have been written.
            self.bytes += len;
            return;
        };
        match f.write_all(line.as_bytes()) {
            Ok(()) => {
                self.bytes += len;
                self.shared.lines.fetch_add(1, Ordering::Relaxed);
                if self.shared.failing.swap(false, Ordering::Relaxed) {
                    tracing::info!("bus log {} written again", self.params.path.display());
                }
            }
            Err(e) => {
                self.shared.dropped.fetch_add(1, Ordering::Relaxed);
                self.fail("writing", e);
                self.file = None;
                self.bytes += len;
            }
        }
    }

    fn flush(&mut self) {
        if let Some(f) = self.file.as_mut() {
            if let Err(e) = f.flush() {
                self.fail("writing", e);
                self.file = None;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::can::candump::parse_line;

    fn params(dir: &Path, max_bytes: u64, files: u32) -> BusLogParams {
        BusLogParams {
            path: dir.join("bus.log"),
            interface: "can0".into(),
            max_bytes,
            files,
        }
    }

    fn frames(n: u32) -> Vec<(f64, Frame)> {
        (0..n)
            .map(|k| {
                let t = 1000.0 + f64::from(k) * 0.01;
                (t, Frame::new(0x0CFF_202A + k % 3, &k.to_le_bytes()))
            })
            .collect()
    }

    fn read(path: &Path) -> Vec<(f64, Frame)> {
        std::fs::read_to_string(path)
            .unwrap_or_default()
            .lines()
            .map(|l| {
                let f = parse_line(l).unwrap_or_else(|| panic!("unreadable line {l:?}"));
                (f.t.unwrap(), f.frame)
            })
            .collect()
    }

    #[test]
    fn every_frame_is_written_in_candump_form_and_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let p = params(dir.path(), 1 << 20, 3);
        let log = BusLog::start(p.clone()).unwrap();
        let sent = frames(500);
        for (t, f) in &sent {
            log.record(*t, f);
        }
        let stats_before = log.stats();
        log.finish(Duration::from_secs(10));
        assert_eq!(read(&p.path), sent);
        assert_eq!(stats_before.dropped, 0);
        let text = std::fs::read_to_string(&p.path).unwrap();
        assert!(
            text.starts_with("(1000.000000) can0 0CFF202A#00000000\n"),
            "{text}"
        );
    }

    #[test]
    fn files_rotate_by_size_and_the_oldest_goes() {
        let dir = tempfile::tempdir().unwrap();
        // One line is 37 bytes: 10 lines per file.
        let p = params(dir.path(), 370, 3);
        let log = BusLog::start(p.clone()).unwrap();
        let sent = frames(45);
        for (t, f) in &sent {
            log.record(*t, f);
        }
        // Wait until written (the writer runs on its own).
        let end = std::time::Instant::now() + Duration::from_secs(10);
        while log.stats().lines < 45 && std::time::Instant::now() < end {
            std::thread::sleep(Duration::from_millis(5));
        }
        let st = log.stats();
        log.finish(Duration::from_secs(10));
        assert_eq!((st.lines, st.rotations, st.dropped), (45, 4, 0));
        // FILE holds the last 5 lines, FILE.1 and FILE.2 the 10 before each; FILE.3 is gone.
        assert_eq!(read(&p.path), sent[40..]);
        assert_eq!(read(&numbered(&p.path, 1)), sent[30..40]);
        assert_eq!(read(&numbered(&p.path, 2)), sent[20..30]);
        assert!(!numbered(&p.path, 3).exists());
        for f in [p.path.clone(), numbered(&p.path, 1), numbered(&p.path, 2)] {
            assert!(std::fs::metadata(&f).unwrap().len() <= 370);
        }
        // A new run rotates the last one's file away first.
        let log = BusLog::start(p.clone()).unwrap();
        log.record(5.0, &sent[0].1);
        log.finish(Duration::from_secs(10));
        assert_eq!(read(&p.path).len(), 1);
        assert_eq!(read(&numbered(&p.path, 1)), sent[40..]);
    }

    #[test]
    fn a_full_channel_drops_and_counts_instead_of_blocking() {
        // A writer that never reads: record() returns at once and counts what does not fit.
        let (tx, _rx) = mpsc::sync_channel::<Entry>(4);
        let log = BusLog {
            tx,
            shared: Arc::new(Shared::default()),
            path: "x".into(),
        };
        for (t, f) in frames(10) {
            log.record(t, &f);
        }
        assert_eq!(log.stats().dropped, 6);
    }

    #[test]
    fn an_unwritable_path_is_an_error_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let blocker = dir.path().join("file");
        std::fs::write(&blocker, "x").unwrap();
        let p = BusLogParams {
            path: blocker.join("bus.log"),
            ..params(dir.path(), 100, 2)
        };
        let e = BusLog::start(p).err().unwrap().to_string();
        assert!(e.contains("file/bus.log"), "{e}");
    }
}
