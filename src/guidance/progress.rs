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
pub const PROGRESS_VERSION: u32 = 2;

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
    /// The plan's identity: every input of the driven order and geometry, by name (the
    /// planner's revision, the job kind, the ENU origin, every field of the planner's
    /// parameters as resolved, the plan's checksum), filled in by the job layer
    /// (`job::identity`). Progress saved under another identity is not resumed.
    pub identity: std::collections::BTreeMap<String, String>,
}

impl JobDefinition {
    /// What differs between this definition and `saved`, one line each naming the item with
    /// the saved and the current value (empty when they are equal).
    pub fn differences(&self, saved: &JobDefinition) -> Vec<String> {
        let (mut now, mut then) = (Vec::new(), Vec::new());
        flatten_json(
            "",
            &serde_json::to_value(self).unwrap_or_default(),
            &mut now,
        );
        flatten_json(
            "",
            &serde_json::to_value(saved).unwrap_or_default(),
            &mut then,
        );
        let now: std::collections::BTreeMap<_, _> = now.into_iter().collect();
        let then: std::collections::BTreeMap<_, _> = then.into_iter().collect();
        let mut keys: Vec<&String> = now.keys().chain(then.keys()).collect();
        keys.sort();
        keys.dedup();
        keys.into_iter()
            .filter(|k| now.get(*k) != then.get(*k))
            .map(|k| {
                let show = |v: Option<&String>| v.map_or("(none)", String::as_str).to_string();
                format!(
                    "{}: saved {}, now {}",
                    k.strip_prefix("identity.").unwrap_or(k),
                    show(then.get(k)),
                    show(now.get(k))
                )
            })
            .collect()
    }

    /// This definition for the job `plan`: a segment job adds its checksum.
    pub fn with_plan(mut self, plan: &crate::plan::job::JobPlan) -> Self {
        if let crate::plan::job::JobPlan::Segments(s) = plan {
            self.plan_checksum = Some(s.checksum());
        }
        self
    }
}

/// Dotted paths and leaf values of a JSON value.
fn flatten_json(prefix: &str, v: &serde_json::Value, out: &mut Vec<(String, String)>) {
    match v {
        serde_json::Value::Object(m) => {
            for (k, v) in m {
                let key = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                flatten_json(&key, v, out);
            }
        }
        serde_json::Value::String(s) => out.push((prefix.to_string(), s.clone())),
        other => out.push((prefix.to_string(), other.to_string())),
    }
}

/// Flatten a value's `Debug` text (`Name { field: value, inner: Inner { … } }`) into
/// `prefix.field` → value entries, so every field of a parameter struct is named without a
/// hand-written list (a new field is included by itself). Lists, tuples and enum payloads
/// stay whole values.
pub fn flatten_debug(
    prefix: &str,
    text: &str,
    out: &mut std::collections::BTreeMap<String, String>,
) {
    let text = text.trim();
    let body = text
        .find(" {")
        .filter(|&i| {
            text.ends_with('}')
                && text[..i]
                    .chars()
                    .all(|c| c.is_alphanumeric() || c == '_' || c == ':')
        })
        .map(|i| &text[i + 2..text.len() - 1]);
    let Some(body) = body else {
        out.insert(prefix.to_string(), text.to_string());
        return;
    };
    for field in split_top_level(body) {
        match field.split_once(": ") {
            Some((name, value)) if !name.trim().is_empty() => {
                flatten_debug(&format!("{prefix}.{}", name.trim()), value, out)
            }
            _ if field.trim().is_empty() => {}
            _ => {
                out.insert(prefix.to_string(), text.to_string());
                return;
            }
        }
    }
}

/// `a, b { c, d }, [e, f]` split at the commas outside brackets and quotes.
fn split_top_level(s: &str) -> Vec<&str> {
    let (mut depth, mut quoted, mut escaped, mut start) = (0i32, false, false, 0usize);
    let mut out = Vec::new();
    for (i, c) in s.char_indices() {
        if quoted {
            match c {
                _ if escaped => escaped = false,
                '\\' => escaped = true,
                '"' => quoted = false,
                _ => {}
            }
            continue;
        }
        match c {
            '"' => quoted = true,
            '{' | '[' | '(' => depth += 1,
            '}' | ']' | ')' => depth -= 1,
            ',' if depth == 0 => {
                out.push(s[start..i].trim());
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(s[start..].trim());
    out
}

/// The largest nudge a progress file may carry, m (far beyond any operator's correction).
pub const MAX_NUDGE_M: f64 = 1000.0;

/// Why saved progress is impossible for the plan it claims: names the field, its value and
/// what the plan allows.
pub fn check_against_plan(p: &Progress, plan: &crate::plan::job::JobPlan) -> Result<(), String> {
    use crate::plan::job::JobPlan;
    if !(p.nudge_m.is_finite() && p.nudge_m.abs() <= MAX_NUDGE_M) {
        return Err(format!("nudge_m {}: beyond ±{MAX_NUDGE_M} m", p.nudge_m));
    }
    if let Some(s) = p.line_worked_m {
        if !(s.is_finite() && s >= 0.0) {
            return Err(format!("line_worked_m {s}: not a distance along the line"));
        }
        if p.phase != Phase::Work {
            return Err(format!(
                "line_worked_m {s} in phase {:?}: only a work line is worked",
                p.phase
            ));
        }
    }
    let (block, rank) = (p.index_block, p.index_rank);
    let (expected_done, last) = match plan {
        JobPlan::Ab(ab) => {
            if let Some(n) = ab.block_count() {
                if block >= n {
                    return Err(format!("index_block {block}: the plan has {n} blocks"));
                }
            }
            if block.checked_mul(ab.block_size() as u64).is_none() {
                return Err(format!("index_block {block}: out of range"));
            }
            let len = ab.block_len(block) as u64;
            if rank >= len {
                return Err(format!("index_rank {rank}: block {block} has {len} lines"));
            }
            (
                ab.sequence_number(block, rank as usize),
                ab.next_position(block, rank as usize).is_none(),
            )
        }
        JobPlan::Segments(job) => {
            if block != 0 {
                return Err(format!(
                    "index_block {block}: a segment job has block 0 only"
                ));
            }
            let n = job.len() as u64;
            if rank >= n {
                return Err(format!("index_rank {rank}: the plan has {n} segments"));
            }
            (rank, rank + 1 == n)
        }
    };
    match p.phase {
        Phase::Finished if !last => Err(format!(
            "phase \"finished\" at index_block {block}, index_rank {rank}, which is not the plan's last line"
        )),
        Phase::Finished if p.lines_done != expected_done + 1 => Err(format!(
            "lines_done {}: a finished plan has {} lines done",
            p.lines_done,
            expected_done + 1
        )),
        Phase::Work | Phase::Turn if p.lines_done != expected_done => Err(format!(
            "lines_done {}: at index_block {block}, index_rank {rank} the plan has {expected_done} lines done",
            p.lines_done
        )),
        _ => Ok(()),
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
    /// The operator's nudge: the job shifted left of its reference direction, m (issue 16
    /// point 5; 0 in files written before it).
    #[serde(default)]
    pub nudge_m: f64,
    /// How far the work line (or work segment) at (block, rank) was worked when saved: m from
    /// its start along it, to the furthest point the vehicle passed inside the engage gate,
    /// saved every [`super::machine::CHECKPOINT_STEP_M`] of work and at every event. A resume
    /// out of the engage gate rejoins the line there instead of at its start. Absent before the
    /// line was worked, in a turn, and in files written before it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_worked_m: Option<f64>,
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
            nudge_m: 0.0,
            line_worked_m: None,
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
