//! [`implement_clear`] for every point a plan tries, made cheap: a lazily filled grid
//! of cells that are clear throughout (one lookup), blocked throughout, or near an edge. A cell
//! near an edge keeps the edges within reach of it and a reference point whose side of every
//! ring is known, so a point there is checked against those few edges (its distance to each,
//! and the parity of the edges crossed on the way to the reference point) instead of against
//! every edge of the field: plan time on a boundary of many vertices no longer grows with them.
//! A cell is classified against the edges near its block of [`BLOCK`] × [`BLOCK`] cells (found
//! once per block), not against every edge: an edge far from the block is far from its cells.

use super::Field;
use crate::geo::polygon::{bbox, contains_point, point_segment_distance};
use crate::geo::{cross, v2, Vec2};
use std::cell::RefCell;
use std::ops::Range;

/// A point of a path keeps the implement inside the field and off the obstacles: inside the
/// boundary and at least `half` m from every boundary edge and every obstacle.
pub fn implement_clear(field: &Field, half: f64, q: &Vec2) -> bool {
    use crate::geo::polygon::point_segment_distance;
    let far = |ring: &Vec<Vec2>| {
        let n = ring.len();
        (0..n).all(|i| point_segment_distance(q, &ring[i], &ring[(i + 1) % n]) >= half - 1e-6)
    };
    field.contains(q)
        && std::iter::once(&field.boundary)
            .chain(&field.obstacles)
            .all(far)
}

/// How far a transit that cannot keep the implement clear of the edge keeps its path inside
/// the field and off the obstacles, m (about half a tractor's width; the implement is lifted
/// and may reach over the edge there): the guarantee for paths that do not work.
pub const TRANSIT_CLEARANCE_M: f64 = 1.5;

/// A test's [`ClearMap::blocked_margin`].
pub(super) type Margin<'a> = &'a dyn Fn(&Vec2) -> f64;

/// The clearance tests of one field, width, r_min and point spacing, and their waypoint grids
/// (built on first need: most plans never need them).
pub(super) struct Tests<'a> {
    /// The field.
    pub(super) field: &'a Field,
    /// The implement clear of the edge and the obstacles.
    pub(super) clear: &'a dyn Fn(&Vec2) -> bool,
    /// The tractor inside the field and off the obstacles ([`TRANSIT_CLEARANCE_M`]).
    pub(super) loose: &'a dyn Fn(&Vec2) -> bool,
    /// The distances from the edges and obstacles the two tests keep, m.
    pub(super) clearance: (f64, f64),
    /// The two tests' [`ClearMap::blocked_margin`]s.
    pub(super) margins: (Margin<'a>, Margin<'a>),
    /// The two tests are one (w ≤ 3 m).
    pub(super) one_test: bool,
    pub(super) grid: &'a std::cell::OnceCell<super::transit::WaypointGrid<'a>>,
    pub(super) loose_grid: &'a std::cell::OnceCell<super::transit::WaypointGrid<'a>>,
}

/// The edges of the rings near one cell.
#[derive(Debug)]
struct Local {
    /// A point of the cell's circumscribed disc on no edge.
    reference: Vec2,
    /// Edges within reach of the cell, grouped by ring: (a, b).
    edges: Vec<(Vec2, Vec2)>,
    /// Rings with edges near the cell: (ring: 0 the boundary, k obstacle k − 1; the reference
    /// inside it; its edges in `edges`).
    rings: Vec<(usize, bool, Range<usize>)>,
    /// The reference point is inside the boundary and outside the obstacles, as far as the
    /// rings without edges near the cell tell (every point of the cell with it).
    far_free: bool,
}

/// Cell states.
const UNKNOWN: u32 = 0;
const CLEAR: u32 = 1;
const BLOCKED: u32 = 2;
/// States from here on: near an edge, `locals[state - NEAR]`.
const NEAR: u32 = 3;

/// Cells per side of a block, whose edges within reach are found once for all its cells.
const BLOCK: usize = 8;

/// What one block of cells knows of the rings, found once for all its cells.
#[derive(Debug)]
struct Block {
    /// The edges of the rings within reach of the block, in ring order and edge order within
    /// a ring: (ring: 0 the boundary, k obstacle k − 1; a; b).
    edges: Vec<(usize, Vec2, Vec2)>,
    /// Per ring with no edge within reach: whether the block's centre is inside it, and so
    /// every point of the block's cells and of their discs (no edge of the ring comes near
    /// them, so none lies between them and the centre); `None` for the rings with edges
    /// within reach. (Asked per cell, the even-odd test ran over every vertex of the field:
    /// a third of the cost of the points checked.)
    inside: Vec<Option<bool>>,
}

type BlockEdges = std::rc::Rc<Block>;

/// [`implement_clear`] of one field and half width through a grid of cells.
pub(super) struct ClearMap<'a> {
    field: &'a Field,
    half: f64,
    origin: Vec2,
    cell: f64,
    nx: usize,
    ny: usize,
    /// `1 / cell`: a point's cell found by two products (a point on a cell's side, put in
    /// either cell by the rounding, lies within a micrometre of both cells' discs, and their
    /// states allow a micrometre).
    inv_cell: f64,
    /// Per cell, its state (a `Cell` each: one load per point, no borrow flag).
    state: Vec<std::cell::Cell<u32>>,
    locals: RefCell<Vec<Local>>,
    /// Per block (row-major, `nx.div_ceil(BLOCK)` a row): its edges and the rings it lies
    /// inside, `None` until first needed.
    blocks: RefCell<Vec<Option<BlockEdges>>>,
    /// The same per super-block of [`SUPER`] × [`SUPER`] blocks (row-major,
    /// `nx.div_ceil(BLOCK * SUPER)` a row): a block's edges are found among its super-block's,
    /// not among every edge of the field (a waypoint grid asks a new block at each node).
    supers: RefCell<Vec<Option<BlockEdges>>>,
}

/// Blocks per side of a super-block.
const SUPER: usize = 8;

impl<'a> ClearMap<'a> {
    /// At most this many grid cells (a few MB).
    const MAX_CELLS: f64 = 4.0e6;

    pub(super) fn new(field: &'a Field, half: f64) -> Self {
        let (lo, hi) = bbox(field.boundary.iter()).unwrap_or((v2(0.0, 0.0), v2(1.0, 1.0)));
        let span = hi - lo;
        let cell = (half.max(0.5)).max((span.x * span.y / Self::MAX_CELLS).sqrt());
        let nx = (span.x / cell).ceil() as usize + 1;
        let ny = (span.y / cell).ceil() as usize + 1;
        ClearMap {
            field,
            half,
            origin: lo,
            cell,
            nx,
            ny,
            inv_cell: 1.0 / cell,
            state: vec![std::cell::Cell::new(UNKNOWN); nx * ny],
            locals: RefCell::new(Vec::new()),
            blocks: RefCell::new(vec![None; nx.div_ceil(BLOCK) * ny.div_ceil(BLOCK)]),
            supers: RefCell::new(vec![
                None;
                nx.div_ceil(BLOCK * SUPER) * ny.div_ceil(BLOCK * SUPER)
            ]),
        }
    }

    /// Is the implement clear at `q` (inside the boundary, off the obstacles, `half` m from
    /// every edge)? The same answer as [`implement_clear`].
    pub(super) fn clear(&self, q: &Vec2) -> bool {
        let x = (q.x - self.origin.x) * self.inv_cell;
        let y = (q.y - self.origin.y) * self.inv_cell;
        // Off the grid (or not a number): outside the boundary's bounding box (the grid covers
        // it with a cell to spare), so outside the field. (Asked of the boundary's every edge,
        // the points of curves that swing out past the field's edge cost as much as the rest.)
        // On it, the cast truncates a non-negative coordinate, as `floor` would (without the
        // libm call per point).
        if !(x >= 0.0 && y >= 0.0 && (x as usize) < self.nx && (y as usize) < self.ny) {
            return false;
        }
        let (i, j) = (x as usize, y as usize);
        let k = j * self.nx + i;
        let known = self.state[k].get();
        let state = if known == UNKNOWN {
            let centre =
                self.origin + v2((i as f64 + 0.5) * self.cell, (j as f64 + 0.5) * self.cell);
            let s = self.classify(centre, &self.block_edges(i / BLOCK, j / BLOCK));
            self.state[k].set(s);
            s
        } else {
            known
        };
        match state {
            CLEAR => true,
            BLOCKED => false,
            s => self
                .locals
                .borrow()
                .get((s - NEAR) as usize)
                .is_none_or(|local| self.clear_near(local, q)),
        }
    }

    /// How far round `q` every point is as blocked as `q`, m, less a micrometre: 0 when `q` is
    /// clear; `half` less its distance to the nearest edge when that is under `half` (a point
    /// nearer than that to `q` is nearer than `half` to that edge, or across it); `half` when
    /// every edge is farther (a millimetre at least: `q` is then outside the field or in an
    /// obstacle, and a point nearer than `half` to it that is not lies across an edge, nearer
    /// than `half` to it). A lower bound: a transit that passes within it of `q` is blocked
    /// there (see [`super::rings`]).
    pub(super) fn blocked_margin(&self, q: &Vec2) -> f64 {
        if self.clear(q) {
            return 0.0;
        }
        let h = self.half - 1e-6;
        let x = (q.x - self.origin.x) * self.inv_cell;
        let y = (q.y - self.origin.y) * self.inv_cell;
        // Off the grid: outside the boundary's bounding box, so outside the field.
        if !(x >= 0.0 && y >= 0.0 && (x as usize) < self.nx && (y as usize) < self.ny) {
            return h;
        }
        // Every edge within `half` of `q` is on its block's list (within `half` of its cell's
        // centre plus the cell's half diagonal).
        let block = self.block_edges(x as usize / BLOCK, y as usize / BLOCK);
        let d = block
            .edges
            .iter()
            .map(|(_, a, b)| point_segment_distance(q, a, b))
            .fold(f64::INFINITY, f64::min);
        if d < h {
            h - d
        } else if d >= self.half + 1e-3 {
            h
        } else {
            0.0
        }
    }

    /// The edges within reach of block (`bi`, `bj`): every edge within `half + reach + 1e-6` of
    /// the centre of one of its cells (reach: the cell's half diagonal) is within `half` plus
    /// the block's half diagonal of the block's centre, since a cell's centre lies at most
    /// (BLOCK − 1) half cell diagonals from it.
    fn block_edges(&self, bi: usize, bj: usize) -> BlockEdges {
        let k = bj * self.nx.div_ceil(BLOCK) + bi;
        if let Some(Some(edges)) = self.blocks.borrow().get(k) {
            return edges.clone();
        }
        let half_block = BLOCK as f64 * 0.5 * self.cell;
        let centre = self.origin
            + v2(bi as f64, bj as f64) * (BLOCK as f64 * self.cell)
            + v2(half_block, half_block);
        // The block's half diagonal, a millimetre wider for rounding.
        let within = self.half + half_block * std::f64::consts::SQRT_2 + 1e-3;
        // Every edge within `within` of the block's centre is on its super-block's list (the
        // block's centre lies within the super-block's half diagonal less the block's of the
        // super-block's centre), in the same order; a ring with no edge on that list has none
        // between the two centres, so the block's centre is inside it when the super-block's is.
        let sup = self.super_edges(bi / SUPER, bj / SUPER);
        let rings = std::iter::once(&self.field.boundary).chain(self.field.obstacles.iter());
        let mut edges = Vec::new();
        let mut inside = Vec::new();
        let mut next = 0;
        for (r, ring) in rings.enumerate() {
            if let Some(known) = sup.inside.get(r).copied().flatten() {
                inside.push(Some(known));
                continue;
            }
            let before = edges.len();
            while let Some(&(_, a, b)) = sup.edges.get(next).filter(|e| e.0 == r) {
                next += 1;
                if point_segment_distance(&centre, &a, &b) <= within {
                    edges.push((r, a, b));
                }
            }
            inside.push((edges.len() == before).then(|| contains_point(ring, &centre)));
        }
        let edges: BlockEdges = std::rc::Rc::new(Block { edges, inside });
        if let Some(slot) = self.blocks.borrow_mut().get_mut(k) {
            *slot = Some(edges.clone());
        }
        edges
    }

    /// The edges within reach of super-block (`si`, `sj`) (every edge within `half` plus its
    /// half diagonal of its centre, a millimetre wider) and the rings with none of them that
    /// its centre is inside, as [`Self::block_edges`] for a block.
    fn super_edges(&self, si: usize, sj: usize) -> BlockEdges {
        let k = sj * self.nx.div_ceil(BLOCK * SUPER) + si;
        if let Some(Some(edges)) = self.supers.borrow().get(k) {
            return edges.clone();
        }
        let half_super = (BLOCK * SUPER) as f64 * 0.5 * self.cell;
        let centre = self.origin
            + v2(si as f64, sj as f64) * ((BLOCK * SUPER) as f64 * self.cell)
            + v2(half_super, half_super);
        let within = self.half + half_super * std::f64::consts::SQRT_2 + 2e-3;
        let rings = std::iter::once(&self.field.boundary).chain(self.field.obstacles.iter());
        let mut edges = Vec::new();
        let mut inside = Vec::new();
        for (r, ring) in rings.enumerate() {
            let n = ring.len();
            let before = edges.len();
            for e in 0..n {
                let (a, b) = (ring[e], ring[(e + 1) % n]);
                if point_segment_distance(&centre, &a, &b) <= within {
                    edges.push((r, a, b));
                }
            }
            inside.push((edges.len() == before).then(|| contains_point(ring, &centre)));
        }
        let edges: BlockEdges = std::rc::Rc::new(Block { edges, inside });
        if let Some(slot) = self.supers.borrow_mut().get_mut(k) {
            *slot = Some(edges.clone());
        }
        edges
    }

    /// The state of the cell about `centre`, whose block is `block`
    /// ([`Self::block_edges`]).
    fn classify(&self, centre: Vec2, block: &Block) -> u32 {
        // Is `p` (of the cell's disc) inside ring `r`: the block's answer where it has one.
        let inside_of = |r: usize, ring: &[Vec2], p: &Vec2| {
            block
                .inside
                .get(r)
                .copied()
                .flatten()
                .unwrap_or_else(|| contains_point(ring, p))
        };
        let block = &block.edges;
        // Every point of the cell lies within `reach` of its centre.
        let reach = self.cell * std::f64::consts::FRAC_1_SQRT_2;
        // implement_clear(field, half + reach, centre); the edges off the block's list are
        // farther than that from the centre.
        let clear_of_edges = block
            .iter()
            .all(|(_, a, b)| point_segment_distance(&centre, a, b) >= self.half + reach - 1e-6);
        let free = || {
            inside_of(0, &self.field.boundary, &centre)
                && self
                    .field
                    .obstacles
                    .iter()
                    .enumerate()
                    .all(|(k, o)| !inside_of(k + 1, o, &centre))
        };
        if clear_of_edges && free() {
            return CLEAR;
        }
        // Blocked throughout (a point of a blocked curve is most often in such a cell, near an
        // edge: one lookup instead of its distances to the edges near it): the centre within
        // `half - reach` of an edge, so every point of the cell within `half` of it; or the
        // centre farther than that from every edge (a millimetre at least, so its side of each
        // ring is sure) and outside the field or inside an obstacle, so a point of the cell
        // that is inside the field and off the obstacles lies across an edge from the centre,
        // within `reach` (< `half`) of that edge.
        if reach <= self.half - 1e-3 {
            let within = self.half - reach - 1e-5;
            if block
                .iter()
                .any(|(_, a, b)| point_segment_distance(&centre, a, b) <= within)
                || !free()
            {
                return BLOCKED;
            }
        }
        let rings = std::iter::once(&self.field.boundary).chain(self.field.obstacles.iter());
        let mut edges = Vec::new();
        let mut near_rings = Vec::new();
        let mut far: Vec<(usize, &Vec<Vec2>)> = Vec::new();
        let mut next = 0;
        for (r, ring) in rings.enumerate() {
            let start = edges.len();
            // Edges a point of the cell could come within `half` of, or cross on its way to
            // the reference point (both within `reach` of the centre): of this ring's edges
            // on the block's list (the others are farther).
            while let Some(&(_, a, b)) = block.get(next).filter(|e| e.0 == r) {
                next += 1;
                if point_segment_distance(&centre, &a, &b) <= self.half + reach + 1e-6 {
                    edges.push((a, b));
                }
            }
            if edges.len() > start {
                near_rings.push((r, ring, start..edges.len()));
            } else {
                far.push((r, ring));
            }
        }
        if edges.is_empty() {
            // No edge within reach and not clear at the centre: outside the field or inside an
            // obstacle throughout.
            return BLOCKED;
        }
        // A reference point on no edge (the centre, else a point nearby within the disc).
        let off_edges = |p: &Vec2| {
            edges
                .iter()
                .all(|(a, b)| point_segment_distance(p, a, b) > 1e-6 * (1.0 + self.cell))
        };
        let reference = (0..8)
            .map(|t| {
                let angle = 0.7 + t as f64 * 0.9;
                centre + v2(angle.cos(), angle.sin()) * (t as f64 * 0.08 * reach)
            })
            .find(off_edges);
        let Some(reference) = reference else {
            // Nowhere to stand: check every point against every edge.
            return self.push_local(Local {
                reference: centre,
                edges: Vec::new(),
                rings: Vec::new(),
                far_free: false,
            });
        };
        let free_of = |r: usize, ring: &Vec<Vec2>| {
            let inside = inside_of(r, ring, &reference);
            if r == 0 {
                inside
            } else {
                !inside
            }
        };
        let far_free = far.iter().all(|&(r, ring)| free_of(r, ring));
        let rings = near_rings
            .into_iter()
            .map(|(r, ring, range)| (r, contains_point(ring, &reference), range))
            .collect();
        self.push_local(Local {
            reference,
            edges,
            rings,
            far_free,
        })
    }

    fn push_local(&self, local: Local) -> u32 {
        let mut locals = self.locals.borrow_mut();
        locals.push(local);
        NEAR + (locals.len() - 1) as u32
    }

    /// [`implement_clear`] at `q` in a cell near an edge.
    fn clear_near(&self, local: &Local, q: &Vec2) -> bool {
        if local.rings.is_empty() {
            return implement_clear(self.field, self.half, q);
        }
        if !local.far_free {
            return false;
        }
        if local
            .edges
            .iter()
            .any(|(a, b)| point_segment_distance(q, a, b) < self.half - 1e-6)
        {
            return false;
        }
        // The side of each near ring: the reference's, flipped by every edge crossed on the
        // segment from `q` to it. Neither end lies on an edge; a vertex on the segment's line
        // counts on one side only (the half-open rule), so a touch counts twice or not at all.
        let r = local.reference;
        let above = |p: &Vec2| cross(&(r - q), &(p - q)) > 0.0;
        local.rings.iter().all(|(ring, inside, range)| {
            let crossings = local.edges[range.clone()]
                .iter()
                .filter(|(a, b)| {
                    above(a) != above(b)
                        && (cross(&(b - a), &(q - a)) > 0.0) != (cross(&(b - a), &(r - a)) > 0.0)
                })
                .count();
            let inside_q = *inside != (crossings % 2 == 1);
            if *ring == 0 {
                inside_q
            } else {
                !inside_q
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A concave field (a notch from the north-east) with one obstacle.
    fn concave_field_with_obstacle() -> Field {
        Field {
            boundary: vec![
                v2(0.0, 0.0),
                v2(120.0, 0.0),
                v2(120.0, 80.0),
                v2(70.0, 30.0),
                v2(40.0, 90.0),
                v2(0.0, 60.0),
            ],
            obstacles: vec![vec![
                v2(20.0, 20.0),
                v2(35.0, 22.0),
                v2(30.0, 35.0),
                v2(18.0, 30.0),
            ]],
        }
    }

    /// The map answers as [`implement_clear`] does, point for point, on a concave field with
    /// an obstacle, near its edges and vertices and outside it.
    #[test]
    fn the_map_agrees_with_the_direct_check() {
        let field = concave_field_with_obstacle();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for half in [0.7, 3.0, 9.0] {
            let map = ClearMap::new(&field, half);
            let mut disagree = 0;
            let mut clear = 0;
            for _ in 0..20_000 {
                let q = v2(rng.gen_range(-10.0..130.0), rng.gen_range(-10.0..100.0));
                let want = implement_clear(&field, half, &q);
                clear += usize::from(want);
                disagree += usize::from(map.clear(&q) != want);
            }
            assert_eq!(disagree, 0, "half {half}");
            assert!(clear > 2_000, "half {half}: {clear} clear points");
            // Some cells near the edges were checked through their local edges.
            assert!(!map.locals.borrow().is_empty());
        }
    }

    /// The field of a failing case of tests/plan/plan_guarantees.rs (a star with a square hole).
    #[test]
    fn the_map_agrees_on_a_star_with_a_hole() {
        let size = 155.29840172620393;
        let pts = [
            (0.42661870111364264, 0.7),
            (0.0, 0.7),
            (0.0, 0.8400777438246129),
            (0.0, 0.7),
            (0.274301038943484, 0.938672995133783),
            (0.5580423271939455, 0.8763936199343776),
        ];
        let n = pts.len() as f64;
        let boundary: Vec<Vec2> = pts
            .iter()
            .enumerate()
            .map(|(i, (u, r))| {
                let a = std::f64::consts::TAU * (i as f64 + 0.05 + 0.9 * u) / n;
                v2(size * r * a.cos(), size * r * a.sin())
            })
            .collect();
        let a = std::f64::consts::TAU * 0.8947645902365421;
        let (cx, cy, h) = (
            size * 0.12 * a.cos(),
            size * 0.12 * a.sin(),
            size * 0.0250323140638256,
        );
        let field = Field {
            boundary,
            obstacles: vec![vec![
                v2(cx - h, cy - h),
                v2(cx + h, cy - h),
                v2(cx + h, cy + h),
                v2(cx - h, cy + h),
            ]],
        };
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for half in [1.5, 16.98, 17.0, 17.1] {
            let map = ClearMap::new(&field, half);
            let mut disagree = Vec::new();
            for _ in 0..100_000 {
                let q = v2(rng.gen_range(-160.0..160.0), rng.gen_range(-160.0..160.0));
                if map.clear(&q) != implement_clear(&field, half, &q) {
                    disagree.push(q);
                }
            }
            assert!(
                disagree.is_empty(),
                "half {half}: {} {:?}",
                disagree.len(),
                &disagree[..disagree.len().min(5)]
            );
        }
    }

    /// Near the edges, where the cells blocked throughout are (within `half` less a cell's
    /// half diagonal of an edge, or outside the field or inside an obstacle): the map answers
    /// as [`implement_clear`] does at points within two half widths of an edge on either
    /// side, and most of the points it finds not clear there it finds in such cells.
    #[test]
    fn the_map_agrees_near_the_edges() {
        let field = concave_field_with_obstacle();
        let rings: Vec<&Vec<Vec2>> = std::iter::once(&field.boundary)
            .chain(field.obstacles.iter())
            .collect();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for half in [0.6, 1.5, 1.72, 3.0, 9.0] {
            let map = ClearMap::new(&field, half);
            let (mut disagree, mut blocked, mut in_blocked_cells) = (0, 0, 0);
            for _ in 0..40_000 {
                let ring = rings[rng.gen_range(0..rings.len())];
                let i = rng.gen_range(0..ring.len());
                let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
                let along = a + (b - a) * rng.gen_range(-0.05..1.05);
                let normal = crate::geo::left_normal(&(b - a).normalize());
                let q = along + normal * rng.gen_range(-2.0 * half..2.0 * half);
                let want = implement_clear(&field, half, &q);
                disagree += usize::from(map.clear(&q) != want);
                if !want {
                    blocked += 1;
                    let x = ((q.x - map.origin.x) * map.inv_cell) as usize;
                    let y = ((q.y - map.origin.y) * map.inv_cell) as usize;
                    let state = map.state.get(y * map.nx + x).map(|c| c.get());
                    in_blocked_cells += usize::from(state == Some(BLOCKED));
                }
            }
            assert_eq!(disagree, 0, "half {half}");
            assert!(
                2 * in_blocked_cells > blocked,
                "half {half}: {in_blocked_cells} of {blocked} in cells blocked throughout"
            );
        }
    }
}
