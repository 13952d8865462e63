//! A short piece of a swath between the turn onto it and a blocked stretch with no detour
//! round it (a small obstacle a few metres into the swath): the transit on past the stretch
//! must start from the piece's end, facing the obstacle with no room to pull back, and often
//! finds no way (`bg_3_holes18_73ha` at w 3 m, r_min 5 m: 5 m of swath before a 10 m
//! obstacle; `bg_86_holes15_40ha` at w 6 m, r_min 8 m: 2 m of swath before a row of small
//! obstacles 245 m long). From the end of the swath before the turn, pulled back as far as a
//! transit may pull back a work end, there is room to turn; [`super::runs::drive_run`] then
//! leaves the piece and its turn out, where that finds a way and the piece's end found none.

use super::PlanSegment;
use crate::geo::Direction;
use crate::plan::types::SegmentKind;

/// Is `segments[from..]` one or more turns and then one forward work piece shorter than
/// `limit` m, after a forward work piece (a stub of a swath and the turn onto it, after the
/// swath before)?
pub(super) fn is_stub_after(segments: &[PlanSegment], from: usize, limit: f64) -> bool {
    let forward_work =
        |s: &PlanSegment| s.kind == SegmentKind::Work && s.direction == Direction::Forward;
    let Some((stub, turns)) = segments.get(from..).and_then(|t| t.split_last()) else {
        return false;
    };
    from > 0
        && forward_work(&segments[from - 1])
        && forward_work(stub)
        && stub.length() < limit
        && !turns.is_empty()
        && turns.iter().all(|s| s.kind == SegmentKind::Turn)
}

/// Where a stub ends that [`is_stub_after`] finds at the end of `segments` with at most `limit`
/// m: the index of the turn onto it (none found: `None`).
pub(super) fn stub_at_end(segments: &[PlanSegment], limit: f64) -> Option<usize> {
    let turns = segments
        .iter()
        .rev()
        .skip(1)
        .take_while(|s| s.kind == SegmentKind::Turn)
        .count();
    let from = segments.len().checked_sub(1 + turns)?;
    is_stub_after(segments, from, limit).then_some(from)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;

    fn seg(kind: SegmentKind, direction: Direction, length: f64) -> PlanSegment {
        PlanSegment {
            kind,
            direction,
            index: 0,
            cell: 0,
            points: vec![v2(0.0, 0.0), v2(length, 0.0)],
        }
    }

    #[test]
    fn a_stub_is_a_short_work_piece_after_turns_after_work() {
        use Direction::{Forward, Reverse};
        use SegmentKind::{Turn, Work};
        let plan = [
            seg(Work, Forward, 100.0),
            seg(Turn, Forward, 10.0),
            seg(Turn, Reverse, 3.0),
            seg(Work, Forward, 4.0),
        ];
        assert!(is_stub_after(&plan, 1, 13.0));
        // Too long, or no turn onto it from a swath.
        assert!(!is_stub_after(&plan, 1, 4.0));
        assert!(!is_stub_after(&plan, 0, 13.0));
        assert!(!is_stub_after(&plan, 2, 13.0));
        assert!(!is_stub_after(&plan, 4, 13.0));
        assert_eq!(stub_at_end(&plan, 13.0), Some(1));
        assert_eq!(stub_at_end(&plan[..3], 13.0), None);
        // A short piece right after a swath (no turn between): not a stub.
        let no_turn = [seg(Work, Forward, 100.0), seg(Work, Forward, 4.0)];
        assert_eq!(stub_at_end(&no_turn, 13.0), None);
    }
}
