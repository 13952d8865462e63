//! The order of a plan's chains: the runs of segments that join one another, split where the
//! plan has a gap (no clear transit between two pieces of work: "drive there by hand", where
//! the steering is given back). Planned region by region from the first headland pass's, a plan
//! could work a small pocket first and give the steering back after a tenth of its work
//! (`de_bb_holes_irregular`: its smallest block first, then the neck). With no gate known, the
//! plan starts with the chain that works the most ground; the others follow, nearest start
//! first. Only the order of whole chains changes: every segment, every transit within a chain
//! and the number of gaps stay as planned, and a chain is never put before one that came
//! before it and works in the same region (the headland order of that region is kept).

use super::{PlanSegment, SegmentKind};
use crate::geo::Vec2;

/// Consecutive segments whose end and start lie farther apart than this do not join, m (the
/// segments of a plan share their joining point).
const JOIN_M: f64 = 1e-3;

/// `segments` with their chains reordered (see the module): the chain with the most ground
/// worked (work, headland and detour length) first, then, of the chains whose predecessors in
/// the same regions are placed, the one that starts nearest the end of the last one placed.
/// `region_of` gives the region of the work segment that starts at a point (asked once per cell
/// and per headland pass: the work segments of one cell lie in one region). The segments'
/// `index` is renumbered to the new order. Unchanged with one chain.
pub(super) fn most_work_first(
    segments: Vec<PlanSegment>,
    region_of: impl Fn(&Vec2) -> usize,
) -> Vec<PlanSegment> {
    let mut chains: Vec<Vec<PlanSegment>> = Vec::new();
    for s in segments {
        let joins = chains
            .last()
            .and_then(|c| c.last())
            .and_then(|prev| Some((*prev.points.last()? - *s.points.first()?).norm() <= JOIN_M));
        match (joins, chains.last_mut()) {
            (Some(true), Some(chain)) => chain.push(s),
            _ => chains.push(vec![s]),
        }
    }
    if chains.len() <= 1 {
        return renumbered(chains);
    }
    let worked = |s: &PlanSegment| {
        matches!(
            s.kind,
            SegmentKind::Work | SegmentKind::Headland | SegmentKind::Detour
        )
    };
    let work: Vec<f64> = chains
        .iter()
        .map(|c| c.iter().filter(|s| worked(s)).map(|s| s.length()).sum())
        .collect();
    // A cell lies in one region: its work segments' region is found once (`region_of` walks
    // the regions' outlines); each headland pass's is found.
    let mut cell_region: std::collections::HashMap<usize, usize> = Default::default();
    let mut region = |s: &PlanSegment| {
        let q = s.points.first()?;
        Some(match s.kind {
            SegmentKind::Headland => region_of(q),
            _ => *cell_region.entry(s.cell).or_insert_with(|| region_of(q)),
        })
    };
    let regions: Vec<Vec<usize>> = chains
        .iter()
        .map(|c| {
            let mut r: Vec<usize> = c
                .iter()
                .filter(|s| worked(s))
                .filter_map(&mut region)
                .collect();
            r.sort_unstable();
            r.dedup();
            r
        })
        .collect();
    let shares = |a: usize, b: usize| regions[a].iter().any(|r| regions[b].contains(r));
    let n = chains.len();
    let mut placed = vec![false; n];
    let mut order: Vec<usize> = Vec::with_capacity(n);
    while order.len() < n {
        let free = (0..n).filter(|&j| !placed[j] && (0..j).all(|i| placed[i] || !shares(i, j)));
        let next = match order.last() {
            None => free.max_by(|&a, &b| work[a].total_cmp(&work[b]).then(b.cmp(&a))),
            Some(&last) => {
                let end = chains[last].last().and_then(|s| s.points.last().copied());
                let away = |j: usize| match (end, chains[j].first().and_then(|s| s.points.first()))
                {
                    (Some(e), Some(q)) => (*q - e).norm(),
                    _ => f64::INFINITY,
                };
                free.min_by(|&a, &b| away(a).total_cmp(&away(b)).then(a.cmp(&b)))
            }
        };
        // The lowest unplaced chain is always free (every chain before it is placed).
        let Some(k) = next.or_else(|| (0..n).find(|&j| !placed[j])) else {
            break;
        };
        placed[k] = true;
        order.push(k);
    }
    let mut slots: Vec<Option<Vec<PlanSegment>>> = chains.into_iter().map(Some).collect();
    renumbered(order.into_iter().filter_map(|k| slots[k].take()).collect())
}

/// The chains' segments in order, each `index` its position.
fn renumbered(chains: Vec<Vec<PlanSegment>>) -> Vec<PlanSegment> {
    let mut segments: Vec<PlanSegment> = chains.into_iter().flatten().collect();
    for (k, s) in segments.iter_mut().enumerate() {
        s.index = k;
    }
    segments
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::{v2, Direction};

    fn seg(kind: SegmentKind, from: (f64, f64), to: (f64, f64)) -> PlanSegment {
        PlanSegment {
            kind,
            direction: Direction::Forward,
            index: 0,
            cell: 0,
            points: vec![v2(from.0, from.1), v2(to.0, to.1)],
        }
    }

    /// Region 0 left of x = 100, region 1 right of it.
    fn region(q: &Vec2) -> usize {
        usize::from(q.x > 100.0)
    }

    #[test]
    fn the_chain_with_most_work_comes_first_and_the_gaps_stay() {
        // A 10 m pocket in region 0, a gap, 300 m of work in region 1.
        let segments = vec![
            seg(SegmentKind::Headland, (0.0, 0.0), (10.0, 0.0)),
            seg(SegmentKind::Work, (200.0, 0.0), (300.0, 0.0)),
            seg(SegmentKind::Turn, (300.0, 0.0), (300.0, 10.0)),
            seg(SegmentKind::Work, (300.0, 10.0), (100.5, 10.0)),
        ];
        let out = most_work_first(segments.clone(), region);
        assert_eq!(out.len(), 4);
        assert_eq!(out[0].points, segments[1].points);
        assert_eq!(out[2].points, segments[3].points);
        assert_eq!(out[3].points, segments[0].points);
        assert!(out.iter().enumerate().all(|(k, s)| s.index == k));
        // The chain kept whole: one gap, as before.
        let gaps = |s: &[PlanSegment]| {
            s.windows(2)
                .filter(|w| (w[1].points[0] - *w[0].points.last().unwrap()).norm() > JOIN_M)
                .count()
        };
        assert_eq!(gaps(&out), gaps(&segments));
    }

    #[test]
    fn a_chain_is_not_put_before_an_earlier_one_of_its_region() {
        // The headland of region 0 (short), a gap, the swaths of region 0 (long): the swaths
        // stay after the headland; a third chain in region 1 comes by distance.
        let segments = vec![
            seg(SegmentKind::Headland, (0.0, 0.0), (10.0, 0.0)),
            seg(SegmentKind::Work, (50.0, 50.0), (90.0, 50.0)),
            seg(SegmentKind::Work, (200.0, 0.0), (210.0, 0.0)),
        ];
        let out = most_work_first(segments.clone(), region);
        assert_eq!(out[0].points, segments[0].points);
        assert_eq!(out[1].points, segments[1].points);
        assert_eq!(out[2].points, segments[2].points);
    }

    #[test]
    fn a_plan_without_gaps_is_unchanged() {
        let segments = vec![
            seg(SegmentKind::Headland, (0.0, 0.0), (10.0, 0.0)),
            seg(SegmentKind::Transit, (10.0, 0.0), (200.0, 0.0)),
            seg(SegmentKind::Work, (200.0, 0.0), (300.0, 0.0)),
        ];
        let mut expected = segments.clone();
        for (k, s) in expected.iter_mut().enumerate() {
            s.index = k;
        }
        assert_eq!(most_work_first(segments, region), expected);
    }
}
