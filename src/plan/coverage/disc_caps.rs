//! The corner discs of the headland passes cut to the part that can meet the area they are
//! taken out of. A disc at a reflex corner of the boundary lies mostly outside the field: only
//! a cap of it reaches into the area of pass centres, yet every one of its ~126 vertices went
//! to the clipper, and on a boundary of many vertices (123 discs, 15 000 vertices) the
//! overlapping discs cost 18 ms a pass. Each disc is cut by a line beyond which no point of the
//! area lies inside its circle, so the area minus the caps is the area minus the discs.

use super::geometry::{in_area, Area};
use crate::geo::{v2, Vec2};

/// Clearance of the cutting line beyond the area's farthest point inside the circle, m: the
/// cap keeps the disc's boundary wherever it could meet the area, with this to spare.
const CUT_MARGIN: f64 = 0.01;

/// The part of `disc` (a convex counter-clockwise polygon whose vertices lie on the circle of
/// radius `rr` about `c`) that can meet `area`: the disc cut by a line beyond which no point of
/// `area` lies inside the circle; the disc whole when no cut removes anything; `None` when no
/// point of `area` lies inside the circle. (Holes of `area` may overlap each other and its
/// outer ring: every edge bounds the cut, and a point in any hole is out of the area.)
pub(super) fn cap(disc: Vec<Vec2>, c: Vec2, rr: f64, area: &[Area]) -> Option<Vec<Vec2>> {
    // The points of the area's edges inside the circle: each edge clipped to it.
    let mut ends: Vec<Vec2> = Vec::new();
    // The angles where the edges cross the circle.
    let mut crossings: Vec<f64> = Vec::new();
    let rings = area
        .iter()
        .flat_map(|(outer, holes)| std::iter::once(outer).chain(holes.iter()));
    for ring in rings {
        let n = ring.len();
        for i in 0..n {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            if a.x.max(b.x) < c.x - rr
                || a.x.min(b.x) > c.x + rr
                || a.y.max(b.y) < c.y - rr
                || a.y.min(b.y) > c.y + rr
            {
                continue;
            }
            // |a + t·(b − a) − c|² = rr²: t² dd + 2t (f·d) + |f|² − rr² = 0.
            let (d, f) = (b - a, a - c);
            let dd = d.dot(&d);
            if dd < 1e-18 {
                continue;
            }
            let half_b = f.dot(&d);
            let disc_q = half_b * half_b - dd * (f.dot(&f) - rr * rr);
            if disc_q <= 0.0 {
                continue;
            }
            let root = disc_q.sqrt();
            let (t0, t1) = ((-half_b - root) / dd, (-half_b + root) / dd);
            let (s0, s1) = (t0.max(0.0), t1.min(1.0));
            if s0 > s1 {
                continue;
            }
            ends.push(a + d * s0);
            ends.push(a + d * s1);
            for t in [t0, t1] {
                if (0.0..=1.0).contains(&t) {
                    let q = a + d * t - c;
                    crossings.push(q.y.atan2(q.x));
                }
            }
        }
    }
    // The arcs of the circle between the crossings, each inside the area or outside it
    // throughout: (start angle, sweep) of those inside.
    crossings.sort_by(f64::total_cmp);
    let tau = std::f64::consts::TAU;
    let arcs: Vec<(f64, f64)> = if crossings.is_empty() {
        vec![(0.0, tau)]
    } else {
        let k = crossings.len();
        (0..k)
            .map(|i| {
                let a0 = crossings[i];
                let a1 = if i + 1 < k {
                    crossings[i + 1]
                } else {
                    crossings[0] + tau
                };
                (a0, a1 - a0)
            })
            .collect()
    };
    let on_circle = |a: f64| c + v2(a.cos(), a.sin()) * rr;
    let inside_arcs: Vec<(f64, f64)> = arcs
        .into_iter()
        .filter(|&(a0, sweep)| {
            let mid = on_circle(a0 + 0.5 * sweep);
            area.iter().any(|a| in_area(a, &mid))
        })
        .collect();
    if ends.is_empty() && inside_arcs.is_empty() {
        return None;
    }
    // The cut across the direction towards the area's points in the circle.
    let towards = ends
        .iter()
        .map(|q| q - c)
        .chain(
            inside_arcs
                .iter()
                .map(|&(a0, s)| on_circle(a0 + 0.5 * s) - c),
        )
        .fold(v2(0.0, 0.0), |acc, q| acc + q);
    let Some(u) = towards.try_normalize(1e-9) else {
        return Some(disc);
    };
    let phi_u = u.y.atan2(u.x);
    // The least (q − c)·u over the area's points in the circle: at the clipped edges' ends, or
    // on an arc inside the area (at its ends, or opposite u when the arc passes there).
    let mut least = ends
        .iter()
        .map(|q| (q - c).dot(&u))
        .fold(f64::INFINITY, f64::min);
    for &(a0, sweep) in &inside_arcs {
        let opposite = (phi_u + std::f64::consts::PI - a0).rem_euclid(tau);
        let lowest = if opposite <= sweep {
            -rr
        } else {
            rr * (a0 - phi_u).cos().min((a0 + sweep - phi_u).cos())
        };
        least = least.min(lowest);
    }
    let cut = least - CUT_MARGIN;
    if disc.iter().all(|q| (q - c).dot(&u) >= cut) {
        return Some(disc);
    }
    // The disc clipped to (q − c)·u ≥ cut (one half-plane of a convex polygon).
    let n = disc.len();
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let (p, q) = (disc[i], disc[(i + 1) % n]);
        let (sp, sq) = ((p - c).dot(&u) - cut, (q - c).dot(&u) - cut);
        if sp >= 0.0 {
            out.push(p);
        }
        if (sp >= 0.0) != (sq >= 0.0) {
            out.push(p + (q - p) * (sp / (sp - sq)));
        }
    }
    (out.len() >= 3).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(c: Vec2, rr: f64, n: usize) -> Vec<Vec2> {
        (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                c + v2(a.cos(), a.sin()) * rr
            })
            .collect()
    }

    /// The area minus a cap is the area minus its disc, and caps are smaller where the disc
    /// only grazes the area; a disc inside the area stays whole, one far from it goes.
    #[test]
    fn a_cap_takes_out_of_the_area_what_its_disc_does() {
        use geo::{Area as _, BooleanOps};
        let square: Area = (
            vec![
                v2(0.0, 0.0),
                v2(100.0, 0.0),
                v2(100.0, 100.0),
                v2(0.0, 100.0),
            ],
            vec![],
        );
        let area = [square.clone()];
        for (c, rr) in [
            (v2(50.0, -8.0), 10.0),
            (v2(-3.0, -3.0), 6.0),
            (v2(50.0, 50.0), 10.0),
            (v2(100.0, 50.0), 20.0),
        ] {
            let disc = circle(c, rr, 126);
            let cut = cap(disc.clone(), c, rr, &area).expect("the disc meets the area");
            assert!(cut.len() <= disc.len() + 2);
            let minus = |d: &[Vec2]| {
                super::super::geometry::to_geo(&square)
                    .difference(&super::super::geometry::to_geo(&(d.to_vec(), vec![])))
                    .unsigned_area()
            };
            assert!((minus(&disc) - minus(&cut)).abs() < 1e-6, "{c:?}");
        }
        let grazing = cap(
            circle(v2(50.0, -8.0), 10.0, 126),
            v2(50.0, -8.0),
            10.0,
            &area,
        );
        assert!(grazing.is_some_and(|g| g.len() < 40));
        let whole = cap(
            circle(v2(50.0, 50.0), 10.0, 126),
            v2(50.0, 50.0),
            10.0,
            &area,
        );
        assert_eq!(whole.map(|w| w.len()), Some(126));
        assert!(cap(
            circle(v2(150.0, 50.0), 10.0, 126),
            v2(150.0, 50.0),
            10.0,
            &area
        )
        .is_none());
    }
}
