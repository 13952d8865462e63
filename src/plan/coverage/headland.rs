//! Headland (seed 003): driveable closed passes around the field and around the large
//! obstacles, and the working area inside them, which the swaths cover.
//!
//! Pass k runs at w/2 + k·w from the edge, so the passes' footprints tile the headland from the
//! edge to passes·w, and the working area is the boundary shrunk by passes·w (the obstacles
//! grown likewise): the outermost swaths' footprints meet the innermost pass's. Where a corner
//! is sharper than the vehicle turns, a pass cannot follow the offset there: at a convex corner
//! it rounds the corner on an arc of radius r_min (an opening of the offset area); at a reflex
//! corner of the field (a convex corner of an obstacle) the offset area is cut by a disc of
//! radius r_min that contains the offset's own arc about the corner, then opened, so the pass
//! bends on radius r_min and keeps at least its offset from the corner. The ground between
//! such a bend and the corner is what the metrics report as unworked near the corner; the pass
//! keeps its offset everywhere else (the whole ring is no longer raised to r_min).

use super::geometry::{offset, Area};
use super::CoverageParams;
pub use crate::geo::polygon::resample;
use crate::geo::{cross, v2, Vec2};
use geo::BooleanOps;

/// Added to every offset the implement must keep, m: round joins are drawn with chords,
/// which cut up to 0.3 mm inside a 6 m arc.
pub const CHORD_MARGIN: f64 = 0.005;

/// The passes bend on radius `r_min · SMOOTHING_RADIUS_FACTOR`: their points lie on chords of
/// the arcs, and three-point curvature over such points reads up to ~3 % above the arc's.
pub const SMOOTHING_RADIUS_FACTOR: f64 = 1.05;

/// Depth by which a disc laid over a concave kink of a pass reaches past the kink, m.
const KINK_DISC_DEPTH: f64 = 0.02;

/// Rounds of finding concave kinks in the passes and cutting them away.
const KINK_ROUNDS: usize = 4;

/// Room for the extra length of continuous-curvature turns (clothoid entries) beyond an arc
/// turn, m.
const TURN_ROOM_MARGIN: f64 = 0.25;

/// How far a path's chords may cut inside its arcs, m: points `point_spacing` apart on an arc
/// of radius ≥ r_min sag by at most spacing²/(8·r_min), plus [`CHORD_MARGIN`].
pub fn chord_margin(p: &CoverageParams) -> f64 {
    CHORD_MARGIN + p.point_spacing * p.point_spacing / (8.0 * p.r_min)
}

/// Does the ring have a reflex (interior angle > 180°) vertex? Rings are counter-clockwise.
pub fn has_reflex_vertex(ring: &[Vec2]) -> bool {
    let n = ring.len();
    (0..n).any(|i| {
        let a = ring[(i + n - 1) % n];
        let b = ring[i];
        let c = ring[(i + 1) % n];
        cross(&(b - a), &(c - b)) < -1e-9
    })
}

/// Width of headland the turns at the swath ends need, m: a pi turn (arcs of r_min joined by
/// a straight, or a semicircle when the swaths are 2·r_min apart) reaches r_min beyond the
/// swath end whatever the spacing, the implement another w/2, and continuous-curvature entries
/// a little more.
pub fn turn_room(p: &CoverageParams) -> f64 {
    p.r_min + 0.5 * p.line_width + TURN_ROOM_MARGIN
}

/// Headland passes planned: the configured number, raised so the headland is as wide as the
/// turns at the swath ends need ([`turn_room`]); without that room the swaths would stop short
/// of the headland and leave a strip unworked.
pub fn passes(p: &CoverageParams) -> usize {
    let needed = (turn_room(p) / p.pass_spacing() - 1e-9).ceil().max(0.0) as usize;
    p.headland_passes.max(needed)
}

/// Why no swath fits a field, with the numbers a farmer needs to change the job.
#[derive(Debug, Clone, PartialEq)]
pub struct NoSwathFits {
    /// Width of the field's widest strip (twice the largest inscribed circle's radius), m.
    pub field_width: f64,
    pub line_width: f64,
    /// 2·r_min, m.
    pub turn_diameter: f64,
    /// Headland passes the turns need at this width ([`passes`]) and their width, m.
    pub passes: usize,
    pub headland_width: f64,
    /// The largest implement width (0.5 m steps, below this one) at which the planner plans
    /// swaths (`None`: none of 0.5 m or more), when searched (`planned`).
    pub largest_width: Option<f64>,
    /// `largest_width` was searched by planning ([`super::narrow::no_swath_reason`]); the strip
    /// test alone does not bound it (the ground the passes leave can hold swaths).
    pub planned: bool,
}

impl std::fmt::Display for NoSwathFits {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let why = if self.field_width < self.line_width {
            format!(
                "the field is {:.1} m wide at its widest, narrower than the implement ({:.1} m)",
                self.field_width, self.line_width
            )
        } else {
            format!(
                "the field is {:.1} m wide at its widest; the {} headland pass(es) the turns need ({:.1} m each side, turn diameter {:.1} m, implement {:.1} m) leave no room for a swath",
                self.field_width, self.passes, self.headland_width, self.turn_diameter, self.line_width
            )
        };
        match (self.largest_width, self.planned) {
            (Some(w), true) => write!(f, "no swath fits: {why}; the largest implement width that plans swaths here is {w:.1} m"),
            (None, true) => write!(f, "no swath fits: {why}; no implement width of 0.5 m or more leaves room for swaths here"),
            (_, false) => write!(f, "no swath fits: {why}"),
        }
    }
}

/// `Some` when the field is too narrow for any swath inside the headland at these parameters
/// (the largest width that plans swaths not yet searched: [`super::narrow::no_swath_reason`]).
pub fn no_swath_fits(field_width: f64, p: &CoverageParams) -> Option<NoSwathFits> {
    if field_width > 2.0 * passes(p) as f64 * p.pass_spacing() + 1e-6 {
        return None;
    }
    Some(NoSwathFits {
        field_width,
        line_width: p.line_width,
        turn_diameter: 2.0 * p.r_min,
        passes: passes(p),
        headland_width: passes(p) as f64 * p.pass_spacing(),
        largest_width: None,
        planned: false,
    })
}

/// Offset of headland pass `k` from the field edge (or an obstacle's), m: w/2 + k·s (s the
/// [pass spacing](CoverageParams::pass_spacing)) plus the chord margin.
pub fn pass_offset(p: &CoverageParams, k: usize) -> f64 {
    p.line_width / 2.0 + k as f64 * p.pass_spacing() + chord_margin(p)
}

/// The area inside which the swaths' footprints lie (the working area): the boundary shrunk
/// by passes·s (s the [pass spacing](CoverageParams::pass_spacing): the outermost swaths lay
/// the overlap onto the inner pass), minus the obstacles with their own headland
/// ([`obstacle_headland_width`], smoothed by a closing of radius r_min).
pub fn working_area(boundary: &[Vec2], obstacles: &[Vec<Vec2>], p: &CoverageParams) -> Vec<Area> {
    let inset = passes(p) as f64 * p.pass_spacing();
    let outer = offset(&[(boundary.to_vec(), vec![])], -inset);
    if obstacles.is_empty() {
        return outer;
    }
    let holes = closing(obstacles, obstacle_headland_width(p), p.r_min);
    let a = geo::MultiPolygon::new(outer.iter().map(super::geometry::to_geo).collect());
    let b = geo::MultiPolygon::new(holes.iter().map(super::geometry::to_geo).collect());
    super::geometry::from_geo(&a.difference(&b))
}

/// Width of the headland around every obstacle, m: out to the outer edge of the outermost
/// obstacle pass less the overlap (w/2 when there are no headland passes).
pub fn obstacle_headland_width(p: &CoverageParams) -> f64 {
    match passes(p) {
        0 => p.line_width / 2.0,
        n => n as f64 * p.pass_spacing(),
    }
}

/// The obstacles grown by `distance` m and closed with radius `r` (grown by `distance + r`,
/// shrunk by `r`): every point is at least `distance` from the obstacles, convex corners are
/// arcs of radius `distance`, concave ones arcs of radius ≥ `r`, and near obstacles merge.
pub fn closing(obstacles: &[Vec<Vec2>], distance: f64, r: f64) -> Vec<Area> {
    let rings: Vec<Area> = obstacles.iter().map(|o| (o.clone(), vec![])).collect();
    offset(&offset(&rings, distance + r), -r)
}

/// A disc as a polygon whose chords stay outside the circle (vertices on radius
/// r / cos(step/2)), so the disc is contained.
fn disc(centre: Vec2, r: f64) -> Area {
    let n = ((std::f64::consts::TAU / 0.05).ceil() as usize).max(16);
    let step = std::f64::consts::TAU / n as f64;
    let rr = r / (0.5 * step).cos();
    (
        (0..n)
            .map(|i| {
                let a = i as f64 * step;
                centre + v2(rr * a.cos(), rr * a.sin())
            })
            .collect(),
        vec![],
    )
}

/// The disc of radius `r` about `centre` cut to its cap that can meet `area`
/// ([`super::disc_caps::cap`]); `None` when it cannot meet it.
fn capped_disc(centre: Vec2, r: f64, area: &[Area]) -> Option<Area> {
    let (ring, _) = disc(centre, r);
    // The polygon's vertices lie outside the circle of radius r (`disc`): the cut takes theirs.
    let rr = ring.first().map_or(0.0, |v| (v - centre).norm());
    super::disc_caps::cap(ring, centre, rr, area).map(|cap| (cap, vec![]))
}

/// Unit bisector of the corner at `ring[i]` pointing to the ring's left (the inside of a
/// counter-clockwise ring); `None` for a spike that folds back on itself.
fn left_bisector(ring: &[Vec2], i: usize) -> Option<Vec2> {
    let n = ring.len();
    let (a, b, c) = (ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]);
    let left = |d: Vec2| v2(-d.y, d.x);
    let n1 = left(b - a).try_normalize(1e-12)?;
    let n2 = left(c - b).try_normalize(1e-12)?;
    (n1 + n2).try_normalize(1e-9)
}

/// Discs of radius `r` that hold the offset's arc of radius `d` about every vertex of `ring`
/// where `ring` turns right (reflex for the area on its left), centred `r − d` beyond the
/// vertex on the right: a pass going round them bends on radius `r` and stays `d` clear.
fn corner_discs(ring: &[Vec2], d: f64, r: f64) -> Vec<Area> {
    corner_disc_centres(ring, d, r)
        .into_iter()
        .map(|c| disc(c, r))
        .collect()
}

/// The centres of [`corner_discs`]`(ring, d, r)`.
fn corner_disc_centres(ring: &[Vec2], d: f64, r: f64) -> Vec<Vec2> {
    if r <= d {
        return Vec::new();
    }
    let n = ring.len();
    (0..n)
        .filter(|&i| {
            let (a, b, c) = (ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]);
            cross(&(b - a), &(c - b)) < -1e-9
        })
        .filter_map(|i| left_bisector(ring, i).map(|m| ring[i] - m * (r - d)))
        .collect()
}

pub(super) fn union(a: &[Area], b: &[Area]) -> Vec<Area> {
    let a = geo::MultiPolygon::new(a.iter().map(super::geometry::to_geo).collect());
    let b = geo::MultiPolygon::new(b.iter().map(super::geometry::to_geo).collect());
    super::geometry::from_geo(&a.union(&b))
}

pub(super) fn difference(a: &[Area], b: &[Area]) -> Vec<Area> {
    let a = geo::MultiPolygon::new(a.iter().map(super::geometry::to_geo).collect());
    let b = geo::MultiPolygon::new(b.iter().map(super::geometry::to_geo).collect());
    super::geometry::from_geo(&a.difference(&b))
}

/// `a` minus the union of `b`, whose areas may overlap each other (the default even-odd rule
/// of [`difference`] would keep where an even number of them overlap).
fn difference_of_union(a: &[Area], b: &[Area]) -> Vec<Area> {
    use geo::algorithm::bool_ops::FillRule;
    // Non-zero winding: outer rings counter-clockwise, holes clockwise.
    let oriented = |areas: &[Area]| {
        geo::MultiPolygon::new(
            areas
                .iter()
                .map(|(outer, holes)| {
                    let cw: Vec<Vec<Vec2>> = holes
                        .iter()
                        .map(|h| h.iter().rev().copied().collect())
                        .collect();
                    super::geometry::to_geo(&(outer.clone(), cw))
                })
                .collect(),
        )
    };
    super::geometry::from_geo(
        &oriented(a).difference_with_fill_rule(&oriented(b), FillRule::NonZero),
    )
}

/// Closed tracks (first point repeated last) along every ring of `areas`, resampled.
fn tracks_of(areas: &[Area], spacing: f64) -> Vec<Vec<Vec2>> {
    areas
        .iter()
        .flat_map(|(outer, holes)| std::iter::once(outer).chain(holes.iter()))
        .filter(|ring| ring.len() >= 3)
        .map(|ring| {
            let mut closed = ring.clone();
            closed.push(ring[0]);
            resample(&closed, spacing)
        })
        .collect()
}

/// Headland passes around the obstacles, nearest the obstacle first: closed tracks (first point
/// repeated last) at [`pass_offset`] from them, every corner an arc of radius ≥ r_min,
/// resampled to `point_spacing`. Obstacles whose passes meet share them.
pub fn obstacle_tracks(obstacles: &[Vec<Vec2>], p: &CoverageParams) -> Vec<Vec<Vec2>> {
    let mut tracks = Vec::new();
    if obstacles.is_empty() {
        return tracks;
    }
    let rs = p.r_min * SMOOTHING_RADIUS_FACTOR;
    for k in 0..passes(p) {
        let d = pass_offset(p, k);
        let rings: Vec<Area> = obstacles.iter().map(|o| (o.clone(), vec![])).collect();
        let mut grown = offset(&rings, d);
        // An obstacle's convex corners turn right for the field around it: walk each obstacle
        // clockwise so they are the right-hand turns.
        let discs: Vec<Area> = obstacles
            .iter()
            .flat_map(|o| {
                let cw: Vec<Vec2> = o.iter().rev().copied().collect();
                corner_discs(&cw, d, rs)
            })
            .collect();
        if !discs.is_empty() {
            grown = union(&grown, &discs);
        }
        // Closing: the concave junctions rounded to r_min, outwards only.
        let closed = offset(&offset(&grown, rs), -rs);
        for (ring, _) in closed {
            let mut c = ring.clone();
            c.push(ring[0]);
            tracks.push(resample(&c, p.point_spacing));
        }
    }
    tracks
}

/// Least distance between two rings that do not cross, m.
pub(super) fn ring_distance(a: &[Vec2], b: &[Vec2]) -> f64 {
    use crate::geo::polygon::point_segment_distance;
    let one_way = |a: &[Vec2], b: &[Vec2]| {
        let n = b.len();
        a.iter()
            .flat_map(|q| (0..n).map(move |i| point_segment_distance(q, &b[i], &b[(i + 1) % n])))
            .fold(f64::INFINITY, f64::min)
    };
    one_way(a, b).min(one_way(b, a))
}

/// Split the obstacles into (small, headland): the large ones (larger than
/// `small_obstacle_max_m`) get headland passes, and so do the small ones a headland pass's
/// implement would reach (nearer the boundary or another headland obstacle than the headland
/// is wide plus w/2): the passes bend round them. The other small ones are passed on detours.
pub fn split_obstacles(
    boundary: &[Vec2],
    obstacles: &[Vec<Vec2>],
    p: &CoverageParams,
) -> (Vec<Vec<Vec2>>, Vec<Vec<Vec2>>) {
    let (mut small, mut large): (Vec<Vec<Vec2>>, Vec<Vec<Vec2>>) = obstacles
        .iter()
        .cloned()
        .partition(|o| super::obstacle_size(o) <= p.small_obstacle_max_m);
    let reach = obstacle_headland_width(p) + 0.5 * p.line_width + chord_margin(p);
    // Promoted ones may bring others within reach: repeat until none moves.
    loop {
        let near = |o: &Vec<Vec2>| {
            ring_distance(o, boundary) < reach || large.iter().any(|l| ring_distance(o, l) < reach)
        };
        let (moved, kept): (Vec<_>, Vec<_>) = small.into_iter().partition(near);
        small = kept;
        if moved.is_empty() {
            break;
        }
        large.extend(moved);
    }
    (small, large)
}

/// `areas` minus every obstacle grown by `margin` m.
pub fn subtract_obstacles(areas: &[Area], obstacles: &[Vec<Vec2>], margin: f64) -> Vec<Area> {
    if obstacles.is_empty() {
        return areas.to_vec();
    }
    let grown: Vec<Area> = offset(
        &obstacles
            .iter()
            .map(|o| (o.clone(), vec![]))
            .collect::<Vec<_>>(),
        margin,
    );
    difference(areas, &grown)
}

/// The headland passes of a field and of the obstacles that get a headland, pass by pass
/// (nearest the edge first): [`Passes::field`] the outer rings, [`Passes::obstacles`] the rings
/// round the obstacles.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Passes {
    pub field: Vec<Vec<Vec2>>,
    pub obstacles: Vec<Vec<Vec2>>,
    /// Each pass's area (the pass runs along its rings), outermost first.
    pub areas: Vec<Vec<Area>>,
}

/// The headland passes of the field with its headland obstacles: pass k runs along the rings of
/// the area at [`pass_offset`] from the boundary *and* from every obstacle (boundary shrunk,
/// obstacles grown, their sharp corners bent round discs of radius r_min, opened), so a pass
/// near an obstacle bends round it instead of crossing it, and obstacles whose headlands meet
/// the field's share its outer pass. Closed tracks, resampled to `point_spacing`.
pub fn passes_around(boundary: &[Vec2], obstacles: &[Vec<Vec2>], p: &CoverageParams) -> Passes {
    let rs = p.r_min * SMOOTHING_RADIUS_FACTOR;
    let mut out = Passes::default();
    for k in 0..passes(p) {
        let d = pass_offset(p, k);
        let eroded = eroded_pass_area(boundary, obstacles, d, rs);
        let opened = open_without_kinks(&eroded, rs, p);
        for (outer, holes) in &opened {
            out.field
                .extend(tracks_of(&[(outer.clone(), vec![])], p.point_spacing));
            for h in holes {
                out.obstacles
                    .extend(tracks_of(&[(h.clone(), vec![])], p.point_spacing));
            }
        }
        out.areas.push(opened);
    }
    out
}

/// The area of pass centres at offset `d` (boundary shrunk by `d`, obstacles grown by `d`, the
/// discs of radius `rs` at the sharp corners taken out: [`corner_discs`]) shrunk by a further
/// `rs`: the first half of the opening of radius `rs`. Shrinking distributes over those steps
/// (shrinking by `d` then `rs` is shrinking by `d + rs`; an area minus a set, shrunk by `rs`, is
/// the area shrunk minus the set grown by `rs`; a disc grown by `rs` is the disc of radius
/// `r + rs`), so this is one offset of the field's own rings instead of an offset of the
/// offset, whose many arc vertices made the clipper cross every edge with every other where
/// the area is narrow (up to 0.3 s a pass).
fn eroded_pass_area(boundary: &[Vec2], obstacles: &[Vec<Vec2>], d: f64, rs: f64) -> Vec<Area> {
    let mut area = offset(&[(boundary.to_vec(), vec![])], -(d + rs));
    let mut centres = corner_disc_centres(boundary, d, rs);
    // An obstacle's convex corners turn right for the field around it: walk each obstacle
    // clockwise so they are the right-hand turns.
    centres.extend(obstacles.iter().flat_map(|o| {
        let cw: Vec<Vec2> = o.iter().rev().copied().collect();
        corner_disc_centres(&cw, d, rs)
    }));
    let grown = if obstacles.is_empty() {
        Vec::new()
    } else {
        let rings: Vec<Area> = obstacles.iter().map(|o| (o.clone(), vec![])).collect();
        offset(&rings, d + rs)
    };
    if area.is_empty() || (centres.is_empty() && grown.is_empty()) {
        return area;
    }
    // Each corner disc cut to its cap that can meet what is left of the area (the rest of it
    // lies outside the area or in a grown obstacle; see [`super::disc_caps`]). The grown
    // obstacles (those without holes) count as holes of the area there.
    let left: Vec<Area> = area
        .iter()
        .map(|(outer, holes)| {
            let mut holes = holes.clone();
            holes.extend(grown.iter().filter(|g| g.1.is_empty()).map(|g| g.0.clone()));
            (outer.clone(), holes)
        })
        .collect();
    let mut taken: Vec<Area> = centres
        .into_iter()
        .filter_map(|c| capped_disc(c, 2.0 * rs, &left))
        .collect();
    taken.extend(grown);
    if !taken.is_empty() {
        area = difference_of_union(&area, &taken);
    }
    area
}

/// The opening of radius `rs` (convex corners rounded) of the area whose first half is
/// `eroded` (the area shrunk by `rs`, [`eroded_pass_area`]), with the concave kinks that the
/// offsets made (where offsets of distant edges meet) cut away by discs of radius `rs` and
/// opened again (the kink discs grown by `rs` taken out of `eroded`, grown back by `rs`).
fn open_without_kinks(eroded: &[Area], rs: f64, p: &CoverageParams) -> Vec<Area> {
    // Each round opens the area minus all the discs so far: opening an opened area again
    // shrinks its arcs of radius rs to points, and the polygon clipping of those degenerate
    // offsets took seconds.
    let mut opened = offset(eroded, rs);
    let mut kink_discs: Vec<Area> = Vec::new();
    for _ in 0..KINK_ROUNDS {
        let kinks = concave_kinks(&opened, p.point_spacing, p.r_min);
        if kinks.is_empty() {
            break;
        }
        // (Each cut to its cap that can meet `eroded`, as the corner discs are.)
        kink_discs.extend(kinks.iter().filter_map(|(q, out)| {
            capped_disc(q + out * (rs - KINK_DISC_DEPTH), 2.0 * rs, eroded)
        }));
        if kink_discs.is_empty() {
            break;
        }
        opened = offset(&difference_of_union(eroded, &kink_discs), rs);
    }
    opened
}

/// The headland passes, outermost first: closed tracks (first point repeated last) at
/// [`pass_offset`] from the boundary, convex corners rounded to r_min (an opening: shrink by
/// r_min, grow by r_min) and reflex corners bent round a disc of radius r_min
/// ([`corner_discs`]), resampled to `point_spacing`.
pub fn headland_tracks(boundary: &[Vec2], p: &CoverageParams) -> Vec<Vec<Vec2>> {
    let rs = p.r_min * SMOOTHING_RADIUS_FACTOR;
    let mut tracks = Vec::new();
    for k in 0..passes(p) {
        let eroded = eroded_pass_area(boundary, &[], pass_offset(p, k), rs);
        tracks.extend(tracks_of(
            &open_without_kinks(&eroded, rs, p),
            p.point_spacing,
        ));
    }
    tracks
}

/// Points of the areas' rings, resampled to `spacing`, where a ring bends away from its area
/// tighter than `r_min` (three-point curvature), each with the unit normal pointing out of
/// the area.
fn concave_kinks(areas: &[Area], spacing: f64, r_min: f64) -> Vec<(Vec2, Vec2)> {
    let mut out = Vec::new();
    for (outer, holes) in areas {
        // Outer rings are CCW with the area on the left; holes are CCW too (from_geo) with the
        // area on their right.
        for (ring, area_left) in
            std::iter::once((outer, true)).chain(holes.iter().map(|h| (h, false)))
        {
            if ring.len() < 3 {
                continue;
            }
            let mut closed = ring.clone();
            closed.push(ring[0]);
            let pts = resample(&closed, spacing);
            let n = pts.len().saturating_sub(1); // last = first
            if n < 3 {
                continue;
            }
            for i in 0..n {
                let (a, b, c) = (pts[(i + n - 1) % n], pts[i], pts[(i + 1) % n]);
                let turn = cross(&(b - a), &(c - b));
                let concave = if area_left { turn < 0.0 } else { turn > 0.0 };
                let chord = (c - a).norm();
                if !concave || chord < 1e-9 {
                    continue;
                }
                let k = 2.0 * turn.abs() / ((b - a).norm() * (c - b).norm() * chord);
                if k > 1.0 / r_min {
                    let t = (c - a) / chord;
                    let left = v2(-t.y, t.x);
                    out.push((b, if area_left { -left } else { left }));
                }
            }
        }
    }
    out
}

/// The closed tracks, each whole when every point is clear and no curve is tighter than
/// `r_min` (the guarantees' three-point curvature and slack, `metrics::checks`), else cut into
/// its stretches that are (open, at least 3 points), each cut reported in `warnings` with its
/// place. (A kink the openings left, 1.2 /m over half a metre at r_min 5.7 m on a random field
/// with a hole, had been returned and refused by the checks.)
pub fn clear_stretches(
    tracks: Vec<Vec<Vec2>>,
    clear: &dyn Fn(&Vec2) -> bool,
    r_min: f64,
    warnings: &std::cell::RefCell<Vec<String>>,
) -> Vec<Vec<Vec2>> {
    let limit = super::metrics::checks::curvature_limit(r_min);
    let mut out = Vec::new();
    for track in tracks {
        // Closed: the last point repeats the first.
        let m = track.len().saturating_sub(1);
        let ok: Vec<bool> = track
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let curve_ok = m < 3 || super::metrics::ring_curvature(&track[..m], i) <= limit;
                curve_ok && clear(q)
            })
            .collect();
        let Some(first_bad) = ok.iter().position(|c| !c) else {
            out.push(track);
            continue;
        };
        // The closed track without its repeated last point, walked from a blocked point.
        let mut stretch: Vec<Vec2> = Vec::new();
        let mut dropped = 0;
        for k in 1..=m {
            let i = (first_bad + k) % m;
            if ok[i] {
                stretch.push(track[i]);
            } else {
                dropped += 1;
                if stretch.len() >= 3 {
                    out.push(std::mem::take(&mut stretch));
                } else {
                    stretch.clear();
                }
            }
        }
        let q = track[first_bad];
        warnings.borrow_mut().push(format!(
            "headland pass cut at ({:.1}, {:.1}): {dropped} of its {m} points would put the implement over the edge or an obstacle or turn tighter than r_min",
            q.x, q.y
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;

    fn params() -> CoverageParams {
        CoverageParams {
            line_width: 6.0,
            r_min: 6.0,
            headland_passes: 2,
            point_spacing: 1.0,
            swath_angle: Default::default(),
            route: Default::default(),
            small_obstacle_max_m: 20.0,
            max_curvature_rate: 0.0,
            headland_order: Default::default(),
            sections: 1,
            overlap: 0.0,
        }
    }

    #[test]
    fn tracks_keep_their_offset_and_turn_no_tighter_than_r_min() {
        let b = vec![
            v2(0.0, 0.0),
            v2(200.0, 0.0),
            v2(200.0, 100.0),
            v2(0.0, 100.0),
        ];
        let p = params();
        let t = headland_tracks(&b, &p);
        assert_eq!(t.len(), 2);
        for (k, track) in t.iter().enumerate() {
            let d = pass_offset(&p, k);
            for q in track {
                let edge = q.x.min(200.0 - q.x).min(q.y).min(100.0 - q.y);
                assert!(edge >= d - 0.05, "pass {k}: {q:?} at {edge} < {d}");
            }
            for w in track.windows(3) {
                let (a, b2, c) = (w[0], w[1], w[2]);
                let k3 = 2.0 * cross(&(b2 - a), &(c - b2)).abs()
                    / ((b2 - a).norm() * (c - b2).norm() * (c - a).norm()).max(1e-12);
                assert!(k3 <= 1.0 / p.r_min * 1.05 + 1e-6, "curvature {k3}");
            }
        }
        // Passes of 6 m at r_min 6 m: turns need 6 + 3 + 0.25 m → 2 passes, 12 m.
        assert_eq!(passes(&p), 2);
        let wa = working_area(&b, &[], &p);
        assert!((super::super::geometry::area_m2(&wa[0]) - 176.0 * 76.0).abs() < 1.0);
    }
}
