//! The regions of a field that are worked one after the other: the pieces of its outermost
//! headland pass's area (the boundary shrunk by w/2 and opened at r_min, so that a piece is
//! ground the tractor drives round at r_min with the implement clear). Two such pieces meet
//! only through a neck narrower than the turns need, where a transit is long or there is none
//! and the plan goes on without one.
//!
//! [`super::plan_field`] works every headland pass, obstacle pass and swath of one region before
//! it goes to the next (the nearest one left), so a field that is two blocks joined by a neck
//! is crossed once, not once per headland pass. With one region (most fields) the order is the
//! plain one: headland passes in order, then the swaths nearest first.

use super::geometry::Area;
use crate::geo::polygon::{contains_point, point_segment_distance};
use crate::geo::Vec2;

/// The regions: the outlines of the outermost pass's pieces.
pub(super) struct Regions {
    outlines: Vec<Vec<Vec2>>,
}

impl Regions {
    /// The regions of the outermost pass's area `outer_pass` (no pieces: one region).
    pub(super) fn new(outer_pass: Option<&Vec<Area>>) -> Self {
        Regions {
            outlines: outer_pass
                .map(|areas| areas.iter().map(|a| a.0.clone()).collect())
                .unwrap_or_default(),
        }
    }

    /// Is the field one region (the order then is the plain one)?
    pub(super) fn single(&self) -> bool {
        self.outlines.len() <= 1
    }

    /// The region of a work item that starts at `q`: the piece whose outline holds it, else the
    /// piece whose outline is nearest (leftover ground in an arm lies outside the outermost
    /// pass's area, beside it).
    pub(super) fn of(&self, q: &Vec2) -> usize {
        if self.single() {
            return 0;
        }
        if let Some(k) = self.outlines.iter().position(|o| contains_point(o, q)) {
            return k;
        }
        let distance = |o: &Vec<Vec2>| {
            let n = o.len();
            (0..n)
                .map(|i| point_segment_distance(q, &o[i], &o[(i + 1) % n]))
                .fold(f64::INFINITY, f64::min)
        };
        (0..self.outlines.len())
            .min_by(|&i, &j| distance(&self.outlines[i]).total_cmp(&distance(&self.outlines[j])))
            .unwrap_or(0)
    }
}

/// The region to work next: that of the work nearest `here` among `starts` (region, where the
/// work starts); `None` when nothing is left.
pub(super) fn nearest(here: Vec2, starts: impl Iterator<Item = (usize, Vec2)>) -> Option<usize> {
    starts
        .map(|(region, q)| ((q - here).norm(), region))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, region)| region)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;

    fn square(x0: f64, y0: f64, side: f64) -> Area {
        let pts = vec![
            v2(x0, y0),
            v2(x0 + side, y0),
            v2(x0 + side, y0 + side),
            v2(x0, y0 + side),
        ];
        (pts, vec![])
    }

    #[test]
    fn a_point_belongs_to_the_piece_that_holds_it_or_the_nearest() {
        let areas = vec![square(0.0, 0.0, 10.0), square(30.0, 0.0, 10.0)];
        let regions = Regions::new(Some(&areas));
        assert!(!regions.single());
        assert_eq!(regions.of(&v2(5.0, 5.0)), 0);
        assert_eq!(regions.of(&v2(35.0, 5.0)), 1);
        // Outside both: the nearer outline.
        assert_eq!(regions.of(&v2(12.0, 5.0)), 0);
        assert_eq!(regions.of(&v2(27.0, 5.0)), 1);
        assert_eq!(
            nearest(
                v2(50.0, 0.0),
                [(0, v2(5.0, 5.0)), (1, v2(33.0, 3.0))].into_iter()
            ),
            Some(1)
        );
        assert_eq!(nearest(v2(50.0, 0.0), std::iter::empty()), None);
    }

    #[test]
    fn one_piece_or_none_is_one_region() {
        let one = vec![square(0.0, 0.0, 10.0)];
        assert!(Regions::new(Some(&one)).single());
        assert!(Regions::new(None).single());
        assert_eq!(Regions::new(None).of(&v2(100.0, 100.0)), 0);
    }
}
