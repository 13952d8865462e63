//! Geometry helpers shared by the coverage stages: conversion to and from the `geo` crate's
//! polygons (used for offsetting), rotation into the swath frame and scan-line intersection.

use crate::geo::polygon::signed_area;
use crate::geo::{v2, Vec2};
use geo::algorithm::buffer::{BufferStyle, LineJoin};
use geo::{Buffer, Coord, LineString, MultiPolygon, Polygon};

/// A polygon with holes in the local frame: (outer ring CCW, holes CCW), not closed.
pub type Area = (Vec<Vec2>, Vec<Vec<Vec2>>);

fn ring_to_geo(ring: &[Vec2]) -> LineString<f64> {
    let mut c: Vec<Coord<f64>> = ring.iter().map(|p| Coord { x: p.x, y: p.y }).collect();
    if let Some(f) = c.first().copied() {
        c.push(f);
    }
    LineString::new(c)
}

fn ring_from_geo(ls: &LineString<f64>) -> Vec<Vec2> {
    let mut r: Vec<Vec2> = ls.0.iter().map(|c| v2(c.x, c.y)).collect();
    if r.len() > 1 && r.first() == r.last() {
        r.pop();
    }
    if signed_area(&r) < 0.0 {
        r.reverse();
    }
    r
}

/// The `geo` polygon of an area.
pub fn to_geo(area: &Area) -> Polygon<f64> {
    Polygon::new(
        ring_to_geo(&area.0),
        area.1.iter().map(|h| ring_to_geo(h)).collect(),
    )
}

/// The areas of a `geo` multipolygon, every ring counter-clockwise.
pub fn from_geo(mp: &MultiPolygon<f64>) -> Vec<Area> {
    mp.0.iter()
        .map(|p| {
            (
                ring_from_geo(p.exterior()),
                p.interiors().iter().map(ring_from_geo).collect(),
            )
        })
        .filter(|(o, _)| o.len() >= 3 && signed_area(o) > 1e-6)
        .collect()
}

/// Largest angle between the chords of a round join, rad: arcs of 6 m radius get 0.12 m
/// chords, fine enough for three-point curvature at 1 m spacing.
pub(super) const JOIN_ANGLE: f64 = 0.02;

/// Offset every area by `distance` (m; negative shrinks the outer rings and grows the holes),
/// with finely stepped round joins.
pub fn offset(areas: &[Area], distance: f64) -> Vec<Area> {
    offset_joined(areas, distance, JOIN_ANGLE)
}

/// Largest angle between the chords of a round join of [`offset_within`], rad.
const COARSEST_JOIN_ANGLE: f64 = 0.5;

/// [`offset`] with round joins only as fine as keeps every chord within `tolerance` m of its
/// arc (never finer than [`offset`]'s): for ground that is measured or simplified to that
/// tolerance afterwards, never driven along. An arc of radius |`distance`| needs chords of
/// angle 2·acos(1 − `tolerance`/|`distance`|): at 1.5 m and 2 cm, 0.33 rad where [`offset`]
/// makes sixteen chords.
pub fn offset_within(areas: &[Area], distance: f64, tolerance: f64) -> Vec<Area> {
    let radius = distance.abs();
    let angle = if tolerance >= radius {
        COARSEST_JOIN_ANGLE
    } else {
        2.0 * (1.0 - tolerance / radius).acos()
    };
    offset_joined(
        areas,
        distance,
        angle.clamp(JOIN_ANGLE, COARSEST_JOIN_ANGLE),
    )
}

/// [`offset`] with round joins of chords `join_angle` rad apart.
fn offset_joined(areas: &[Area], distance: f64, join_angle: f64) -> Vec<Area> {
    // A piece that cannot hold a disc of radius −distance shrinks to nothing: skip it. Such
    // slivers (a few metres across, edged by arcs of smaller radius) cost the clipper up to
    // 150 ms each, as every offset edge of the collapsing arcs crosses every other.
    let mp = MultiPolygon::new(
        areas
            .iter()
            .filter(|a| distance >= 0.0 || may_hold_disc(a, -distance))
            .map(to_geo)
            .collect(),
    );
    let style = BufferStyle::new(distance).line_join(LineJoin::Round(join_angle));
    from_geo(&mp.buffer_with_style(style))
}

/// Could a disc of radius `r` fit inside `area`? `false` when it certainly cannot: the area is
/// smaller than the disc, or its convex hull is narrower than the disc in some direction.
fn may_hold_disc(area: &Area, r: f64) -> bool {
    if area_m2(area) < std::f64::consts::PI * r * r {
        return false;
    }
    let (lo, hi) = crate::geo::polygon::bbox(area.0.iter()).unwrap_or((v2(0.0, 0.0), v2(0.0, 0.0)));
    if (hi - lo).x < 2.0 * r || (hi - lo).y < 2.0 * r {
        return false;
    }
    super::swath_angle::min_span(&area.0).is_none_or(|(_, width)| width >= 2.0 * r)
}

/// Width of the widest strip of `area` (boundary minus holes): twice the radius of the
/// largest circle inside it, found by bisection on inward offsets to 1 cm, m.
pub fn inscribed_width(area: &Area) -> f64 {
    let (lo, hi) = crate::geo::polygon::bbox(area.0.iter()).unwrap_or((v2(0.0, 0.0), v2(0.0, 0.0)));
    let (mut inside, mut outside) = (0.0, 0.5 * (hi - lo).x.min((hi - lo).y) + 0.01);
    let one = std::slice::from_ref(area);
    while outside - inside > 0.005 {
        let mid = 0.5 * (inside + outside);
        if offset(one, -mid).is_empty() {
            outside = mid;
        } else {
            inside = mid;
        }
    }
    2.0 * inside
}

/// The areas with every vertex dropped that lies within `tolerance` m of the outline without
/// it (Ramer–Douglas–Peucker).
pub fn simplified(areas: &[Area], tolerance: f64) -> Vec<Area> {
    use geo::Simplify;
    from_geo(&MultiPolygon::new(areas.iter().map(to_geo).collect()).simplify(tolerance))
}

/// Length of every ring of `area`, closing edges included, m.
pub fn perimeter(area: &Area) -> f64 {
    std::iter::once(&area.0)
        .chain(area.1.iter())
        .map(|ring| {
            let n = ring.len();
            (0..n)
                .map(|i| (ring[(i + 1) % n] - ring[i]).norm())
                .sum::<f64>()
        })
        .sum()
}

/// Rotate `p` by `angle` rad counter-clockwise about the origin.
#[inline]
pub fn rotate(p: &Vec2, angle: f64) -> Vec2 {
    let (s, c) = angle.sin_cos();
    v2(c * p.x - s * p.y, s * p.x + c * p.y)
}

/// Rotate every vertex of an area.
pub fn rotate_area(area: &Area, angle: f64) -> Area {
    (
        area.0.iter().map(|p| rotate(p, angle)).collect(),
        area.1
            .iter()
            .map(|h| h.iter().map(|p| rotate(p, angle)).collect())
            .collect(),
    )
}

/// The x-intervals where the horizontal line at `y` is inside `area` (even-odd over the outer
/// ring and the holes), sorted.
pub fn scan_intervals(area: &Area, y: f64) -> Vec<(f64, f64)> {
    crossings(edges(area), y)
}

/// The edges of an area's rings, each from a vertex to the next, in ring order.
fn edges(area: &Area) -> impl Iterator<Item = (Vec2, Vec2)> + '_ {
    std::iter::once(&area.0)
        .chain(area.1.iter())
        .flat_map(|ring| (0..ring.len()).map(move |i| (ring[i], ring[(i + 1) % ring.len()])))
}

/// The x-intervals between the crossings of `edges` with the line at `y`, sorted.
fn crossings(edges: impl Iterator<Item = (Vec2, Vec2)>, y: f64) -> Vec<(f64, f64)> {
    // Half-open rule so a vertex on the line counts once.
    let mut xs: Vec<f64> = edges
        .filter(|(a, b)| (a.y <= y) != (b.y <= y))
        .map(|(a, b)| a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y))
        .collect();
    xs.sort_by(|a, b| a.total_cmp(b));
    xs.chunks_exact(2).map(|c| (c[0], c[1])).collect()
}

/// An area's edges sorted into bands of y, for many [`scan_intervals`] of one area (the lines
/// of a cell): a line looks only at the edges of its band, with the same answer.
pub struct Scanner {
    /// Per band of `height` m from `bottom` up: the edges (in ring order, as
    /// [`scan_intervals`] takes them) whose y-extent meets it.
    bands: Vec<Vec<(Vec2, Vec2)>>,
    bottom: f64,
    height: f64,
    /// Every vertex's y, sorted.
    heights: Vec<f64>,
}

/// Most bands of a [`Scanner`].
const SCAN_BANDS: usize = 256;

impl Scanner {
    pub fn new(area: &Area) -> Self {
        let mut heights: Vec<f64> = edges(area).map(|e| e.0.y).collect();
        heights.sort_by(f64::total_cmp);
        let (bottom, top) = match (heights.first(), heights.last()) {
            (Some(&b), Some(&t)) => (b, t),
            _ => (0.0, 0.0),
        };
        let count = heights.len().clamp(1, SCAN_BANDS);
        let height = if top > bottom {
            (top - bottom) / count as f64
        } else {
            1.0
        };
        let mut scanner = Scanner {
            bands: vec![Vec::new(); count],
            bottom,
            height,
            heights,
        };
        for e in edges(area) {
            let (lo, hi) = (
                scanner.band(e.0.y.min(e.1.y)),
                scanner.band(e.0.y.max(e.1.y)),
            );
            for band in &mut scanner.bands[lo..=hi] {
                band.push(e);
            }
        }
        scanner
    }

    /// The band holding `y` (the nearest end band beyond them). Monotone in `y` (each
    /// operation is correctly rounded), so an edge from y₀ to y₁ lies in every band of the
    /// y between them; a line below every vertex (or at NaN) crosses no edge of band 0.
    fn band(&self, y: f64) -> usize {
        let k = ((y - self.bottom) / self.height).floor();
        if k >= 0.0 {
            (k as usize).min(self.bands.len() - 1)
        } else {
            0
        }
    }

    /// [`scan_intervals`] of the area at `y`.
    pub fn intervals(&self, y: f64) -> Vec<(f64, f64)> {
        crossings(self.bands[self.band(y)].iter().copied(), y)
    }

    /// The vertices' heights `v` with |v − y| < `half`, ascending.
    pub fn heights_within(&self, y: f64, half: f64) -> impl Iterator<Item = f64> + '_ {
        // A metre of slack round the band for the search; the exact test on each.
        let from = self.heights.partition_point(|&v| v < y - half - 1.0);
        let to = self.heights.partition_point(|&v| v <= y + half + 1.0);
        self.heights[from..to.max(from)]
            .iter()
            .copied()
            .filter(move |v| (v - y).abs() < half)
    }
}

/// Is `q` inside `area`: in its outer ring and in none of its holes?
pub fn in_area((outer, holes): &Area, q: &Vec2) -> bool {
    use crate::geo::polygon::contains_point;
    contains_point(outer, q) && !holes.iter().any(|h| contains_point(h, q))
}

/// Area of an area with holes, m².
pub fn area_m2(area: &Area) -> f64 {
    signed_area(&area.0) - area.1.iter().map(|h| signed_area(h).abs()).sum::<f64>()
}

/// Convex hull (Andrew's monotone chain), counter-clockwise, without collinear points.
pub fn convex_hull(points: &[Vec2]) -> Vec<Vec2> {
    let mut p: Vec<Vec2> = points
        .iter()
        .copied()
        .filter(|q| q.x.is_finite() && q.y.is_finite())
        .collect();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let turn = |o: &Vec2, a: &Vec2, b: &Vec2| crate::geo::cross(&(a - o), &(b - o));
    let mut lower: Vec<Vec2> = Vec::new();
    for q in &p {
        while lower.len() >= 2 && turn(&lower[lower.len() - 2], &lower[lower.len() - 1], q) <= 0.0 {
            lower.pop();
        }
        lower.push(*q);
    }
    let mut upper: Vec<Vec2> = Vec::new();
    for q in p.iter().rev() {
        while upper.len() >= 2 && turn(&upper[upper.len() - 2], &upper[upper.len() - 1], q) <= 0.0 {
            upper.pop();
        }
        upper.push(*q);
    }
    lower.pop();
    upper.pop();
    lower.extend(upper);
    lower
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`Scanner::intervals`] gives [`scan_intervals`]'s answer, to the bit: on random star
    /// polygons with holes (some edges long, some flat), at random heights, at every vertex's
    /// height (the half-open rule), and below and above the area.
    #[test]
    fn the_scanner_scans_as_every_edge_does() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for case in 0..200 {
            let star = |rng: &mut rand_chacha::ChaCha8Rng, c: Vec2, r: f64, n: usize| {
                (0..n)
                    .map(|k| {
                        let a = std::f64::consts::TAU * k as f64 / n as f64;
                        let rr = r * rng.gen_range(0.3..1.0);
                        // Some vertices share a height (flat edges).
                        let y = if k % 7 == 3 { c.y } else { c.y + rr * a.sin() };
                        v2(c.x + rr * a.cos(), y)
                    })
                    .collect::<Vec<Vec2>>()
            };
            let n = rng.gen_range(3..(if case % 10 == 0 { 600 } else { 40 }));
            let outer = star(&mut rng, v2(0.0, 0.0), 100.0, n);
            let holes: Vec<Vec<Vec2>> = (0..rng.gen_range(0..3))
                .map(|_| {
                    let c = v2(rng.gen_range(-20.0..20.0), rng.gen_range(-20.0..20.0));
                    let k = rng.gen_range(3..12);
                    star(&mut rng, c, 8.0, k)
                })
                .collect();
            let area: Area = (outer, holes);
            let scanner = Scanner::new(&area);
            let mut ys: Vec<f64> = (0..50).map(|_| rng.gen_range(-120.0..120.0)).collect();
            ys.extend(area.0.iter().chain(area.1.iter().flatten()).map(|q| q.y));
            ys.extend([-1e9, 1e9, f64::NAN]);
            for y in ys {
                let (a, b) = (scanner.intervals(y), scan_intervals(&area, y));
                let bits = |v: &[(f64, f64)]| -> Vec<(u64, u64)> {
                    v.iter()
                        .map(|(x0, x1)| (x0.to_bits(), x1.to_bits()))
                        .collect()
                };
                assert_eq!(bits(&a), bits(&b), "case {case}, y {y}");
            }
        }
    }

    #[test]
    fn offset_square_and_scan() {
        let sq: Area = (
            vec![v2(0.0, 0.0), v2(10.0, 0.0), v2(10.0, 10.0), v2(0.0, 10.0)],
            vec![],
        );
        let inset = offset(std::slice::from_ref(&sq), -1.0);
        assert_eq!(inset.len(), 1);
        assert!((area_m2(&inset[0]) - 64.0).abs() < 0.01);
        let iv = scan_intervals(&sq, 5.0);
        assert_eq!(iv.len(), 1);
        assert!((iv[0].0 - 0.0).abs() < 1e-12 && (iv[0].1 - 10.0).abs() < 1e-12);
        let hull = convex_hull(&[
            v2(0.0, 0.0),
            v2(1.0, 1.0),
            v2(2.0, 0.0),
            v2(1.0, 0.2),
            v2(1.0, -1.0),
        ]);
        assert_eq!(hull.len(), 4);
    }

    /// The coarse joins keep every vertex within the tolerance inside the exact offset (the
    /// chords' vertices lie on the arcs, the chords between them at most `tolerance` inside),
    /// with fewer vertices than the fine joins; the fine joins are kept where the tolerance
    /// asks for them.
    #[test]
    fn coarse_joins_stay_within_their_tolerance() {
        let sq: Area = (
            vec![v2(0.0, 0.0), v2(10.0, 0.0), v2(10.0, 10.0), v2(0.0, 10.0)],
            vec![],
        );
        let one = std::slice::from_ref(&sq);
        // Distance from the square, outside it: the exact grown outline is at `d` everywhere.
        let from_square = |q: &Vec2| {
            let n = sq.0.len();
            (0..n)
                .map(|i| {
                    crate::geo::polygon::point_segment_distance(q, &sq.0[i], &sq.0[(i + 1) % n])
                })
                .fold(f64::INFINITY, f64::min)
        };
        for (d, tolerance) in [(1.5, 0.02), (6.0, 0.02), (30.0, 0.05)] {
            let fine = offset(one, d);
            let coarse = offset_within(one, d, tolerance);
            assert!(coarse[0].0.len() < fine[0].0.len(), "d {d}");
            // Every chord's midpoint within the tolerance of the arc, no vertex off it.
            let ring = &coarse[0].0;
            for (i, a) in ring.iter().enumerate() {
                let b = ring[(i + 1) % ring.len()];
                assert!((from_square(a) - d).abs() < 1e-3, "d {d}: vertex {a:?}");
                let mid = 0.5 * (a + b);
                assert!(
                    from_square(&mid) > d - tolerance - 1e-3,
                    "d {d}: chord {a:?}–{b:?}"
                );
            }
            let lost = area_m2(&fine[0]) - area_m2(&coarse[0]);
            assert!(lost >= -1e-6 && lost < 4.0 * tolerance * 0.5 * std::f64::consts::PI * d);
        }
        // A tolerance finer than the fine joins' chords: the fine joins.
        let fine = offset(one, 1.0);
        assert_eq!(offset_within(one, 1.0, 1e-6)[0].0.len(), fine[0].0.len());
    }

    #[test]
    fn an_area_too_thin_for_the_inward_offset_vanishes() {
        let thin: Area = (
            vec![v2(0.0, 0.0), v2(100.0, 0.0), v2(100.0, 9.0), v2(0.0, 9.0)],
            vec![],
        );
        let wide: Area = (
            vec![
                v2(0.0, 20.0),
                v2(100.0, 20.0),
                v2(100.0, 40.0),
                v2(0.0, 40.0),
            ],
            vec![],
        );
        assert!(offset(std::slice::from_ref(&thin), -4.6).is_empty());
        let both = offset(&[thin.clone(), wide], -4.6);
        assert_eq!(both.len(), 1);
        assert!((area_m2(&both[0]) - 90.8 * 10.8).abs() < 0.01);
        assert!(!may_hold_disc(&thin, 4.6) && may_hold_disc(&thin, 4.4));
    }
}
