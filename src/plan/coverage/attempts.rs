//! The order in which [`super::plan_field`] tries the ways of a transit between two runs:
//! how far each pulls the work ends back, which way it takes, and which clearance test holds.

use super::CoverageParams;

/// The reversing transits are tried with the ends pulled back this many times, evenly up to
/// the forward attempts' longest pull-back (none first).
const REVERSE_CUTS: usize = 4;

/// A way a transit is looked for.
#[derive(Clone, Copy, Debug)]
pub(super) enum Way {
    /// One CSC (Dubins) curve.
    Direct,
    /// Onto a headland pass's ring, along it, off it.
    Headland,
    /// Through the waypoint grid.
    Waypoints,
    /// A Reeds–Shepp path, backing up.
    Reverse,
}

/// The attempts, in order, as (points pulled back from each end, way, relaxed test: only the
/// tractor inside the field). Without shortening any work first (direct, then along the
/// headland), then pulling the ends back point by point up to r_min, then backing out (no
/// work shortened, the tractor inside the field), then pulling back further up to
/// `max_cut` points, along the headland too every r_min / 2 of it (the least cut that reaches
/// the headland's rings, not only the most); all with the implement clear of the edge. Then
/// with only the tractor inside the field: direct, along the headland, through waypoints
/// (not `to_own_cell`: such a cell is left when not reached, and the search is the dearest),
/// and backing out with the ends pulled back.
pub(super) fn order(
    p: &CoverageParams,
    max_cut: usize,
    to_own_cell: bool,
) -> Vec<(usize, Way, bool)> {
    let before_reverse = ((p.r_min / p.point_spacing).ceil() as usize).min(max_cut);
    let headland_every = ((0.5 * p.r_min / p.point_spacing).ceil() as usize).max(1);
    let mut attempts = vec![(0, Way::Direct, false), (0, Way::Headland, false)];
    attempts.extend((1..=before_reverse).map(|t| (t, Way::Direct, false)));
    attempts.push((0, Way::Reverse, true));
    attempts.extend((before_reverse + 1..=max_cut).flat_map(|t| {
        let along = t % headland_every == 0 || t == max_cut;
        std::iter::once((t, Way::Direct, false)).chain(along.then_some((t, Way::Headland, false)))
    }));
    attempts.extend([(0, Way::Direct, true), (0, Way::Headland, true)]);
    if !to_own_cell {
        attempts.push((0, Way::Waypoints, true));
    }
    attempts
        .extend((1..REVERSE_CUTS).map(|i| (i * max_cut / (REVERSE_CUTS - 1), Way::Reverse, true)));
    attempts
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pulled back further, the headland is tried every r_min / 2 of the cut, each time
    /// before the next direct attempt: no attempt of the implement clear pulls back more than
    /// one that comes after it, beyond r_min.
    #[test]
    fn the_headland_is_tried_at_every_half_r_min_of_pulling_back() {
        let p = super::super::tests::params(6.0, 8.0, 1);
        let order = order(&p, 30, false);
        let headland: Vec<usize> = order
            .iter()
            .filter(|a| matches!(a.1, Way::Headland) && !a.2)
            .map(|a| a.0)
            .collect();
        assert_eq!(headland, [0, 12, 16, 20, 24, 28, 30]);
        let strict: Vec<usize> = order
            .iter()
            .filter(|a| !a.2 && a.0 > 8)
            .map(|a| a.0)
            .collect();
        assert!(strict.windows(2).all(|w| w[0] <= w[1]), "{strict:?}");
        // To a cell of its own: no waypoint search.
        assert!(order.iter().any(|a| matches!(a.1, Way::Waypoints)));
        assert!(!super::order(&p, 30, true)
            .iter()
            .any(|a| matches!(a.1, Way::Waypoints)));
    }
}
