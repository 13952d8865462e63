//! The bounded file reader: every file agsteer reads whole goes through [`read_bytes`] or
//! [`read_text`], and every file it streams (candump logs) is opened by [`open_stream`].
//!
//! A path that is not a regular file (a directory, a FIFO, a socket, a device such as
//! `/dev/zero`) is refused at once, before anything is read, and without blocking: the file is
//! opened with `O_NONBLOCK` (opening a FIFO for reading would otherwise wait for a writer) and
//! checked with `fstat` on the open descriptor, so the check and the read concern the same
//! file. A regular file larger than its kind's limit is refused from its size before reading,
//! and the read itself is capped at the limit plus one byte, so a file that grows while it is
//! read cannot exceed it either.

use std::fs::File;
use std::io::Read;
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

/// What a file is for, which sets its size limit and names it in errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    /// A TOML configuration (or a fault scenario or an accuracy scenario).
    Config,
    /// A field: GeoJSON or TASKDATA.XML.
    Field,
    /// A manoeuvre map (GeoJSON in local metres).
    Map,
    /// A progress file.
    Progress,
    /// `agsteer maneuver --batch` JSON lines.
    Batch,
    /// A candump log (streamed line by line; only the per-line limit applies).
    Log,
}

impl FileKind {
    /// The kinds read whole, with a size limit.
    pub const ALL: [FileKind; 5] = [
        FileKind::Config,
        FileKind::Field,
        FileKind::Map,
        FileKind::Progress,
        FileKind::Batch,
    ];

    /// Largest size of a file of this kind, bytes.
    pub const fn max_bytes(self) -> u64 {
        const MIB: u64 = 1024 * 1024;
        match self {
            FileKind::Config => MIB,
            FileKind::Field => 16 * MIB,
            FileKind::Map => 16 * MIB,
            FileKind::Progress => MIB,
            FileKind::Batch => 16 * MIB,
            FileKind::Log => u64::MAX,
        }
    }

    /// The kind in words, for errors and the README table.
    pub const fn what(self) -> &'static str {
        match self {
            FileKind::Config => "configuration file",
            FileKind::Field => "field file",
            FileKind::Map => "manoeuvre map file",
            FileKind::Progress => "progress file",
            FileKind::Batch => "manoeuvre batch file",
            FileKind::Log => "candump log",
        }
    }
}

/// Why a file was refused or could not be read. The message names the kind, the path and,
/// for a size, the value and the limit.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    #[error("{what} {}: {source}", path.display())]
    Io {
        what: &'static str,
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{what} {}: is {found}, not a regular file", path.display())]
    NotAFile {
        what: &'static str,
        path: PathBuf,
        found: &'static str,
    },
    #[error("{what} {}: {size} bytes, over the limit of {limit} bytes for a {what}", path.display())]
    TooLarge {
        what: &'static str,
        path: PathBuf,
        size: u64,
        limit: u64,
    },
    #[error("{what} {}: not UTF-8 text (byte {offset})", path.display())]
    NotText {
        what: &'static str,
        path: PathBuf,
        offset: usize,
    },
}

impl FileError {
    /// The path the error is about.
    pub fn path(&self) -> &Path {
        match self {
            FileError::Io { path, .. }
            | FileError::NotAFile { path, .. }
            | FileError::TooLarge { path, .. }
            | FileError::NotText { path, .. } => path,
        }
    }

    /// The problem without the kind and path, for callers whose own error names the file.
    pub fn problem(&self) -> String {
        match self {
            FileError::Io { source, .. } => source.to_string(),
            FileError::NotAFile { found, .. } => format!("is {found}, not a regular file"),
            FileError::TooLarge {
                what, size, limit, ..
            } => {
                format!("{size} bytes, over the limit of {limit} bytes for a {what}")
            }
            FileError::NotText { offset, .. } => format!("not UTF-8 text (byte {offset})"),
        }
    }

    /// As an `std::io::Error` (same kind for I/O errors) whose message is [`Self::problem`],
    /// for errors that wrap an `io::Error` and name the path themselves.
    pub fn into_io(self) -> std::io::Error {
        match self {
            FileError::Io { source, .. } => source,
            other => std::io::Error::new(std::io::ErrorKind::InvalidData, other.problem()),
        }
    }

    /// Whether the file does not exist (some files, e.g. a progress file, are optional).
    pub fn is_not_found(&self) -> bool {
        matches!(self, FileError::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound)
    }
}

fn file_type_name(ft: std::fs::FileType) -> &'static str {
    if ft.is_dir() {
        "a directory"
    } else if ft.is_fifo() {
        "a FIFO"
    } else if ft.is_socket() {
        "a socket"
    } else if ft.is_char_device() {
        "a character device"
    } else if ft.is_block_device() {
        "a block device"
    } else {
        "not a regular file"
    }
}

/// Open `path` for reading if it is a regular file; refuse anything else without blocking.
/// Returns the file and its size.
fn open_regular(path: &Path, kind: FileKind) -> Result<(File, u64), FileError> {
    let what = kind.what();
    let io = |source| FileError::Io {
        what,
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
        .map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.file_type().is_file() {
        return Err(FileError::NotAFile {
            what,
            path: path.to_path_buf(),
            found: file_type_name(meta.file_type()),
        });
    }
    Ok((file, meta.len()))
}

/// Open a file to stream it (a log): refused unless it is a regular file.
pub fn open_stream(path: &Path, kind: FileKind) -> Result<File, FileError> {
    open_regular(path, kind).map(|(f, _)| f)
}

/// Read a whole file of `kind`: refused unless it is a regular file of at most
/// `kind.max_bytes()` bytes (checked before reading, and again while reading).
pub fn read_bytes(path: &Path, kind: FileKind) -> Result<Vec<u8>, FileError> {
    let limit = kind.max_bytes();
    let (file, size) = open_regular(path, kind)?;
    let too_large = |size| FileError::TooLarge {
        what: kind.what(),
        path: path.to_path_buf(),
        size,
        limit,
    };
    if size > limit {
        return Err(too_large(size));
    }
    let mut bytes = Vec::with_capacity(usize::try_from(size).unwrap_or(0));
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|source| FileError::Io {
            what: kind.what(),
            path: path.to_path_buf(),
            source,
        })?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// [`read_bytes`] as UTF-8 text.
pub fn read_text(path: &Path, kind: FileKind) -> Result<String, FileError> {
    let bytes = read_bytes(path, kind)?;
    String::from_utf8(bytes).map_err(|e| FileError::NotText {
        what: kind.what(),
        path: path.to_path_buf(),
        offset: e.utf8_error().valid_up_to(),
    })
}

/// One line of a line-oriented input, at most [`MAX_LINE_BYTES`](super::MAX_LINE_BYTES).
#[derive(Debug, PartialEq, Eq)]
pub enum Line {
    /// The line without its end (`\n` or `\r\n`), lossily decoded as UTF-8.
    Text(String),
    /// A line longer than the limit: its length (it was skipped, not held).
    TooLong(usize),
}

/// Read the next line of `input`, holding at most `max` bytes of it; `Ok(None)` at the end.
/// A longer line is consumed to its end and reported as [`Line::TooLong`].
pub fn next_line(input: &mut impl std::io::BufRead, max: usize) -> std::io::Result<Option<Line>> {
    let mut buf = Vec::new();
    let mut len = 0usize;
    let mut seen_any = false;
    loop {
        let chunk = match input.fill_buf() {
            Ok(c) => c,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        if chunk.is_empty() {
            break;
        }
        seen_any = true;
        let (take, done) = match chunk.iter().position(|&b| b == b'\n') {
            Some(i) => (i, true),
            None => (chunk.len(), false),
        };
        if len + take <= max {
            buf.extend_from_slice(&chunk[..take]);
        }
        len += take;
        input.consume(if done { take + 1 } else { take });
        if done {
            break;
        }
    }
    if !seen_any {
        return Ok(None);
    }
    if len > max {
        return Ok(Some(Line::TooLong(len)));
    }
    if buf.last() == Some(&b'\r') {
        buf.pop();
    }
    Ok(Some(Line::Text(String::from_utf8_lossy(&buf).into_owned())))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    #[test]
    fn a_directory_is_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let e = read_bytes(dir.path(), FileKind::Config).unwrap_err();
        assert!(matches!(e, FileError::NotAFile { .. }), "{e:?}");
        let msg = e.to_string();
        assert!(msg.contains(&dir.path().display().to_string()), "{msg}");
        assert!(msg.contains("directory"), "{msg}");
    }

    #[test]
    fn a_device_is_refused_before_reading() {
        let e = read_bytes(Path::new("/dev/zero"), FileKind::Field).unwrap_err();
        assert!(matches!(e, FileError::NotAFile { .. }), "{e:?}");
        assert!(e.to_string().contains("/dev/zero"), "{e}");
        assert!(e.to_string().contains("character device"), "{e}");
    }

    #[test]
    fn a_fifo_is_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("fifo");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo on a NUL-terminated path we own; no memory is shared.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let e = read_bytes(&fifo, FileKind::Progress).unwrap_err();
        assert!(e.to_string().contains("FIFO"), "{e}");
        assert!(open_stream(&fifo, FileKind::Log).is_err());
    }

    #[test]
    fn an_oversize_file_is_refused_with_size_and_limit() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("big.toml");
        let f = File::create(&p).unwrap();
        f.set_len(FileKind::Config.max_bytes() + 1).unwrap();
        let e = read_bytes(&p, FileKind::Config).unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, FileError::TooLarge { .. }), "{e:?}");
        assert!(msg.contains("1048577 bytes"), "{msg}");
        assert!(msg.contains("limit of 1048576"), "{msg}");
    }

    #[test]
    fn a_small_file_is_read_and_missing_is_not_found() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.toml");
        File::create(&p).unwrap().write_all(b"x = 1\n").unwrap();
        assert_eq!(read_text(&p, FileKind::Config).unwrap(), "x = 1\n");
        let e = read_text(&dir.path().join("none"), FileKind::Config).unwrap_err();
        assert!(e.is_not_found());
        File::create(&p).unwrap().write_all(b"\xff\xfe").unwrap();
        assert!(matches!(
            read_text(&p, FileKind::Config),
            Err(FileError::NotText { offset: 0, .. })
        ));
    }

    #[test]
    fn long_lines_are_skipped_not_held() {
        let mut text = b"short\r\n".to_vec();
        text.extend(std::iter::repeat_n(b'x', 100));
        text.extend(b"\nlast");
        let mut r = std::io::BufReader::with_capacity(8, &text[..]);
        assert_eq!(
            next_line(&mut r, 10).unwrap(),
            Some(Line::Text("short".into()))
        );
        assert_eq!(next_line(&mut r, 10).unwrap(), Some(Line::TooLong(100)));
        assert_eq!(
            next_line(&mut r, 10).unwrap(),
            Some(Line::Text("last".into()))
        );
        assert_eq!(next_line(&mut r, 10).unwrap(), None);
        let mut empty = std::io::BufReader::new(&b"\n"[..]);
        assert_eq!(
            next_line(&mut empty, 10).unwrap(),
            Some(Line::Text(String::new()))
        );
        assert_eq!(next_line(&mut empty, 10).unwrap(), None);
    }
}
