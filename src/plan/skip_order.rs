//! The seed-000 skip order (docs/METHODS.md, Blocks and the skip order): in which order a run of
//! parallel lines is driven so that no turn joins lines closer than `2·r_min`, used by AB jobs
//! ([`crate::plan::abline`]) and by field swaths ([`crate::plan::coverage`]).
//!
//! Contract: pure functions of line counts. One tolerance and one block rule:
//! * [`min_gap_lines`]: two lines `k` apart are far enough for a pi turn when
//!   `k·spacing + ε ≥ 2·r_min`, ε = [`GAP_TOLERANCE`] (the turn selector's rule,
//!   [`crate::plan::turns::turn_shape`]);
//! * [`block_size`]: blocks of `N = 2·min_gap + a` lines (`a` ≥ 1; fields use 1);
//! * [`block_count`]: a run of `n` lines is cut into blocks of `N`, the last one taking the
//!   remainder; fewer than `2·N` lines are one block;
//! * inside a block the lines are driven in the shortest order that starts at its first line,
//!   never moves fewer than `min_gap` lines, and (when a block follows) ends at least
//!   `min_gap` before the next block's first line ([`solve_block_order`]).
//!
//! [`skip_order`] applies the rule to a whole run (a field's swaths, each block solved with
//! its own end constraint). An AB plan ([`crate::plan::abline::AbPlan`]) stores one order per
//! block size and so drives a last block of `N` lines (when `line_num` is a multiple of `N`)
//! in the first block's order, whose end keeps the gap a next block would need.

mod table;

pub use crate::plan::turns::GAP_TOLERANCE;

/// Largest block solved exactly (Held–Karp over subsets); larger blocks use a bounded search.
pub const EXACT_MAX_LINES: usize = 20;

/// Largest block accepted, lines. `N = 2·ceil(2·r_min/line_width) + a` beyond this means a
/// line width far below the turning radius (or a huge `a`), a configuration error rather
/// than a job; refusing it keeps the plan's memory and set-up time bounded.
pub const MAX_BLOCK_LINES: usize = 4096;

/// Lines that must lie between two consecutive lines for a pi turn between them:
/// `ceil((2·r_min − ε) / spacing)`, ε = [`GAP_TOLERANCE`] (0 when any spacing will do).
pub fn min_gap_lines(r_min: f64, spacing: f64) -> usize {
    ((2.0 * r_min - GAP_TOLERANCE) / spacing).ceil().max(0.0) as usize
}

/// Lines per block, `N = 2·min_gap + a` (saturating).
pub fn block_size(min_gap: usize, a: usize) -> usize {
    min_gap.saturating_mul(2).saturating_add(a)
}

/// Blocks of a run of `lines` lines cut by blocks of `block_size`: (number of blocks, lines in
/// the last one). Full blocks of `block_size`, the last one taking the remainder; fewer than
/// `2·block_size` lines are one block. `lines` ≥ 1, `block_size` ≥ 1.
pub fn block_count(lines: u64, block_size: usize) -> (u64, u64) {
    let n = block_size.max(1) as u64;
    let full = lines / n;
    if full <= 1 {
        (1, lines)
    } else {
        (full, n + lines % n)
    }
}

/// The whole skip order of a run of `n` lines (0-based, in driving order): blocks of
/// [`block_size`]`(min_gap, a)` lines cut by [`block_count`], each solved by
/// [`solve_block_order`], the last one without an end constraint. With `min_gap` ≤ 1 every
/// move is allowed and the lines are driven in turn.
pub fn skip_order(n: usize, min_gap: usize, a: usize) -> Vec<usize> {
    skip_order_with(n, min_gap, a, &mut BlockOrders::default())
}

/// Block orders already solved, by (lines, `min_gap`, `next_block`): the runs of a field cut
/// into blocks of few sizes, so a plan of many runs solves each block size once (the exact
/// solver costs ~0.1 ms a block; a field of 300 runs at w 3 m spent 40 % of its plan in it).
#[derive(Debug, Clone, Default)]
pub struct BlockOrders(std::collections::HashMap<(usize, usize, bool), BlockOrder>);

impl BlockOrders {
    /// [`solve_block_order`]`(n, min_gap, next_block)`, solved on first need.
    pub fn get(&mut self, n: usize, min_gap: usize, next_block: bool) -> &BlockOrder {
        self.0
            .entry((n, min_gap, next_block))
            .or_insert_with(|| solve_block_order(n, min_gap, next_block))
    }
}

/// [`skip_order`] with the block orders taken from (and added to) `orders`.
pub fn skip_order_with(n: usize, min_gap: usize, a: usize, orders: &mut BlockOrders) -> Vec<usize> {
    if min_gap <= 1 || n < 2 {
        return (0..n).collect();
    }
    let size = block_size(min_gap, a);
    let (blocks, last) = block_count(n as u64, size);
    let mut order = Vec::with_capacity(n);
    let mut start = 0;
    for b in 0..blocks {
        let len = if b + 1 == blocks { last as usize } else { size };
        let bo = orders.get(len, min_gap, b + 1 < blocks);
        order.extend(bo.lines().map(|l| start + l as usize));
        start += len;
    }
    order
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
/// Blocks of [`table::TABLE_MIN_LINES`]`..=`[`EXACT_MAX_LINES`] lines are
/// looked up in the table of this function's answers (`skip_order/table.rs`, made by it and
/// checked against it by the tests): a block of 20 lines cost ~5 ms, and a plan at w 3 m,
/// r_min 8 m (blocks of 13 lines, last blocks of 13–25) up to 18 ms for its few sizes.
fn held_karp(n: usize, min_gap: usize, next_block: bool) -> Vec<usize> {
    table::exact_order(n, min_gap, next_block)
        .unwrap_or_else(|| held_karp_solve(n, min_gap, next_block))
}

/// [`held_karp`] solved (not looked up).
fn held_karp_solve(n: usize, min_gap: usize, next_block: bool) -> Vec<usize> {
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
    // The cost of every move, looked up (the extension loop below runs ~20 million times for
    // a block of 20 lines).
    let costs: Vec<u16> = (0..n * n)
        .map(|k| move_cost((k / n).abs_diff(k % n), min_gap) as u16)
        .collect();
    let cost = |a: usize, b: usize| costs[a * n + b];
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
            // (The cost of a move from `last` to line nb + 1 at `from_last[nb + 1]`.)
            let from_last = &costs[last * n..(last + 1) * n];
            while free != 0 {
                let nb = free.trailing_zeros() as usize;
                free &= free - 1;
                let c = cur + from_last[nb + 1];
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

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// (short moves, distance in lines) of a move sequence: the lexicographic cost the
    /// solver must minimise, computed independently of its internal weights.
    pub(crate) type Cost = (u32, u64);

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

    pub(crate) fn lines_cost(lines: &[i64], n: usize, min_gap: usize, next_block: bool) -> Cost {
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

    pub(crate) fn assert_permutation(lines: &[i64], n: usize) {
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

    /// The table of exact orders holds the solver's answers: every entry (blocks of up to 16
    /// lines in a debug build, where the larger ones take seconds), and `min_gap` beyond `n`
    /// (looked up as `n`: every move is short then, whatever `min_gap`).
    #[test]
    fn the_table_of_exact_orders_is_the_solvers() {
        use table::{exact_order, TABLE_MIN_LINES};
        let largest = if cfg!(debug_assertions) {
            16
        } else {
            EXACT_MAX_LINES
        };
        for n in TABLE_MIN_LINES..=largest {
            for min_gap in (0..=n).chain([n + 1, n + 7]) {
                for next_block in [false, true] {
                    assert_eq!(
                        exact_order(n, min_gap, next_block),
                        Some(held_karp_solve(n, min_gap, next_block)),
                        "n={n} gap={min_gap} next={next_block}"
                    );
                }
            }
        }
        assert_eq!(exact_order(TABLE_MIN_LINES - 1, 3, true), None);
        assert_eq!(exact_order(EXACT_MAX_LINES + 1, 3, true), None);
    }

    /// Writes `src/plan/skip_order/table.rs`'s table (`cargo test --release --lib
    /// print_the_table_of_exact_orders -- --ignored --nocapture`).
    #[test]
    #[ignore]
    fn print_the_table_of_exact_orders() {
        use table::{DIGITS, TABLE_MIN_LINES};
        for n in TABLE_MIN_LINES..=EXACT_MAX_LINES {
            for min_gap in 0..=n {
                for next_block in [false, true] {
                    let s: String = held_karp_solve(n, min_gap, next_block)
                        .iter()
                        .map(|&l| DIGITS[l] as char)
                        .collect();
                    println!("    \"{s}\",");
                }
            }
        }
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
}
