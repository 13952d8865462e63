//! The seed-000 job state machine (docs/METHODS.md, The job state machine), run every control
//! period.
//!
//! It owns the current global path (one work line or one turn, regenerated lazily at each
//! change) and the local B-spline path, and keeps `index_block`, `index_rank`,
//! `index_global` and `index_local`. It never allocates per cycle: the path buffers are reused
//! and events are pushed only when something changes.

use super::progress::{JobDefinition, Phase, Progress, PROGRESS_VERSION};
use crate::geo::{path_length, signed_offset, wrap_angle, Direction, PathPoint, Pose, Tag, Vec2};
use crate::plan::abline::AbPlan;
use crate::plan::job::{JobPlan, JobSegment};
use crate::plan::types::PlanError;
use crate::track::local_path::{nearest_global, LocalPath, LocalPathParams};

/// Something the binaries log.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    LineStarted {
        block: u64,
        rank: u64,
        line: u64,
    },
    LineFinished {
        block: u64,
        rank: u64,
        line: u64,
    },
    TurnStarted {
        from_line: u64,
        to_line: u64,
    },
    BlockChanged {
        block: u64,
    },
    JobFinished {
        lines_done: u64,
    },
    /// The operator nudged the job: every line shifted left of the job's reference
    /// direction by `nudge_m` in all (issue 16 point 5).
    Nudged {
        nudge_m: f64,
    },
}

impl std::fmt::Display for Event {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Event::LineStarted { block, rank, line } => {
                write!(f, "line started: line {line} (block {block}, rank {rank})")
            }
            Event::LineFinished { block, rank, line } => {
                write!(f, "line finished: line {line} (block {block}, rank {rank})")
            }
            Event::TurnStarted { from_line, to_line } => {
                write!(f, "turn started: line {from_line} → line {to_line}")
            }
            Event::BlockChanged { block } => write!(f, "block changed: block {block}"),
            Event::JobFinished { lines_done } => write!(f, "job finished: {lines_done} lines"),
            Event::Nudged { nudge_m } => {
                write!(f, "nudged: the job is {nudge_m:+.3} m left of its plan")
            }
        }
    }
}

/// Work advanced along a line between two progress checkpoints (a save without an event), m.
/// A restart out of the engage gate rejoins the line at most this far behind where the work
/// stopped (plus what the driver drove while the daemon was down).
pub const CHECKPOINT_STEP_M: f64 = 5.0;

/// Tuning of the state machine.
#[derive(Debug, Clone, PartialEq)]
pub struct GuidanceParams {
    /// The path is "near its end" within this distance of its last point, m.
    pub end_distance: f64,
    /// Local B-spline path parameters.
    pub local: LocalPathParams,
    /// Global points searched either side of the previous nearest point each cycle.
    pub search_window: usize,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum GuidanceError {
    #[error(
        "saved progress belongs to a different job (job parameters differ); refusing to resume"
    )]
    DifferentJob,
    #[error("saved progress is impossible in this plan: {0}")]
    Impossible(String),
    #[error("saved progress points at block {block}, rank {rank}, which this job does not have")]
    OutOfRange { block: u64, rank: u64 },
    #[error(transparent)]
    Plan(#[from] PlanError),
}

/// The job state machine.
pub struct Guidance {
    plan: JobPlan,
    job: JobDefinition,
    params: GuidanceParams,
    index_block: u64,
    index_rank: usize,
    phase: Phase,
    lines_done: u64,
    path: Vec<PathPoint>,
    index_global: usize,
    local: LocalPath,
    events: Vec<Event>,
    /// An approach path driven before the current line (docs/METHODS.md, Manoeuvres at work; issue
    /// 6 part 5b): segments split at cusps, from the vehicle to the line start. Not part of the
    /// job: never saved.
    approach: Vec<JobSegment>,
    /// The approach segment being driven, while approaching.
    approach_index: Option<usize>,
    /// The operator's nudge: the job shifted left of its reference direction, m (saved
    /// with progress).
    nudge_m: f64,
    /// How far the current work line (or work segment) has been worked: the furthest point of
    /// `path` passed inside the engage gate ([`Guidance::mark_worked`]) and its distance from
    /// the line's start along it, m. `None` until then and off work lines. Kept while an
    /// approach is driven; saved with progress.
    worked: Option<(usize, f64)>,
    /// `worked`'s distance at the last progress checkpoint, m.
    checkpoint_m: f64,
    /// The work advanced [`CHECKPOINT_STEP_M`] since the last checkpoint: progress is due.
    checkpoint_due: bool,
    /// While approaching: where the approach leads.
    rejoin: Rejoin,
    /// While approaching: the path and `index_global` before it, restored if it is cancelled.
    before_approach: (Vec<PathPoint>, usize),
}

impl Guidance {
    /// Start a job on its first line (step 1).
    pub fn new(
        plan: impl Into<JobPlan>,
        job: JobDefinition,
        params: GuidanceParams,
    ) -> Result<Self, GuidanceError> {
        let local = LocalPath::new(&params.local);
        let mut g = Guidance {
            plan: plan.into(),
            job,
            params,
            index_block: 0,
            index_rank: 0,
            phase: Phase::Work,
            lines_done: 0,
            path: Vec::with_capacity(1024),
            index_global: 0,
            local,
            events: Vec::with_capacity(16),
            approach: Vec::new(),
            approach_index: None,
            nudge_m: 0.0,
            worked: None,
            checkpoint_m: 0.0,
            checkpoint_due: false,
            rejoin: Rejoin::default(),
            before_approach: (Vec::new(), 0),
        };
        g.start_work_line()?;
        Ok(g)
    }

    /// Continue a job from saved progress. A turn in progress is regenerated and driven again;
    /// finished lines are never driven again.
    pub fn resume(
        plan: impl Into<JobPlan>,
        job: JobDefinition,
        params: GuidanceParams,
        saved: &Progress,
    ) -> Result<Self, GuidanceError> {
        if saved.job != job {
            return Err(GuidanceError::DifferentJob);
        }
        let plan = plan.into();
        super::progress::check_against_plan(saved, &plan).map_err(GuidanceError::Impossible)?;
        let mut g = Guidance::new(plan, job, params)?;
        g.events.clear();
        let (block, rank) = (saved.index_block, saved.index_rank);
        let in_range = match &g.plan {
            JobPlan::Ab(plan) => {
                plan.block_count().is_none_or(|n| block < n)
                    && (rank as usize) < plan.block_len(block)
            }
            JobPlan::Segments(job) => block == 0 && (rank as usize) < job.len(),
        };
        if !in_range {
            return Err(GuidanceError::OutOfRange { block, rank });
        }
        g.index_block = block;
        g.index_rank = rank as usize;
        g.lines_done = saved.lines_done;
        g.nudge_m = saved.nudge_m;
        match saved.phase {
            Phase::Finished => {
                g.phase = Phase::Finished;
                g.path.clear();
            }
            _ if matches!(g.plan, JobPlan::Segments(_)) => g.start_segment(),
            Phase::Work => g.start_work_line()?,
            Phase::Turn => match g.previous_position() {
                Some(prev) => g.start_turn(prev)?,
                None => g.start_work_line()?,
            },
        }
        if let Some(station) = saved.line_worked_m.filter(|_| g.phase == Phase::Work) {
            let length = path_length(&g.path);
            if !(station.is_finite() && station >= 0.0 && station <= length + 1.0) {
                return Err(GuidanceError::Impossible(format!(
                    "line_worked_m {station}: the line at index_block {block}, index_rank {rank} is {length:.1} m long"
                )));
            }
            let (k, at) = point_at_distance(&g.path, station);
            g.set_worked(k, at);
        }
        Ok(g)
    }

    /// One control period (steps 2–4): update the indices for `pose`, switch paths at their
    /// ends, rebuild the local path when `index_global` moved.
    pub fn update(&mut self, pose: &Pose) -> Result<(), GuidanceError> {
        if self.phase == Phase::Finished || self.path.len() < 2 {
            return Ok(());
        }
        self.index_global = nearest_global(
            &self.path,
            &pose.pos,
            self.index_global,
            self.params.search_window,
        );
        if self.near_end(&pose.pos) {
            match self.phase {
                Phase::Finished => {}
                _ if self.approach_index.is_some() => self.finish_approach_segment()?,
                _ if matches!(self.plan, JobPlan::Segments(_)) => self.finish_segment(),
                Phase::Turn => self.start_work_line()?,
                Phase::Work => self.finish_line()?,
            }
            if self.phase == Phase::Finished {
                return Ok(());
            }
            // From the new path's first point, or where an approach rejoined the line.
            self.index_global = nearest_global(&self.path, &pose.pos, self.index_global, 4);
        }
        if self.local.built_for() != Some(self.index_global) {
            self.local.rebuild(&self.path, self.index_global);
        }
        self.local.nearest(&pose.pos);
        Ok(())
    }

    fn near_end(&self, p: &Vec2) -> bool {
        let n = self.path.len();
        if self.index_global + 2 < n {
            return false;
        }
        let last = self.path[n - 1].pos;
        let d = last - self.path[n - 2].pos;
        let len = d.norm();
        if len <= 0.0 {
            return true;
        }
        (p - last).dot(&(d / len)) > -self.params.end_distance
    }

    /// The AB plan (`None` for a segment job).
    fn ab(&self) -> Option<&AbPlan> {
        match &self.plan {
            JobPlan::Ab(plan) => Some(plan),
            JobPlan::Segments(_) => None,
        }
    }

    /// Load segment `index_rank` of a segment job as the global path.
    fn start_segment(&mut self) {
        let JobPlan::Segments(job) = &self.plan else {
            return;
        };
        let i = self.index_rank;
        (self.worked, self.checkpoint_m) = (None, 0.0);
        job.points_into(i, &mut self.path);
        let work = job.segments().get(i).is_some_and(|s| s.is_work());
        self.phase = if work { Phase::Work } else { Phase::Turn };
        self.index_global = 0;
        self.local.invalidate();
        self.events.push(if work {
            Event::LineStarted {
                block: 0,
                rank: i as u64,
                line: i as u64,
            }
        } else {
            Event::TurnStarted {
                from_line: i.saturating_sub(1) as u64,
                to_line: i as u64 + 1,
            }
        });
    }

    /// A segment of a segment job is done: count it and load the next one.
    fn finish_segment(&mut self) {
        let JobPlan::Segments(job) = &self.plan else {
            return;
        };
        let i = self.index_rank;
        let n = job.len();
        if self.phase == Phase::Work {
            self.events.push(Event::LineFinished {
                block: 0,
                rank: i as u64,
                line: i as u64,
            });
        }
        // Every finished segment counts, so saved progress resumes on the next one.
        self.lines_done += 1;
        if i + 1 >= n {
            self.phase = Phase::Finished;
            self.path.clear();
            self.events.push(Event::JobFinished {
                lines_done: self.lines_done,
            });
        } else {
            self.index_rank = i + 1;
            self.start_segment();
        }
    }

    fn finish_line(&mut self) -> Result<(), GuidanceError> {
        let Some(plan) = self.ab() else {
            return Ok(());
        };
        let (block, rank) = (self.index_block, self.index_rank);
        let line = plan.line_of(block, rank);
        let next = plan.next_position(block, rank);
        self.lines_done += 1;
        self.events.push(Event::LineFinished {
            block,
            rank: rank as u64,
            line,
        });
        match next {
            None => {
                self.phase = Phase::Finished;
                self.path.clear();
                self.events.push(Event::JobFinished {
                    lines_done: self.lines_done,
                });
            }
            Some((next_block, next_rank)) => {
                self.index_block = next_block;
                self.index_rank = next_rank;
                if next_block != block {
                    self.events.push(Event::BlockChanged { block: next_block });
                }
                self.start_turn((block, rank))?;
            }
        }
        Ok(())
    }

    fn start_turn(&mut self, from: (u64, usize)) -> Result<(), GuidanceError> {
        let JobPlan::Ab(plan) = &self.plan else {
            return Ok(());
        };
        let to = (self.index_block, self.index_rank);
        (self.worked, self.checkpoint_m) = (None, 0.0);
        self.path.clear();
        plan.turn_points(from, to, &mut self.path)?;
        self.phase = Phase::Turn;
        self.index_global = 0;
        self.local.invalidate();
        self.events.push(Event::TurnStarted {
            from_line: plan.line_of(from.0, from.1),
            to_line: plan.line_of(to.0, to.1),
        });
        Ok(())
    }

    fn start_work_line(&mut self) -> Result<(), GuidanceError> {
        let JobPlan::Ab(plan) = &self.plan else {
            self.start_segment();
            return Ok(());
        };
        (self.worked, self.checkpoint_m) = (None, 0.0);
        self.path.clear();
        plan.work_line_points(self.index_block, self.index_rank, &mut self.path);
        self.phase = Phase::Work;
        self.index_global = 0;
        self.local.invalidate();
        self.events.push(Event::LineStarted {
            block: self.index_block,
            rank: self.index_rank as u64,
            line: self.current_line(),
        });
        Ok(())
    }

    fn previous_position(&self) -> Option<(u64, usize)> {
        if self.index_rank > 0 {
            Some((self.index_block, self.index_rank - 1))
        } else if self.index_block > 0 {
            let b = self.index_block - 1;
            Some((b, self.ab()?.block_len(b).checked_sub(1)?))
        } else {
            None
        }
    }

    /// Events since the last call, oldest first.
    pub fn drain_events(&mut self) -> std::vec::Drain<'_, Event> {
        self.events.drain(..)
    }

    /// Did any event happen in the last update (a progress save point)?
    pub fn has_events(&self) -> bool {
        !self.events.is_empty()
    }

    /// A snapshot to persist.
    pub fn progress(&self) -> Progress {
        Progress {
            version: PROGRESS_VERSION,
            job: self.job.clone(),
            index_block: self.index_block,
            index_rank: self.index_rank as u64,
            phase: self.saved_phase(),
            lines_done: self.lines_done,
            nudge_m: self.nudge_m,
            line_worked_m: self.worked.map(|(_, at)| at),
        }
    }

    /// The phase progress saves: while approaching, the one the approach was planned in.
    fn saved_phase(&self) -> Phase {
        if self.approach_index.is_some() {
            self.rejoin.phase
        } else {
            self.phase
        }
    }

    /// The operator's nudge, m left of [`Guidance::reference_direction`].
    pub fn nudge_m(&self) -> f64 {
        self.nudge_m
    }

    /// Set the operator's nudge (m, positive left): saved with progress from now on (an
    /// [`Event::Nudged`] says it changed).
    pub fn set_nudge(&mut self, nudge_m: f64) {
        if nudge_m.is_finite() && nudge_m != self.nudge_m {
            self.nudge_m = nudge_m;
            self.events.push(Event::Nudged { nudge_m });
        }
    }

    /// The job's reference direction, which a nudge is left of: A→B of an AB job, the first
    /// segment's direction of a segment job (unit vector).
    pub fn reference_direction(&self) -> Vec2 {
        let d = match &self.plan {
            JobPlan::Ab(plan) => {
                let (a, b) = plan.line_endpoints(0, false);
                b - a
            }
            JobPlan::Segments(job) => job
                .segments()
                .first()
                .and_then(|s| Some(*s.points.get(1)? - *s.points.first()?))
                .unwrap_or(Vec2::new(1.0, 0.0)),
        };
        let n = d.norm();
        if n > 0.0 && n.is_finite() {
            d / n
        } else {
            Vec2::new(1.0, 0.0)
        }
    }

    /// Signed cross-track error of `pose` from the current global path (positive = vehicle
    /// left of the path), m, and heading error (vehicle − path), rad.
    pub fn errors(&self, pose: &Pose) -> Option<(f64, f64)> {
        let n = self.path.len();
        if n < 2 {
            return None;
        }
        let i = self.index_global.min(n - 2);
        let a = self.path[i].pos;
        let d = self.path[i + 1].pos - a;
        let len = d.norm();
        if len <= 0.0 {
            return None;
        }
        let dir = d / len;
        let xte = signed_offset(&pose.pos, &a, &dir);
        // Driven in reverse, the vehicle faces against the direction of travel.
        let facing = match self.path[i].direction {
            Direction::Forward => dir.y.atan2(dir.x),
            Direction::Reverse => (-dir.y).atan2(-dir.x),
        };
        Some((xte, wrap_angle(pose.heading - facing)))
    }

    /// Distance from `pose` to the current global path, m: to the nearest of the segments
    /// either side of the nearest point, not to a segment's extension as the cross-track error
    /// is (off a short curved path that would read small far from it), except beyond the
    /// path's ends: there the vehicle rolls on along it before a cusp or after the end of a
    /// line, and the distance is to the first or last segment's extension. `None` without a
    /// path.
    pub fn distance_from_path(&self, pose: &Pose) -> Option<f64> {
        let n = self.path.len();
        if n < 2 || self.phase == Phase::Finished {
            return None;
        }
        let i = self.index_global.min(n - 1);
        (i.saturating_sub(1)..(i + 1).min(n - 1))
            .filter_map(|k| {
                let (a, b) = (self.path[k].pos, self.path[k + 1].pos);
                let d = b - a;
                let len2 = d.norm_squared();
                if len2 <= 0.0 {
                    return None;
                }
                let mut along = (pose.pos - a).dot(&d) / len2;
                if k > 0 {
                    along = along.max(0.0);
                }
                if k + 2 < n {
                    along = along.min(1.0);
                }
                Some((pose.pos - (a + d * along)).norm())
            })
            .reduce(f64::min)
    }

    /// Where a segment job's current segment does not start where the previous one ended (a
    /// gap the planner left: no clear transit between them, "drive there by hand"): the
    /// distance across it, m. `None` where the segments join (within [`GAP_M`]), on the first
    /// segment, while approaching and for AB jobs.
    pub fn gap_before(&self) -> Option<f64> {
        let segments = self.segments_driven()?;
        let previous = segments
            .get(self.index_rank.checked_sub(1)?)?
            .points
            .last()?;
        let start = segments.get(self.index_rank)?.points.first()?;
        let d = (start - previous).norm();
        (d > GAP_M).then_some(d)
    }

    /// The AB plan, when this is an AB job.
    pub fn plan(&self) -> Option<&AbPlan> {
        self.ab()
    }
    /// What the job drives.
    pub fn job_plan(&self) -> &JobPlan {
        &self.plan
    }
    pub fn local_path(&self) -> &LocalPath {
        &self.local
    }
    pub fn global_path(&self) -> &[PathPoint] {
        &self.path
    }
    pub fn phase(&self) -> Phase {
        self.phase
    }
    pub fn is_finished(&self) -> bool {
        self.phase == Phase::Finished
    }
    pub fn index_block(&self) -> u64 {
        self.index_block
    }
    pub fn index_rank(&self) -> usize {
        self.index_rank
    }
    pub fn index_global(&self) -> usize {
        self.index_global
    }
    pub fn lines_done(&self) -> u64 {
        self.lines_done
    }
    /// Absolute index of the line being driven (or turned into).
    /// For a segment job: the index of the segment being driven.
    pub fn current_line(&self) -> u64 {
        match &self.plan {
            JobPlan::Ab(plan) => plan.line_of(self.index_block, self.index_rank),
            JobPlan::Segments(_) => self.index_rank as u64,
        }
    }
    /// Driving direction at the current point of the path (forward when there is none).
    pub fn direction(&self) -> Direction {
        self.path
            .get(self.index_global)
            .map(|p| p.direction)
            .unwrap_or_default()
    }

    /// Driving direction of the next segment of a segment job or an approach (`None` at the
    /// last one; forward for AB jobs, whose lines and turns are all driven forward, until they
    /// finish).
    pub fn next_direction(&self) -> Option<Direction> {
        if let Some(i) = self.approach_index {
            return Some(match self.approach.get(i + 1) {
                Some(s) => s.direction,
                None => match &self.plan {
                    JobPlan::Segments(job) => job
                        .segments()
                        .get(self.rejoin.segment.unwrap_or(self.index_rank))
                        .map(|s| s.direction)
                        .unwrap_or_default(),
                    JobPlan::Ab(_) => Direction::Forward,
                },
            });
        }
        match &self.plan {
            JobPlan::Segments(job) => job.segments().get(self.index_rank + 1).map(|s| s.direction),
            JobPlan::Ab(_) => (!self.is_finished()).then_some(Direction::Forward),
        }
    }

    /// Distance from `p` to the end of the current path, measured along it from the nearest
    /// point, m (0 when finished).
    pub fn remaining(&self, p: &Vec2) -> f64 {
        let n = self.path.len();
        if n < 2 {
            return 0.0;
        }
        let i = self.index_global.min(n - 1);
        let rest = path_length(&self.path[i..]);
        let d = self.path[(i + 1).min(n - 1)].pos - self.path[i.min(n - 2)].pos;
        let len = d.norm();
        let ahead = if len > 0.0 {
            (p - self.path[i].pos).dot(&(d / len))
        } else {
            0.0
        };
        (rest - ahead).max(0.0)
    }

    /// Where the vehicle must stop next beyond the current path, if within `within` m of its
    /// end: the segments after the current one driven the same way, up to the next change of
    /// direction or the job's end, when they are no longer than `within` in all. Gives their
    /// length, m, and whether a change of direction (a cusp) follows them rather than the
    /// job's end. A segment shorter than the braking distance before a cusp (a short piece of
    /// swath before backing out) is so braked for from the segments before it. Called every
    /// control period: it reads at most `within` m of points. `None` when the stop is farther,
    /// on an approach path, an AB job or a finished job.
    pub fn stop_after_within(&self, within: f64) -> Option<(f64, bool)> {
        let segments = self.segments_driven()?;
        let direction = segments.get(self.index_rank)?.direction;
        let mut length = 0.0;
        for s in &segments[self.index_rank + 1..] {
            if s.direction != direction {
                return Some((length, true));
            }
            for w in s.points.windows(2) {
                length += (w[1] - w[0]).norm();
                if length > within {
                    return None;
                }
            }
        }
        Some((length, false))
    }

    /// A segment job's segments while one of them is driven (not on an approach path, not
    /// finished).
    fn segments_driven(&self) -> Option<&[crate::plan::job::JobSegment]> {
        let JobPlan::Segments(job) = &self.plan else {
            return None;
        };
        (self.approach_index.is_none() && self.phase != Phase::Finished).then(|| job.segments())
    }

    /// At a cusp the vehicle stops within reach of the end of a segment: move on to the next
    /// segment as if its end had been reached. Does nothing unless a segment job's next
    /// segment exists.
    pub fn advance_segment(&mut self) {
        if self.approach_index.is_some() {
            // Errors here come from regenerating an AB line that was generated before.
            let _ = self.finish_approach_segment();
            return;
        }
        if matches!(self.plan, JobPlan::Segments(_)) && self.phase != Phase::Finished {
            self.finish_segment();
        }
    }

    /// Tag of the path being driven.
    pub fn tag(&self) -> Tag {
        match self.phase {
            Phase::Turn => Tag::Turn,
            _ => Tag::Work,
        }
    }
}

mod approach;
use approach::{point_at_distance, Rejoin};

/// Segments of a job whose ends are farther apart than this do not join: a gap, m. (A plan's
/// segments join exactly; a cusp starts where the segment before it ended.)
pub const GAP_M: f64 = 0.5;

#[cfg(test)]
mod tests;
