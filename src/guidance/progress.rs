//! Job progress that survives power loss: a pure encoding with a checksum inside.
//!
//! The file holds two lines: the progress as one JSON object, then `crc32c <hex> <length>`
//! computed over the exact bytes of the first line. Anything that does not match is corrupt and
//! is never trusted. File handling (temp file, fsync, rename) lives in
//! [`crate::store::progress_file`].

use serde::{Deserialize, Serialize};

const CRC: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);
/// First word of the checksum line.
const CHECKSUM_TAG: &str = "crc32c";
/// Format version written into every file.
pub const PROGRESS_VERSION: u32 = 1;

/// The parameters that define a job (the configuration's job keys, filled in by the
/// configuration layer, and a segment job's checksum). A saved progress only applies to the
/// same job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JobDefinition {
    pub point_a_m: [f64; 2],
    pub point_b_m: [f64; 2],
    pub line_width_m: f64,
    pub line_num: u64,
    pub r_min_m: f64,
    pub side: crate::plan::types::Side,
    pub a: i64,
    pub point_spacing_m: f64,
    /// For a segment job (a field plan): the CRC-32C of its segments
    /// ([`SegmentJob::checksum`](crate::plan::job::SegmentJob::checksum)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plan_checksum: Option<u32>,
}

impl JobDefinition {
    /// This definition for the job `plan`: a segment job adds its checksum.
    pub fn with_plan(mut self, plan: &crate::plan::job::JobPlan) -> Self {
        if let crate::plan::job::JobPlan::Segments(s) = plan {
            self.plan_checksum = Some(s.checksum());
        }
        self
    }
}

/// What the job is doing at the saved moment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Driving the work line at (block, rank).
    Work,
    /// Turning into the work line at (block, rank).
    Turn,
    /// Every line is done.
    Finished,
}

/// Where a job stands. Lines are driven in a fixed order, so the finished lines are exactly
/// the first `lines_done` positions of that order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Progress {
    pub version: u32,
    pub job: JobDefinition,
    /// Block of the line being driven or turned into.
    pub index_block: u64,
    /// Rank in the block's order of that line.
    pub index_rank: u64,
    pub phase: Phase,
    /// Lines finished so far.
    pub lines_done: u64,
}

/// Why a progress file cannot be trusted.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ProgressError {
    #[error("progress file is truncated (no checksum line)")]
    Truncated,
    #[error("progress checksum line is malformed: {0:?}")]
    BadChecksumLine(String),
    #[error("progress checksum mismatch: file says {stored:08x}/{stored_len} bytes, content is {actual:08x}/{actual_len} bytes")]
    ChecksumMismatch {
        stored: u32,
        stored_len: usize,
        actual: u32,
        actual_len: usize,
    },
    #[error("progress content is not valid: {0}")]
    Content(String),
    #[error("progress format version {0} is not supported (expected {PROGRESS_VERSION})")]
    Version(u32),
}

impl Progress {
    /// Encode with the checksum line.
    pub fn encode(&self) -> String {
        let body = serde_json::to_string(self).unwrap_or_else(|_| String::from("{}"));
        let crc = CRC.checksum(body.as_bytes());
        format!("{body}\n{CHECKSUM_TAG} {crc:08x} {}\n", body.len())
    }

    /// Decode and verify. Never trusts content whose checksum does not match.
    pub fn decode(bytes: &[u8]) -> Result<Progress, ProgressError> {
        let text =
            std::str::from_utf8(bytes).map_err(|_| ProgressError::Content("not UTF-8".into()))?;
        let text = text.strip_suffix('\n').ok_or(ProgressError::Truncated)?;
        let (body, check) = text.rsplit_once('\n').ok_or(ProgressError::Truncated)?;
        let mut words = check.split(' ');
        let (tag, hex, len) = (words.next(), words.next(), words.next());
        let (stored, stored_len) = match (tag, hex, len, words.next()) {
            (Some(CHECKSUM_TAG), Some(h), Some(l), None) => (
                u32::from_str_radix(h, 16)
                    .map_err(|_| ProgressError::BadChecksumLine(check.into()))?,
                l.parse::<usize>()
                    .map_err(|_| ProgressError::BadChecksumLine(check.into()))?,
            ),
            _ => return Err(ProgressError::BadChecksumLine(check.into())),
        };
        let actual = CRC.checksum(body.as_bytes());
        if actual != stored || stored_len != body.len() {
            return Err(ProgressError::ChecksumMismatch {
                stored,
                stored_len,
                actual,
                actual_len: body.len(),
            });
        }
        let p: Progress =
            serde_json::from_str(body).map_err(|e| ProgressError::Content(e.to_string()))?;
        if p.version != PROGRESS_VERSION {
            return Err(ProgressError::Version(p.version));
        }
        Ok(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Progress {
        Progress {
            version: PROGRESS_VERSION,
            job: crate::config::Config::default().job_definition(),
            index_block: 2,
            index_rank: 5,
            phase: Phase::Turn,
            lines_done: 23,
        }
    }

    #[test]
    fn round_trip() {
        let p = sample();
        assert_eq!(Progress::decode(p.encode().as_bytes()), Ok(p));
    }

    #[test]
    fn every_truncation_is_rejected() {
        let enc = sample().encode();
        for n in 0..enc.len() {
            assert!(
                Progress::decode(&enc.as_bytes()[..n]).is_err(),
                "truncated to {n} bytes was accepted"
            );
        }
    }

    #[test]
    fn every_single_byte_flip_in_body_is_rejected() {
        let enc = sample().encode();
        let body_len = enc.find('\n').unwrap();
        for i in 0..body_len {
            let mut b = enc.clone().into_bytes();
            b[i] ^= 0x01;
            assert!(Progress::decode(&b).is_err(), "flip at {i} accepted");
        }
    }
}
