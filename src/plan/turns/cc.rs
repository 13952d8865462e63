//! The continuous-curvature turns between parallel lines (a positive
//! `TurnParams::max_curvature_rate`): the CC quarter turn, the CC pi turn (two quarter turns and a straight) and, for lines
//! too close for it, the CC bulb (three CC turns). Each returns `false` (nothing written) where
//! it does not fit, and [`super`] falls back to its turns of arcs.

use super::TurnParams;
use crate::geo::{cross, PathPoint, Vec2};

/// A forward continuous-curvature quarter turn (clothoid + arc + clothoid at κ_max = 1/r_min
/// and σ_max = `max_curvature_rate`), to the left or right, and its reach: being symmetric, it
/// ends as far along its start heading as across it, m (a little more than r_min).
pub(crate) fn cc_quarter_turn(
    params: &TurnParams,
    left: bool,
) -> (Vec<crate::plan::maneuver::path::CurveSegment>, f64) {
    use crate::geo::{Direction, Pose};
    use crate::plan::maneuver::cc_turn::cc_turn;
    use crate::plan::maneuver::path::{CurveParams, CurvePath};
    let curve = CurveParams {
        kappa_max: 1.0 / params.r_min,
        sigma_max: params.max_curvature_rate,
    };
    let delta = if left {
        std::f64::consts::FRAC_PI_2
    } else {
        -std::f64::consts::FRAC_PI_2
    };
    let segments = cc_turn(delta, Direction::Forward, &curve);
    let reach = CurvePath {
        start: Pose::new(0.0, 0.0, 0.0),
        segments: segments.clone(),
    }
    .end_pose()
    .pos
    .x;
    (segments, reach)
}

/// The pi turn with continuous curvature: a CC quarter turn (clothoid + arc + clothoid at
/// κ_max = 1/r_min and σ_max = `max_curvature_rate`), a straight across, a second CC quarter
/// turn. A CC quarter turn reaches a distance q > r_min both along and across, so it needs the
/// lines at least 2·q apart and level; `false` (nothing written) otherwise, and the arcs are
/// used.
pub(super) fn cc_pi_turn(
    p1: Vec2,
    dir1: Vec2,
    p2: Vec2,
    n: Vec2,
    d: f64,
    params: &TurnParams,
    out: &mut Vec<PathPoint>,
) -> bool {
    use crate::geo::{Direction, Pose};
    use crate::plan::maneuver::path::{CurvePath, CurveSegment};
    let (quarter, q) = cc_quarter_turn(params, cross(&dir1, &n) > 0.0);
    let start = Pose::new(p1.x, p1.y, dir1.y.atan2(dir1.x));
    let level = (p2 - p1).dot(&dir1).abs() < 1e-3;
    if !level || d + 1e-9 < 2.0 * q || !q.is_finite() {
        return false;
    }
    let mut segments = quarter.clone();
    segments.push(CurveSegment::line(Direction::Forward, d - 2.0 * q));
    segments.extend(quarter);
    let mut samples = Vec::new();
    CurvePath { start, segments }.sample(params.point_spacing.min(0.5), &mut samples);
    append_turn(out, &samples, p1, p2, |pos| pos);
    true
}

/// The continuous-curvature turn for lines too close for [`cc_pi_turn`] (a low curvature
/// rate makes a CC quarter turn reach far more than r_min): three CC turns (each clothoid +
/// arc + clothoid from κ = 0 to κ = 0, so their joins keep the curvature continuous) with
/// deflections −β, π + 2β, −β (positive toward the next line). β < 0 bends all three toward
/// the next line (β = −π/2: two quarter turns and the CC chord between them, a little wider
/// than the CC pi turn); β > 0 is a bulb, first away from the next line. The sequence is its
/// own mirror image (reversed and reflected about the mid-line), so the turn always ends level
/// with its start, heading back; β is found by bisection on the lateral reach. `false`
/// (nothing written) when the lines are not level or the reach cannot be met.
pub(super) fn cc_bulb_turn(
    p1: Vec2,
    dir1: Vec2,
    p2: Vec2,
    n: Vec2,
    d: f64,
    params: &TurnParams,
    out: &mut Vec<PathPoint>,
) -> bool {
    use crate::geo::{Direction, Pose};
    use crate::plan::maneuver::cc_turn::cc_turn;
    use crate::plan::maneuver::path::{CurveParams, CurvePath};
    use std::f64::consts::{FRAC_PI_2, PI};
    let level = (p2 - p1).dot(&dir1).abs() < 1e-3;
    if !level || params.max_curvature_rate <= 0.0 || !d.is_finite() {
        return false;
    }
    let curve = CurveParams {
        kappa_max: 1.0 / params.r_min,
        sigma_max: params.max_curvature_rate,
    };
    // Canonical frame: start at the origin heading +x, the next line to the left (+y).
    let path = |beta: f64| {
        let mut segments = cc_turn(-beta, Direction::Forward, &curve);
        segments.extend(cc_turn(PI + 2.0 * beta, Direction::Forward, &curve));
        segments.extend(cc_turn(-beta, Direction::Forward, &curve));
        CurvePath {
            start: Pose::new(0.0, 0.0, 0.0),
            segments,
        }
    };
    let reach = |beta: f64| path(beta).end_pose().pos.y;
    // The lateral reach falls as β grows (the bulb folds back on itself).
    let (mut lo, mut hi) = (-FRAC_PI_2, FRAC_PI_2);
    let (r_lo, r_hi) = (reach(lo), reach(hi));
    if !(r_hi <= d && d <= r_lo) {
        return false;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if reach(mid) > d {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let canonical = path(0.5 * (lo + hi));
    let end = canonical.end_pose();
    if (end.pos.y - d).abs() > 1e-6 || end.pos.x.abs() > 1e-6 {
        return false;
    }
    let mut samples = Vec::new();
    canonical.sample(params.point_spacing.min(0.5), &mut samples);
    // A tall bulb between close lines crosses itself (its legs swing out and back over each
    // other): a tracker's nearest-point search would jump at the crossing. The arcs then.
    if crosses_itself(&samples) {
        return false;
    }
    // Canonical (x along dir1, y toward the next line) into the world.
    append_turn(out, &samples, p1, p2, |pos| p1 + dir1 * pos.x + n * pos.y);
    true
}

/// Append the sampled turn to `out`, each position moved by `place`, its ends exactly `p1` and
/// `p2` (as the arc turns have them).
fn append_turn(
    out: &mut Vec<PathPoint>,
    samples: &[crate::plan::maneuver::path::PathSample],
    p1: Vec2,
    p2: Vec2,
    place: impl Fn(Vec2) -> Vec2,
) {
    let first = out.len();
    out.extend(samples.iter().map(|s| PathPoint {
        pos: place(s.pose.pos),
        tag: crate::geo::Tag::Turn,
        direction: crate::geo::Direction::Forward,
    }));
    if let Some(q) = out.get_mut(first) {
        q.pos = p1;
    }
    if let Some(q) = out.last_mut() {
        q.pos = p2;
    }
}

/// Whether the sampled path crosses itself (two segments that are not neighbours intersect).
fn crosses_itself(samples: &[crate::plan::maneuver::path::PathSample]) -> bool {
    let pts: Vec<Vec2> = samples.iter().map(|s| s.pose.pos).collect();
    let orient = |a: Vec2, b: Vec2, c: Vec2| cross(&(b - a), &(c - a));
    for i in 0..pts.len().saturating_sub(1) {
        let (a, b) = (pts[i], pts[i + 1]);
        for j in i + 2..pts.len().saturating_sub(1) {
            let (c, d) = (pts[j], pts[j + 1]);
            if orient(a, b, c) * orient(a, b, d) < 0.0 && orient(c, d, a) * orient(c, d, b) < 0.0 {
                return true;
            }
        }
    }
    false
}
