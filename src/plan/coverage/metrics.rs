//! Plan metrics computed independently of the planner's bookkeeping, with the `geo` crate's
//! polygon boolean operations (i_overlay): implement footprints are unions of buffered
//! segments, clipped against the field, the working area and each other.
//!
//! Footprint of a polyline of width `w`: the polyline stroked `w` wide with butt caps (the
//! implement's edge is square to the path) and round joins, by `geo`'s buffer; all the
//! segments of one kind are stroked and merged in one sweep.

pub mod checks;

use super::{Field, FieldPlan, PlanSegment, SegmentKind};
use crate::geo::polygon::{bbox, contains_point, point_segment_distance, segment_distance};
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
    geo::algorithm::bool_ops::unary_union(&strokes(segments, width))
}

/// Each segment's footprint, `width` wide, as polygons that overlap only where two segments
/// work the same ground (one buffer per polyline; see [`footprint`]).
fn strokes<'a>(
    segments: impl IntoIterator<Item = &'a PlanSegment>,
    width: f64,
) -> Vec<Polygon<f64>> {
    segments
        .into_iter()
        .map(|s| merged(&s.points))
        .filter(|pts| pts.len() >= 2)
        .flat_map(|pts| stroke(&pts, width))
        .collect()
}

/// Butt-capped, round-joined stroke of the polyline `pts`, `width` wide.
fn stroke(pts: &[Vec2], width: f64) -> Vec<Polygon<f64>> {
    let style = BufferStyle::new(0.5 * width)
        .line_cap(LineCap::Butt)
        .line_join(LineJoin::Round(JOIN_ANGLE));
    LineString::new(pts.iter().map(coord).collect())
        .buffer_with_style(style)
        .0
}

/// How far inside a section's edge its edge lines are taken, m ([`sections_area`]): an edge
/// of a swath's outer section runs along the headland pass's footprint edge, where inside
/// and outside are a rounding apart.
const SECTION_EDGE_INSET_M: f64 = 0.01;

/// `n` equal sections across an implement `width` wide: each one's width, m; the lateral
/// offset of section k's centre (left of the implement's centre positive), m; and the offsets
/// from a section's centre of the lines whose ground tells whether it is on: its edges
/// [`SECTION_EDGE_INSET_M`] inside, and its centre, m.
fn section_layout(width: f64, n: usize) -> (f64, impl Fn(usize) -> f64, [f64; 3]) {
    let w = width / n as f64;
    let edge = 0.5 * w - SECTION_EDGE_INSET_M.min(0.25 * w);
    let lateral = move |k: usize| (k as f64 + 0.5) * w - 0.5 * width;
    (w, lateral, [-edge, 0.0, edge])
}

/// The area, m², that the swaths and detours (`Work`, `Detour`, in driving order) of a plan
/// made for n > 1 sections work, as a section controller with a coverage map switches them:
/// each section on where ground left to work lies under it (its centre line or one of its
/// edge lines, [`SECTION_EDGE_INSET_M`] inside, over it). Left to work: `ground` (the field
/// less the headland passes' footprints) less the footprints of the swaths and detours driven
/// before. A section switches off only once nothing under it is left to work, so section
/// control never leaves a sliver where an edge runs slanted to the swaths, and lays at most a
/// section's width twice. Each straight swath's sections are found on scan lines in the
/// swath's frame (`geometry::scan_intervals`, the ground turned once per swath direction);
/// a curved path (a detour round an obstacle) is sampled along its length
/// ([`curved_sections`]).
///
/// The ground so worked, united with the headland passes' footprints, is that of the whole
/// footprints (a section is off only over ground worked by the passes or before), so
/// [`plan_metrics`] takes the ground worked from the whole footprints and this area only for
/// the overlap: united, the sections' many near-coincident long edges kept i_overlay 4's
/// fragment split busy for minutes on a large field at w 3 m (bg_arable_60ha).
fn sections_area<'a>(
    swaths: impl IntoIterator<Item = &'a PlanSegment>,
    width: f64,
    n: usize,
    ground: &MultiPolygon<f64>,
) -> f64 {
    use super::geometry::{from_geo, in_area, rotate, rotate_area, scan_intervals, Area};
    let ground = from_geo(ground);
    // The ground turned into each swath direction met so far (swaths of a cell share one).
    let mut turned: Vec<(f64, Vec<Area>)> = Vec::new();
    let (w, lateral, probes) = section_layout(width, n);
    let (mut out, mut curved) = (Vec::new(), 0.0);
    // The whole footprints of the swaths and detours driven so far, in driving order, with
    // their bounding boxes.
    // (A straight swath also with its centre line: two swaths' footprints meet only where
    // their centre lines come closer than w, which neighbours w apart do not.)
    type Done = (Area, (Vec2, Vec2), Option<(Vec2, Vec2)>);
    let mut done: Vec<Done> = Vec::new();
    let meets = |(lo, hi): &(Vec2, Vec2), (a, b): &(Vec2, Vec2)| {
        lo.x <= b.x && a.x <= hi.x && lo.y <= b.y && a.y <= hi.y
    };
    for s in swaths {
        let pts = merged(&s.points);
        if pts.len() < 2 {
            continue;
        }
        let (a, b) = (pts[0], pts[pts.len() - 1]);
        let t = (b - a) / (b - a).norm().max(1e-12);
        if pts.iter().any(|q| cross(&t, &(q - a)).abs() >= 1e-6) {
            // A curved path (a detour round an obstacle): its sections sampled along it.
            let stroked = from_geo(&MultiPolygon::new(stroke(&pts, width)));
            let bounds = bbox(stroked.iter().flat_map(|g| g.0.iter())).unwrap_or((a, b));
            let before: Vec<&Area> = done
                .iter()
                .filter(|(_, bb, _)| meets(bb, &bounds))
                .map(|(g, _, _)| g)
                .collect();
            let whole: f64 = stroked.iter().map(super::geometry::area_m2).sum();
            curved += (whole
                - curved_sections(&pts, width, n, &|q| {
                    ground.iter().any(|g| in_area(g, q)) && !before.iter().any(|g| in_area(g, q))
                }))
            .max(0.0);
            done.extend(stroked.into_iter().map(|g| {
                let bb = bbox(g.0.iter()).unwrap_or((a, b));
                (g, bb, None)
            }));
            continue;
        }
        let angle = t.y.atan2(t.x);
        let i = match turned.iter().position(|(g, _)| (g - angle).abs() < 1e-12) {
            Some(i) => i,
            None => {
                let areas = ground.iter().map(|g| rotate_area(g, -angle)).collect();
                turned.push((angle, areas));
                turned.len() - 1
            }
        };
        let areas = &turned[i].1;
        let at = |x: f64, l: f64| a + t * x + crate::geo::v2(-t.y, t.x) * l;
        // The swath in its frame: from (x0, y) along +x for `length`; left is +y.
        let (start, length) = (rotate(&a, -angle), (b - a).dot(&t));
        let corners = vec![
            at(0.0, -0.5 * width),
            at(length, -0.5 * width),
            at(length, 0.5 * width),
            at(0.0, 0.5 * width),
        ];
        let bounds = bbox(corners.iter()).unwrap_or((a, b));
        // What was worked before that may lie under this swath, in its frame.
        let before: Vec<Area> = done
            .iter()
            .filter(|(_, bb, centre)| {
                meets(bb, &bounds)
                    && centre.is_none_or(|(c0, c1)| segment_distance(a, b, c0, c1).0 < width)
            })
            .map(|(g, _, _)| rotate_area(g, -angle))
            .collect();
        let stretches: Vec<Vec<(f64, f64)>> = (0..n)
            .map(|k| {
                let lines = probes.map(|d| start.y + lateral(k) + d);
                let left_on = |y: f64| {
                    let left = areas.iter().flat_map(|g| scan_intervals(g, y)).collect();
                    let worked = before.iter().flat_map(|g| scan_intervals(g, y)).collect();
                    without(
                        super::swaths::merge_overlapping(left),
                        &super::swaths::merge_overlapping(worked),
                    )
                };
                super::swaths::merge_overlapping(
                    lines
                        .iter()
                        .flat_map(|&y| left_on(y))
                        .map(|(x0, x1)| (x0 - start.x).max(0.0)..(x1 - start.x).min(length))
                        .filter(|r| r.end > r.start)
                        .map(|r| (r.start, r.end))
                        .collect(),
                )
            })
            .collect();
        out.extend(sections_polygons(&stretches, w, &lateral, &at));
        done.push(((corners, Vec::new()), bounds, Some((a, b))));
    }
    out.iter().map(|q| q.unsigned_area()).sum::<f64>() + curved
}

/// Spacing of the samples along a curved path whose sections are found one sample at a time,
/// m ([`curved_sections`]).
const CURVED_SAMPLE_M: f64 = 0.2;

/// The area `n` sections of an implement `width` wide leave unworked along the curved
/// polyline `pts` because they are off, m²: sampled every [`CURVED_SAMPLE_M`], a section is on
/// from one sample to the next where its centre or an edge point ([`SECTION_EDGE_INSET_M`]
/// inside) is `left` at either sample, else off over the quadrilateral between the two
/// samples' cross-sections. (The path's footprint less this is the ground its sections work:
/// quadrilaterals summed would count twice what a tight bend's inner side sweeps twice.)
fn curved_sections(pts: &[Vec2], width: f64, n: usize, left: &dyn Fn(&Vec2) -> bool) -> f64 {
    let (w, lateral, probes) = section_layout(width, n);
    // Samples (point, left normal) along the path.
    let mut samples: Vec<(Vec2, Vec2)> = Vec::new();
    for seg in pts.windows(2) {
        let d = seg[1] - seg[0];
        let len = d.norm();
        if len <= 1e-9 {
            continue;
        }
        let normal = crate::geo::v2(-d.y, d.x) / len;
        let steps = (len / CURVED_SAMPLE_M).ceil() as usize;
        samples.extend((0..steps).map(|i| (seg[0] + d * (i as f64 / steps as f64), normal)));
    }
    if let (Some(last), Some(&(_, normal))) = (pts.last(), samples.last()) {
        samples.push((*last, normal));
    }
    let on_at = |(q, normal): &(Vec2, Vec2), k: usize| {
        probes
            .iter()
            .any(|d| left(&(q + normal * (lateral(k) + d))))
    };
    let mut area = 0.0;
    let mut on = vec![false; samples.len()];
    for k in 0..n {
        for (o, s) in on.iter_mut().zip(&samples) {
            *o = on_at(s, k);
        }
        for (i, pair) in samples.windows(2).enumerate() {
            if on[i] || on[i + 1] {
                continue;
            }
            let side = |(q, normal): &(Vec2, Vec2), l: f64| q + normal * (lateral(k) + l);
            let quad = [
                side(&pair[0], -0.5 * w),
                side(&pair[1], -0.5 * w),
                side(&pair[1], 0.5 * w),
                side(&pair[0], 0.5 * w),
            ];
            // (Not where the section's edge moves backward, inside a bend tighter than its
            // offset: the footprint there is not the quadrilateral.)
            let ahead = pair[1].0 - pair[0].0;
            if (quad[1] - quad[0]).dot(&ahead) > 0.0 && (quad[2] - quad[3]).dot(&ahead) > 0.0 {
                area += crate::geo::polygon::signed_area(&quad).abs();
            }
        }
    }
    area
}

/// The headland passes (in driving order) of a plan made for n > 1 sections, the area their
/// sections work, m²: each pass's sections switch off over what the passes before it worked
/// (within w/2 of their centre lines, butt ends), found through a grid of their segments.
fn headland_sections_area<'a>(
    passes: impl IntoIterator<Item = &'a PlanSegment>,
    width: f64,
    n: usize,
) -> f64 {
    let cell = width.max(1e-3);
    let key = |q: &Vec2| ((q.x / cell).floor() as i64, (q.y / cell).floor() as i64);
    // Segments of the passes before, by grid cell: (a, b, first of its pass, last of it).
    type Segment = (Vec2, Vec2, bool, bool);
    let mut grid: std::collections::HashMap<(i64, i64), Vec<Segment>> =
        std::collections::HashMap::new();
    let half = 0.5 * width;
    let mut area = 0.0;
    for s in passes {
        let pts = merged(&s.points);
        if pts.len() < 2 {
            continue;
        }
        let worked_before = |q: &Vec2| {
            let (i, j) = key(q);
            (i - 1..=i + 1)
                .flat_map(|x| (j - 1..=j + 1).map(move |y| (x, y)))
                .any(|c| {
                    grid.get(&c).is_some_and(|segs| {
                        segs.iter().any(|&(a, b, first, last)| {
                            let d = b - a;
                            let t = (q - a).dot(&d) / d.norm_squared().max(1e-12);
                            !((first && t < 0.0) || (last && t > 1.0))
                                && point_segment_distance(q, &a, &b) <= half
                        })
                    })
                })
        };
        let whole: f64 = stroke(&pts, width).iter().map(|q| q.unsigned_area()).sum();
        area += (whole - curved_sections(&pts, width, n, &|q| !worked_before(q))).max(0.0);
        let closed = (pts[0] - pts[pts.len() - 1]).norm() < 1e-6;
        let m = pts.len() - 1;
        for (i, seg) in pts.windows(2).enumerate() {
            let (first, last) = (!closed && i == 0, !closed && i + 1 == m);
            // In every cell that the bounding box of a piece of it, a cell long at most, meets
            // (a long diagonal segment's own box would span a square of cells).
            let d = seg[1] - seg[0];
            let pieces = (d.norm() / cell).ceil().max(1.0) as usize;
            let mut cells: Vec<(i64, i64)> = (0..pieces)
                .flat_map(|k| {
                    let a = key(&(seg[0] + d * (k as f64 / pieces as f64)));
                    let b = key(&(seg[0] + d * ((k + 1) as f64 / pieces as f64)));
                    (a.0.min(b.0)..=a.0.max(b.0))
                        .flat_map(move |x| (a.1.min(b.1)..=a.1.max(b.1)).map(move |y| (x, y)))
                })
                .collect();
            cells.sort_unstable();
            cells.dedup();
            for c in cells {
                grid.entry(c)
                    .or_default()
                    .push((seg[0], seg[1], first, last));
            }
        }
    }
    area
}

/// The parts of the sorted, disjoint intervals `from` outside the sorted, disjoint intervals
/// `cut`.
fn without(from: Vec<(f64, f64)>, cut: &[(f64, f64)]) -> Vec<(f64, f64)> {
    if cut.is_empty() {
        return from;
    }
    let mut out = Vec::with_capacity(from.len());
    for (mut x0, x1) in from {
        for &(c0, c1) in cut {
            if c1 <= x0 || c0 >= x1 {
                continue;
            }
            if c0 > x0 {
                out.push((x0, c0));
            }
            x0 = x0.max(c1);
        }
        if x1 > x0 {
            out.push((x0, x1));
        }
    }
    out
}

/// The polygons of one straight swath's sections, each on over its `stretches` (along the
/// swath, m): one staircase polygon when each section is on over one stretch overlapping its
/// neighbours' (stroked apart, the sections' long shared edges made a large field's union
/// take minutes), else a rectangle per stretch. `at(x, l)`: the point x along the swath and l
/// to its left.
fn sections_polygons(
    stretches: &[Vec<(f64, f64)>],
    w: f64,
    lateral: &dyn Fn(usize) -> f64,
    at: &dyn Fn(f64, f64) -> Vec2,
) -> Vec<Polygon<f64>> {
    let n = stretches.len();
    let rectangle = |k: usize, (x0, x1): (f64, f64)| {
        let (lo, hi) = (lateral(k) - 0.5 * w, lateral(k) + 0.5 * w);
        to_geo_polygon(&[at(x0, lo), at(x1, lo), at(x1, hi), at(x0, hi)], &[])
    };
    let staircase = stretches.iter().all(|s| s.len() == 1)
        && stretches
            .windows(2)
            .all(|s| s[0][0].0 < s[1][0].1 && s[1][0].0 < s[0][0].1);
    if !staircase {
        return (0..n)
            .flat_map(|k| stretches[k].iter().map(move |&iv| (k, iv)))
            .map(|(k, iv)| rectangle(k, iv))
            .collect();
    }
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
    let corners: Vec<Vec2> = (0..ring.len())
        .filter(|&i| {
            let (p, q, r) = (
                ring[(i + ring.len() - 1) % ring.len()],
                ring[i],
                ring[(i + 1) % ring.len()],
            );
            cross(&(q - p), &(r - q)).abs() > 1e-9
        })
        .map(|i| ring[i])
        .collect();
    vec![to_geo_polygon(&corners, &[])]
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

/// [`three_point_curvature`] at point `k` of the closed ring `open` (its points, the first not
/// repeated), with its neighbours round the ring, 1/m.
pub fn ring_curvature(open: &[Vec2], k: usize) -> f64 {
    let m = open.len();
    three_point_curvature(&open[(k + m - 1) % m], &open[k % m], &open[(k + 1) % m])
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
    let working = MultiPolygon::new(
        plan.working_area
            .iter()
            .map(|(outer, holes)| to_geo_polygon(outer, holes))
            .collect(),
    );
    // Obstacles are removed from the working area too, whatever the planner reported.
    let obstacles = MultiPolygon::new(
        field
            .obstacles
            .iter()
            .map(|o| to_geo_polygon(o, &[]))
            .collect(),
    );
    let working = working.difference(&obstacles);
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
    let union = |p: &[Polygon<f64>]| geo::algorithm::bool_ops::unary_union(p);
    let headland_strokes = strokes(of(plan, &[Headland]), line_width);
    let work_strokes = strokes(of(plan, &[Work, Detour]), line_width);
    let work_fp = union(&work_strokes);
    let passes_fp = union(&[headland_strokes.as_slice(), work_strokes.as_slice()].concat());
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
    // (Strokes overlap only where two segments work the same ground.) With sections, a swath
    // counts the ground its sections work (`sections_area`: the ground worked is the same).
    let area_of = |p: &[Polygon<f64>]| p.iter().map(|q| q.unsigned_area()).fold(0.0, |a, b| a + b);
    let sum_single = if plan.sections > 1 {
        let left = field_poly.difference(&union(&headland_strokes));
        let n = plan.sections;
        sections_area(of(plan, &[Work, Detour]), line_width, n, &left)
            + headland_sections_area(of(plan, &[Headland]), line_width, n)
    } else {
        area_of(&headland_strokes) + area_of(&work_strokes)
    };
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

/// Ground of the field that no working footprint (work, detour, headland) covers (with
/// sections too: see [`sections_area`]).
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
