//! Plan metrics computed independently of the planner's bookkeeping, with the `geo` crate's
//! polygon boolean operations (i_overlay): implement footprints are unions of buffered
//! segments, clipped against the field, the working area and each other.
//!
//! Footprint of a polyline of width `w`: the polyline stroked `w` wide with butt caps (the
//! implement's edge is square to the path) and round joins, by `geo`'s buffer; all the
//! segments of one kind are stroked and merged in one sweep.

pub mod checks;

use super::{Field, FieldPlan, PlanSegment, SegmentKind};
use crate::geo::polygon::{contains_point, point_segment_distance};
use crate::geo::{cross, Vec2};
use geo::algorithm::buffer::{BufferStyle, LineCap, LineJoin};
use geo::{Area, BooleanOps, Buffer, Coord, LineString, MultiLineString, MultiPolygon, Polygon};
use serde::Serialize;

/// Angle step of the chords drawing a round join, rad (a 3 m join is short by < 0.2 mm).
const JOIN_ANGLE: f64 = 0.02;
/// Points closer than this are merged before building footprints, m.
const MERGE_M: f64 = 1e-6;

/// Metrics of one plan. Fractions are 0–1; lengths m; areas m².
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanMetrics {
    /// Area of the working area (inside the headland, minus obstacles), m².
    pub working_area_m2: f64,
    /// Area of the field (boundary minus obstacles), m².
    pub field_area_m2: f64,
    /// The whole field worked: union of the work, detour and headland footprints ∩ field, over
    /// the field area (boundary minus obstacles).
    pub covered_fraction: f64,
    /// Union of the work and detour footprints ∩ working area, over the working area.
    pub working_area_covered_fraction: f64,
    /// Field area no working footprint covers (field − work, detour and headland footprints),
    /// m².
    pub unworked_area_m2: f64,
    /// (Σ footprint areas of the working passes − area of their union) / area of the union,
    /// for work, detour and headland segments.
    pub overlap_fraction: f64,
    /// Footprint of every segment (all kinds) outside the field boundary, m².
    pub outside_area_m2: f64,
    /// Length of path (all kinds) outside the field boundary, m.
    pub outside_length_m: f64,
    /// Path points (all kinds) inside an obstacle inflated by `line_width/2`.
    pub obstacle_intrusions: usize,
    /// Length of path (all kinds) inside an obstacle, m.
    pub obstacle_length_m: f64,
    /// Footprint of the working passes (work, detour, headland) inside obstacles, m².
    pub obstacle_footprint_m2: f64,
    /// Largest three-point curvature over all segments, 1/m.
    pub max_curvature: f64,
    /// Largest three-point curvature of each segment, in plan order, 1/m.
    pub segment_max_curvature: Vec<f64>,
    /// Turn and transit points outside the field boundary or inside an obstacle.
    pub turn_points_outside: usize,
    pub work_length_m: f64,
    pub headland_length_m: f64,
    pub detour_length_m: f64,
    pub turn_length_m: f64,
    pub transit_length_m: f64,
    pub total_length_m: f64,
    /// Number of turn segments.
    pub turns: usize,
    /// Changes of driving direction between consecutive segments.
    pub reversals: usize,
}

fn coord(p: &Vec2) -> Coord<f64> {
    Coord { x: p.x, y: p.y }
}

/// A closed `geo` ring from an open CCW ring.
fn line_string(ring: &[Vec2]) -> LineString<f64> {
    let mut coords: Vec<Coord<f64>> = ring.iter().map(coord).collect();
    if let Some(first) = coords.first().copied() {
        coords.push(first);
    }
    LineString::new(coords)
}

/// A `geo` polygon from an outer ring and holes (local metres).
pub fn to_geo_polygon(outer: &[Vec2], holes: &[Vec<Vec2>]) -> Polygon<f64> {
    Polygon::new(
        line_string(outer),
        holes.iter().map(|h| line_string(h)).collect(),
    )
}

fn merged(points: &[Vec2]) -> Vec<Vec2> {
    let mut out: Vec<Vec2> = Vec::with_capacity(points.len());
    for p in points {
        if out.last().is_none_or(|q| (p - q).norm() > MERGE_M) {
            out.push(*p);
        }
    }
    out
}

/// Union of the footprints of `segments`, `width` wide: each polyline stroked on its own with
/// butt caps and round joins by `geo`'s buffer, then one union of them all. (Stroking all the
/// polylines in one buffer ran out of memory, an 8 GiB allocation in i_overlay 4.0.7's stroke,
/// on a plan whose passes and swaths lie on the axes:
/// `tests::footprints_of_a_plan_on_the_axes`; the union is as fast and agrees to 10⁻⁸.)
pub fn footprint<'a>(
    segments: impl IntoIterator<Item = &'a PlanSegment>,
    width: f64,
) -> MultiPolygon<f64> {
    worked_footprint(segments, width, None)
}

/// The sections of a plan's implement and the ground left to them ([`FieldPlan::sections`],
/// [`section_ground`]).
type Sectioned<'a> = Option<(usize, &'a MultiPolygon<f64>)>;

/// The union of the footprints of `segments`, `width` wide (each polyline stroked on its own).
fn worked_footprint<'a>(
    segments: impl IntoIterator<Item = &'a PlanSegment>,
    width: f64,
    sectioned: Sectioned<'_>,
) -> MultiPolygon<f64> {
    geo::algorithm::bool_ops::unary_union(&worked_strokes(segments, width, sectioned))
}

/// The ground `segments` work, `width` wide, as polygons that overlap only where two segments
/// work the same ground: each segment's whole footprint; for the swaths (`Work`) of a plan
/// made for n > 1 sections, the ground its sections work ([`section_strokes`]).
///
/// The union of the sectioned strokes and the headland passes' footprints is that of the
/// whole footprints (a section is off only where the ground under it is the passes'), so the
/// metrics take the ground worked from the whole footprints, whose union i_overlay 4 forms in
/// a second, and the sectioned strokes only for the sum of their areas (the overlap): united,
/// their many near-coincident long edges kept its fragment split busy for minutes on a large
/// field at w 3 m (bg_arable_60ha).
fn worked_strokes<'a>(
    segments: impl IntoIterator<Item = &'a PlanSegment>,
    width: f64,
    sectioned: Sectioned<'_>,
) -> Vec<Polygon<f64>> {
    let rings = sectioned
        .filter(|(n, _)| *n > 1)
        .map(|(n, on)| (n, Rings::of(on)));
    let mut strokes = Vec::new();
    for s in segments {
        let pts = merged(&s.points);
        if pts.len() < 2 {
            continue;
        }
        match &rings {
            Some((n, rings)) if s.kind == SegmentKind::Work => {
                strokes.extend(section_strokes(&pts, width, *n, rings))
            }
            _ => strokes.extend(stroke(&line(&pts), width)),
        }
    }
    strokes
}

/// Butt-capped, round-joined stroke of `line`, `width` wide.
fn stroke(line: &LineString<f64>, width: f64) -> Vec<Polygon<f64>> {
    let style = BufferStyle::new(0.5 * width)
        .line_cap(LineCap::Butt)
        .line_join(LineJoin::Round(JOIN_ANGLE));
    line.buffer_with_style(style).0
}

fn line(pts: &[Vec2]) -> LineString<f64> {
    LineString::new(pts.iter().map(coord).collect())
}

/// How far inside a section's edge its edge lines are taken, m ([`section_strokes`]): an edge
/// of a swath's outer section runs along the headland pass's footprint edge, where inside
/// and outside are a rounding apart.
const SECTION_EDGE_INSET_M: f64 = 0.01;

/// The ground a swath along `pts` works with `n` sections, each on where `rings` (the ground
/// left to the swaths, [`section_ground`]) holds any of it: its centre line or one of its edge
/// lines ([`SECTION_EDGE_INSET_M`] inside) is inside. A section switches off only once nothing
/// under it is left to work, so section control never leaves a sliver where an edge runs
/// slanted to the swaths, and lays at most a section's width twice. A straight swath whose
/// sections are each on over one stretch overlapping its neighbours' is one staircase polygon
/// (stroked apart, the sections' long shared edges made the union of a large field's strips
/// take minutes); else each section's stretches are stroked; a curved swath's sections by
/// their centre lines alone.
fn section_strokes(pts: &[Vec2], width: f64, n: usize, rings: &Rings) -> Vec<Polygon<f64>> {
    let w = width / n as f64;
    let lateral = |k: usize| (k as f64 + 0.5) * w - 0.5 * width;
    let (a, b) = (pts[0], pts[pts.len() - 1]);
    let t = (b - a) / (b - a).norm().max(1e-12);
    let straight = pts.iter().all(|q| cross(&t, &(q - a)).abs() < 1e-6);
    if !straight {
        return (0..n)
            .flat_map(|k| rings.inside_pieces(&offset_polyline(pts, lateral(k))))
            .flat_map(|piece| stroke(&line(&piece), w))
            .collect();
    }
    let normal = crate::geo::v2(-t.y, t.x);
    let at = |x: f64, l: f64| a + t * x + normal * l;
    let length = (b - a).dot(&t);
    let edge = 0.5 * w - SECTION_EDGE_INSET_M.min(0.25 * w);
    // Each section's stretches along the swath (from `a`), merged.
    let stretches: Vec<Vec<(f64, f64)>> = (0..n)
        .map(|k| {
            let mut s: Vec<(f64, f64)> = [-edge, 0.0, edge]
                .iter()
                .flat_map(|d| {
                    let l = lateral(k) + d;
                    rings.inside_pieces(&[at(0.0, l), at(length, l)])
                })
                .map(|p| ((p[0] - a).dot(&t), (p[p.len() - 1] - a).dot(&t)))
                .collect();
            s.sort_by(|x, y| x.0.total_cmp(&y.0));
            let mut merged: Vec<(f64, f64)> = Vec::with_capacity(s.len());
            for iv in s {
                match merged.last_mut() {
                    Some(m) if iv.0 <= m.1 => m.1 = m.1.max(iv.1),
                    _ => merged.push(iv),
                }
            }
            merged
        })
        .collect();
    let one_each = stretches.iter().all(|s| s.len() == 1);
    if one_each
        && stretches
            .windows(2)
            .all(|s| s[0][0].0 < s[1][0].1 && s[1][0].0 < s[0][0].1)
    {
        // Up the far ends (right to left), back down the near ends.
        let mut ring: Vec<Vec2> = (0..n)
            .flat_map(|k| {
                let x = stretches[k][0].1;
                [at(x, lateral(k) - 0.5 * w), at(x, lateral(k) + 0.5 * w)]
            })
            .collect();
        ring.extend((0..n).rev().flat_map(|k| {
            let x = stretches[k][0].0;
            [at(x, lateral(k) + 0.5 * w), at(x, lateral(k) - 0.5 * w)]
        }));
        // Without the repeated corners where neighbouring sections end level.
        ring.dedup_by(|q, p| (*q - *p).norm() < 1e-9);
        let mut corners: Vec<Vec2> = Vec::with_capacity(ring.len());
        for (i, q) in ring.iter().enumerate() {
            let (p, r) = (
                ring[(i + ring.len() - 1) % ring.len()],
                ring[(i + 1) % ring.len()],
            );
            if cross(&(q - p), &(r - q)).abs() > 1e-9 {
                corners.push(*q);
            }
        }
        return vec![to_geo_polygon(&corners, &[])];
    }
    (0..n)
        .flat_map(|k| stretches[k].iter().map(move |&(x0, x1)| (k, x0, x1)))
        .flat_map(|(k, x0, x1)| stroke(&line(&[at(x0, lateral(k)), at(x1, lateral(k))]), w))
        .collect()
}

/// The rings of a multipolygon with their edges' bounding boxes, to cut polylines at them.
struct Rings {
    /// (exterior, holes) of each polygon, closed (first point repeated last).
    polygons: Vec<(Vec<Vec2>, Vec<Vec<Vec2>>)>,
    /// Every ring edge: (start, end, bounding-box min, bounding-box max).
    edges: Vec<(Vec2, Vec2, Vec2, Vec2)>,
}

impl Rings {
    fn of(area: &MultiPolygon<f64>) -> Self {
        let ring = |l: &LineString<f64>| -> Vec<Vec2> {
            l.0.iter().map(|c| crate::geo::v2(c.x, c.y)).collect()
        };
        let polygons: Vec<(Vec<Vec2>, Vec<Vec<Vec2>>)> = area
            .0
            .iter()
            .map(|p| (ring(p.exterior()), p.interiors().iter().map(ring).collect()))
            .collect();
        let edges = polygons
            .iter()
            .flat_map(|(e, hs)| std::iter::once(e).chain(hs.iter()))
            .flat_map(|r| {
                r.windows(2)
                    .map(|w| (w[0], w[1], w[0].inf(&w[1]), w[0].sup(&w[1])))
            })
            .collect();
        Rings { polygons, edges }
    }

    fn contains(&self, q: &Vec2) -> bool {
        self.polygons
            .iter()
            .any(|(e, hs)| contains_point(e, q) && !hs.iter().any(|h| contains_point(h, q)))
    }

    /// The pieces of the polyline `line` inside the area: the line is cut where it crosses a
    /// ring (chord by chord, edges whose bounding box misses the chord's skipped) and each
    /// piece kept if its middle is inside. Collinear points are dropped first (a straight swath
    /// is one chord).
    fn inside_pieces(&self, line: &[Vec2]) -> Vec<Vec<Vec2>> {
        let mut pts: Vec<Vec2> = Vec::with_capacity(line.len());
        for &q in line {
            if let [.., a, b] = pts[..] {
                if cross(&(b - a), &(q - b)).abs() <= 1e-9 * (b - a).norm() * (q - b).norm() {
                    pts.pop();
                }
            }
            pts.push(q);
        }
        if pts.len() < 2 {
            return Vec::new();
        }
        // Cuts as chord index + fraction along it.
        let mut cuts = vec![0.0, (pts.len() - 1) as f64];
        for (i, w) in pts.windows(2).enumerate() {
            let (a, b) = (w[0], w[1]);
            let (lo, hi) = (a.inf(&b), a.sup(&b));
            let r = b - a;
            for (c, d, elo, ehi) in &self.edges {
                if elo.x > hi.x || ehi.x < lo.x || elo.y > hi.y || ehi.y < lo.y {
                    continue;
                }
                let s = d - c;
                let denom = cross(&r, &s);
                if denom.abs() < 1e-15 {
                    continue;
                }
                let t = cross(&(c - a), &s) / denom;
                let u = cross(&(c - a), &r) / denom;
                if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u) {
                    cuts.push(i as f64 + t);
                }
            }
        }
        cuts.sort_by(f64::total_cmp);
        let at = |s: f64| {
            let i = (s.floor() as usize).min(pts.len() - 2);
            pts[i] + (pts[i + 1] - pts[i]) * (s - i as f64)
        };
        cuts.windows(2)
            .filter(|c| c[1] - c[0] > 1e-12 && self.contains(&at(0.5 * (c[0] + c[1]))))
            .map(|c| {
                let mut piece = vec![at(c[0])];
                let first = c[0].floor() as usize + 1;
                piece.extend(
                    (first..pts.len())
                        .take_while(|&k| (k as f64) < c[1])
                        .map(|k| pts[k]),
                );
                piece.push(at(c[1]));
                piece
            })
            .collect()
    }
}

/// The ground left to a plan's swath sections, `None` for a plan without sections
/// ([`FieldPlan::sections`]): the field less the headland passes' footprints.
fn section_ground(field: &Field, plan: &FieldPlan, line_width: f64) -> Option<MultiPolygon<f64>> {
    (plan.sections > 1).then(|| {
        let headland = plan
            .segments
            .iter()
            .filter(|s| s.kind == SegmentKind::Headland);
        field_polygon(field).difference(&footprint(headland, line_width))
    })
}

/// `pts` moved `d` to the left of the direction of travel (each point along the normal of the
/// chord through its neighbours), m.
fn offset_polyline(pts: &[Vec2], d: f64) -> Vec<Vec2> {
    let n = pts.len();
    (0..n)
        .map(|i| {
            let t = pts[(i + 1).min(n - 1)] - pts[i.saturating_sub(1)];
            let t = t / t.norm().max(1e-12);
            pts[i] + crate::geo::v2(-t.y, t.x) * d
        })
        .collect()
}

/// Three-point curvature at `b`: 1/radius of the circle through `a`, `b`, `c`, 1/m.
pub fn three_point_curvature(a: &Vec2, b: &Vec2, c: &Vec2) -> f64 {
    let (ab, bc, ca) = ((b - a).norm(), (c - b).norm(), (a - c).norm());
    let denom = ab * bc * ca;
    if denom <= 0.0 {
        return 0.0;
    }
    (2.0 * cross(&(b - a), &(c - b)) / denom).abs()
}

fn max_curvature(points: &[Vec2]) -> f64 {
    merged(points)
        .windows(3)
        .map(|w| three_point_curvature(&w[0], &w[1], &w[2]))
        .fold(0.0, f64::max)
}

fn inside_inflated(p: &Vec2, obstacle: &[Vec2], margin: f64) -> bool {
    if contains_point(obstacle, p) {
        return true;
    }
    let n = obstacle.len();
    (0..n).any(|i| point_segment_distance(p, &obstacle[i], &obstacle[(i + 1) % n]) < margin)
}

/// All metrics of `plan` for `field` with implement width `line_width` (m).
pub fn plan_metrics(field: &Field, plan: &FieldPlan, line_width: f64) -> PlanMetrics {
    use SegmentKind::*;
    let field_poly = MultiPolygon::new(vec![to_geo_polygon(&field.boundary, &field.obstacles)]);
    let boundary_poly = MultiPolygon::new(vec![to_geo_polygon(&field.boundary, &[])]);
    let obstacles = obstacle_polygons(field);
    let working = working_polygon(plan, &obstacles);
    let on_ground = section_ground(field, plan, line_width);
    let sectioned = on_ground.as_ref().map(|g| (plan.sections, g));
    let working_area_m2 = working.unsigned_area();
    let field_area_m2 = field_poly.unsigned_area();

    fn of<'a>(
        plan: &'a FieldPlan,
        kinds: &'a [SegmentKind],
    ) -> impl Iterator<Item = &'a PlanSegment> + 'a {
        plan.segments
            .iter()
            .filter(move |s| kinds.contains(&s.kind))
    }
    // The whole footprints for the ground worked (see `worked_strokes`).
    let work_strokes = worked_strokes(of(plan, &[Work, Detour]), line_width, None);
    let mut passes_strokes = worked_strokes(of(plan, &[Headland]), line_width, None);
    passes_strokes.extend(work_strokes.iter().cloned());
    let union = |p: &[Polygon<f64>]| geo::algorithm::bool_ops::unary_union(p);
    let (work_fp, passes_fp) = (union(&work_strokes), union(&passes_strokes));
    let all_fp = footprint(plan.segments.iter(), line_width);

    let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
    let working_area_covered_fraction = ratio(
        work_fp.intersection(&working).unsigned_area(),
        working_area_m2,
    );
    let worked_m2 = passes_fp.intersection(&field_poly).unsigned_area();
    let covered_fraction = ratio(worked_m2, field_area_m2);
    let unworked_area_m2 = (field_area_m2 - worked_m2).max(0.0);
    let obstacle_footprint_m2 = passes_fp.intersection(&obstacles).unsigned_area();
    let paths = MultiLineString::new(
        plan.segments
            .iter()
            .map(|s| merged(&s.points))
            .filter(|pts| pts.len() >= 2)
            .map(|pts| LineString::new(pts.iter().map(coord).collect()))
            .collect(),
    );
    let length = |m: &MultiLineString<f64>| -> f64 {
        use geo::{Euclidean, Length};
        m.0.iter()
            .map(|l| Euclidean.length(l))
            .fold(0.0, |a, b| a + b)
    };
    let outside_length_m = length(&boundary_poly.clip(&paths, true));
    let obstacle_length_m = length(&obstacles.clip(&paths, false));
    // (Strokes overlap only where two segments work the same ground.) With sections, each
    // swath counts the ground its sections work.
    let sectioned_strokes = sectioned.map(|_| {
        let mut strokes = worked_strokes(of(plan, &[Work, Detour]), line_width, sectioned);
        strokes.extend(worked_strokes(of(plan, &[Headland]), line_width, None));
        strokes
    });
    let sum_single: f64 = sectioned_strokes
        .as_ref()
        .unwrap_or(&passes_strokes)
        .iter()
        .map(|p| p.unsigned_area())
        .fold(0.0, |a, b| a + b);
    let union_area = passes_fp.unsigned_area();
    let overlap_fraction = ratio((sum_single - union_area).max(0.0), union_area);
    let outside_area_m2 = all_fp.difference(&boundary_poly).unsigned_area();

    let mut obstacle_intrusions = 0;
    let mut turn_points_outside = 0;
    for s in &plan.segments {
        for p in &s.points {
            if field
                .obstacles
                .iter()
                .any(|o| inside_inflated(p, o, 0.5 * line_width))
            {
                obstacle_intrusions += 1;
            }
            if matches!(s.kind, Turn | Transit)
                && (!contains_point(&field.boundary, p)
                    || field.obstacles.iter().any(|o| contains_point(o, p)))
            {
                turn_points_outside += 1;
            }
        }
    }
    let segment_max_curvature: Vec<f64> = plan
        .segments
        .iter()
        .map(|s| max_curvature(&s.points))
        .collect();
    let len_of = |k: SegmentKind| -> f64 {
        plan.segments
            .iter()
            .filter(|s| s.kind == k)
            .map(|s| crate::geo::polygon::polyline_length(&s.points))
            .fold(0.0, |a, b| a + b)
    };
    let reversals = plan
        .segments
        .windows(2)
        .filter(|w| w[0].direction != w[1].direction)
        .count();
    let (work_length_m, headland_length_m, detour_length_m) =
        (len_of(Work), len_of(Headland), len_of(Detour));
    let (turn_length_m, transit_length_m) = (len_of(Turn), len_of(Transit));
    PlanMetrics {
        working_area_m2,
        field_area_m2,
        covered_fraction,
        working_area_covered_fraction,
        unworked_area_m2,
        overlap_fraction,
        outside_area_m2,
        outside_length_m,
        obstacle_intrusions,
        obstacle_length_m,
        obstacle_footprint_m2,
        max_curvature: segment_max_curvature.iter().copied().fold(0.0, f64::max),
        segment_max_curvature,
        turn_points_outside,
        work_length_m,
        headland_length_m,
        detour_length_m,
        turn_length_m,
        transit_length_m,
        total_length_m: work_length_m
            + headland_length_m
            + detour_length_m
            + turn_length_m
            + transit_length_m,
        turns: plan.segments.iter().filter(|s| s.kind == Turn).count(),
        reversals,
    }
}

/// The field (boundary minus obstacles) as a `geo` multipolygon.
pub fn field_polygon(field: &Field) -> MultiPolygon<f64> {
    MultiPolygon::new(vec![to_geo_polygon(&field.boundary, &field.obstacles)])
}

/// The field's obstacles as one multipolygon.
fn obstacle_polygons(field: &Field) -> MultiPolygon<f64> {
    MultiPolygon::new(
        field
            .obstacles
            .iter()
            .map(|o| to_geo_polygon(o, &[]))
            .collect(),
    )
}

/// The plan's working area without the field's obstacles (removed whatever the planner
/// reported).
fn working_polygon(plan: &FieldPlan, obstacles: &MultiPolygon<f64>) -> MultiPolygon<f64> {
    MultiPolygon::new(
        plan.working_area
            .iter()
            .map(|(outer, holes)| to_geo_polygon(outer, holes))
            .collect(),
    )
    .difference(obstacles)
}

/// Ground of the field that no working footprint (work, detour, headland) covers (with
/// sections too: see `worked_strokes`).
pub fn unworked_ground(field: &Field, plan: &FieldPlan, line_width: f64) -> MultiPolygon<f64> {
    use SegmentKind::*;
    let passes = plan
        .segments
        .iter()
        .filter(|s| matches!(s.kind, Work | Detour | Headland));
    field_polygon(field).difference(&footprint(passes, line_width))
}

/// Ground the implement cannot reach driving forward and turning no tighter than `r_min`:
/// the field minus its opening by `r_min + line_width/2` (the union of every disc of that
/// radius inside the field). A pass rounding a convex corner on an arc of radius `r_min`
/// sweeps exactly such a disc's edge with the outer edge of its footprint, so what lies
/// outside every such disc (sharp corners, necks narrower than the disc) is left to hand work
/// or to reversing manoeuvres.
pub fn unreachable_ground(field: &Field, line_width: f64, r_min: f64) -> MultiPolygon<f64> {
    let radius = r_min + 0.5 * line_width;
    let f = field_polygon(field);
    let style = |d: f64| BufferStyle::new(d).line_join(LineJoin::Round(JOIN_ANGLE));
    let opened = f
        .buffer_with_style(style(-radius))
        .buffer_with_style(style(radius));
    f.difference(&opened)
}

/// Area (m²) and number of pieces of at least `min_piece_m2` of a multipolygon.
pub fn area_and_pieces(mp: &MultiPolygon<f64>, min_piece_m2: f64) -> (f64, usize) {
    let area = mp.unsigned_area();
    let pieces =
        mp.0.iter()
            .filter(|p| p.unsigned_area() >= min_piece_m2)
            .count();
    (area, pieces)
}

#[cfg(test)]
mod tests;
