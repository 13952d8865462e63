//! What the guidance drives: a [`JobPlan`], either an AB plan (lines generated lazily) or a
//! [`SegmentJob`], a fixed list of segments (a field plan, sequential AB lines, arcs, a
//! manoeuvre) driven in order by the same state machine, local path and tracker.
//!
//! Contract: turns planned segments ([`PlanSegment`]s, a manoeuvre's parts between cusps) into
//! driveable [`JobSegment`]s and identifies the list by a checksum saved with progress. Pure;
//! uses only the planners' types (`plan::types`, `plan::abline`, `plan::maneuver`) and
//! [`crate::geo`].

use crate::geo::{Direction, PathPoint, Tag, Vec2};
use crate::plan::abline::AbPlan;
use crate::plan::maneuver::drive::{split_at_cusps, DrivenPart};
use crate::plan::maneuver::path::CurvePath;
use crate::plan::types::{PlanError, PlanSegment, SegmentKind};

/// What the state machine drives.
#[derive(Debug, Clone)]
pub enum JobPlan {
    /// An AB job: work lines generated lazily by block and rank, turns between them.
    Ab(Box<AbPlan>),
    /// A fixed list of segments (a field plan) driven in order. Its positions are
    /// (block 0, rank = segment index); turns are segments of their own.
    Segments(SegmentJob),
}

impl From<AbPlan> for JobPlan {
    fn from(plan: AbPlan) -> Self {
        JobPlan::Ab(Box::new(plan))
    }
}

impl From<SegmentJob> for JobPlan {
    fn from(job: SegmentJob) -> Self {
        JobPlan::Segments(job)
    }
}

/// One driveable piece of a segment job.
#[derive(Debug, Clone, PartialEq)]
pub struct JobSegment {
    /// What the segment is for (work, turn, headland, detour, transit).
    pub kind: SegmentKind,
    pub direction: Direction,
    /// The cell of a field plan it belongs to.
    pub cell: usize,
    /// Points in driving order, local ENU m, at least two.
    pub points: Vec<Vec2>,
}

impl JobSegment {
    /// Work-like segments (the implement works: swaths, headland passes, detours) count as
    /// lines; turns and transits do not.
    pub fn is_work(&self) -> bool {
        matches!(
            self.kind,
            SegmentKind::Work | SegmentKind::Headland | SegmentKind::Detour
        )
    }

    /// The path-point tag of this segment.
    pub fn tag(&self) -> Tag {
        if self.is_work() {
            Tag::Work
        } else {
            Tag::Turn
        }
    }

    /// The parts of a manoeuvre path between its cusps as `kind` segments of cell 0.
    pub fn from_driven_parts(
        parts: impl IntoIterator<Item = DrivenPart>,
        kind: SegmentKind,
    ) -> Vec<JobSegment> {
        parts
            .into_iter()
            .map(|p| JobSegment {
                kind,
                direction: p.direction,
                cell: 0,
                points: p.points,
            })
            .collect()
    }

    /// Length along the points, m.
    pub fn length(&self) -> f64 {
        crate::geo::polygon::polyline_length(&self.points)
    }
}

/// A list of segments with a checksum that identifies it in saved progress.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentJob {
    segments: Vec<JobSegment>,
    checksum: u32,
}

const CRC: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);

impl SegmentJob {
    /// A job of `segments` in driving order. Consecutive duplicate points are dropped; a
    /// segment left with fewer than two points, or with a non-finite point, is an error.
    pub fn new(mut segments: Vec<JobSegment>) -> Result<Self, PlanError> {
        if segments.is_empty() {
            return Err(PlanError::Invalid {
                name: "segments",
                value: 0.0,
                rule: "a segment job needs at least one segment",
            });
        }
        let mut digest = CRC.digest();
        for (i, s) in segments.iter_mut().enumerate() {
            if s.points
                .iter()
                .any(|p| !(p.x.is_finite() && p.y.is_finite()))
            {
                return Err(PlanError::Invalid {
                    name: "segment point",
                    value: i as f64,
                    rule: "every point must be finite",
                });
            }
            s.points.dedup_by(|a, b| (*a - *b).norm() < 1e-6);
            if s.points.len() < 2 {
                return Err(PlanError::Invalid {
                    name: "segment points",
                    value: i as f64,
                    rule: "every segment needs two distinct points",
                });
            }
            digest.update(&[s.kind as u8, s.direction as u8]);
            digest.update(&(s.cell as u64).to_le_bytes());
            for p in &s.points {
                digest.update(&p.x.to_le_bytes());
                digest.update(&p.y.to_le_bytes());
            }
        }
        Ok(SegmentJob {
            segments,
            checksum: digest.finalize(),
        })
    }

    /// Planned segments (a field plan's, sequential AB lines) in driving order.
    pub fn from_plan_segments(
        segments: impl IntoIterator<Item = PlanSegment>,
    ) -> Result<Self, PlanError> {
        SegmentJob::new(
            segments
                .into_iter()
                .map(|s| JobSegment {
                    kind: s.kind,
                    direction: s.direction,
                    cell: s.cell,
                    points: s.points,
                })
                .collect(),
        )
    }

    /// The parts of a manoeuvre path between its cusps, as `kind` segments.
    pub fn from_driven_parts(
        parts: impl IntoIterator<Item = DrivenPart>,
        kind: SegmentKind,
    ) -> Result<Self, PlanError> {
        SegmentJob::new(JobSegment::from_driven_parts(parts, kind))
    }

    /// A manoeuvre's `path` as the guidance drives it: one transit segment per part between
    /// cusps, points every `spacing_m`.
    pub fn from_curve_path(path: &CurvePath, spacing_m: f64) -> Result<Self, PlanError> {
        SegmentJob::from_driven_parts(split_at_cusps(path, spacing_m), SegmentKind::Transit)
    }

    pub fn segments(&self) -> &[JobSegment] {
        &self.segments
    }
    pub fn len(&self) -> usize {
        self.segments.len()
    }
    pub fn is_empty(&self) -> bool {
        self.segments.is_empty()
    }
    /// CRC-32C over every segment's kind, direction, cell and points.
    pub fn checksum(&self) -> u32 {
        self.checksum
    }

    /// Write segment `i`'s points into `out` (cleared first).
    pub fn points_into(&self, i: usize, out: &mut Vec<PathPoint>) {
        out.clear();
        if let Some(s) = self.segments.get(i) {
            let (tag, direction) = (s.tag(), s.direction);
            out.extend(s.points.iter().map(|&pos| PathPoint {
                pos,
                tag,
                direction,
            }));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;

    fn seg(kind: SegmentKind, pts: &[(f64, f64)]) -> JobSegment {
        JobSegment {
            kind,
            direction: Direction::Forward,
            cell: 0,
            points: pts.iter().map(|&(x, y)| v2(x, y)).collect(),
        }
    }

    #[test]
    fn rejects_degenerate_segments_and_checksums_content() {
        assert!(SegmentJob::new(vec![]).is_err());
        assert!(SegmentJob::new(vec![seg(SegmentKind::Work, &[(0.0, 0.0), (0.0, 0.0)])]).is_err());
        assert!(
            SegmentJob::new(vec![seg(SegmentKind::Work, &[(0.0, 0.0), (f64::NAN, 1.0)])]).is_err()
        );
        let a = SegmentJob::new(vec![seg(SegmentKind::Work, &[(0.0, 0.0), (0.0, 10.0)])]).unwrap();
        let b = SegmentJob::new(vec![seg(SegmentKind::Work, &[(0.0, 0.0), (0.0, 10.5)])]).unwrap();
        let c = SegmentJob::new(vec![seg(SegmentKind::Turn, &[(0.0, 0.0), (0.0, 10.0)])]).unwrap();
        assert_ne!(a.checksum(), b.checksum());
        assert_ne!(a.checksum(), c.checksum());
        let mut out = Vec::new();
        c.points_into(0, &mut out);
        assert_eq!(out.len(), 2);
        assert_eq!(out[0].tag, Tag::Turn);
    }
}
