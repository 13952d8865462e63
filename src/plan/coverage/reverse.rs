//! Transits with reversing (seed 004's Reeds–Shepp paths): where no forward transit stays
//! inside the field (a swath ending in a pocket narrower than a turn, parts joined by a neck),
//! a farmer backs out and drives on. Tried by [`super::plan_field`] before the plan goes on
//! with a gap.

use crate::geo::{Direction, Pose, Vec2};
use crate::plan::maneuver::cc_reeds_shepp::cc_reeds_shepp_shortest;
use crate::plan::maneuver::path::CurveParams;
use crate::plan::maneuver::{drive::split_at_cusps_while, reeds_shepp::reeds_shepp_paths};

/// Words longer than the shortest by more than this many full circles of radius r_min are not
/// tried: no farmer backs out that way, and sampling every word of a gap that stays cost more
/// than the plan.
const LONGER_BY_TURNS: f64 = 1.0;

/// A plain word's forward first part shorter than this is not used for a turn between swaths,
/// m (see [`transit`]): long enough to steer from straight to full lock and back, 2·κ_max/σ_max
/// with a curvature-rate limit `sigma_max` > 0 (1/m²), else 0.
pub fn turn_lead_in(r_min: f64, sigma_max: f64) -> f64 {
    if sigma_max > 0.0 {
        2.0 / (r_min * sigma_max)
    } else {
        0.0
    }
}

/// The shortest Reeds–Shepp path of radius `r_min` (m) from `from` to `to` (position, heading
/// rad), at most [`LONGER_BY_TURNS`] circles longer than the shortest, whose points, sampled
/// every `spacing` m, all pass `ok`, as parts driven in one direction
/// each; `None` when every word's path fails somewhere.
/// With a curvature-rate limit `sigma_max` > 0 (1/m²), the shortest continuous-curvature path
/// is tried first: the steering cannot follow a curvature step at full lock backing out.
/// A plain word whose first part drives forward is used only when that part is at least
/// `lead_in` m long ([`turn_lead_in`] for a turn, which starts at a swath's end with the
/// wheels straight; 0 for a transit). Shorter, the tractor reached the cusp off the path and
/// heading wrong, and was 0.7–1.6 m RMS off the reversing leg after it in the simulator
/// (`f2c_nl_field_188` at w 6 m, r_min 8 m, first parts 0.1–2.2 m long); the words that back
/// up first were tracked within 2–6 cm RMS.
pub fn transit(
    from: (Vec2, f64),
    to: (Vec2, f64),
    r_min: f64,
    sigma_max: f64,
    spacing: f64,
    ok: &dyn Fn(&Vec2) -> bool,
    lead_in: f64,
) -> Option<Vec<(Direction, Vec<Vec2>)>> {
    let pose = |(pos, heading): (Vec2, f64)| Pose { pos, heading };
    let curve = CurveParams {
        kappa_max: 1.0 / r_min,
        sigma_max,
    };
    let smooth = (sigma_max > 0.0)
        .then(|| cc_reeds_shepp_shortest(&pose(from), &pose(to), &curve))
        .flatten();
    // (Is the path a plain word: the smooth one, if any, comes first.)
    let mut paths: Vec<_> = smooth.into_iter().map(|p| (false, p)).collect();
    paths.extend(
        reeds_shepp_paths(&pose(from), &pose(to), r_min)
            .into_iter()
            .map(|p| (true, p)),
    );
    let shortest = paths
        .iter()
        .map(|p| p.1.length())
        .fold(f64::INFINITY, f64::min);
    let longest = shortest + LONGER_BY_TURNS * std::f64::consts::TAU * r_min;
    // A plain word's first part forward and shorter than `lead_in`.
    let short_lead_in = |parts: &[crate::plan::maneuver::drive::DrivenPart]| {
        parts.first().is_some_and(|part| {
            part.direction == Direction::Forward
                && crate::geo::polygon::polyline_length(&part.points) < lead_in
        })
    };
    // Each path's points checked as they are sampled: a path blocked anywhere is not sampled
    // past its first blocked point.
    paths
        .iter()
        .take_while(|path| path.1.length() <= longest)
        .filter_map(|(plain, path)| {
            Some((*plain, split_at_cusps_while(path, spacing, &mut |q| ok(q))?))
        })
        .find(|(plain, parts)| !(*plain && short_lead_in(parts)))
        .map(|(_, parts)| parts)
        .map(|parts| {
            parts
                .into_iter()
                .filter(|part| part.points.len() >= 2)
                .map(|part| (part.direction, part.points))
                .collect()
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;
    use std::f64::consts::PI;

    /// Between two ends of adjacent swaths 3 m apart at the end of a pocket 5 m deep, no
    /// forward turn of radius 8 m fits; the reversing transit does, inside the pocket, and
    /// reverses at least once.
    #[test]
    fn backs_out_of_a_pocket_no_forward_turn_fits() {
        // The pocket: x ≤ 0 (the swath ends at x = 0), |y| ≤ 12, 60 m long.
        let inside = |q: &Vec2| q.x <= 0.5 && q.x >= -60.0 && q.y.abs() <= 12.0;
        let from = (v2(0.0, 0.0), 0.0);
        let to = (v2(0.0, 3.0), PI);
        let parts = transit(from, to, 8.0, 0.0, 0.5, &inside, 0.0).expect("a reversing way");
        assert!(parts.iter().any(|(d, _)| *d == Direction::Reverse));
        let first = parts.first().unwrap().1[0];
        let last = *parts.last().unwrap().1.last().unwrap();
        assert!((first - from.0).norm() < 1e-6 && (last - to.0).norm() < 1e-6);
        // With a curvature-rate limit the way leaves the swath's end and reaches the next
        // swath's start straight (curvature rising at the rate), not at full lock as a plain
        // word does: the steering cannot step there, and backing out it tracked 1.2 m RMS.
        let end_curvature = |parts: &[(Direction, Vec<Vec2>)]| {
            let k = |w: &[Vec2]| {
                crate::plan::coverage::metrics::three_point_curvature(&w[0], &w[1], &w[2])
            };
            let first = &parts.first().unwrap().1;
            let last = &parts.last().unwrap().1;
            k(&first[..3]).max(k(&last[last.len() - 3..]))
        };
        // (Room for the longer smooth path: 20 m ahead, 30 m each side.)
        let roomy = |q: &Vec2| q.x <= 20.0 && q.x >= -60.0 && q.y.abs() <= 30.0;
        let plain = transit(from, to, 8.0, 0.0, 0.25, &roomy, 0.0).expect("a plain way");
        let smooth = transit(from, to, 8.0, 0.1, 0.25, &roomy, 0.0).expect("a smooth way");
        assert!(
            end_curvature(&plain) > 0.1,
            "plain {}",
            end_curvature(&plain)
        );
        assert!(
            end_curvature(&smooth) < 0.05,
            "smooth {}",
            end_curvature(&smooth)
        );
        // In a pocket 1.5 m deep, no way: every word's path fails somewhere.
        let shallow = |q: &Vec2| inside(q) && q.x >= -1.0;
        assert!(transit(from, to, 8.0, 0.0, 0.5, &shallow, 0.0).is_none());
    }
}
