//! Decomposition of a concave working area (seed 001): cut at reflex vertices into convex
//! cells, then merge adjacent cells whose union is still swept by single swaths at no more
//! swaths than the two apart. A convex area stays one cell.

use super::geometry::{from_geo, rotate_area, scan_intervals, to_geo, Area};
use super::headland::has_reflex_vertex;
use super::swath_angle::min_span;
use crate::geo::{cross, Vec2};
use geo::BooleanOps;

/// The cells of the working area `working` with their swath angles (rad): every area at the
/// field's angle (`field.swath_angle` fixed, or the minimum span of the whole working area),
/// or cut into convex cells merged where single swaths still sweep them, each at its own
/// minimum span (`min_turns`); then each piece of `own` ([`super::leftover::Worked::own`]) at
/// its own minimum span, last.
pub fn cells(working: &[Area], own: &[Area], p: &super::CoverageParams) -> Vec<(Area, f64)> {
    use super::SwathAngle;
    let own_angle = |a: &Area| min_span(&a.0).map_or(0.0, |s| s.0);
    let global_angle = match p.swath_angle {
        SwathAngle::Fixed { angle } => Some(angle),
        SwathAngle::MinSpan => {
            let pts: Vec<Vec2> = working.iter().flat_map(|a| a.0.iter().copied()).collect();
            min_span(&pts).map(|s| s.0)
        }
        SwathAngle::MinTurns => None,
    };
    let mut cells: Vec<(Area, f64)> = Vec::new();
    for area in working {
        match global_angle {
            Some(a) => cells.push((area.clone(), a)),
            None => {
                let pieces: Vec<Area> = convex_cells(&area.0)
                    .into_iter()
                    .flat_map(|c| from_geo(&to_geo(&(c, vec![])).intersection(&to_geo(area))))
                    .collect();
                for c in merge_cells(pieces, p.pass_spacing()) {
                    let a = own_angle(&c);
                    cells.push((c, a));
                }
            }
        }
    }
    cells.extend(own.iter().map(|a| (a.clone(), own_angle(a))));
    cells
}

/// Largest number of cuts made (a guard against degenerate input).
const MAX_CUTS: usize = 256;

/// First hit of the ray `o + t·d` (t > 0) on `ring`, skipping edges that touch vertex `skip`:
/// (t, edge index, parameter along the edge).
fn ray_hit(ring: &[Vec2], o: &Vec2, d: &Vec2, skip: usize) -> Option<(f64, usize, f64)> {
    let n = ring.len();
    let mut best: Option<(f64, usize, f64)> = None;
    for j in 0..n {
        if j == skip || (j + 1) % n == skip {
            continue;
        }
        let (a, b) = (ring[j], ring[(j + 1) % n]);
        let e = b - a;
        let den = cross(d, &e);
        if den.abs() < 1e-12 {
            continue;
        }
        let w = a - o;
        let t = cross(&w, &e) / den;
        let u = cross(&w, d) / den;
        if t > 1e-9 && (-1e-9..=1.0 + 1e-9).contains(&u) && best.is_none_or(|b| t < b.0) {
            best = Some((t, j, u.clamp(0.0, 1.0)));
        }
    }
    best
}

/// Split `ring` (CCW) along a cut from vertex `i` to the point at parameter `u` on edge `j`.
fn split(ring: &[Vec2], i: usize, j: usize, u: f64) -> (Vec<Vec2>, Vec<Vec2>) {
    let n = ring.len();
    let q = ring[j] + (ring[(j + 1) % n] - ring[j]) * u;
    let mut a = vec![ring[i]];
    let mut k = (i + 1) % n;
    while k != (j + 1) % n {
        a.push(ring[k]);
        k = (k + 1) % n;
    }
    a.push(q);
    let mut b = vec![q];
    let mut k = (j + 1) % n;
    while k != i {
        b.push(ring[k]);
        k = (k + 1) % n;
    }
    b.push(ring[i]);
    let clean = |mut r: Vec<Vec2>| {
        r.dedup_by(|x, y| (*x - *y).norm() < 1e-6);
        if r.len() > 1 && (r[0] - r[r.len() - 1]).norm() < 1e-6 {
            r.pop();
        }
        r
    };
    (clean(a), clean(b))
}

/// Convex cells of a simple counter-clockwise ring: at each reflex vertex the two edges are
/// extended into the area; the cut that reaches another reflex vertex is preferred, else the
/// longest. Recursive until no reflex vertex is left.
pub fn convex_cells(ring: &[Vec2]) -> Vec<Vec<Vec2>> {
    let mut todo = vec![ring.to_vec()];
    let mut done = Vec::new();
    let mut cuts = 0;
    while let Some(r) = todo.pop() {
        let n = r.len();
        if n < 3 {
            continue;
        }
        if !has_reflex_vertex(&r) || cuts >= MAX_CUTS {
            done.push(r);
            continue;
        }
        let reflex: Vec<usize> = (0..n)
            .filter(|&i| {
                let (a, b, c) = (r[(i + n - 1) % n], r[i], r[(i + 1) % n]);
                cross(&(b - a), &(c - b)) < -1e-9
            })
            .collect();
        // (score, vertex, edge, parameter): reaching a reflex vertex beats any length.
        let mut best: Option<(f64, usize, usize, f64)> = None;
        for &i in &reflex {
            let (a, b, c) = (r[(i + n - 1) % n], r[i], r[(i + 1) % n]);
            for d in [(b - a).normalize(), (b - c).normalize()] {
                let Some((t, j, u)) = ray_hit(&r, &b, &d, i) else {
                    continue;
                };
                let q = r[j] + (r[(j + 1) % n] - r[j]) * u;
                let at_reflex = reflex.iter().any(|&k| k != i && (r[k] - q).norm() < 1e-6);
                let score = t + if at_reflex { 1e9 } else { 0.0 };
                if best.is_none_or(|x| score > x.0) {
                    best = Some((score, i, j, u));
                }
            }
        }
        match best {
            Some((_, i, j, u)) => {
                let (a, b) = split(&r, i, j, u);
                cuts += 1;
                todo.push(a);
                todo.push(b);
            }
            None => done.push(r),
        }
    }
    done
}

/// Swaths a cell needs at its best direction, and whether every scan line across it at that
/// direction meets it in one piece (so it can be swept by single swaths).
pub fn swath_need(cell: &Area, line_width: f64) -> Option<(f64, usize, bool)> {
    let (angle, span) = min_span(&cell.0)?;
    let n = (span / line_width - 1e-9).ceil().max(1.0) as usize;
    let rot = rotate_area(cell, -angle);
    let (lo, hi) = rot
        .0
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p.y), h.max(p.y))
        });
    let steps = ((hi - lo) / (line_width / 4.0)).ceil().max(1.0) as usize;
    let single = (1..steps).all(|k| {
        let y = lo + (hi - lo) * k as f64 / steps as f64;
        scan_intervals(&rot, y).len() <= 1
    });
    Some((angle, n, single))
}

/// Merge adjacent cells (sharing part of an edge) while the union is still swept by single
/// swaths and needs no more swaths than the two apart.
pub fn merge_cells(mut cells: Vec<Area>, line_width: f64) -> Vec<Area> {
    loop {
        let mut merged = false;
        'outer: for i in 0..cells.len() {
            for j in i + 1..cells.len() {
                let (Some((_, ni, _)), Some((_, nj, _))) = (
                    swath_need(&cells[i], line_width),
                    swath_need(&cells[j], line_width),
                ) else {
                    continue;
                };
                let u = to_geo(&cells[i]).union(&to_geo(&cells[j]));
                let parts = from_geo(&u);
                if parts.len() != 1 || !parts[0].1.is_empty() {
                    continue;
                }
                let Some((_, nu, single)) = swath_need(&parts[0], line_width) else {
                    continue;
                };
                if single && nu <= ni + nj {
                    cells[i] = parts[0].clone();
                    cells.remove(j);
                    merged = true;
                    break 'outer;
                }
            }
        }
        if !merged {
            return cells;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;

    #[test]
    fn l_shape_cuts_into_two_convex_cells_and_convex_stays_whole() {
        let l = vec![
            v2(0.0, 0.0),
            v2(200.0, 0.0),
            v2(200.0, 100.0),
            v2(100.0, 100.0),
            v2(100.0, 200.0),
            v2(0.0, 200.0),
        ];
        let cells = convex_cells(&l);
        assert_eq!(cells.len(), 2);
        let total: f64 = cells
            .iter()
            .map(|c| crate::geo::polygon::signed_area(c))
            .sum();
        assert!((total - 30_000.0).abs() < 1e-6);
        assert!(cells.iter().all(|c| !has_reflex_vertex(c)));
        let sq = vec![v2(0.0, 0.0), v2(10.0, 0.0), v2(10.0, 10.0), v2(0.0, 10.0)];
        assert_eq!(convex_cells(&sq).len(), 1);
        // Swept along x, the L needs 17 swaths of 12 m, the two cells 9 + 9: they merge.
        let areas: Vec<Area> = cells.into_iter().map(|c| (c, vec![])).collect();
        let merged = merge_cells(areas.clone(), 12.0);
        assert_eq!(merged.len(), 1);
        assert_eq!(
            swath_need(&merged[0], 12.0).map(|s| (s.1, s.2)),
            Some((17, true))
        );
        // A U does not: across its arms a scan line meets it twice.
        let u = vec![
            v2(0.0, 0.0),
            v2(300.0, 0.0),
            v2(300.0, 200.0),
            v2(200.0, 200.0),
            v2(200.0, 60.0),
            v2(100.0, 60.0),
            v2(100.0, 200.0),
            v2(0.0, 200.0),
        ];
        let cells: Vec<Area> = convex_cells(&u).into_iter().map(|c| (c, vec![])).collect();
        assert!(cells.len() >= 3);
        let merged = merge_cells(cells, 12.0);
        assert!(merged.len() >= 2, "{}", merged.len());
        assert!(merged
            .iter()
            .all(|c| swath_need(c, 12.0).is_some_and(|s| s.2)));
    }
}
