//! Where a job is taken up again: how far the current line has been worked (marked inside
//! the engage gate, saved at checkpoints) and the approach paths that rejoin it there, or lead
//! to the next work line from a turn (docs/METHODS.md, Progress survives power loss).

use super::{Guidance, GuidanceError, CHECKPOINT_STEP_M};
use crate::geo::{path_length, PathPoint, Pose, Tag};
use crate::guidance::progress::Phase;
use crate::plan::job::{JobPlan, JobSegment};

impl Guidance {
    /// Work advanced [`CHECKPOINT_STEP_M`] along the line since the last checkpoint: save
    /// progress now (clears the flag; events are save points of their own).
    pub fn take_checkpoint(&mut self) -> bool {
        std::mem::take(&mut self.checkpoint_due)
    }

    /// The vehicle is on the current work line (inside the engage gate, where an engage needs
    /// no approach): the line counts as worked up to its nearest point, never back. Does
    /// nothing in a turn, while approaching or once finished. No allocation; the distance is
    /// summed over the points passed since the last call only.
    pub fn mark_worked(&mut self) {
        if self.phase != Phase::Work || self.approach_index.is_some() || self.path.len() < 2 {
            return;
        }
        let k = self.index_global.min(self.path.len() - 1);
        let (from, mut at) = match self.worked {
            Some((from, _)) if k <= from => return,
            Some(w) => w,
            None => (0, 0.0),
        };
        at += path_length(&self.path[from..=k]);
        self.worked = Some((k, at));
        if at - self.checkpoint_m >= CHECKPOINT_STEP_M {
            self.checkpoint_m = at;
            self.checkpoint_due = true;
        }
    }

    /// How far the current line has been worked, m from its start (`None` before, in a turn).
    pub fn worked_m(&self) -> Option<f64> {
        self.worked.map(|(_, at)| at)
    }

    pub(super) fn set_worked(&mut self, k: usize, at: f64) {
        self.worked = Some((k, at));
        self.checkpoint_m = at;
        self.index_global = k;
    }

    /// The point of the current path an approach leads to: on a work line, where the work
    /// stopped (the furthest point worked, wherever the vehicle now is: a driver who wants to
    /// work a stretch again drives onto the line there, inside the gate, and engages without an
    /// approach); its start before the line was worked and in a turn.
    fn rejoin_index(&self) -> usize {
        match self.worked {
            Some((k, _)) if self.phase == Phase::Work && self.approach_index.is_none() => k,
            _ => 0,
        }
    }

    /// Drive `segments` (an approach path from the vehicle to [`Guidance::approach_target`],
    /// split at its cusps) before the line, which is then driven from that target on. Not once
    /// finished nor while approaching; `false` when refused. An empty list is accepted and
    /// changes nothing. In a turn of an AB job the approach replaces the rest of the turn
    /// (a turn is no work); on a work line the line is driven on from where its work stopped
    /// (from its start if it was not worked yet; it is not finished, so it counts once).
    pub fn set_approach(&mut self, segments: Vec<JobSegment>) -> bool {
        self.set_approach_with(segments, true)
    }

    /// [`Guidance::set_approach`] to [`Guidance::approach_target_with`]`(skip)`.
    pub fn set_approach_with(&mut self, segments: Vec<JobSegment>, skip: bool) -> bool {
        if !self.approach_allowed() {
            return false;
        }
        if segments.is_empty() {
            return true;
        }
        self.rejoin = Rejoin {
            index: self.rejoin_index(),
            phase: self.phase,
            segment: self.next_work_segment().filter(|_| skip),
        };
        self.approach = segments;
        self.before_approach.0.clone_from(&self.path);
        self.before_approach.1 = self.index_global;
        self.load_approach_segment(0);
        true
    }

    /// Whether [`Guidance::set_approach`] would accept an approach now: not finished and not
    /// already approaching. At the job's start, and when the job is resumed (after a restart,
    /// a pause or a manual drive) away from where it stopped: the approach re-acquires the
    /// line (issue 16 point 8).
    pub fn approach_allowed(&self) -> bool {
        self.approach_index.is_none() && self.phase != Phase::Finished && self.path.len() >= 2
    }

    /// Where an approach path leads: on a work line (or work segment) that was worked, where
    /// the work stopped ([`Guidance::mark_worked`]); else the start of the current work line;
    /// in a turn, the start of the line it leads to (an AB job's next line, a segment job's
    /// next work segment: the turns, transits and manoeuvres before it are no work and are
    /// replaced by the approach; the current segment's start when no work segment follows).
    /// Facing along the line there. Allocates (once per engage request, never per cycle).
    pub fn approach_target(&self) -> Option<Pose> {
        self.approach_target_with(true)
    }

    /// Whether [`Guidance::approach_target`] leads past the segment the vehicle is in (a
    /// segment job's turn, transit or manoeuvre followed by a work segment).
    pub fn approach_can_skip(&self) -> bool {
        self.next_work_segment().is_some()
    }

    /// [`Guidance::approach_target`]; with `skip` false, in a segment job's non-work segment,
    /// that segment's own start (the fallback where no clear way leads to the next one).
    pub fn approach_target_with(&self, skip: bool) -> Option<Pose> {
        let mut line = Vec::new();
        let points: &[PathPoint] = match (&self.plan, self.phase) {
            (JobPlan::Ab(plan), Phase::Turn) => {
                plan.work_line_points(self.index_block, self.index_rank, &mut line);
                &line
            }
            (JobPlan::Segments(job), Phase::Turn) => {
                match self.next_work_segment().filter(|_| skip) {
                    Some(j) => {
                        job.points_into(j, &mut line);
                        &line
                    }
                    None => &self.path,
                }
            }
            _ => &self.path,
        };
        let i = self.rejoin_index().min(points.len().saturating_sub(2));
        let (a, b) = (points.get(i)?.pos, points.get(i + 1)?.pos);
        let d = b - a;
        Some(Pose::new(a.x, a.y, d.y.atan2(d.x)))
    }

    /// Drop an approach that was set but is not wanted: the engage it was planned for was
    /// refused, or steering was given back while driving it. The job is back on the path it was
    /// on before, at the same point and phase, with its worked distance; the next engage plans
    /// a new approach from wherever the vehicle is then. Nothing while not approaching.
    pub fn cancel_approach(&mut self) {
        if self.approach_index.take().is_none() {
            return;
        }
        self.approach.clear();
        let rejoin = std::mem::take(&mut self.rejoin);
        std::mem::swap(&mut self.path, &mut self.before_approach.0);
        self.index_global = self.before_approach.1;
        self.phase = rejoin.phase;
        self.local.invalidate();
    }

    /// Whether an approach path is being driven.
    pub fn is_approaching(&self) -> bool {
        self.approach_index.is_some()
    }

    fn load_approach_segment(&mut self, i: usize) {
        let Some(s) = self.approach.get(i) else {
            return;
        };
        self.path.clear();
        self.path.extend(s.points.iter().map(|&pos| PathPoint {
            pos,
            tag: Tag::Turn,
            direction: s.direction,
        }));
        self.approach_index = Some(i);
        self.phase = Phase::Turn;
        self.index_global = 0;
        self.local.invalidate();
    }

    /// An approach segment is done: load the next one, or the line it leads to.
    pub(super) fn finish_approach_segment(&mut self) -> Result<(), GuidanceError> {
        let Some(i) = self.approach_index else {
            return Ok(());
        };
        if i + 1 < self.approach.len() {
            self.load_approach_segment(i + 1);
            return Ok(());
        }
        self.approach_index = None;
        self.approach.clear();
        let rejoin = std::mem::take(&mut self.rejoin);
        if let Some(j) = rejoin.segment {
            // The non-work segments the approach replaced count as done, as driven ones do.
            self.lines_done += (j - self.index_rank) as u64;
            self.index_rank = j;
        }
        let worked = self.worked;
        self.start_work_line()?;
        let k = rejoin.index.min(self.path.len().saturating_sub(1));
        if let Some((_, at)) = worked.filter(|_| k > 0 && self.phase == Phase::Work) {
            // Rejoined where the work stopped: on from there (`at` ≥ the distance to `k`).
            let to_k = path_length(&self.path[..=k]);
            self.set_worked(k, to_k.min(at));
        }
        Ok(())
    }

    /// In a non-work segment of a segment job (not approaching): the next work segment, which
    /// an approach leads to.
    fn next_work_segment(&self) -> Option<usize> {
        let JobPlan::Segments(job) = &self.plan else {
            return None;
        };
        if self.phase != Phase::Turn || self.approach_index.is_some() {
            return None;
        }
        let from = self.index_rank + 1;
        job.segments()
            .get(from..)?
            .iter()
            .position(|s| s.is_work())
            .map(|k| from + k)
    }
}

/// Where an approach leads (kept while it is driven).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Rejoin {
    /// The point of the line the approach rejoins (index into the line's points).
    pub(super) index: usize,
    /// The phase the job was in when the approach was planned (what progress saves).
    pub(super) phase: Phase,
    /// A segment job's work segment the approach leads to, past the non-work segments it
    /// replaces (`None`: the current segment).
    pub(super) segment: Option<usize>,
}

impl Default for Rejoin {
    fn default() -> Self {
        Rejoin {
            index: 0,
            phase: Phase::Work,
            segment: None,
        }
    }
}

/// The last point of `points` at most `distance` along them from the first, and its distance.
pub(super) fn point_at_distance(points: &[PathPoint], distance: f64) -> (usize, f64) {
    let mut at = 0.0;
    for (i, w) in points.windows(2).enumerate() {
        let next = at + (w[1].pos - w[0].pos).norm();
        if next > distance {
            return (i, at);
        }
        at = next;
    }
    (points.len().saturating_sub(1), at)
}
