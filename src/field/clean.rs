//! Boundary ring clean-up: duplicates, collinear points, arcs of short edges replaced by
//! regression-fitted straight segments (seed 001), orientation.

use crate::envelope;
use crate::geo::polygon::{make_ccw, point_segment_distance, self_intersection, signed_area};
use crate::geo::{cross, Vec2};

/// Points closer than this are duplicates, m.
const DUPLICATE_M: f64 = 1e-3;
/// A point closer than this to the segment joining its neighbours is collinear, m.
const COLLINEAR_M: f64 = 1e-3;
/// Samples per fitted stretch for the line regression.
const FIT_SAMPLES: usize = 16;

/// Result of [`clean_ring`].
#[derive(Debug, Clone, PartialEq)]
pub struct RingCleanup {
    /// The cleaned ring, CCW, not closed. Empty-ish (fewer than 3 points) when the input had
    /// fewer than 3 distinct points.
    pub ring: Vec<Vec2>,
    /// Distinct points of the input.
    pub distinct_points: usize,
    pub duplicates_removed: usize,
    pub collinear_removed: usize,
    pub fitted_removed: usize,
    pub reoriented: bool,
    /// |area| of the input ring after dropping duplicates, m².
    pub area_before_m2: f64,
    /// |area| of the cleaned ring, m².
    pub area_after_m2: f64,
    /// Edges (indices into the de-duplicated input) that intersect, if the ring is not simple.
    pub self_intersection: Option<(usize, usize)>,
}

fn dedupe(ring: &[Vec2]) -> Vec<Vec2> {
    let mut out: Vec<Vec2> = Vec::with_capacity(ring.len());
    for p in ring {
        if out.last().is_none_or(|q| (p - q).norm() > DUPLICATE_M) {
            out.push(*p);
        }
    }
    while out.len() > 1 && (out[0] - out[out.len() - 1]).norm() <= DUPLICATE_M {
        out.pop();
    }
    out
}

fn drop_collinear(ring: &mut Vec<Vec2>) -> usize {
    let mut removed = 0;
    let mut i = 0;
    while ring.len() > 3 && i < ring.len() {
        let n = ring.len();
        let prev = ring[(i + n - 1) % n];
        let next = ring[(i + 1) % n];
        let p = ring[i];
        let between = (p - prev).dot(&(next - p)) > 0.0;
        if between && point_segment_distance(&p, &prev, &next) < COLLINEAR_M {
            ring.remove(i);
            removed += 1;
            i = i.saturating_sub(1);
        } else {
            i += 1;
        }
    }
    removed
}

/// Douglas–Peucker on a closed ring: which vertices to keep.
fn douglas_peucker(ring: &[Vec2], tolerance: f64) -> Vec<bool> {
    let n = ring.len();
    let mut keep = vec![false; n];
    let far = (1..n)
        .max_by(|&a, &b| {
            let da = (ring[a] - ring[0]).norm();
            let db = (ring[b] - ring[0]).norm();
            da.total_cmp(&db)
        })
        .unwrap_or(0);
    keep[0] = true;
    keep[far] = true;
    // Ranges over indices 0..=n where n stands for 0 again.
    let mut stack = vec![(0usize, far), (far, n)];
    while let Some((a, b)) = stack.pop() {
        if b <= a + 1 {
            continue;
        }
        let (pa, pb) = (ring[a % n], ring[b % n]);
        let (mut best, mut best_d) = (a, -1.0);
        for (k, p) in ring.iter().enumerate().take(b).skip(a + 1) {
            let d = point_segment_distance(p, &pa, &pb);
            if d > best_d {
                best = k;
                best_d = d;
            }
        }
        if best_d > tolerance {
            keep[best] = true;
            stack.push((a, best));
            stack.push((best, b));
        }
    }
    keep
}

/// Total-least-squares line through evenly spaced samples of a polyline: (centroid, unit
/// direction).
fn fit_line(points: &[Vec2]) -> (Vec2, Vec2) {
    let total: f64 = points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    let mut samples = Vec::with_capacity(FIT_SAMPLES + 1);
    let step = total / FIT_SAMPLES as f64;
    let mut seg = 0;
    let mut seg_start = 0.0;
    for k in 0..=FIT_SAMPLES {
        let s = step * k as f64;
        while seg + 1 < points.len() - 1 && seg_start + (points[seg + 1] - points[seg]).norm() < s {
            seg_start += (points[seg + 1] - points[seg]).norm();
            seg += 1;
        }
        let len = (points[seg + 1] - points[seg]).norm();
        let t = if len > 0.0 {
            ((s - seg_start) / len).clamp(0.0, 1.0)
        } else {
            0.0
        };
        samples.push(points[seg] + (points[seg + 1] - points[seg]) * t);
    }
    let c = samples.iter().sum::<Vec2>() / samples.len() as f64;
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for p in &samples {
        let d = p - c;
        sxx += d.x * d.x;
        syy += d.y * d.y;
        sxy += d.x * d.y;
    }
    let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let mut dir = Vec2::new(angle.cos(), angle.sin());
    let chord = points[points.len() - 1] - points[0];
    if dir.dot(&chord) < 0.0 {
        dir = -dir;
    }
    (c, dir)
}

/// Replace stretches between Douglas–Peucker vertices that hold more than one dropped point
/// by regression lines, and intersect neighbouring lines for the new vertices. Falls back to
/// the Douglas–Peucker vertex where neighbouring lines are near-parallel or meet far away.
fn fit_stretches(ring: &[Vec2], keep: &[bool], tolerance: f64) -> Vec<Vec2> {
    let n = ring.len();
    let kept: Vec<usize> = (0..n).filter(|&i| keep[i]).collect();
    let m = kept.len();
    let lines: Vec<(Vec2, Vec2)> = (0..m)
        .map(|j| {
            let a = kept[j];
            let b = if j + 1 < m { kept[j + 1] } else { kept[0] + n };
            let stretch: Vec<Vec2> = (a..=b).map(|k| ring[k % n]).collect();
            if stretch.len() > 3 {
                fit_line(&stretch)
            } else {
                let d = ring[b % n] - ring[a];
                (ring[a], d / d.norm().max(f64::MIN_POSITIVE))
            }
        })
        .collect();
    (0..m)
        .map(|j| {
            let (c0, d0) = lines[(j + m - 1) % m];
            let (c1, d1) = lines[j];
            let fallback = ring[kept[j]];
            let denom = cross(&d0, &d1);
            if denom.abs() < 1e-3 {
                return fallback;
            }
            let t = cross(&(c1 - c0), &d1) / denom;
            let p = c0 + d0 * t;
            if (p - fallback).norm() > 2.0 * tolerance.max(1e-9) {
                fallback
            } else {
                p
            }
        })
        .collect()
}

/// Clean one ring (local metres). `tolerance` is the largest distance of a dropped point from
/// the Douglas–Peucker simplification the fitted segments start from, m; 0 disables fitting.
pub fn clean_ring(ring: &[Vec2], tolerance: f64) -> RingCleanup {
    let mut work = dedupe(ring);
    let distinct_points = work.len();
    let mut out = RingCleanup {
        ring: Vec::new(),
        distinct_points,
        duplicates_removed: ring.len() - distinct_points,
        collinear_removed: 0,
        fitted_removed: 0,
        reoriented: false,
        area_before_m2: 0.0,
        area_after_m2: 0.0,
        self_intersection: None,
    };
    if work.len() < 3 {
        out.ring = work;
        return out;
    }
    out.area_before_m2 = signed_area(&work).abs();
    if work.len() > envelope::SIMPLIFY_ABOVE_POINTS {
        // The checks below are quadratic: a large ring is simplified first, within the
        // tolerance (a map's rings, cleaned without fitting, within 1 cm).
        let tol = if tolerance > 0.0 {
            tolerance
        } else {
            envelope::MAP_SIMPLIFY_TOLERANCE_M
        };
        let keep = douglas_peucker(&work, tol);
        let before = work.len();
        work = (0..before).filter(|&i| keep[i]).map(|i| work[i]).collect();
        out.fitted_removed = before - work.len();
        if work.len() > envelope::MAX_RING_POINTS {
            // Refused by the caller (too many points); not checked here.
            out.ring = work;
            return out;
        }
    }
    out.self_intersection = self_intersection(&work);
    if out.self_intersection.is_some() {
        out.ring = work;
        return out;
    }
    out.collinear_removed = drop_collinear(&mut work);
    if tolerance > 0.0 && work.len() > 3 {
        let keep = douglas_peucker(&work, tolerance);
        let simplified: Vec<Vec2> = (0..work.len())
            .filter(|&i| keep[i])
            .map(|i| work[i])
            .collect();
        let fitted = fit_stretches(&work, &keep, tolerance);
        let chosen = if fitted.len() >= 3 && self_intersection(&fitted).is_none() {
            fitted
        } else {
            simplified
        };
        if chosen.len() >= 3 && self_intersection(&chosen).is_none() {
            out.fitted_removed += work.len() - chosen.len();
            work = chosen;
        }
    }
    out.reoriented = signed_area(&work) < 0.0;
    make_ccw(&mut work);
    out.area_after_m2 = signed_area(&work).abs();
    out.ring = work;
    out
}

#[cfg(test)]
pub(crate) mod tests_support {
    use super::*;

    /// The Douglas–Peucker ring alone (chords, no regression fit).
    pub fn dp(ring: &[Vec2], tolerance: f64) -> Vec<Vec2> {
        let keep = douglas_peucker(ring, tolerance);
        (0..ring.len())
            .filter(|&i| keep[i])
            .map(|i| ring[i])
            .collect()
    }
}
