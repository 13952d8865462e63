//! The ground inside the headland that neither the passes' footprints nor the working area
//! cover (docs/METHODS.md, Headland and working area): found once from the passes' areas, it
//! joins the working area where an implement-wide disc fits, or is worked as cells of its own.

use super::geometry::{in_area, offset_within, simplified, Area};
use super::headland::{
    difference, pass_offset, ring_distance, union, Passes, SMOOTHING_RADIUS_FACTOR,
};
use super::CoverageParams;
use crate::geo::Vec2;

/// Vertices of the leftover ground dropped within this distance of its outline, m
/// ([`with_leftover`]): its offsets' fine arcs made the clipper cross every edge with every
/// other (over a second on one parcel), for ground drawn to a few centimetres anyway.
const LEFTOVER_SIMPLIFY_M: f64 = 0.05;

/// The leftover ground's offsets keep their chords this close to their arcs, m: within the
/// simplification, and within the slack, so the footprints still overlap where they meet.
const LEFTOVER_CHORD_M: f64 = 0.02;

/// [`offset_within`] to [`LEFTOVER_CHORD_M`].
fn offset(areas: &[Area], distance: f64) -> Vec<Area> {
    offset_within(areas, distance, LEFTOVER_CHORD_M)
}

/// How much wider than the implement each footprint is taken when the leftover ground is
/// found, m ([`with_leftover`]).
const LEFTOVER_SLACK_M: f64 = 0.05;

/// Leftover ground smaller than this many implement widths squared is left ([`with_leftover`]).
const LEFTOVER_MIN_AREA_W2: f64 = 1.0;

/// A leftover piece whose opening at w/2 keeps less than this fraction of it is worked whole,
/// as a cell of its own ([`with_leftover`]).
const KEPT_FRACTION: f64 = 0.5;

/// The ground a plan works by swaths ([`with_leftover`]).
#[derive(Debug, Clone, Default)]
pub struct Worked {
    /// The working area with the leftover ground wide enough for it: swaths at the field's
    /// swath angle.
    pub working: Vec<Area>,
    /// Pieces worked as cells of their own, each at its own minimum-span angle: leftover strips
    /// too narrow for a disc an implement wide (between the passes' footprints in an arm the
    /// inner passes do not reach, which swaths at the field's angle would only cross for a few
    /// metres), or mostly so, and the ground outside the outermost pass where it
    /// splits at a neck. A run of one that no transit reaches, or that strands the vehicle, is
    /// put back (the plan's own choice: nothing is driven by hand for it).
    pub own: Vec<Area>,
}

/// The working area with the ground inside the outermost pass that neither the passes'
/// footprints nor `working` cover, larger than w² and a mean w/4 thick at least (one pass
/// works it): in an arm narrower than the inner passes need (each pass is opened at r_min and
/// vanishes there) that ground was never worked. Where discs an implement wide fit (an opening
/// of radius w/2) over half of a piece, those parts join the working area and get swaths, with
/// turns on the passes' ground where they fit; any other piece (a strip narrower than the
/// implement, with a wider bulge or none) is worked whole along its length ([`Worked::own`]),
/// and so is the ground a neck leaves outside the outermost pass.
pub fn with_leftover(
    working: Vec<Area>,
    (boundary, obstacles): (&[Vec2], &[Vec<Vec2>]),
    passes: &Passes,
    p: &CoverageParams,
) -> Worked {
    if passes.areas.is_empty() {
        return Worked {
            working,
            own: Vec::new(),
        };
    }
    let half = p.line_width / 2.0;
    let min_area = LEFTOVER_MIN_AREA_W2 * p.line_width * p.line_width;
    // Inside pass k's footprint and outside pass k + 1's (the working area's after the last):
    // the footprints tile the headland, so their edges coincide where both passes run; each
    // footprint is taken LEFTOVER_SLACK_M wider, which keeps the clipper off coincident edges.
    let reach = half + LEFTOVER_SLACK_M;
    let areas: Vec<Vec<Area>> = passes
        .areas
        .iter()
        .map(|a| simplified(a, LEFTOVER_SIMPLIFY_M))
        .collect();
    let left: Vec<Area> = (0..areas.len())
        .flat_map(|k| {
            let inner = match areas.get(k + 1) {
                Some(next) => offset(next, reach),
                None => offset(&simplified(&working, LEFTOVER_SIMPLIFY_M), LEFTOVER_SLACK_M),
            };
            difference(&offset(&areas[k], -reach), &inner)
        })
        // Slivers (mean thickness 2·area/perimeter under w/4) go first, cheaply.
        .filter(|a| {
            let area = super::geometry::area_m2(a);
            area > min_area && 4.0 * area >= half * super::geometry::perimeter(a)
        })
        .collect();
    // Outside the outermost pass's footprint: where the field narrows to a neck, the outermost
    // pass (opened at r_min) splits into rings round each side and leaves the neck's ground;
    // kept where a disc of the turns' radius (and the implement's width) fits, which the
    // corners that the pass rounds off (the unreachable ground) do not hold. (A pass that did
    // not split runs through every neck: nothing to find, and the clips are skipped.)
    let junctions = if areas[0].len() < 2 {
        Vec::new()
    } else {
        // The ground outside the pass's footprint (grown by reach0), opened at r: shrinking
        // distributes over the difference (the field shrunk by r minus the footprint grown by
        // r), which spares the clipper the thin band all along the boundary, whose offset
        // crossed every arc with every other (11 ms of a 35 ms plan at w 36).
        let reach0 = pass_offset(p, 0) + LEFTOVER_SLACK_M;
        let r = (p.r_min * SMOOTHING_RADIUS_FACTOR).max(half);
        let eroded = difference(
            &offset(&[(boundary.to_vec(), obstacles.to_vec())], -r),
            &offset(&areas[0], reach0 + r),
        );
        offset(&simplified(&eroded, LEFTOVER_SIMPLIFY_M), r)
    };
    let eroded = offset(&simplified(&left, LEFTOVER_SIMPLIFY_M), -half);
    let wide: Vec<Area> = offset(&simplified(&eroded, LEFTOVER_SIMPLIFY_M), half)
        .into_iter()
        .filter(|a| super::geometry::area_m2(a) > min_area)
        .collect();
    // Is `q` in or on a leftover piece (a kept piece's vertices lie in or on the piece it came
    // from, within the simplification)?
    let near = |q: &Vec2, piece: &Area| {
        std::iter::once(&piece.0)
            .chain(&piece.1)
            .any(|ring| ring_distance(std::slice::from_ref(q), ring) < 2.0 * LEFTOVER_SIMPLIFY_M)
            || in_area(piece, q)
    };
    // Each kept piece stands by sixteen of its vertices, spread round it, for the piece it
    // came from; a piece whose opening kept less than KEPT_FRACTION of it (a strip narrower than
    // the implement, with a wider bulge or none) is worked whole as a cell of its own, along its
    // length; the others' kept pieces join the working area.
    let source = |w: &Area| {
        let samples: Vec<Vec2> =
            w.0.iter()
                .step_by(w.0.len().div_ceil(16).max(1))
                .copied()
                .collect();
        left.iter()
            .position(|piece| samples.iter().any(|q| near(q, piece)))
    };
    let mut kept = vec![0.0; left.len()];
    let from: Vec<Option<usize>> = wide.iter().map(source).collect();
    for (w, j) in wide.iter().zip(&from) {
        if let Some(k) = j.and_then(|j| kept.get_mut(j)) {
            *k += super::geometry::area_m2(w);
        }
    }
    let whole: Vec<bool> = left
        .iter()
        .zip(&kept)
        .map(|(piece, k)| *k < KEPT_FRACTION * super::geometry::area_m2(piece))
        .collect();
    let wide: Vec<Area> = wide
        .into_iter()
        .zip(&from)
        .filter(|(_, j)| j.is_none_or(|j| !whole[j]))
        .map(|(w, _)| w)
        .collect();
    let own = left
        .into_iter()
        .zip(&whole)
        .filter(|(_, w)| **w)
        .map(|(piece, _)| piece)
        .chain(
            junctions
                .into_iter()
                .filter(|a| super::geometry::area_m2(a) > min_area),
        )
        .collect();
    let working = if wide.is_empty() {
        working
    } else {
        union(&working, &wide)
    };
    Worked { working, own }
}
