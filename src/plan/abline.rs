//! The seed-000 AB-line planner (docs/METHODS.md, AB-line work).
//!
//! Work line `k` is line A→B shifted `k·line_width` to the configured side. Lines are
//! generated lazily: the plan stores only the parameters and the driving order of one block
//! (plus the last block's, when it is larger), so its memory does not depend on `line_num`.
//!
//! Lines are grouped in blocks of `N = 2·ceil(2·r_min/line_width) + a` and driven in the
//! seed-000 skip order of [`crate::plan::skip_order`] (the one block rule fields use too):
//! inside a block, the shortest order that never turns between lines closer than `2·r_min`
//! (so every turn is a pi turn), starting at the block's first line and ending where the next
//! block's first line is at least `2·r_min` away. When no order avoids lines closer than
//! `2·r_min` (a block of fewer than `2·ceil(2·r_min/line_width) + 1` lines), the plan does not
//! fail: the order has the fewest such "short" moves, then the shortest distance, and the
//! short moves are driven with bulb turns (the turn selector's choice for forward-only turns,
//! [`crate::plan::turns::turn_shape`]).
//!
//! Contract: pure; uses only `plan::{types, turns, skip_order}` and [`crate::geo`].

use super::skip_order::{
    block_count, block_size, min_gap_lines, solve_block_order, BlockOrder, MAX_BLOCK_LINES,
};
use super::turns::{forward_turn, TurnCache, TurnParams};
pub use super::types::Side;
use super::types::{PlanError, PlanSegment, SegmentKind};
use crate::geo::{cross, left_normal, v2, Direction, PathPoint, Vec2};

/// The seed's five parameters and the shape of the generated paths.
#[derive(Debug, Clone, PartialEq)]
pub struct AbParams {
    /// Point A of the first line, local ENU, m.
    pub point_a: Vec2,
    /// Point B of the first line, local ENU, m.
    pub point_b: Vec2,
    /// Spacing between adjacent lines, m.
    pub line_width: f64,
    /// Number of lines; 0 = unlimited.
    pub line_num: u64,
    /// Minimum turning radius, m.
    pub r_min: f64,
    /// Side of A→B for the next lines.
    pub side: Side,
    /// The seed's `a` (≥ 1) in the block size.
    pub block_extra: u32,
    /// Spacing of the global points of a work line, m.
    pub point_spacing: f64,
    /// Turn shape.
    pub turn: TurnParams,
}

/// An AB job's plan: lines, blocks, orders and turns, generated on demand.
#[derive(Debug, Clone)]
pub struct AbPlan {
    params: AbParams,
    /// Unit direction A→B.
    dir: Vec2,
    shift: Vec2,
    length: f64,
    block_size: usize,
    min_gap: usize,
    /// Number of blocks; `None` when unlimited.
    blocks: Option<u64>,
    first_order: BlockOrder,
    last_order: Option<BlockOrder>,
    /// The plan's turns solved once at construction in the canonical frame (start at the origin
    /// heading +x, end at (0, lateral)), by lateral offset (mm): [`AbPlan::turn_points`], called
    /// by guidance inside a control period, then only moves points (no solving, no allocation).
    turns: Vec<(i64, Vec<PathPoint>)>,
}

impl AbPlan {
    pub fn new(params: AbParams) -> Result<AbPlan, PlanError> {
        let ab = params.point_b - params.point_a;
        let length = ab.norm();
        PlanError::check("point_a", params.point_a.x + params.point_a.y, true)?;
        PlanError::check("|B - A|", length, length >= 1e-3)?;
        PlanError::check("line_width", params.line_width, params.line_width > 0.0)?;
        PlanError::check("r_min", params.r_min, params.r_min > 0.0)?;
        PlanError::check(
            "point_spacing",
            params.point_spacing,
            params.point_spacing > 0.0,
        )?;
        if params.block_extra < 1 {
            return Err(PlanError::Invalid {
                name: "block_extra (a)",
                value: params.block_extra as f64,
                rule: "must be an integer >= 1",
            });
        }
        params.turn.validate()?;
        if (params.turn.r_min - params.r_min).abs() > 1e-9 * params.r_min {
            return Err(PlanError::Invalid {
                name: "turn.r_min",
                value: params.turn.r_min,
                rule: "must equal r_min",
            });
        }
        let dir = ab / length;
        let shift = match params.side {
            Side::Left => left_normal(&dir),
            Side::Right => -left_normal(&dir),
        } * params.line_width;
        let min_gap = min_gap_lines(params.r_min, params.line_width);
        let block_size = block_size(min_gap, params.block_extra as usize);
        if block_size > MAX_BLOCK_LINES {
            return Err(PlanError::Invalid {
                name: "block size N = 2·ceil(2·r_min/line_width) + a",
                value: block_size as f64,
                rule: "must be at most 4096 lines",
            });
        }
        let (blocks, first_order, last_order) = if params.line_num == 0 {
            (None, solve_block_order(block_size, min_gap, true), None)
        } else {
            match block_count(params.line_num, block_size) {
                // One block holds every line; nothing follows it.
                (1, n) => (Some(1), solve_block_order(n as usize, min_gap, false), None),
                (full, last) => {
                    let first = solve_block_order(block_size, min_gap, true);
                    // A last block of N lines is driven in the first block's order.
                    let last = (last as usize != block_size)
                        .then(|| solve_block_order(last as usize, min_gap, false));
                    (Some(full), first, last)
                }
            }
        };
        let mut plan = AbPlan {
            params,
            dir,
            shift,
            length,
            block_size,
            min_gap,
            blocks,
            first_order,
            last_order,
            turns: Vec::new(),
        };
        plan.turns = plan.canonical_turns();
        Ok(plan)
    }

    /// The turns between consecutive lines: the first two blocks (the line order repeats with
    /// them, both parities of the driving direction) and the last two of a finite job. A turn
    /// that cannot be solved is left out: [`AbPlan::turn_points`] solves it again and reports.
    fn canonical_turns(&self) -> Vec<(i64, Vec<PathPoint>)> {
        let mut firsts = vec![0u64, 1];
        if let Some(n) = self.blocks {
            firsts.extend([n.saturating_sub(2), n.saturating_sub(1)]);
        }
        let mut turns: Vec<(i64, Vec<PathPoint>)> = Vec::new();
        for block in firsts {
            for rank in 0..self.block_len(block) {
                let Some(next) = self.next_position(block, rank) else {
                    continue;
                };
                let (e1, dir1, s2) = self.turn_ends((block, rank), next);
                let lateral = cross(&dir1, &(s2 - e1));
                let key = turn_key(lateral);
                if turns.iter().any(|(k, _)| *k == key) {
                    continue;
                }
                let mut points = Vec::new();
                let solved = forward_turn(
                    v2(0.0, 0.0),
                    v2(1.0, 0.0),
                    v2(0.0, lateral),
                    lateral.abs(),
                    &self.params.turn,
                    &mut points,
                );
                if solved.is_ok() {
                    turns.push((key, points));
                }
            }
        }
        turns
    }

    /// The end of line `from` (with its travel direction) and the start of line `to`.
    fn turn_ends(&self, from: (u64, usize), to: (u64, usize)) -> (Vec2, Vec2, Vec2) {
        let (fl, tl) = (self.line_of(from.0, from.1), self.line_of(to.0, to.1));
        let (s1, e1) = self.line_endpoints(fl, self.line_reversed(from.0, from.1));
        let (s2, _) = self.line_endpoints(tl, self.line_reversed(to.0, to.1));
        (e1, (e1 - s1) / self.length, s2)
    }

    pub fn params(&self) -> &AbParams {
        &self.params
    }
    /// N, lines per full block.
    pub fn block_size(&self) -> usize {
        self.block_size
    }
    /// Lines that must lie between two consecutive lines: ceil(2·r_min/line_width).
    pub fn min_gap_lines(&self) -> usize {
        self.min_gap
    }
    /// Number of blocks; `None` when unlimited.
    pub fn block_count(&self) -> Option<u64> {
        self.blocks
    }
    /// Unit direction of line A→B.
    pub fn direction(&self) -> Vec2 {
        self.dir
    }
    /// Length of each line, m.
    pub fn line_length(&self) -> f64 {
        self.length
    }

    fn order(&self, block: u64) -> &BlockOrder {
        match (&self.last_order, self.blocks) {
            (Some(o), Some(n)) if block + 1 == n => o,
            _ => &self.first_order,
        }
    }

    /// The driving order of `block`.
    pub fn block_order(&self, block: u64) -> &BlockOrder {
        self.order(block)
    }

    /// Lines in `block` (0 past the end).
    pub fn block_len(&self, block: u64) -> usize {
        match self.blocks {
            Some(n) if block >= n => 0,
            _ => self.order(block).len(),
        }
    }

    /// Absolute line number (0-based) at (block, rank).
    pub fn line_of(&self, block: u64, rank: usize) -> u64 {
        let rel = self.order(block).line_at(rank);
        (block * self.block_size as u64).saturating_add_signed(rel)
    }

    /// The position after (block, rank), or `None` at the end of the job.
    pub fn next_position(&self, block: u64, rank: usize) -> Option<(u64, usize)> {
        if rank + 1 < self.block_len(block) {
            Some((block, rank + 1))
        } else if self.blocks.is_none_or(|n| block + 1 < n) {
            Some((block + 1, 0))
        } else {
            None
        }
    }

    /// Lines driven before (block, rank).
    pub fn sequence_number(&self, block: u64, rank: usize) -> u64 {
        block
            .saturating_mul(self.block_size as u64)
            .saturating_add(rank as u64)
    }

    /// Lines alternate direction in driving order: even positions run A→B.
    pub fn line_reversed(&self, block: u64, rank: usize) -> bool {
        self.sequence_number(block, rank) % 2 == 1
    }

    /// Start and end of line `line` in its driving direction.
    pub fn line_endpoints(&self, line: u64, reversed: bool) -> (Vec2, Vec2) {
        let off = self.shift * line as f64;
        let a = self.params.point_a + off;
        let b = self.params.point_b + off;
        if reversed {
            (b, a)
        } else {
            (a, b)
        }
    }

    /// Append the global points of the work line at (block, rank): about `point_spacing`
    /// apart, exact ends, tag work.
    pub fn work_line_points(&self, block: u64, rank: usize, out: &mut Vec<PathPoint>) {
        let (s, e) =
            self.line_endpoints(self.line_of(block, rank), self.line_reversed(block, rank));
        let n = ((self.length / self.params.point_spacing).ceil() as usize).max(1);
        for i in 0..=n {
            out.push(PathPoint::work(s + (e - s) * (i as f64 / n as f64)));
        }
    }

    /// Append the turn from the end of the line at `from` to the start of the line at `to`:
    /// a pi turn when they are at least 2·r_min apart, a bulb turn otherwise
    /// ([`forward_turn`]).
    pub fn turn_points(
        &self,
        from: (u64, usize),
        to: (u64, usize),
        out: &mut Vec<PathPoint>,
    ) -> Result<(), PlanError> {
        let (e1, dir1, s2) = self.turn_ends(from, to);
        let offset = s2 - e1;
        let lateral = cross(&dir1, &offset);
        let level = dir1.dot(&offset).abs() <= 1e-6 * self.length.max(1.0);
        let cached = self.turns.iter().find(|(k, _)| *k == turn_key(lateral));
        if let (true, Some((_, shape))) = (level, cached) {
            let nrm = left_normal(&dir1);
            let last = shape.len().saturating_sub(1);
            for (i, q) in shape.iter().enumerate() {
                // The ends exactly on the lines, as a solved turn has them.
                let pos = match i {
                    0 => e1,
                    i if i == last => s2,
                    _ => e1 + dir1 * q.pos.x + nrm * q.pos.y,
                };
                out.push(PathPoint { pos, ..*q });
            }
            return Ok(());
        }
        let (fl, tl) = (self.line_of(from.0, from.1), self.line_of(to.0, to.1));
        let gap = fl.abs_diff(tl) as f64 * self.params.line_width;
        forward_turn(e1, dir1, s2, gap, &self.params.turn, out)
    }
}

/// The key of a turn in [`AbPlan`]'s cache: its lateral offset, mm (the sign is the side).
fn turn_key(lateral: f64) -> i64 {
    (lateral * 1000.0).round() as i64
}

/// The lines of a finite AB job driven in turn (line 0, 1, 2, … alternating direction), as
/// segments: work lines and the turns between them, solved once in the canonical frame and
/// reused (pi turn when `line_width ≥ 2·r_min`, else a fishtail with a reversal). This is the
/// operator's "sequential" order; [`AbPlan`] is the seed-000 block order.
pub fn sequential_segments(params: &AbParams) -> Result<Vec<PlanSegment>, PlanError> {
    let plan = AbPlan::new(AbParams {
        line_num: params.line_num,
        ..params.clone()
    })?;
    if params.line_num == 0 {
        return Err(PlanError::Invalid {
            name: "line_num",
            value: 0.0,
            rule: "must be at least 1 for sequential lines",
        });
    }
    let spacing = params.point_spacing;
    let mut cache = TurnCache::default();
    let mut out: Vec<PlanSegment> = Vec::new();
    let push = |out: &mut Vec<PlanSegment>, kind, direction, points: Vec<Vec2>| {
        let index = out.len();
        out.push(PlanSegment {
            kind,
            direction,
            index,
            cell: 0,
            points,
        });
    };
    for line in 0..params.line_num {
        let (s, e) = plan.line_endpoints(line, line % 2 == 1);
        if line > 0 {
            let (ps, pe) = plan.line_endpoints(line - 1, (line - 1) % 2 == 1);
            let dir = (pe - ps) / plan.length;
            for part in cache.turn(pe, dir, s, &params.turn)? {
                push(&mut out, SegmentKind::Turn, part.direction, part.points);
            }
        }
        let n = ((plan.length / spacing).ceil() as usize).max(1);
        let points = (0..=n)
            .map(|i| s + (e - s) * (i as f64 / n as f64))
            .collect();
        push(&mut out, SegmentKind::Work, Direction::Forward, points);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;
    use crate::plan::skip_order::tests::{assert_permutation, lines_cost};

    fn params(line_width: f64, r_min: f64, a: u32, line_num: u64) -> AbParams {
        AbParams {
            point_a: v2(0.0, 0.0),
            point_b: v2(0.0, 100.0),
            line_width,
            line_num,
            r_min,
            side: Side::Right,
            block_extra: a,
            point_spacing: 1.0,
            turn: TurnParams {
                r_min,
                arc_step: 5f64.to_radians(),
                merge_distance: 0.05,
                point_spacing: 1.0,
                max_points: 500,
                max_curvature_rate: 0.0,
            },
        }
    }

    /// Largest distance from a point of `a` to the polyline `b`, m.
    fn hausdorff(a: &[PathPoint], b: &[PathPoint]) -> f64 {
        a.iter()
            .map(|q| {
                b.windows(2)
                    .map(|s| {
                        let (p0, d) = (s[0].pos, s[1].pos - s[0].pos);
                        let t =
                            ((q.pos - p0).dot(&d) / d.norm_squared().max(1e-18)).clamp(0.0, 1.0);
                        (q.pos - (p0 + d * t)).norm()
                    })
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn turns_from_the_cache_are_the_turns_solved_in_place() {
        // Finite and endless jobs, odd and even blocks, pi and bulb turns, arcs and
        // continuous-curvature turns: every turn the job drives, moved from the cache, is the
        // turn solved at its own ends.
        for (w, r, a, n, rate) in [
            (3.0, 5.0, 1, 12, 0.0),
            (3.0, 5.0, 1, 12, 0.05),
            (2.0, 5.0, 3, 31, 0.021),
            (6.0, 4.0, 2, 0, 0.1),
            (12.0, 5.0, 1, 7, 0.05),
        ] {
            let mut p = params(w, r, a, n);
            p.point_a = v2(3.0, -7.0);
            p.point_b = v2(40.0, 80.0);
            p.turn.max_curvature_rate = rate;
            let plan = AbPlan::new(p.clone()).unwrap();
            assert!(!plan.turns.is_empty());
            let mut pos = Some((0u64, 0usize));
            let (mut cached, mut solved) = (Vec::new(), Vec::new());
            for _ in 0..(if n == 0 {
                3 * plan.block_size()
            } else {
                n as usize
            }) {
                let Some(from) = pos else { break };
                let Some(to) = plan.next_position(from.0, from.1) else {
                    break;
                };
                cached.clear();
                solved.clear();
                plan.turn_points(from, to, &mut cached).unwrap();
                let (e1, dir1, s2) = plan.turn_ends(from, to);
                let gap = cross(&dir1, &(s2 - e1)).abs();
                forward_turn(e1, dir1, s2, gap, &p.turn, &mut solved).unwrap();
                // The same curve: an arc's step count can differ by one between frames (its
                // sweep at a multiple of the step), so the points are compared with the other's
                // polyline, within the chords' sag (5° steps at r_min 4–5 m: under 5 mm).
                let what = format!("{w} {r} {a} {n} {rate} {from:?}");
                assert!(hausdorff(&cached, &solved) < 0.01, "{what}");
                assert!(hausdorff(&solved, &cached) < 0.01, "{what}");
                let (lc, ls) = (
                    crate::geo::path_length(&cached),
                    crate::geo::path_length(&solved),
                );
                assert!((lc - ls).abs() < 0.005 * ls, "{what}: {lc} vs {ls} m");
                assert!(cached.iter().all(|q| q.tag == solved[0].tag), "{what}");
                assert_eq!(cached.first().map(|q| q.pos), Some(e1));
                assert_eq!(cached.last().map(|q| q.pos), Some(s2));
                pos = Some(to);
            }
        }
    }

    #[test]
    fn block_size_formula() {
        // N = 2·ceil(2r/w) + a
        assert_eq!(
            AbPlan::new(params(3.0, 5.0, 1, 12)).unwrap().block_size(),
            9
        );
        assert_eq!(
            AbPlan::new(params(3.0, 3.0, 1, 12)).unwrap().block_size(),
            5
        );
        assert_eq!(
            AbPlan::new(params(2.0, 5.0, 1, 12)).unwrap().block_size(),
            11
        );
        assert_eq!(
            AbPlan::new(params(2.0, 5.0, 3, 12)).unwrap().block_size(),
            13
        );
        assert_eq!(
            AbPlan::new(params(12.0, 5.0, 1, 12)).unwrap().block_size(),
            3
        );
    }

    #[test]
    fn hundred_lines_with_n_11_are_8x11_plus_12() {
        let plan = AbPlan::new(params(2.0, 5.0, 1, 100)).unwrap();
        assert_eq!(plan.block_size(), 11);
        assert_eq!(plan.block_count(), Some(9));
        let lens: Vec<usize> = (0..9).map(|b| plan.block_len(b)).collect();
        assert_eq!(lens, [vec![11; 8], vec![12]].concat());
        assert_eq!(plan.block_len(9), 0);
    }

    #[test]
    fn huge_blocks_use_the_iterative_search_without_overflowing_the_stack() {
        // 2·5 m / 5 mm = 2000 → N = 4001 lines, searched depth-first 4001 deep.
        let plan = AbPlan::new(params(0.005, 5.0, 1, 0)).unwrap();
        assert_eq!(plan.block_size(), 4001);
        let o = plan.block_order(0);
        assert_eq!(o.short_moves, 0);
        let lines: Vec<i64> = o.lines().collect();
        assert_permutation(&lines, 4001);
        assert_eq!(lines_cost(&lines, 4001, 2000, true).0, 0);
        // Beyond MAX_BLOCK_LINES: an error, not an allocation of gigabytes.
        assert!(AbPlan::new(params(0.001, 5.0, 1, 0)).is_err());
        assert!(AbPlan::new(params(3.0, 5.0, u32::MAX, 0)).is_err());
    }

    #[test]
    fn consecutive_lines_are_2_rmin_apart_when_feasible() {
        for (w, r, a) in [
            (3.0, 5.0, 1),
            (2.0, 5.0, 1),
            (3.0, 3.0, 2),
            (1.0, 4.0, 1),
            (4.0, 6.0, 3),
        ] {
            let plan = AbPlan::new(params(w, r, a, 1000)).unwrap();
            let n = plan.block_size();
            for block in [0u64, 1, plan.block_count().unwrap() - 1] {
                let o = plan.block_order(block);
                assert_eq!(o.short_moves, 0, "w={w} r={r} a={a}");
                let lines: Vec<u64> = (0..plan.block_len(block))
                    .map(|k| plan.line_of(block, k))
                    .collect();
                for p in lines.windows(2) {
                    assert!(
                        p[0].abs_diff(p[1]) as f64 * w >= 2.0 * r - 1e-9,
                        "{lines:?}"
                    );
                }
                if block + 1 < plan.block_count().unwrap() {
                    let next_first = plan.line_of(block + 1, 0);
                    assert_eq!(next_first, (block + 1) * n as u64);
                    let last = *lines.last().unwrap();
                    assert!(next_first.abs_diff(last) as f64 * w >= 2.0 * r - 1e-9);
                }
            }
        }
    }

    #[test]
    fn every_line_once_for_awkward_counts() {
        let base = params(3.0, 5.0, 1, 0);
        let n = AbPlan::new(base.clone()).unwrap().block_size() as u64;
        for count in [1, n - 1, n, n + 1, 2 * n + 3, 100] {
            let plan = AbPlan::new(AbParams {
                line_num: count,
                ..base.clone()
            })
            .unwrap();
            let mut pos = Some((0u64, 0usize));
            let mut lines = Vec::new();
            while let Some((b, r)) = pos {
                lines.push(plan.line_of(b, r));
                pos = plan.next_position(b, r);
                assert!(lines.len() as u64 <= count);
            }
            lines.sort_unstable();
            assert_eq!(lines, (0..count).collect::<Vec<_>>(), "count {count}");
        }
    }

    #[test]
    fn unlimited_job_keeps_going() {
        let plan = AbPlan::new(params(3.0, 5.0, 1, 0)).unwrap();
        assert_eq!(plan.block_count(), None);
        let mut pos = (0u64, 0usize);
        for _ in 0..10_000 {
            pos = plan.next_position(pos.0, pos.1).expect("unlimited");
        }
        assert!(pos.0 > 1000);
    }

    #[test]
    fn memory_does_not_grow_with_line_num() {
        let small = AbPlan::new(params(3.0, 5.0, 1, 100)).unwrap();
        let huge = AbPlan::new(params(3.0, 5.0, 1, 100_000)).unwrap();
        // 100 = 11·9 + 1 and 100 000 = 11 111·9 + 1: the same stored orders.
        assert_eq!(small.first_order, huge.first_order);
        assert_eq!(small.last_order, huge.last_order);
        assert_eq!(std::mem::size_of_val(&small), std::mem::size_of_val(&huge));
    }

    #[test]
    fn directions_alternate_and_turns_connect_lines() {
        let plan = AbPlan::new(params(3.0, 5.0, 1, 20)).unwrap();
        let mut pos = (0u64, 0usize);
        let mut buf = Vec::new();
        while let Some(next) = plan.next_position(pos.0, pos.1) {
            assert_ne!(
                plan.line_reversed(pos.0, pos.1),
                plan.line_reversed(next.0, next.1)
            );
            buf.clear();
            plan.work_line_points(pos.0, pos.1, &mut buf);
            let line_end = buf.last().unwrap().pos;
            assert!(buf
                .windows(2)
                .all(|w| (w[1].pos - w[0].pos).norm() <= 1.0 + 1e-9));
            buf.clear();
            plan.turn_points(pos, next, &mut buf).unwrap();
            assert!((buf[0].pos - line_end).norm() < 1e-9);
            let mut next_line = Vec::new();
            plan.work_line_points(next.0, next.1, &mut next_line);
            assert!((buf.last().unwrap().pos - next_line[0].pos).norm() < 1e-9);
            pos = next;
        }
    }

    #[test]
    fn lines_lie_on_the_configured_side() {
        let mut p = params(3.0, 5.0, 1, 5);
        let right = AbPlan::new(p.clone()).unwrap();
        // A→B points north; right is east.
        assert!(right.line_endpoints(1, false).0.x > 2.9);
        p.side = Side::Left;
        let left = AbPlan::new(p).unwrap();
        assert!(left.line_endpoints(1, false).0.x < -2.9);
    }

    #[test]
    fn bad_parameters_are_errors_not_panics() {
        assert!(AbPlan::new(params(0.0, 5.0, 1, 5)).is_err());
        assert!(AbPlan::new(params(f64::NAN, 5.0, 1, 5)).is_err());
        assert!(AbPlan::new(params(3.0, 5.0, 0, 5)).is_err());
        let mut p = params(3.0, 5.0, 1, 5);
        p.point_b = p.point_a;
        assert!(AbPlan::new(p).is_err());
        let mut p = params(3.0, 5.0, 1, 5);
        p.point_a.x = f64::INFINITY;
        assert!(AbPlan::new(p).is_err());
        let mut p = params(3.0, 5.0, 1, 5);
        p.turn.r_min = 6.0;
        assert!(
            AbPlan::new(p).is_err(),
            "turn radius disagreeing with r_min"
        );
    }

    /// Walk a whole job, generating every turn; returns (pi turns, bulb turns).
    fn drive(plan: &AbPlan) -> (usize, usize) {
        let w = plan.params().line_width;
        let r = plan.params().r_min;
        let (mut pi, mut bulb) = (0, 0);
        let mut pos = (0u64, 0usize);
        let mut buf = Vec::new();
        while let Some(next) = plan.next_position(pos.0, pos.1) {
            buf.clear();
            plan.turn_points(pos, next, &mut buf)
                .expect("every turn of a plan is drivable");
            let gap = plan
                .line_of(pos.0, pos.1)
                .abs_diff(plan.line_of(next.0, next.1));
            if gap as f64 * w >= 2.0 * r - 1e-6 {
                pi += 1;
            } else {
                bulb += 1;
            }
            pos = next;
        }
        (pi, bulb)
    }

    #[test]
    fn infeasible_blocks_fall_back_to_fewest_short_moves_driven_as_bulb_turns() {
        // w = 3, r = 5: min gap 4 lines, N = 9. With 8 lines (N − 1) no order avoids short
        // moves (lines 3 and 4 each have a single partner 7 and 0), so the plan must not fail.
        let base = params(3.0, 5.0, 1, 0);
        let n = AbPlan::new(base.clone()).unwrap().block_size() as u64;
        assert_eq!(n, 9);
        for count in [n - 1, 5, 2] {
            let plan = AbPlan::new(AbParams {
                line_num: count,
                ..base.clone()
            })
            .unwrap();
            assert_eq!(plan.block_count(), Some(1));
            let order = plan.block_order(0);
            assert!(order.short_moves > 0, "count {count}");
            let (_, bulb) = drive(&plan);
            assert_eq!(bulb, order.short_moves as usize);
        }
        // Feasible jobs have pi turns only, including between blocks.
        for count in [n, 2 * n + 3, 100] {
            let plan = AbPlan::new(AbParams {
                line_num: count,
                ..base.clone()
            })
            .unwrap();
            let (pi, bulb) = drive(&plan);
            assert_eq!((pi, bulb), (count as usize - 1, 0), "count {count}");
        }
    }
}
