//! Where a headland pass is started: a closed one (a field's or an obstacle's ring) a little
//! ahead of the vehicle where a direct clear transit reaches it, and, when no transit at all
//! reaches that start, the other starts tried in turn ([`other_starts`], [`first_reached`]): a
//! ring in a bay of an obstacle may be entered from the bay's mouth but not at the point
//! nearest the way in (`de_bb_13_holes16` at w 3 m, r_min 5 m: 3 of the 40 points of such a
//! ring had no way to them, the start chosen among them, and the plan went on there without a
//! transit, twice). An open stretch of a cut pass is started at its end nearer the vehicle,
//! else at the other.

use super::metrics::ring_curvature;
use super::transit;
use super::CoverageParams;
use crate::geo::{vec_heading, Vec2};

/// Other starts of a ring tried, at most, when no transit reaches the first one.
const OTHER_STARTS: usize = 8;

/// The start of the closed track `open` (its points, the first not repeated) for a vehicle at
/// `at`: the first of at most about 48 points round the track from the one nearest a point
/// 2.5·r_min ahead of the vehicle that a direct curve with every point passing `clear`
/// reaches, else that nearest one (no vehicle yet: the [`straight_start`] nearest the middle
/// of the boundary's longest edge).
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
        return straight_start(open, nearest, p);
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

/// How far a start found by [`straight_start`] runs straight, in r_min.
const STRAIGHT_AHEAD_R_MIN: f64 = 2.5;

/// The most a point of a straight start's stretch turns, as a curvature in 1/r_min.
const STRAIGHT_CURVATURE_R_MIN: f64 = 0.1;

/// The point of the closed track `open` nearest `from` (round the track either way) where it
/// runs straight for [`STRAIGHT_AHEAD_R_MIN`]·r_min: every point of that stretch turns by at
/// most [`STRAIGHT_CURVATURE_R_MIN`]/r_min. `from` when none does (a ring of arcs). Where the
/// steering is engaged with no way to the pass before it (the plan's start, or after a gap),
/// the tractor settles on a straight before the first curve: a pass started in an S-bend
/// at r_min (holdout `dk_0` at w 6 m, r_min 5 m) took it 2.6 m off within 3 s and the steering
/// was given back (`off_line`) before the first line.
pub(super) fn straight_start(open: &[Vec2], from: usize, p: &CoverageParams) -> usize {
    let m = open.len();
    if m < 3 {
        return from.min(m.saturating_sub(1));
    }
    // Point k bends when its three-point curvature (the guarantees' measure) is too sharp.
    let bends: Vec<bool> = (0..m)
        .map(|k| ring_curvature(open, k) > STRAIGHT_CURVATURE_R_MIN / p.r_min)
        .collect();
    // The points ahead of each start that must not bend: the stretch's length in pieces.
    let ahead = STRAIGHT_AHEAD_R_MIN * p.r_min;
    let straight_from = |i: usize| {
        let mut run = 0.0;
        for k in 0..m {
            let (a, b) = (open[(i + k) % m], open[(i + k + 1) % m]);
            if k > 0 && bends[(i + k) % m] {
                return false;
            }
            run += (b - a).norm();
            if run >= ahead {
                return true;
            }
        }
        false
    };
    (0..=m / 2)
        .flat_map(|d| [(from + d) % m, (from + m - d) % m])
        .find(|&i| straight_from(i))
        .unwrap_or(from)
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
/// without a gap (`gaps` not counting up), with its cut; else `instead` where given (a start
/// the steering is better engaged at, gone to with its gap: [`straight_start`]), else the
/// first, whose gap and warning stand (those of the others tried are taken back).
pub(super) fn first_reached<T: PartialEq>(
    mut tries: impl Iterator<Item = T>,
    instead: impl FnOnce() -> Option<T>,
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
    match instead() {
        Some(start) if start != first => {
            gaps.set(gaps_then);
            warnings.borrow_mut().truncate(warned);
            let cut = go(&start);
            Some((start, cut))
        }
        _ => Some((first, cut)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::geo::v2;

    /// A track round a 40 m square, 1 m apart from (0, 0) anticlockwise, its corners sharp.
    fn square_track() -> Vec<Vec2> {
        let side = |k: usize| k as f64;
        (0..40)
            .map(|k| v2(side(k), 0.0))
            .chain((0..40).map(|k| v2(40.0, side(k))))
            .chain((0..40).map(|k| v2(40.0 - side(k), 40.0)))
            .chain((0..40).map(|k| v2(0.0, 40.0 - side(k))))
            .collect()
    }

    #[test]
    fn a_straight_start_is_the_nearest_point_with_a_straight_stretch_ahead() {
        let track = square_track();
        let p = crate::plan::coverage::tests::params(6.0, 5.0, 1);
        // 12.5 m straight ahead at r_min 5 m. From (35, 0), 5 m before the corner: the nearest
        // start with 12.5 m of straight ahead is the corner, the next side ahead (5 points on),
        // not (27, 0) (8 back); from (38, 0) it is (40, 0) too, from (32, 0) (27, 0).
        let from = 35;
        assert_eq!(track[straight_start(&track, from, &p)], v2(40.0, 0.0));
        assert_eq!(track[straight_start(&track, 38, &p)], v2(40.0, 0.0));
        assert_eq!(track[straight_start(&track, 32, &p)], v2(27.0, 0.0));
        // From a point with the straight ahead: itself.
        assert_eq!(straight_start(&track, 41, &p), 41);
        // At r_min 20 m (50 m ahead) no side is long enough: the point asked.
        let p = crate::plan::coverage::tests::params(6.0, 20.0, 1);
        assert_eq!(straight_start(&track, from, &p), from);
    }

    #[test]
    fn with_no_start_reached_the_one_given_instead_is_gone_to_with_one_gap() {
        let gaps = std::cell::Cell::new(3);
        let warnings = std::cell::RefCell::new(vec!["before".to_string()]);
        let mut asked = Vec::new();
        let never = |t: &usize| {
            asked.push(*t);
            gaps.set(gaps.get() + 1);
            warnings.borrow_mut().push(format!("no way to {t}"));
            0
        };
        let got = first_reached([5, 6, 7].into_iter(), || Some(9), &gaps, &warnings, never);
        assert_eq!(got, Some((9, 0)));
        assert_eq!(asked, [5, 6, 7, 9]);
        assert_eq!(gaps.get(), 4);
        assert_eq!(*warnings.borrow(), ["before", "no way to 9"]);
        // Reached: `instead` is not asked for.
        let got = first_reached(
            [1, 2].into_iter(),
            || unreachable!(),
            &gaps,
            &warnings,
            |_| 2,
        );
        assert_eq!(got, Some((1, 2)));
    }

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
