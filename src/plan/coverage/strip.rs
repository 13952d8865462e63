//! Fields too narrow to turn in, worked in lanes along their length (the strip plan that
//! [`super::narrow`] tries when headland passes and swaths work little): a farmer drives a
//! strip between a ditch and a hedge lane by lane and backs round at its ends.

use super::geometry::{in_area, offset, Area};
use super::headland::{pass_offset, tracks_of, Passes};
use super::CoverageParams;
use crate::geo::{cross, Vec2};

/// Most rings of a strip plan ([`lanes`]) from the edge in.
const MAX_STRIP_LANES: usize = 50;

/// Lanes along a field too narrow to turn in (the strip plan of [`super::narrow`]): the rings
/// of the field shrunk by [`pass_offset`] for k = 0, 1, … (its holes grown by as much) while
/// any ground is left, resampled to `point_spacing`, as [`Passes`] (field rings, hole rings,
/// each ring's area). They are not opened at r_min as the headland passes are: in a strip
/// narrower than a turn that opening leaves nothing, while driving along the strip needs no
/// room to turn. [`clear_stretches`](super::headland::clear_stretches) then cuts each ring
/// where it turns tighter than r_min (a strip's ends, its sharp corners) or its implement is
/// not clear, and the stretches are joined by transits, reversing where no forward one fits.
/// Where ring k + 1 does not fit (the strip is not a whole number of lanes wide there), the
/// middle of ring k's area, which its footprints leave, gets a lane along it
/// ([`middle_lanes`]).
pub fn lanes(boundary: &[Vec2], holes: &[Vec<Vec2>], p: &CoverageParams) -> Passes {
    let mut out = Passes::default();
    let field = [(boundary.to_vec(), holes.to_vec())];
    let mut inner = offset(&field, -pass_offset(p, 0));
    for k in 0..MAX_STRIP_LANES {
        if inner.is_empty() {
            break;
        }
        let next = offset(&field, -pass_offset(p, k + 1));
        // The footprints of a piece's rings reach w/2 into it from each side; a middle wider
        // than MIDDLE_GAP_SHARE·w gets a lane along it where the next ring does not run (there
        // the piece is at most 2·s wide, s the pass spacing).
        let near = (1.0 + MIDDLE_GAP_SHARE) * p.line_width;
        let far = 2.0 * p.pass_spacing() + p.point_spacing;
        for piece in &inner {
            for lane in middle_lanes(piece, (near, far), p.point_spacing) {
                // Its pairs end short of the piece's ends (the sides meet there): on straight
                // to them, as far as the implement is clear (`clear_stretches` cuts the rest).
                let lane = extended(&lane, far, p.point_spacing);
                let in_next = |q: &Vec2| next.iter().any(|a| in_area(a, q));
                for run in lane.split(in_next) {
                    if run.len() >= 3 {
                        out.field.push(run.to_vec());
                    }
                }
            }
        }
        add_rings(
            &mut out,
            std::mem::replace(&mut inner, next),
            p.point_spacing,
        );
    }
    out
}

/// A strip's middle left between its lanes' footprints narrower than this share of the
/// implement width is not given a lane of its own ([`lanes`]).
const MIDDLE_GAP_SHARE: f64 = 0.1;

/// Points round a piece (at the point spacing) above which [`middle_lanes`] gives it none.
const MAX_MIDDLE_RIM_POINTS: usize = 4000;

/// Lanes along the middle of `piece` where it is `near` to `far` m wide, as open tracks
/// resampled to `spacing`: the midpoints between each point of its rings (resampled) and the
/// nearest point of a ring across the piece (on the same ring, one farther along it than `far`
/// either way, so not a neighbour on the same side), that nearest point `near` to `far` away.
/// Each pair of sides gives one lane, from the side met first (rings in order, each walked from
/// its sharpest turn). None for a piece of more than [`MAX_MIDDLE_RIM_POINTS`] points round
/// (each point is paired by a search over all of them).
fn middle_lanes(piece: &Area, (near, far): (f64, f64), spacing: f64) -> Vec<Vec<Vec2>> {
    use crate::geo::polygon::{closest_point_on_segment, resample};
    let rims: Vec<Vec<Vec2>> = std::iter::once(&piece.0)
        .chain(&piece.1)
        .map(|ring| {
            let mut closed = ring.clone();
            closed.extend(ring.first());
            let mut r = resample(&closed, spacing);
            r.pop();
            let m = r.len();
            let turn = |i: usize| {
                let (a, b, c) = (r[(i + m - 1) % m], r[i], r[(i + 1) % m]);
                cross(&(b - a), &(c - b)).atan2((b - a).dot(&(c - b))).abs()
            };
            let first = (0..m).max_by(|&i, &j| turn(i).total_cmp(&turn(j)));
            r.rotate_left(first.unwrap_or(0));
            r
        })
        .filter(|r| r.len() >= 3)
        .collect();
    if rims.iter().map(Vec::len).sum::<usize>() > MAX_MIDDLE_RIM_POINTS {
        return Vec::new();
    }
    // Arc length along each rim at each of its points.
    let along: Vec<Vec<f64>> = rims
        .iter()
        .map(|r| {
            let steps = (0..r.len()).map(|i| (r[(i + 1) % r.len()] - r[i]).norm());
            std::iter::once(0.0)
                .chain(steps.scan(0.0, |s, d| {
                    *s += d;
                    Some(*s)
                }))
                .collect()
        })
        .collect();
    let mut lanes = Vec::new();
    for (a, rim) in rims.iter().enumerate() {
        let mut lane: Vec<Vec2> = Vec::new();
        for (i, q) in rim.iter().enumerate() {
            let mut across: Option<(f64, Vec2, (usize, usize))> = None;
            for (b, other) in rims.iter().enumerate() {
                let (n, total) = (other.len(), along[b][other.len()]);
                for j in 0..n {
                    if a == b {
                        let apart = (along[a][j] - along[a][i]).abs();
                        if apart.min(total - apart) < far {
                            continue;
                        }
                    }
                    let c = closest_point_on_segment(q, &other[j], &other[(j + 1) % n]);
                    let d = (c - q).norm();
                    if across.is_none_or(|x| d < x.0) {
                        across = Some((d, c, (b, j)));
                    }
                }
            }
            match across {
                Some((d, c, side)) if d > near && d <= far && (a, i) < side => {
                    lane.push((q + c) / 2.0)
                }
                _ if lane.len() >= 2 => lanes.push(resample(&std::mem::take(&mut lane), spacing)),
                _ => lane.clear(),
            }
        }
        if lane.len() >= 2 {
            lanes.push(resample(&lane, spacing));
        }
    }
    lanes
}

/// `lane` (at least two points) run on straight from each end along its direction there by
/// `length` m, points `spacing` apart.
fn extended(lane: &[Vec2], length: f64, spacing: f64) -> Vec<Vec2> {
    let n = lane.len();
    if n < 2 {
        return lane.to_vec();
    }
    let steps = (length / spacing).ceil() as usize;
    let on = |end: Vec2, from: Vec2| {
        let dir = (end - from).try_normalize(1e-9).unwrap_or_default();
        (1..=steps).map(move |k| end + dir * (k as f64 * spacing))
    };
    let mut out: Vec<Vec2> = on(lane[0], lane[1]).collect();
    out.reverse();
    out.extend_from_slice(lane);
    out.extend(on(lane[n - 1], lane[n - 2]));
    out
}

/// The rings of `area` as tracks of `out` (outer rings as field tracks, holes as obstacle
/// tracks), and the area as its pass area.
fn add_rings(out: &mut Passes, area: Vec<Area>, spacing: f64) {
    if area.is_empty() {
        return;
    }
    for (outer, holes) in &area {
        out.field
            .extend(tracks_of(&[(outer.clone(), vec![])], spacing));
        for h in holes {
            out.obstacles
                .extend(tracks_of(&[(h.clone(), vec![])], spacing));
        }
    }
    out.areas.push(area);
}
