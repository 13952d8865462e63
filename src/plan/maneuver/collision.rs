//! Collision checks of the vehicle rectangle against a map (docs/METHODS.md, Collision check;
//! seed 004 ¶41–42).
//!
//! The vehicle is a rectangle placed at its reference point, the centre of the rear axle
//! (docs/CONVENTIONS.md, Reference point), optionally followed by an implement rectangle. The
//! implement is taken as **rigidly** attached (three-point linkage): it keeps the tractor's
//! heading, its front edge `hitch_offset_m` behind the rear axle. A trailed implement would swing
//! in on turns; that is not modelled.
//!
//! A [`CollisionMap`] holds a boundary polygon (or none: free space) and obstacle polygons.
//! The broad phase is a uniform grid: every map edge is listed in each cell its bounding box
//! touches, and a rectangle only tests the edges listed in the cells under its own bounding box.
//! A rectangle is clear when
//! 1. no rectangle edge meets a map edge (segment intersection, touching counts), and
//! 2. it is not wholly outside the boundary (one corner inside), and not wholly inside an
//!    obstacle (one corner inside one), and no obstacle lies wholly inside it (one obstacle
//!    vertex inside the rectangle).
//!
//! Paths are checked by sampling. Between two samples `ds` apart along a path of curvature at
//! most κ, any point of the vehicle at distance ≤ R from the rear axle moves along a curve no
//! longer than `ds·(1 + R·κ)` (translation plus rotation). [`Footprint::sample_spacing_m`]
//! chooses `ds` so that this is at most the tolerance `tol`: every point of the swept area is
//! then within `tol/2` of the same point in one of the two neighbouring samples (a point on a
//! curve of length L is within L/2 of one of its ends). The swept area is therefore covered by
//! the sampled rectangles grown by `tol/2` on each side; the checks grow the rectangle by the
//! footprint's `margin_m`, so the continuous sweep of the bare vehicle is proved clear when
//! `margin_m ≥ tol/2` (the `[maneuver]` validation enforces this).

use super::path::CurvePath;
use crate::geo::polygon::{bbox, contains_point, point_segment_distance, segments_intersect};
use crate::geo::{v2, Pose, Vec2};

/// The vehicle's own rectangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VehicleBox {
    /// Overall length, m.
    pub length_m: f64,
    /// Overall width, m.
    pub width_m: f64,
    /// Distance of the rear axle ahead of the rear edge, m.
    pub rear_axle_from_rear_m: f64,
}

/// A rigidly mounted implement behind the vehicle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImplementBox {
    /// Length along the vehicle axis, m.
    pub length_m: f64,
    /// Width, m (centred on the vehicle axis).
    pub width_m: f64,
    /// Distance of the implement's front edge behind the rear axle, m.
    pub hitch_offset_m: f64,
}

/// Everything that must stay clear: the vehicle, an optional implement and a safety margin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footprint {
    pub vehicle: VehicleBox,
    pub implement: Option<ImplementBox>,
    /// Every rectangle is grown by this on all sides before checking, m.
    pub margin_m: f64,
}

/// A rectangle in the vehicle frame: x forward from the rear axle, y to the left.
#[derive(Debug, Clone, Copy, PartialEq)]
struct LocalBox {
    x_min: f64,
    x_max: f64,
    half_width: f64,
}

impl Footprint {
    fn local_boxes(&self) -> ([LocalBox; 2], usize) {
        let m = self.margin_m;
        let v = &self.vehicle;
        let body = LocalBox {
            x_min: -v.rear_axle_from_rear_m - m,
            x_max: v.length_m - v.rear_axle_from_rear_m + m,
            half_width: 0.5 * v.width_m + m,
        };
        match self.implement {
            Some(i) => (
                [
                    body,
                    LocalBox {
                        x_min: -i.hitch_offset_m - i.length_m - m,
                        x_max: -i.hitch_offset_m + m,
                        half_width: 0.5 * i.width_m + m,
                    },
                ],
                2,
            ),
            None => ([body, body], 1),
        }
    }

    /// The rectangles (vehicle, then implement) at `pose`, corners counter-clockwise from the
    /// rear right.
    pub fn rectangles(&self, pose: &Pose) -> Vec<[Vec2; 4]> {
        let (boxes, n) = self.local_boxes();
        boxes[..n].iter().map(|b| corners(b, pose)).collect()
    }

    /// Largest distance of any (grown) rectangle corner from the rear axle, m.
    pub fn max_corner_radius_m(&self) -> f64 {
        let (boxes, n) = self.local_boxes();
        boxes[..n]
            .iter()
            .map(|b| {
                let x = b.x_min.abs().max(b.x_max.abs());
                (x * x + b.half_width * b.half_width).sqrt()
            })
            .fold(0.0, f64::max)
    }

    /// Sample spacing along a path, m, such that no point of the footprint moves more than
    /// `tolerance_m` between samples where |κ| ≤ `kappa_max` (see the module documentation).
    pub fn sample_spacing_m(&self, tolerance_m: f64, kappa_max: f64) -> f64 {
        tolerance_m / (1.0 + self.max_corner_radius_m() * kappa_max.abs())
    }
}

fn corners(b: &LocalBox, pose: &Pose) -> [Vec2; 4] {
    let (s, c) = pose.heading.sin_cos();
    let at = |x: f64, y: f64| v2(pose.pos.x + c * x - s * y, pose.pos.y + s * x + c * y);
    [
        at(b.x_min, -b.half_width),
        at(b.x_max, -b.half_width),
        at(b.x_max, b.half_width),
        at(b.x_min, b.half_width),
    ]
}

/// Why a rectangle is not clear.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blocked {
    /// It crosses or lies outside the map boundary.
    OutsideBoundary,
    /// It touches obstacle number `0` (index in the map's obstacle list).
    Obstacle(usize),
}

impl std::fmt::Display for Blocked {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Blocked::OutsideBoundary => write!(f, "the vehicle is not inside the map boundary"),
            Blocked::Obstacle(i) => write!(f, "the vehicle touches obstacle {i}"),
        }
    }
}

/// Why a map cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MapError {
    #[error("{what} has {points} points, at least 3 needed")]
    TooFewPoints { what: String, points: usize },
    #[error("{what} has a coordinate that is not a finite number")]
    NotFinite { what: String },
    #[error("grid cell size {0} m must be finite and > 0")]
    BadCell(f64),
}

#[derive(Debug, Clone, Copy)]
struct Edge {
    a: Vec2,
    b: Vec2,
    /// `None` = boundary, `Some(i)` = obstacle i.
    owner: Option<usize>,
}

/// A boundary and obstacles, with a uniform-grid broad phase over their edges.
#[derive(Debug, Clone)]
pub struct CollisionMap {
    boundary: Option<Vec<Vec2>>,
    boundary_bbox: Option<(Vec2, Vec2)>,
    obstacles: Vec<Vec<Vec2>>,
    obstacle_bbox: Vec<(Vec2, Vec2)>,
    edges: Vec<Edge>,
    origin: Vec2,
    cell_m: f64,
    nx: usize,
    ny: usize,
    /// Cell k's edges are `cell_edges[cell_start[k]..cell_start[k + 1]]`.
    cell_start: Vec<u32>,
    cell_edges: Vec<u32>,
    /// Per cell: radius of a disc around any point of the cell that is certainly free (no map
    /// edge within it, and the cell centre in free space), m; ≤ 0 = unknown. Lets a pose whose
    /// footprint fits in that disc skip the exact test.
    cell_free_radius: Vec<f64>,
}

/// Most grid cells a map may have; the cell size grows to stay below it.
const MAX_CELLS: f64 = 250_000.0;
/// The free-disc table is built only when cells × edges is below this.
const MAX_FREE_TABLE_WORK: usize = 5_000_000;

impl CollisionMap {
    /// A map from a boundary ring (`None` = unbounded free space) and obstacle rings, with a
    /// broad-phase grid of `cell_m` cells (grown if the map would need more than 250 000).
    pub fn new(
        boundary: Option<Vec<Vec2>>,
        obstacles: Vec<Vec<Vec2>>,
        cell_m: f64,
    ) -> Result<Self, MapError> {
        if !(cell_m.is_finite() && cell_m > 0.0) {
            return Err(MapError::BadCell(cell_m));
        }
        let check = |what: String, ring: &[Vec2]| {
            if ring.len() < 3 {
                return Err(MapError::TooFewPoints {
                    what,
                    points: ring.len(),
                });
            }
            if ring.iter().any(|p| !(p.x.is_finite() && p.y.is_finite())) {
                return Err(MapError::NotFinite { what });
            }
            Ok(())
        };
        if let Some(b) = &boundary {
            check("the boundary".into(), b)?;
        }
        for (i, o) in obstacles.iter().enumerate() {
            check(format!("obstacle {i}"), o)?;
        }
        let mut edges = Vec::new();
        let mut push_ring = |ring: &[Vec2], owner: Option<usize>| {
            for k in 0..ring.len() {
                edges.push(Edge {
                    a: ring[k],
                    b: ring[(k + 1) % ring.len()],
                    owner,
                });
            }
        };
        if let Some(b) = &boundary {
            push_ring(b, None);
        }
        for (i, o) in obstacles.iter().enumerate() {
            push_ring(o, Some(i));
        }
        let obstacle_bbox: Vec<(Vec2, Vec2)> = obstacles
            .iter()
            .map(|o| bbox(o.iter()).unwrap_or((v2(0.0, 0.0), v2(0.0, 0.0))))
            .collect();
        let boundary_bbox = boundary.as_ref().and_then(|b| bbox(b.iter()));
        let all = bbox(edges.iter().map(|e| &e.a)).unwrap_or((v2(0.0, 0.0), v2(1.0, 1.0)));
        let span = all.1 - all.0;
        let mut cell = cell_m;
        let area = (span.x.max(cell) / cell) * (span.y.max(cell) / cell);
        if area > MAX_CELLS {
            cell *= (area / MAX_CELLS).sqrt();
        }
        let nx = ((span.x / cell).floor() as usize + 1).max(1);
        let ny = ((span.y / cell).floor() as usize + 1).max(1);
        let mut map = CollisionMap {
            boundary,
            boundary_bbox,
            obstacles,
            obstacle_bbox,
            edges,
            origin: all.0,
            cell_m: cell,
            nx,
            ny,
            cell_start: Vec::new(),
            cell_edges: Vec::new(),
            cell_free_radius: Vec::new(),
        };
        // Counting sort of (cell, edge) pairs.
        let mut counts = vec![0u32; nx * ny + 1];
        let ranges: Vec<_> = map
            .edges
            .iter()
            .map(|e| map.cell_range(&e.a.inf(&e.b), &e.a.sup(&e.b)))
            .collect();
        for r in ranges.iter().flatten() {
            for iy in r.2..=r.3 {
                for ix in r.0..=r.1 {
                    counts[iy * nx + ix + 1] += 1;
                }
            }
        }
        for k in 1..counts.len() {
            counts[k] += counts[k - 1];
        }
        let mut fill = counts.clone();
        let mut cell_edges = vec![0u32; counts[nx * ny] as usize];
        for (i, r) in ranges.iter().enumerate() {
            if let Some(r) = r {
                for iy in r.2..=r.3 {
                    for ix in r.0..=r.1 {
                        let k = iy * nx + ix;
                        cell_edges[fill[k] as usize] = i as u32;
                        fill[k] += 1;
                    }
                }
            }
        }
        map.cell_start = counts;
        map.cell_edges = cell_edges;
        map.cell_free_radius = map.free_radius_table();
        Ok(map)
    }

    /// The per-cell free-disc radii (see `cell_free_radius`).
    fn free_radius_table(&self) -> Vec<f64> {
        let cells = self.nx * self.ny;
        let vertices: usize = self.obstacles.iter().map(Vec::len).sum::<usize>()
            + self.boundary.as_ref().map_or(0, Vec::len);
        if cells.saturating_mul(self.edges.len() + vertices) > MAX_FREE_TABLE_WORK {
            return vec![0.0; cells];
        }
        let half_diag = std::f64::consts::FRAC_1_SQRT_2 * self.cell_m;
        let mut out = Vec::with_capacity(cells);
        for iy in 0..self.ny {
            for ix in 0..self.nx {
                let c = self.origin
                    + v2(
                        (ix as f64 + 0.5) * self.cell_m,
                        (iy as f64 + 0.5) * self.cell_m,
                    );
                let free = self.boundary.as_ref().is_none_or(|b| contains_point(b, &c))
                    && !self.obstacles.iter().any(|o| contains_point(o, &c));
                if !free {
                    out.push(0.0);
                    continue;
                }
                let d = self
                    .edges
                    .iter()
                    .map(|e| point_segment_distance(&c, &e.a, &e.b))
                    .fold(f64::INFINITY, f64::min);
                out.push(d - half_diag);
            }
        }
        out
    }

    /// Whether a disc of radius `r` about `p` is certainly free (table look-up only).
    fn disc_surely_free(&self, p: &Vec2, r: f64) -> bool {
        let fx = ((p.x - self.origin.x) / self.cell_m).floor();
        let fy = ((p.y - self.origin.y) / self.cell_m).floor();
        if !(fx >= 0.0 && fy >= 0.0 && fx < self.nx as f64 && fy < self.ny as f64) {
            return false;
        }
        self.cell_free_radius
            .get(fy as usize * self.nx + fx as usize)
            .is_some_and(|&free| free > r)
    }

    /// Unbounded free space.
    pub fn free() -> Self {
        CollisionMap {
            boundary: None,
            boundary_bbox: None,
            obstacles: Vec::new(),
            obstacle_bbox: Vec::new(),
            edges: Vec::new(),
            origin: v2(0.0, 0.0),
            cell_m: 1.0,
            nx: 1,
            ny: 1,
            cell_start: vec![0, 0],
            cell_edges: Vec::new(),
            cell_free_radius: vec![0.0],
        }
    }

    pub fn boundary(&self) -> Option<&[Vec2]> {
        self.boundary.as_deref()
    }

    pub fn obstacles(&self) -> &[Vec<Vec2>] {
        &self.obstacles
    }

    /// Grid cells (ix0, ix1, iy0, iy1) under a bounding box, clamped; `None` when it misses
    /// the grid.
    fn cell_range(&self, min: &Vec2, max: &Vec2) -> Option<(usize, usize, usize, usize)> {
        let fx0 = ((min.x - self.origin.x) / self.cell_m).floor();
        let fy0 = ((min.y - self.origin.y) / self.cell_m).floor();
        let fx1 = ((max.x - self.origin.x) / self.cell_m).floor();
        let fy1 = ((max.y - self.origin.y) / self.cell_m).floor();
        let (nx, ny) = (self.nx as f64, self.ny as f64);
        if !(fx1 >= 0.0 && fy1 >= 0.0 && fx0 < nx && fy0 < ny) {
            return None;
        }
        Some((
            fx0.max(0.0) as usize,
            fx1.min(nx - 1.0) as usize,
            fy0.max(0.0) as usize,
            fy1.min(ny - 1.0) as usize,
        ))
    }

    /// Whether the rectangle with corners `c` (in order around it) is clear.
    pub fn rectangle_clear(&self, c: &[Vec2; 4]) -> Result<(), Blocked> {
        let Some((min, max)) = bbox(c.iter()) else {
            return Err(Blocked::OutsideBoundary);
        };
        if let Some((bmin, bmax)) = self.boundary_bbox {
            if min.x < bmin.x || min.y < bmin.y || max.x > bmax.x || max.y > bmax.y {
                return Err(Blocked::OutsideBoundary);
            }
        }
        if let Some((ix0, ix1, iy0, iy1)) = self.cell_range(&min, &max) {
            for iy in iy0..=iy1 {
                for ix in ix0..=ix1 {
                    let k = iy * self.nx + ix;
                    let (s, e) = (self.cell_start[k] as usize, self.cell_start[k + 1] as usize);
                    for &ei in &self.cell_edges[s..e] {
                        let edge = &self.edges[ei as usize];
                        let (emin, emax) = (edge.a.inf(&edge.b), edge.a.sup(&edge.b));
                        if emax.x < min.x || emin.x > max.x || emax.y < min.y || emin.y > max.y {
                            continue;
                        }
                        for j in 0..4 {
                            if segments_intersect(&c[j], &c[(j + 1) % 4], &edge.a, &edge.b) {
                                return Err(match edge.owner {
                                    None => Blocked::OutsideBoundary,
                                    Some(i) => Blocked::Obstacle(i),
                                });
                            }
                        }
                    }
                }
            }
        }
        // No edge crossings: containment decides.
        if let Some(b) = &self.boundary {
            if !contains_point(b, &c[0]) {
                return Err(Blocked::OutsideBoundary);
            }
        }
        for (i, (o, (omin, omax))) in self.obstacles.iter().zip(&self.obstacle_bbox).enumerate() {
            if omax.x < min.x || omin.x > max.x || omax.y < min.y || omin.y > max.y {
                continue;
            }
            if contains_point(o, &c[0]) || point_in_rectangle(c, &o[0]) {
                return Err(Blocked::Obstacle(i));
            }
        }
        Ok(())
    }

    /// Whether rectangles already placed in the world (corners in order) are clear, given
    /// that they all lie within `radius` of `centre` (the quick free-disc test uses it).
    pub fn placed_clear(
        &self,
        centre: &Vec2,
        radius: f64,
        rectangles: &[[Vec2; 4]],
    ) -> Result<(), Blocked> {
        if self.disc_surely_free(centre, radius) {
            return Ok(());
        }
        for r in rectangles {
            self.rectangle_clear(r)?;
        }
        Ok(())
    }

    /// Whether `footprint` at `pose` is clear.
    pub fn pose_clear(&self, footprint: &Footprint, pose: &Pose) -> Result<(), Blocked> {
        if self.disc_surely_free(&pose.pos, footprint.max_corner_radius_m()) {
            return Ok(());
        }
        let (boxes, n) = footprint.local_boxes();
        for b in &boxes[..n] {
            self.rectangle_clear(&corners(b, pose))?;
        }
        Ok(())
    }

    /// Whether `footprint` stays clear along `path`: the start pose and, on each segment of
    /// length `L`, the poses at `L k / n`, `k = 1..=n`, `n = ceil(L / spacing_m)` (so samples
    /// are at most `spacing_m` apart; see [`Footprint::sample_spacing_m`]).
    pub fn path_clear(&self, footprint: &Footprint, path: &CurvePath, spacing_m: f64) -> bool {
        let mut pose = path.start;
        if self.pose_clear(footprint, &pose).is_err() {
            return false;
        }
        for seg in &path.segments {
            if seg.length > 0.0 {
                let n = (seg.length / spacing_m).ceil().max(1.0) as usize;
                for k in 1..=n {
                    let s = seg.length * k as f64 / n as f64;
                    if self.pose_clear(footprint, &seg.pose_at(&pose, s)).is_err() {
                        return false;
                    }
                }
            }
            pose = seg.end_pose(&pose);
        }
        true
    }
}

/// Whether `p` is inside (or on) the rectangle with corners `c` in order.
fn point_in_rectangle(c: &[Vec2; 4], p: &Vec2) -> bool {
    let u = c[1] - c[0];
    let v = c[3] - c[0];
    let d = p - c[0];
    let (du, dv) = (d.dot(&u), d.dot(&v));
    du >= 0.0 && du <= u.norm_squared() && dv >= 0.0 && dv <= v.norm_squared()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::geo::rect;
    use std::f64::consts::FRAC_PI_2;

    /// A 4 × 2 m vehicle, rear axle 1 m from the rear, no implement, `margin_m` clearance.
    pub(crate) fn tractor_with_margin(margin_m: f64) -> Footprint {
        Footprint {
            vehicle: VehicleBox {
                length_m: 4.0,
                width_m: 2.0,
                rear_axle_from_rear_m: 1.0,
            },
            implement: None,
            margin_m,
        }
    }

    fn tractor() -> Footprint {
        tractor_with_margin(0.0)
    }

    #[test]
    fn rectangle_is_placed_about_the_rear_axle() {
        let r = tractor().rectangles(&Pose::new(10.0, 5.0, FRAC_PI_2));
        // Heading north: rear edge 1 m south of the axle, front 3 m north, 1 m either side.
        let (min, max) = bbox(r[0].iter()).unwrap();
        assert!((min - v2(9.0, 4.0)).norm() < 1e-9, "{min:?}");
        assert!((max - v2(11.0, 8.0)).norm() < 1e-9, "{max:?}");
        let mut f = tractor();
        f.implement = Some(ImplementBox {
            length_m: 2.0,
            width_m: 6.0,
            hitch_offset_m: 0.5,
        });
        let r = f.rectangles(&Pose::new(0.0, 0.0, 0.0));
        assert_eq!(r.len(), 2);
        let (min, max) = bbox(r[1].iter()).unwrap();
        assert!((min - v2(-2.5, -3.0)).norm() < 1e-9 && (max - v2(-0.5, 3.0)).norm() < 1e-9);
    }

    #[test]
    fn inside_boundary_clear_of_obstacles() {
        let map = CollisionMap::new(
            Some(rect(0.0, 0.0, 50.0, 20.0)),
            vec![rect(20.0, 8.0, 24.0, 12.0)],
            2.0,
        )
        .unwrap();
        let f = tractor();
        assert_eq!(map.pose_clear(&f, &Pose::new(5.0, 10.0, 0.0)), Ok(()));
        // Nose through the boundary.
        assert_eq!(
            map.pose_clear(&f, &Pose::new(48.0, 10.0, 0.0)),
            Err(Blocked::OutsideBoundary)
        );
        // Wholly outside.
        assert_eq!(
            map.pose_clear(&f, &Pose::new(80.0, 10.0, 0.0)),
            Err(Blocked::OutsideBoundary)
        );
        // Corner into the obstacle.
        assert_eq!(
            map.pose_clear(&f, &Pose::new(17.5, 7.5, 0.0)),
            Err(Blocked::Obstacle(0))
        );
        // Vehicle wholly inside a big obstacle: no edge crossing, containment must catch it.
        let big = CollisionMap::new(None, vec![rect(-10.0, -10.0, 10.0, 10.0)], 1.0).unwrap();
        assert_eq!(
            big.pose_clear(&f, &Pose::new(0.0, 0.0, 0.3)),
            Err(Blocked::Obstacle(0))
        );
        // A small obstacle wholly under the vehicle.
        let small = CollisionMap::new(None, vec![rect(0.5, -0.2, 0.9, 0.2)], 1.0).unwrap();
        assert_eq!(
            small.pose_clear(&f, &Pose::new(0.0, 0.0, 0.0)),
            Err(Blocked::Obstacle(0))
        );
        assert_eq!(small.pose_clear(&f, &Pose::new(0.0, 5.0, 0.0)), Ok(()));
    }

    #[test]
    fn margin_and_implement_count() {
        let map = CollisionMap::new(Some(rect(0.0, 0.0, 50.0, 20.0)), vec![], 2.0).unwrap();
        let mut f = tractor();
        // 0.5 m from the north edge with the body; a 0.6 m margin reaches it.
        let p = Pose::new(10.0, 18.5, 0.0);
        assert_eq!(map.pose_clear(&f, &p), Ok(()));
        f.margin_m = 0.6;
        assert_eq!(map.pose_clear(&f, &p), Err(Blocked::OutsideBoundary));
        f.margin_m = 0.0;
        f.implement = Some(ImplementBox {
            length_m: 1.0,
            width_m: 4.0,
            hitch_offset_m: 0.2,
        });
        assert_eq!(map.pose_clear(&f, &p), Err(Blocked::OutsideBoundary));
    }

    #[test]
    fn grid_agrees_with_brute_force() {
        // Many small obstacles and poses: the broad phase must never hide a hit.
        let mut obstacles = Vec::new();
        for i in 0..10 {
            for j in 0..5 {
                let (x, y) = (5.0 + 9.0 * i as f64, 4.0 + 8.0 * j as f64);
                obstacles.push(vec![v2(x, y), v2(x + 1.5, y + 0.3), v2(x + 0.4, y + 1.7)]);
            }
        }
        let boundary = rect(0.0, 0.0, 100.0, 45.0);
        let map = CollisionMap::new(Some(boundary.clone()), obstacles.clone(), 3.0).unwrap();
        let coarse = CollisionMap::new(Some(boundary.clone()), obstacles.clone(), 1e6).unwrap();
        let f = tractor();
        let mut hits = 0;
        for k in 0..4000 {
            let x = (k as f64 * 0.6180339887 * 100.0) % 100.0;
            let y = (k as f64 * 0.4142135623 * 45.0) % 45.0;
            let h = k as f64 * 0.7;
            let p = Pose::new(x, y, h);
            let r = map.pose_clear(&f, &p);
            // Brute force: every edge, every vertex.
            let c = f.rectangles(&p)[0];
            let mut brute = Ok(());
            let edges_hit = |ring: &[Vec2]| {
                (0..ring.len()).any(|i| {
                    (0..4).any(|j| {
                        segments_intersect(
                            &c[j],
                            &c[(j + 1) % 4],
                            &ring[i],
                            &ring[(i + 1) % ring.len()],
                        )
                    })
                })
            };
            if edges_hit(&boundary) || !contains_point(&boundary, &c[0]) {
                brute = Err(Blocked::OutsideBoundary);
            } else {
                for (i, o) in obstacles.iter().enumerate() {
                    let crosses = (0..o.len()).any(|e| {
                        (0..4).any(|j| {
                            segments_intersect(&c[j], &c[(j + 1) % 4], &o[e], &o[(e + 1) % o.len()])
                        })
                    });
                    if crosses || contains_point(o, &c[0]) || point_in_rectangle(&c, &o[0]) {
                        brute = Err(Blocked::Obstacle(i));
                        break;
                    }
                }
            }
            assert_eq!(r.is_ok(), brute.is_ok(), "pose {p:?}: {r:?} vs {brute:?}");
            assert_eq!(coarse.pose_clear(&f, &p).is_ok(), brute.is_ok());
            hits += usize::from(r.is_err());
        }
        assert!(
            hits > 200 && hits < 3800,
            "test poses mix clear and blocked: {hits}"
        );
    }

    #[test]
    fn free_disc_shortcut_agrees_with_the_exact_test() {
        // A big open yard with one obstacle: most poses take the free-disc shortcut, and every
        // answer must equal the exact test (a single huge cell never takes the shortcut).
        let boundary = vec![
            v2(0.0, 0.0),
            v2(80.0, 0.0),
            v2(80.0, 60.0),
            v2(30.0, 70.0),
            v2(0.0, 60.0),
        ];
        let obstacles = vec![rect(40.0, 20.0, 44.0, 50.0)];
        let fine = CollisionMap::new(Some(boundary.clone()), obstacles.clone(), 2.0).unwrap();
        let exact = CollisionMap::new(Some(boundary), obstacles, 1e6).unwrap();
        let f = tractor();
        let r = f.max_corner_radius_m();
        let mut shortcut = 0;
        for k in 0..5000 {
            let p = Pose::new(
                (k as f64 * 0.618_033_988_7 * 90.0) % 90.0 - 5.0,
                (k as f64 * 0.414_213_562_3 * 80.0) % 80.0 - 5.0,
                k as f64 * 0.9,
            );
            shortcut += usize::from(fine.disc_surely_free(&p.pos, r));
            assert_eq!(
                fine.pose_clear(&f, &p).is_ok(),
                exact.pose_clear(&f, &p).is_ok(),
                "{p:?}"
            );
        }
        assert!(shortcut > 2000, "the shortcut is exercised: {shortcut}");
    }

    #[test]
    fn sample_spacing_bounds_corner_motion() {
        let f = tractor();
        let kappa = 0.2;
        let tol = 0.2;
        let ds = f.sample_spacing_m(tol, kappa);
        // Drive a circle of curvature κ in steps of ds: every corner moves at most tol.
        let r = 1.0 / kappa;
        let mut prev = f.rectangles(&Pose::new(0.0, 0.0, 0.0))[0];
        let mut worst: f64 = 0.0;
        for k in 1..200 {
            let a = k as f64 * ds * kappa;
            let p = Pose::new(r * a.sin(), r * (1.0 - a.cos()), a);
            let c = f.rectangles(&p)[0];
            for j in 0..4 {
                worst = worst.max((c[j] - prev[j]).norm());
            }
            prev = c;
        }
        assert!(worst <= tol + 1e-9, "{worst}");
        assert!(worst > 0.5 * tol, "spacing not needlessly small: {worst}");
    }

    #[test]
    fn free_space_is_clear_and_bad_maps_are_errors() {
        let f = tractor();
        assert_eq!(
            CollisionMap::free().pose_clear(&f, &Pose::new(1e4, -3e3, 1.0)),
            Ok(())
        );
        assert!(CollisionMap::new(Some(vec![v2(0.0, 0.0), v2(1.0, 0.0)]), vec![], 1.0).is_err());
        assert!(CollisionMap::new(None, vec![rect(0.0, 0.0, f64::NAN, 1.0)], 1.0).is_err());
        assert!(CollisionMap::new(None, vec![], 0.0).is_err());
    }
}
