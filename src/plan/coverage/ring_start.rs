//! Where a headland pass is started: a closed one (a field's or an obstacle's ring) a little
//! ahead of the vehicle where a direct clear transit reaches it, and, when no transit at all
//! reaches that start, the other starts tried in turn ([`other_starts`], [`first_reached`]): a
//! ring in a bay of an obstacle may be entered from the bay's mouth but not at the point
//! nearest the way in (`de_bb_13_holes16` at w 3 m, r_min 5 m: 3 of the 40 points of such a
//! ring had no way to them, the start chosen among them, and the plan went on there without a
//! transit, twice). An open stretch of a cut pass is started at its end nearer the vehicle,
//! else at the other.

use super::transit;
use super::CoverageParams;
use crate::geo::{vec_heading, Vec2};

/// Other starts of a ring tried, at most, when no transit reaches the first one.
const OTHER_STARTS: usize = 8;

/// The start of the closed track `open` (its points, the first not repeated) for a vehicle at
/// `at`: the first of at most about 48 points round the track from the one nearest a point
/// 2.5·r_min ahead of the vehicle that a direct curve with every point passing `clear`
/// reaches, else that nearest one (no vehicle yet: the point nearest the middle of the
/// boundary's longest edge).
pub(super) fn first_start(
    open: &[Vec2],
    at: Option<(Vec2, f64)>,
    boundary: &[Vec2],
    p: &CoverageParams,
    clear: &dyn Fn(&Vec2) -> bool,
) -> usize {
    let target = match at {
        Some((q, h)) => q + crate::geo::heading_vec(h) * (2.5 * p.r_min),
        None => {
            let b = boundary;
            let i = (0..b.len())
                .max_by(|&i, &j| {
                    let li = (b[(i + 1) % b.len()] - b[i]).norm();
                    let lj = (b[(j + 1) % b.len()] - b[j]).norm();
                    li.total_cmp(&lj)
                })
                .unwrap_or(0);
            0.5 * (b[i] + b[(i + 1) % b.len()])
        }
    };
    let nearest = (0..open.len())
        .min_by(|&i, &j| {
            (open[i] - target)
                .norm()
                .total_cmp(&(open[j] - target).norm())
        })
        .unwrap_or(0);
    let m = open.len();
    let Some((q, h)) = at else {
        return nearest;
    };
    // At most about 48 candidate starts around the track (each try is a whole curve).
    (0..m)
        .step_by((m / 48).max(1))
        .map(|k| (nearest + k) % m)
        .find(|&i| {
            let hi = vec_heading(&(open[(i + 1) % m] - open[i]));
            transit::clear_transit(q, h, open[i], hi, p.r_min, p.point_spacing, clear).is_some()
        })
        .unwrap_or(nearest)
}

/// The starts tried after `first` on a ring of `m` points when no transit reaches it: at most
/// [`OTHER_STARTS`], evenly round the ring from `first` (none on a ring too short to hold
/// them apart).
pub(super) fn other_starts(m: usize, first: usize) -> impl Iterator<Item = usize> {
    let count = OTHER_STARTS.min(m.saturating_sub(1));
    (1..=count).map(move |k| (first + k * m / (count + 1)) % m)
}

/// The closed track of the ring `open` started at `start` (its start repeated last).
pub(super) fn track_from(open: &[Vec2], start: usize) -> Vec<Vec2> {
    let m = open.len();
    (0..=m).map(|k| open[(start + k) % m]).collect()
}

/// The first of `tries` that `go` (a transit to it: the points cut from its start) reaches
/// without a gap (`gaps` not counting up), with its cut; else the first, whose gap and warning
/// stand (those of the others tried are taken back).
pub(super) fn first_reached<T>(
    mut tries: impl Iterator<Item = T>,
    gaps: &std::cell::Cell<usize>,
    warnings: &std::cell::RefCell<Vec<String>>,
    mut go: impl FnMut(&T) -> usize,
) -> Option<(T, usize)> {
    let first = tries.next()?;
    let (gaps_then, warned) = (gaps.get(), warnings.borrow().len());
    let cut = go(&first);
    if gaps.get() == gaps_then {
        return Some((first, cut));
    }
    for other in tries {
        let (g, w) = (gaps.get(), warnings.borrow().len());
        let cut = go(&other);
        let reached = gaps.get() == g;
        // Reached: the first one's gap is none.
        let (g, w) = if reached { (gaps_then, warned) } else { (g, w) };
        gaps.set(g);
        warnings.borrow_mut().truncate(w);
        if reached {
            return Some((other, cut));
        }
    }
    Some((first, cut))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn other_starts_are_spread_round_the_ring_and_never_the_first() {
        let starts: Vec<usize> = other_starts(40, 17).collect();
        assert_eq!(starts.len(), OTHER_STARTS);
        assert!(starts.iter().all(|&s| s != 17 && s < 40));
        let mut sorted = starts.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), starts.len());
        assert_eq!(other_starts(3, 0).collect::<Vec<_>>(), [1, 2]);
        assert_eq!(other_starts(1, 0).count(), 0);
    }
}
