//! The operator's job book (issue 16 point 5): the AB lines recorded by set A / set B and the
//! job selected, kept in `jobs.json` in the state directory so that a restart drives the job
//! the operator chose (and resumes its progress). Written as the progress file is (atomic,
//! exclusive temp file, fsync, rename; refused through a link), with a CRC-32C line; a corrupt
//! file is moved aside and the configured job is driven.

use super::progress_file::{move_aside_as, read_state_file, save_bytes, ProgressFileError};
use crate::geo::wgs84::LatLon;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// File name of the job book inside the state directory.
pub const JOBS_FILE_NAME: &str = "jobs.json";
/// The most lines a book records (select_job numbers them 1..=250).
pub const MAX_LINES: usize = 250;

const CRC: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);
const CHECKSUM_TAG: &str = "crc32c";

/// An AB line recorded by set A / set B (WGS-84, so it does not depend on a job's origin).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordedLine {
    pub a: LatLon,
    pub b: LatLon,
}

/// The recorded lines and the job selected: 0 the configured job, k the k-th line.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JobBook {
    pub selected: u8,
    pub lines: Vec<RecordedLine>,
}

impl JobBook {
    /// The line job `k` (1-based) names.
    pub fn line(&self, k: u8) -> Option<&RecordedLine> {
        (k as usize).checked_sub(1).and_then(|i| self.lines.get(i))
    }

    /// Record a line (the oldest goes when the book is full); its job number.
    pub fn record(&mut self, line: RecordedLine) -> u8 {
        if self.lines.len() >= MAX_LINES {
            self.lines.remove(0);
        }
        self.lines.push(line);
        self.lines.len() as u8
    }

    /// The file's text with its checksum line.
    pub fn encode(&self) -> String {
        let body = serde_json::to_string(self).unwrap_or_else(|_| String::from("{}"));
        let crc = CRC.checksum(body.as_bytes());
        format!("{body}\n{CHECKSUM_TAG} {crc:08x} {}\n", body.len())
    }

    /// Decode and check (checksum, line count, the selection names a line, finite points).
    pub fn decode(bytes: &[u8]) -> Result<JobBook, String> {
        let text = std::str::from_utf8(bytes).map_err(|_| "not UTF-8".to_string())?;
        let text = text
            .strip_suffix('\n')
            .ok_or("truncated (no checksum line)")?;
        let (body, check) = text
            .rsplit_once('\n')
            .ok_or("truncated (no checksum line)")?;
        let expected = format!(
            "{CHECKSUM_TAG} {:08x} {}",
            CRC.checksum(body.as_bytes()),
            body.len()
        );
        if check != expected {
            return Err(format!("checksum line {check:?}, content is {expected:?}"));
        }
        let book: JobBook = serde_json::from_str(body).map_err(|e| e.to_string())?;
        if book.lines.len() > MAX_LINES {
            return Err(format!("{} lines, at most {MAX_LINES}", book.lines.len()));
        }
        if book.selected as usize > book.lines.len() {
            return Err(format!(
                "selected {}: only {} lines recorded",
                book.selected,
                book.lines.len()
            ));
        }
        let ok = |p: &LatLon| p.lat_deg.abs() <= 90.0 && p.lon_deg.abs() <= 180.0;
        if let Some(i) = book.lines.iter().position(|l| !(ok(&l.a) && ok(&l.b))) {
            return Err(format!("line {}: a point off the globe", i + 1));
        }
        Ok(book)
    }
}

/// The job book's path in `state_dir`.
pub fn jobs_path(state_dir: &Path) -> PathBuf {
    state_dir.join(JOBS_FILE_NAME)
}

/// Save atomically (see [`crate::store::progress_file::save`]).
pub fn save(path: &Path, book: &JobBook) -> Result<(), ProgressFileError> {
    save_bytes(path, ".jobs.json.", book.encode().as_bytes())
}

/// Load the book: an empty one when there is no file; a corrupt file is moved aside
/// (`jobs.json.corrupt-N`) and reported.
pub fn load(path: &Path) -> Result<JobBook, ProgressFileError> {
    match read_state_file(path)? {
        None => Ok(JobBook::default()),
        Some(bytes) => JobBook::decode(&bytes).map_err(|reason| move_aside_as(path, reason)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn book() -> JobBook {
        let p = |lat_deg, lon_deg| LatLon { lat_deg, lon_deg };
        JobBook {
            selected: 2,
            lines: vec![
                RecordedLine {
                    a: p(52.0, 5.0),
                    b: p(52.001, 5.0),
                },
                RecordedLine {
                    a: p(52.0, 5.001),
                    b: p(52.001, 5.002),
                },
            ],
        }
    }

    #[test]
    fn round_trip_and_every_corruption_refused() {
        let b = book();
        let text = b.encode();
        assert_eq!(JobBook::decode(text.as_bytes()).unwrap(), b);
        for i in 0..text.len() - 1 {
            let mut bytes = text.clone().into_bytes();
            bytes[i] ^= 0x01;
            assert!(JobBook::decode(&bytes).is_err(), "flip at {i}");
        }
        let bad = JobBook {
            selected: 3,
            ..book()
        };
        assert!(JobBook::decode(bad.encode().as_bytes())
            .unwrap_err()
            .contains("selected 3"));
    }

    #[test]
    fn saved_book_loads_and_a_corrupt_one_is_moved_aside() {
        let dir = tempfile::tempdir().unwrap();
        let path = jobs_path(&dir.path().join("state"));
        assert_eq!(load(&path).unwrap(), JobBook::default());
        save(&path, &book()).unwrap();
        assert_eq!(load(&path).unwrap(), book());
        std::fs::write(&path, "{}\n").unwrap();
        let e = load(&path).unwrap_err().to_string();
        assert!(e.contains("moved aside"), "{e}");
        assert!(!path.exists());
        assert_eq!(load(&path).unwrap(), JobBook::default());
    }

    #[test]
    fn a_full_book_drops_its_oldest_line() {
        let mut b = JobBook::default();
        let l = book().lines[0];
        for _ in 0..MAX_LINES {
            b.record(l);
        }
        assert_eq!(b.record(book().lines[1]), MAX_LINES as u8);
        assert_eq!(b.lines.len(), MAX_LINES);
        assert_eq!(b.line(MAX_LINES as u8), Some(&book().lines[1]));
        assert_eq!(b.line(0), None);
    }
}
