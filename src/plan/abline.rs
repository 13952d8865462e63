//! The seed-000 AB-line planner (SPEC §2).
//!
//! Work line `k` is line A→B shifted `k·line_width` to the configured side. Lines are
//! generated lazily: the plan stores only the parameters and the driving order of one block
//! (plus the last block's, when it is larger), so its memory does not depend on `line_num`.
//!
//! Lines are grouped in blocks of `N = 2·ceil(2·r_min/line_width) + a`. Inside a block the
//! lines are driven in the shortest order that never turns between lines closer than
//! `2·r_min` (so every turn is a pi turn), starting at the block's first line and ending where
//! the next block's first line is at least `2·r_min` away. The order is solved exactly by
//! dynamic programming over subsets for blocks of up to [`EXACT_MAX_LINES`] lines, and by a
//! heuristic beyond (see [`solve_block_order`]). When no order avoids lines closer than
//! `2·r_min` (a block of fewer than `2·ceil(2·r_min/line_width) + 1` lines), the plan does not
//! fail: the order has the fewest such "short" moves, then the shortest distance, and the
//! short moves are driven with bulb turns.

use super::coverage::turns::TurnCache;
use super::coverage::{PlanSegment, SegmentKind};
use super::turns::{bulb_turn, pi_turn, TurnParams};
use super::PlanError;
use crate::geo::{left_normal, Direction, PathPoint, Vec2};
use serde::{Deserialize, Serialize};

/// Largest block solved exactly (Held–Karp over subsets); larger blocks use a bounded search.
pub const EXACT_MAX_LINES: usize = 20;

/// Largest block accepted, lines. `N = 2·ceil(2·r_min/line_width) + a` beyond this means a
/// line width far below the turning radius (or a huge `a`), a configuration error rather
/// than a job; refusing it keeps the plan's memory and set-up time bounded.
pub const MAX_BLOCK_LINES: usize = 4096;

/// Side of A→B on which the following lines are laid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    Left,
    Right,
}

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

/// A block's driving order, stored as differences between consecutive relative line
/// numbers (the first line is always 0): `[5, 12, 4]` from 0 is stored as `[+5, +7, -8]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BlockOrder {
    pub diffs: Vec<i32>,
    /// Moves between lines closer than 2·r_min (0 whenever a valid order exists).
    pub short_moves: u32,
}

impl BlockOrder {
    /// Number of lines.
    pub fn len(&self) -> usize {
        self.diffs.len() + 1
    }
    pub fn is_empty(&self) -> bool {
        false
    }
    /// Relative line numbers in driving order.
    pub fn lines(&self) -> impl Iterator<Item = i64> + '_ {
        std::iter::once(0i64).chain(self.diffs.iter().scan(0i64, |acc, d| {
            *acc += *d as i64;
            Some(*acc)
        }))
    }
    /// Relative line number at `rank`.
    pub fn line_at(&self, rank: usize) -> i64 {
        self.diffs[..rank.min(self.diffs.len())]
            .iter()
            .map(|d| *d as i64)
            .sum()
    }
}

/// Weight of one short move in the fallback cost. Exact blocks have at most
/// [`EXACT_MAX_LINES`] = 20 lines, so their total distance (at most 20 moves of at most 19
/// lines, 380) stays below this and "fewer short moves" always wins over "shorter"; the whole
/// cost (at most 20·512 + 380) fits the DP's `u16` cells.
const SHORT_MOVE_COST: u32 = 512;

/// Cost of a move of `gap` lines: short moves dominate, then total distance (in lines).
#[inline]
fn move_cost(gap: usize, min_gap: usize) -> u32 {
    gap as u32 + if gap < min_gap { SHORT_MOVE_COST } else { 0 }
}

/// The shortest driving order of a block of `n` lines (relative numbers 0..n).
///
/// * Moves between lines fewer than `min_gap` lines apart are "short" (closer than 2·r_min)
///   and forbidden. When no order without them exists (a small remainder block, or
///   `line_num = N − 1`), the order minimises first the number of short moves, then the
///   distance; the short moves are then driven with bulb turns.
/// * The order starts at line 0. With `next_block` = true it must end on a line from which
///   line `n` (the next block's first) is at least `min_gap` away; the move there is counted.
///
/// Exact for `n` ≤ [`EXACT_MAX_LINES`] (dynamic programming over subsets, see `held_karp`);
/// a bounded search beyond (see `heuristic`). Pure; allocates O(2^(n−1)·(n−1)) `u16` for the
/// exact solver (20 MB at n = 20).
pub fn solve_block_order(n: usize, min_gap: usize, next_block: bool) -> BlockOrder {
    let lines = if n <= EXACT_MAX_LINES {
        held_karp(n, min_gap, next_block)
    } else {
        heuristic(n, min_gap, next_block)
    };
    let mut short = 0u32;
    let diffs: Vec<i32> = lines
        .windows(2)
        .map(|w| {
            let d = w[1] as i32 - w[0] as i32;
            if (d.unsigned_abs() as usize) < min_gap {
                short += 1;
            }
            d
        })
        .collect();
    BlockOrder {
        diffs,
        short_moves: short,
    }
}

/// Exact order: first with short moves forbidden (the usual, feasible case, which also only
/// visits the allowed moves and so runs about twice as fast), then, if that has no solution,
/// with short moves allowed at [`SHORT_MOVE_COST`] each.
fn held_karp(n: usize, min_gap: usize, next_block: bool) -> Vec<usize> {
    if n <= 1 {
        return vec![0; n.max(1)];
    }
    held_karp_pass(n, min_gap, next_block, true)
        .or_else(|| held_karp_pass(n, min_gap, next_block, false))
        .unwrap_or_else(|| (0..n).collect())
}

/// One DP pass over subsets (Held–Karp). State: (set of visited lines other than 0, last
/// line); line `j` ≥ 1 is bit `j − 1`. Line 0 is always first, so only 2^(n−1) sets exist,
/// each with n − 1 `u16` cells. With `strict`, short moves and an end too close to the next
/// block are impossible and `None` means no such order exists; otherwise they cost
/// [`SHORT_MOVE_COST`] each and there is always an answer. `2 ≤ n ≤ EXACT_MAX_LINES`.
fn held_karp_pass(n: usize, min_gap: usize, next_block: bool, strict: bool) -> Option<Vec<usize>> {
    const INF: u16 = u16::MAX;
    let m = n - 1;
    let full: usize = (1usize << m) - 1;
    let cost = |a: usize, b: usize| move_cost(a.abs_diff(b), min_gap) as u16;
    // allowed[l]: the lines (as bits) that may follow line l.
    let allowed: Vec<usize> = (0..n)
        .map(|l| {
            (1..n)
                .filter(|&j| j != l && (!strict || l.abs_diff(j) >= min_gap))
                .fold(0usize, |acc, j| acc | 1 << (j - 1))
        })
        .collect();
    let mut dp = vec![INF; (full + 1) * m];
    let mut first = allowed[0];
    while first != 0 {
        let b = first.trailing_zeros() as usize;
        first &= first - 1;
        dp[(1 << b) * m + b] = cost(0, b + 1);
    }
    // Sets in increasing order: every set is final before any superset is extended.
    for mask in 1..=full {
        let row = mask * m;
        let mut rest = mask;
        while rest != 0 {
            let b = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            let cur = dp[row + b];
            if cur == INF {
                continue;
            }
            let last = b + 1;
            let mut free = full & !mask & allowed[last];
            while free != 0 {
                let nb = free.trailing_zeros() as usize;
                free &= free - 1;
                let c = cur + cost(last, nb + 1);
                let slot = &mut dp[(mask | 1 << nb) * m + nb];
                if c < *slot {
                    *slot = c;
                }
            }
        }
    }
    let end_cost = |last: usize| -> Option<u32> {
        if !next_block {
            Some(0)
        } else if strict && n - last < min_gap {
            None
        } else {
            Some(move_cost(n - last, min_gap))
        }
    };
    let mut best: Option<(u32, usize)> = None;
    for last in 1..n {
        let c = dp[full * m + last - 1];
        if c == INF {
            continue;
        }
        if let Some(e) = end_cost(last) {
            let total = c as u32 + e;
            if best.is_none_or(|(b, _)| total < b) {
                best = Some((total, last));
            }
        }
    }
    let (_, mut last) = best?;
    // Walk back: a predecessor whose stored cost plus the move gives the stored cost.
    let mut order = vec![0usize; n];
    let mut mask = full;
    for pos in (1..n).rev() {
        order[pos] = last;
        let here = dp[mask * m + last - 1];
        let prev_mask = mask & !(1 << (last - 1));
        if prev_mask == 0 {
            break;
        }
        let mut rest = prev_mask;
        let mut found = None;
        while rest != 0 {
            let b = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            let p = b + 1;
            let c = dp[prev_mask * m + b];
            if c != INF && allowed[p] >> (last - 1) & 1 == 1 && c + cost(p, last) == here {
                found = Some(p);
                break;
            }
        }
        mask = prev_mask;
        last = found?;
    }
    Some(order)
}

/// Node budget of the depth-first search for blocks too large to solve exactly.
const SEARCH_BUDGET: usize = 20_000;

/// Largest part of a block solved exactly when chaining parts (see [`chained_order`]); 16
/// lines solve in a few milliseconds.
const CHAIN_PART_LINES: usize = 16;

/// (short moves, distance in lines) of `lines` in order, counting the move on to line `n`
/// when `next_block`: the lexicographic cost every block order minimises.
fn lexicographic_cost(lines: &[usize], n: usize, min_gap: usize, next_block: bool) -> (u32, u64) {
    let end = next_block.then_some(n);
    let moves = lines.windows(2).map(|w| w[0].abs_diff(w[1])).chain(
        end.into_iter()
            .filter_map(|e| lines.last().map(|&l| e.abs_diff(l))),
    );
    moves.fold((0, 0), |(short, dist), gap| {
        (short + u32::from(gap < min_gap), dist + gap as u64)
    })
}

/// Order for blocks larger than [`EXACT_MAX_LINES`]: the cheapest (fewest short moves, then
/// shortest) of three candidates, each with no short move whenever `n ≥ 2·min_gap + 1`:
///
/// * [`chained_order`]: the block cut into consecutive parts of about 16 lines (at least
///   `2·min_gap + 1`), each solved exactly (or, when larger than 20 lines, by the lattice)
///   with the next part's first line as its end constraint: the AB block rule one level down;
/// * a depth-first search that tries the nearest allowed line first and backtracks, within
///   a budget of [`SEARCH_BUDGET`] placed lines;
/// * the lattice order of [`interleaved_order`], always available.
///
/// The tests check it against the exact DP on every block the DP can solve (within 40 %,
/// never a short move where an order without one exists).
fn heuristic(n: usize, min_gap: usize, next_block: bool) -> Vec<usize> {
    let candidates = [
        chained_order(n, min_gap, next_block, CHAIN_PART_LINES),
        depth_first_order(n, min_gap, next_block, SEARCH_BUDGET),
        Some(interleaved_order(n)),
    ];
    candidates
        .into_iter()
        .flatten()
        .min_by_key(|lines| lexicographic_cost(lines, n, min_gap, next_block))
        .unwrap_or_else(|| (0..n).collect())
}

/// The block cut into consecutive parts of near-equal size, each at least `2·min_gap + 1`
/// lines (so each has an order with no short move), preferring parts of at most
/// `part_lines`. Each part starts at its first line and ends at least `min_gap` before the
/// next part's first line (for the last part: as the block must end): parts of up to
/// [`EXACT_MAX_LINES`] are solved exactly, larger ones take the lattice order (whose end
/// always leaves `ceil(size/2) ≥ min_gap` to the next part). `None` when `n < 2·min_gap + 1`.
fn chained_order(
    n: usize,
    min_gap: usize,
    next_block: bool,
    part_lines: usize,
) -> Option<Vec<usize>> {
    let least = 2 * min_gap + 1;
    let mut parts = n.div_ceil(part_lines.max(1));
    if n / parts < least {
        parts = n / least;
    }
    if parts == 0 {
        return None;
    }
    // Parts have two sizes and two end rules: solve each kind once.
    let mut solved: Vec<((usize, bool), Vec<usize>)> = Vec::new();
    let mut order = Vec::with_capacity(n);
    let mut offset = 0;
    for i in 0..parts {
        let size = n / parts + usize::from(i < n % parts);
        let next = i + 1 < parts || next_block;
        let key = (size, next);
        let part = match solved.iter().position(|(k, _)| *k == key) {
            Some(j) => &solved[j].1,
            None => {
                let lines = if size <= EXACT_MAX_LINES {
                    held_karp(size, min_gap, next)
                } else {
                    interleaved_order(size)
                };
                solved.push((key, lines));
                &solved[solved.len() - 1].1
            }
        };
        order.extend(part.iter().map(|&l| l + offset));
        offset += size;
    }
    Some(order)
}

/// Iterative (no recursion, so no stack limit on `n`) depth-first search for an order with no
/// short move that ends at least `min_gap` before line `n` when `next_block`. Candidates from
/// line `c`: `c − d`, `c + d` for `d = min_gap, min_gap + 1, …`. `None` when no order exists
/// or more than `budget` lines were placed.
fn depth_first_order(
    n: usize,
    min_gap: usize,
    next_block: bool,
    budget: usize,
) -> Option<Vec<usize>> {
    let gap = min_gap.max(1);
    let mut visited = vec![false; n.max(1)];
    let mut order = Vec::with_capacity(n.max(1));
    // cursor[k]: the next candidate to try from order[k]; candidate i is at distance
    // gap + i/2, below the line for even i, above it for odd i.
    let mut cursor = Vec::with_capacity(n.max(1));
    visited[0] = true;
    order.push(0usize);
    cursor.push(0usize);
    let mut placed = 0usize;
    loop {
        let depth = order.len() - 1;
        let cur = order[depth];
        if order.len() >= n {
            if !next_block || n - cur >= min_gap {
                return Some(order);
            }
        } else {
            let mut chosen = None;
            while gap + cursor[depth] / 2 < n {
                let i = cursor[depth];
                cursor[depth] += 1;
                let dist = gap + i / 2;
                let cand = if i % 2 == 0 {
                    cur.checked_sub(dist)
                } else {
                    Some(cur + dist).filter(|&c| c < n)
                };
                if let Some(c) = cand.filter(|&c| !visited[c]) {
                    chosen = Some(c);
                    break;
                }
            }
            if let Some(c) = chosen {
                placed += 1;
                if placed > budget {
                    return None;
                }
                visited[c] = true;
                order.push(c);
                cursor.push(0);
                continue;
            }
        }
        // Dead end or a complete order ending too close to the next block: backtrack.
        if depth == 0 {
            return None;
        }
        visited[cur] = false;
        order.pop();
        cursor.pop();
    }
}

/// A lattice order of `n` lines from line 0 whose moves are all at least `ceil(n/2) − 1`
/// lines long and whose end is at least `ceil(n/2)` lines before line `n`; so with
/// `n ≥ 2·min_gap + 1` (every full block) it has no short move and meets the end constraint.
///
/// * odd `n = 2h − 1`: 0, h, 1, h+1, …, h−2, 2h−2, h−1 (moves h and h−1, ends at h−1);
/// * even `n = 2h`: 0, 2h−1, h−1, 2h−2, h−2, …, h+1, 1, h (moves h and h−1, ends at h).
pub fn interleaved_order(n: usize) -> Vec<usize> {
    let h = n.div_ceil(2);
    let mut order = Vec::with_capacity(n);
    if n % 2 == 1 {
        for i in 0..h {
            order.push(i);
            if i + h < n {
                order.push(i + h);
            }
        }
    } else if n > 0 {
        order.push(0);
        for j in 0..h - 1 {
            order.push(2 * h - 1 - j);
            order.push(h - 1 - j);
        }
        order.push(h);
    }
    order
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
        let min_gap = ((2.0 * params.r_min / params.line_width) - 1e-9)
            .ceil()
            .max(0.0) as usize;
        let block_size = min_gap
            .saturating_mul(2)
            .saturating_add(params.block_extra as usize);
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
            let full = params.line_num / block_size as u64;
            let rem = (params.line_num % block_size as u64) as usize;
            if full <= 1 {
                // One block holds every line; nothing follows it.
                let n = params.line_num as usize;
                (Some(1), solve_block_order(n, min_gap, false), None)
            } else {
                let first = solve_block_order(block_size, min_gap, true);
                let last = (rem > 0).then(|| solve_block_order(block_size + rem, min_gap, false));
                (Some(full), first, last)
            }
        };
        Ok(AbPlan {
            params,
            dir,
            shift,
            length,
            block_size,
            min_gap,
            blocks,
            first_order,
            last_order,
        })
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
    /// a pi turn when they are at least 2·r_min apart, a bulb turn otherwise.
    pub fn turn_points(
        &self,
        from: (u64, usize),
        to: (u64, usize),
        out: &mut Vec<PathPoint>,
    ) -> Result<(), PlanError> {
        let (fl, tl) = (self.line_of(from.0, from.1), self.line_of(to.0, to.1));
        let (s1, e1) = self.line_endpoints(fl, self.line_reversed(from.0, from.1));
        let (s2, _) = self.line_endpoints(tl, self.line_reversed(to.0, to.1));
        let dir1 = (e1 - s1) / self.length;
        let lateral = fl.abs_diff(tl) as f64 * self.params.line_width;
        if lateral + 1e-6 >= 2.0 * self.params.r_min {
            pi_turn(e1, dir1, s2, &self.params.turn, out)
        } else {
            bulb_turn(e1, dir1, s2, &self.params.turn, out)
        }
    }
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

    /// (short moves, distance in lines) of a move sequence: the lexicographic cost the
    /// solver must minimise, computed independently of its internal weights.
    type Cost = (u32, u64);

    fn add(c: Cost, gap: usize, min_gap: usize) -> Cost {
        (c.0 + u32::from(gap < min_gap), c.1 + gap as u64)
    }

    /// Best cost over all (n−1)! orders starting at 0.
    fn brute_force(n: usize, min_gap: usize, next_block: bool) -> Cost {
        fn rec(cur: usize, left: &mut Vec<usize>, n: usize, g: usize, nb: bool, acc: Cost) -> Cost {
            if left.is_empty() {
                return if nb { add(acc, n - cur, g) } else { acc };
            }
            let mut best = (u32::MAX, u64::MAX);
            for i in 0..left.len() {
                let nx = left.remove(i);
                best = best.min(rec(nx, left, n, g, nb, add(acc, cur.abs_diff(nx), g)));
                left.insert(i, nx);
            }
            best
        }
        rec(0, &mut (1..n).collect(), n, min_gap, next_block, (0, 0))
    }

    fn lines_cost(lines: &[i64], n: usize, min_gap: usize, next_block: bool) -> Cost {
        let mut c = lines
            .windows(2)
            .fold((0, 0), |c, w| add(c, w[0].abs_diff(w[1]) as usize, min_gap));
        if next_block {
            c = add(c, n - *lines.last().unwrap() as usize, min_gap);
        }
        c
    }

    fn order_cost(o: &BlockOrder, n: usize, min_gap: usize, next_block: bool) -> Cost {
        lines_cost(&o.lines().collect::<Vec<_>>(), n, min_gap, next_block)
    }

    fn assert_permutation(lines: &[i64], n: usize) {
        let mut seen = lines.to_vec();
        seen.sort_unstable();
        assert_eq!(seen, (0..n as i64).collect::<Vec<_>>(), "{lines:?}");
        assert_eq!(lines[0], 0);
    }

    #[test]
    fn order_is_optimal_against_brute_force() {
        // min_gap up to 5 covers infeasible blocks (n < 2·min_gap), where the fallback must
        // minimise short moves first, then distance.
        let mut fallbacks = 0;
        for n in 1..=9 {
            for min_gap in 1..=5 {
                for next_block in [false, true] {
                    let o = solve_block_order(n, min_gap, next_block);
                    assert_eq!(o.len(), n);
                    let lines: Vec<i64> = o.lines().collect();
                    assert_permutation(&lines, n);
                    let cost = order_cost(&o, n, min_gap, next_block);
                    let best = brute_force(n, min_gap, next_block);
                    assert_eq!(
                        cost, best,
                        "n={n} gap={min_gap} next={next_block} {lines:?}"
                    );
                    // short_moves counts the moves inside the block.
                    let inside = lines_cost(&lines, n, min_gap, false).0;
                    assert_eq!(o.short_moves, inside);
                    if best.0 > 0 {
                        fallbacks += 1;
                    }
                }
            }
        }
        assert!(fallbacks > 10, "the infeasible cases were exercised");
    }

    #[test]
    fn lattice_order_is_valid_whenever_a_full_block_is() {
        for n in 1..=64 {
            let lines: Vec<i64> = interleaved_order(n).iter().map(|&l| l as i64).collect();
            assert_eq!(lines.len(), n);
            assert_permutation(&lines, n);
            for min_gap in 1..=(n.saturating_sub(1)) / 2 {
                assert_eq!(
                    lines_cost(&lines, n, min_gap, true).0,
                    0,
                    "n={n} gap={min_gap} {lines:?}"
                );
            }
        }
    }

    #[test]
    fn heuristic_is_valid_for_large_blocks_and_no_worse_than_its_candidates() {
        for n in [21usize, 30, 64] {
            let gaps = [1usize, 4, 9, 13, (n - 1) / 2];
            for min_gap in gaps.into_iter().filter(|&g| 2 * g < n) {
                for next_block in [false, true] {
                    let o = solve_block_order(n, min_gap, next_block);
                    let lines: Vec<i64> = o.lines().collect();
                    assert_permutation(&lines, n);
                    assert_eq!(o.short_moves, 0, "n={n} gap={min_gap}");
                    let cost = lines_cost(&lines, n, min_gap, next_block);
                    assert_eq!(cost.0, 0);
                    let lattice: Vec<i64> =
                        interleaved_order(n).iter().map(|&l| l as i64).collect();
                    assert!(cost <= lines_cost(&lattice, n, min_gap, next_block));
                    if let Some(c) = chained_order(n, min_gap, next_block, CHAIN_PART_LINES) {
                        let c: Vec<i64> = c.iter().map(|&l| l as i64).collect();
                        assert_permutation(&c, n);
                        assert!(cost <= lines_cost(&c, n, min_gap, next_block));
                    }
                }
            }
        }
    }

    /// The proven-optimal check of the large-block candidates: on blocks the DP solves
    /// exactly, force them to work as they do on large blocks and compare.
    #[test]
    fn heuristic_candidates_are_near_optimal_where_the_dp_can_check_them() {
        // Chained parts (forced to 6–10 lines): measured worst 1.12× the optimum.
        let mut worst_chain: f64 = 1.0;
        for n in 7..=16 {
            for min_gap in 1..=(n - 1) / 2 {
                for next_block in [false, true] {
                    let exact = order_cost(
                        &solve_block_order(n, min_gap, next_block),
                        n,
                        min_gap,
                        next_block,
                    );
                    assert_eq!(exact.0, 0);
                    for part in [6, 8, 10] {
                        let Some(c) = chained_order(n, min_gap, next_block, part) else {
                            continue;
                        };
                        let c: Vec<i64> = c.iter().map(|&l| l as i64).collect();
                        assert_permutation(&c, n);
                        let c = lines_cost(&c, n, min_gap, next_block);
                        assert_eq!(c.0, 0, "n={n} gap={min_gap}: chained made a short move");
                        assert!(c.1 >= exact.1, "the DP is not optimal: n={n} gap={min_gap}");
                        worst_chain = worst_chain.max(c.1 as f64 / exact.1 as f64);
                    }
                }
            }
        }
        assert!(
            worst_chain <= 1.15,
            "chained up to {worst_chain:.3}× the optimum"
        );
        // Depth-first search: measured worst 1.39×.
        let mut worst_dfs: f64 = 1.0;
        for n in 5..=14 {
            for min_gap in 1..=(n - 1) / 2 {
                let exact = order_cost(&solve_block_order(n, min_gap, true), n, min_gap, true);
                let Some(lines) = depth_first_order(n, min_gap, true, SEARCH_BUDGET) else {
                    panic!("search failed on a small feasible block n={n} gap={min_gap}");
                };
                let lines: Vec<i64> = lines.iter().map(|&l| l as i64).collect();
                assert_permutation(&lines, n);
                let h = lines_cost(&lines, n, min_gap, true);
                assert_eq!(h.0, 0, "n={n} gap={min_gap}: search made a short move");
                assert!(h.1 >= exact.1, "the DP is not optimal: n={n} gap={min_gap}");
                worst_dfs = worst_dfs.max(h.1 as f64 / exact.1 as f64);
            }
        }
        assert!(
            worst_dfs <= 1.40,
            "search up to {worst_dfs:.3}× the optimum"
        );
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
