//! The files agsteer reads and writes besides its configuration: the progress file (atomic,
//! checksummed; a corrupt one is moved aside) and the job's input files (a field, a manoeuvre
//! map).
//!
//! Contract: file I/O only, blocking, done at start-up or on a writer thread, never in the
//! control loop. What the bytes mean is decided elsewhere ([`crate::guidance::progress`]
//! encodes progress, [`crate::field`] parses fields); whether a saved progress belongs to the
//! job is the job layer's question ([`crate::job::resume`]).

pub mod progress_file;

use crate::envelope::{FileError, FileKind};
use std::path::Path;

/// Read a job's input file (a field, a manoeuvre map) as text, through the bounded reader of
/// the input envelope (a directory, FIFO, device or over-size file is refused at once).
pub fn read_input(path: &Path, kind: FileKind) -> Result<String, FileError> {
    crate::envelope::read_text(path, kind)
}
