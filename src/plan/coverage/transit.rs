//! Transits between cells, runs and headland passes: the shortest Dubins curve-straight-curve
//! (LSL, RSR, LSR, RSL) with radius r_min whose points keep clear of the field edge and the
//! obstacles, so every transit is driveable forward (curvature ≤ 1/r_min).

use crate::geo::{heading_vec, left_normal, wrap_angle, Vec2};
use std::f64::consts::TAU;

/// Points of the Dubins CSC path from (`p1`, heading `h1`) to (`p2`, heading `h2`) with turn
/// senses `s1`, `s2` (+1 left, −1 right), about `step` m apart; `None` when the word has no
/// solution. Returns (length m, points).
#[allow(clippy::too_many_arguments)]
fn csc(
    p1: Vec2,
    h1: f64,
    p2: Vec2,
    h2: f64,
    s1: f64,
    s2: f64,
    r: f64,
    step: f64,
) -> Option<(f64, Vec<Vec2>)> {
    let c1 = p1 + left_normal(&heading_vec(h1)) * (s1 * r);
    let c2 = p2 + left_normal(&heading_vec(h2)) * (s2 * r);
    let d = c2 - c1;
    let dist = d.norm();
    // Tangent direction of the straight.
    let theta = if s1 == s2 {
        if dist < 1e-9 {
            return None;
        }
        d.y.atan2(d.x)
    } else {
        if dist < 2.0 * r {
            return None;
        }
        let alpha = (2.0 * r / dist).asin();
        d.y.atan2(d.x) + s1 * alpha
    };
    let sweep = |from: f64, to: f64, s: f64| {
        let a = wrap_angle(to - from) * s;
        if a < -1e-9 {
            a + TAU
        } else {
            a.max(0.0)
        }
    };
    let a1 = sweep(h1, theta, s1);
    let a2 = sweep(theta, h2, s2);
    // Tangent points.
    let t1 = c1 - left_normal(&heading_vec(theta)) * (s1 * r);
    let t2 = c2 - left_normal(&heading_vec(theta)) * (s2 * r);
    let straight = (t2 - t1).norm();
    if (t2 - t1).dot(&heading_vec(theta)) < -1e-6 {
        return None;
    }
    let mut pts = Vec::new();
    let arc = |c: Vec2, h0: f64, sweep: f64, s: f64, pts: &mut Vec<Vec2>| {
        let n = ((sweep * r) / step).ceil().max(1.0) as usize;
        for i in 0..=n {
            let h = h0 + s * sweep * i as f64 / n as f64;
            pts.push(c - left_normal(&heading_vec(h)) * (s * r));
        }
    };
    arc(c1, h1, a1, s1, &mut pts);
    let n = (straight / step).ceil().max(1.0) as usize;
    for i in 1..n {
        pts.push(t1 + (t2 - t1) * (i as f64 / n as f64));
    }
    arc(c2, theta, a2, s2, &mut pts);
    if let Some(last) = pts.last_mut() {
        *last = p2;
    }
    Some((r * (a1 + a2) + straight, pts))
}

/// The shortest CSC transit for which `clear` holds at every point, else the shortest one
/// (`false` second element).
pub fn transit(
    p1: Vec2,
    h1: f64,
    p2: Vec2,
    h2: f64,
    r: f64,
    step: f64,
    clear: &dyn Fn(&Vec2) -> bool,
) -> Option<(Vec<Vec2>, bool)> {
    let mut cands: Vec<(f64, Vec<Vec2>)> = [(1.0, 1.0), (-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0)]
        .iter()
        .filter_map(|&(a, b)| csc(p1, h1, p2, h2, a, b, r, step))
        .collect();
    cands.sort_by(|a, b| a.0.total_cmp(&b.0));
    let first = cands.first().map(|c| c.1.clone())?;
    for (_, pts) in &cands {
        if pts.iter().all(clear) {
            return Some((pts.clone(), true));
        }
    }
    Some((first, false))
}

/// Like [`transit`], but when no direct curve is clear, through one of `waypoints` (tried
/// nearest the way first, each with eight headings): two clear curves back to back.
#[allow(clippy::too_many_arguments)]
pub fn route(
    p1: Vec2,
    h1: f64,
    p2: Vec2,
    h2: f64,
    r: f64,
    step: f64,
    clear: &dyn Fn(&Vec2) -> bool,
    waypoints: &[Vec2],
) -> Option<(Vec<Vec2>, bool)> {
    let direct = transit(p1, h1, p2, h2, r, step, clear)?;
    if direct.1 {
        return Some(direct);
    }
    let mut order: Vec<&Vec2> = waypoints.iter().collect();
    order.sort_by(|a, b| {
        let da = (*a - p1).norm() + (p2 - *a).norm();
        let db = (*b - p1).norm() + (p2 - *b).norm();
        da.total_cmp(&db)
    });
    for w in order.into_iter().take(60) {
        for k in 0..8 {
            let hw = k as f64 * std::f64::consts::FRAC_PI_4;
            let Some((a, true)) = transit(p1, h1, *w, hw, r, step, clear) else {
                continue;
            };
            let Some((b, true)) = transit(*w, hw, p2, h2, r, step, clear) else {
                continue;
            };
            let mut pts = a;
            pts.extend(b.into_iter().skip(1));
            return Some((pts, true));
        }
    }
    Some(direct)
}

/// A straight from `a` to `b` as points about `step` m apart.
pub fn straight(a: Vec2, b: Vec2, step: f64) -> Vec<Vec2> {
    let n = ((b - a).norm() / step).ceil().max(1.0) as usize;
    (0..=n)
        .map(|i| a + (b - a) * (i as f64 / n as f64))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;

    #[test]
    fn csc_ends_at_the_goal_with_bounded_curvature() {
        let (pts, ok) =
            transit(v2(0.0, 0.0), 0.0, v2(30.0, 20.0), 3.0, 6.0, 0.5, &|_| true).unwrap();
        assert!(ok);
        assert!((pts.last().unwrap() - v2(30.0, 20.0)).norm() < 1e-9);
        for w in pts.windows(3) {
            let (a, b, c) = (w[0], w[1], w[2]);
            let k = 2.0 * crate::geo::cross(&(b - a), &(c - b)).abs()
                / ((b - a).norm() * (c - b).norm() * (c - a).norm()).max(1e-12);
            assert!(k <= 1.0 / 6.0 * 1.02, "curvature {k}");
        }
        let end_dir = pts[pts.len() - 1] - pts[pts.len() - 2];
        assert!((end_dir.y.atan2(end_dir.x) - 3.0).abs() < 0.1);
    }
}
