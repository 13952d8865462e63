//! The trap length ([`super::trap_length`]) and the blocked margin it is built on
//! ([`ClearMap::blocked_margin`]) against what the curves and the clearance test find, on an
//! L-shaped field with an obstacle: every proof they give is one the full search would reach.

use super::*;
use crate::geo::polygon::resample;
use crate::geo::v2;
use crate::plan::coverage::clear_map::{implement_clear, ClearMap};
use crate::plan::coverage::Field;
use rand::{Rng, SeedableRng};
use std::f64::consts::PI;

/// An L (arms 40 m wide, 100 m long) with a square obstacle in its corner.
fn l_field() -> Field {
    Field {
        boundary: vec![
            v2(0.0, 0.0),
            v2(100.0, 0.0),
            v2(100.0, 40.0),
            v2(40.0, 40.0),
            v2(40.0, 100.0),
            v2(0.0, 100.0),
        ],
        obstacles: vec![vec![
            v2(15.0, 15.0),
            v2(25.0, 15.0),
            v2(25.0, 25.0),
            v2(15.0, 25.0),
        ]],
    }
}

/// A pose on or near the field, heading anywhere.
fn pose(rng: &mut impl Rng) -> (Vec2, f64) {
    let q = v2(rng.gen_range(-5.0..105.0), rng.gen_range(-5.0..105.0));
    (q, rng.gen_range(-PI..PI))
}

/// Every point within a blocked point's margin is blocked too, and a clear point has none.
#[test]
fn a_blocked_points_margin_is_blocked_throughout() {
    let field = l_field();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    for half in [0.75, 1.5, 6.0] {
        let map = ClearMap::new(&field, half);
        let mut with_margin = 0;
        for _ in 0..4_000 {
            let (q, _) = pose(&mut rng);
            let m = map.blocked_margin(&q);
            if map.clear(&q) {
                assert_eq!(m, 0.0, "clear {q:?} with a margin, half {half}");
                continue;
            }
            if m > 0.0 {
                with_margin += 1;
                for _ in 0..8 {
                    let d = m * rng.gen::<f64>().sqrt();
                    let p = q + heading_vec(rng.gen_range(-PI..PI)) * d;
                    assert!(
                        !implement_clear(&field, half, &p),
                        "{p:?} is clear, {d} m from {q:?} whose margin is {m}, half {half}"
                    );
                }
            }
        }
        assert!(with_margin > 300, "half {half}: {with_margin} margins");
    }
}

/// Every curve of radius r at least a pose's trap length long, leaving the pose or arriving at
/// it, is blocked at one of its points; and the poses near the edges facing it have one.
#[test]
fn every_curve_as_long_as_the_trap_length_is_blocked() {
    let field = l_field();
    let map = ClearMap::new(&field, 1.5);
    let clear = |q: &Vec2| map.clear(q);
    let margin = |q: &Vec2| map.blocked_margin(q);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let step = 0.5;
    let (mut traps, mut checked) = (0, 0);
    for r in [5.0, 8.0] {
        for _ in 0..300 {
            let (p, h) = pose(&mut rng);
            for forward in [true, false] {
                let trap = trap_length(&margin, (p, h, forward), r, step);
                if !trap.is_finite() {
                    continue;
                }
                traps += 1;
                for _ in 0..20 {
                    let (g, hg) = pose(&mut rng);
                    let words = if forward {
                        words_by_length(p, h, g, hg, r)
                    } else {
                        words_by_length(g, hg, p, h, r)
                    };
                    for w in words.iter().filter(|w| w.length >= trap) {
                        checked += 1;
                        assert!(
                            w.points(step, &clear).is_none(),
                            "a clear curve of {} m from a pose trapped at {trap} m: {p:?} {h}",
                            w.length
                        );
                    }
                }
            }
        }
    }
    assert!(
        traps > 100 && checked > 2_000,
        "{traps} traps, {checked} curves"
    );
}

/// [`Rings::transit_with`] finds the same transits with the margin's proofs as without them.
#[test]
fn trap_lengths_give_the_same_transits() {
    let field = l_field();
    let map = ClearMap::new(&field, 1.5);
    let clear = |q: &Vec2| map.clear(q);
    let margin = |q: &Vec2| map.blocked_margin(q);
    let track = [
        v2(6.0, 6.0),
        v2(94.0, 6.0),
        v2(94.0, 34.0),
        v2(34.0, 34.0),
        v2(34.0, 94.0),
        v2(6.0, 94.0),
        v2(6.0, 6.0),
    ];
    let rings = Rings::new(&[resample(&track, 1.0)], &clear, f64::INFINITY);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    let (mut with, mut without) = (Ends::with_margin(&margin), Ends::default());
    let (mut found, mut none) = (0, 0);
    for _ in 0..150 {
        let ((p1, h1), (p2, h2)) = (pose(&mut rng), pose(&mut rng));
        let want = rings.transit_with(p1, h1, p2, h2, 5.0, 0.5, &clear, &mut without);
        let got = rings.transit_with(p1, h1, p2, h2, 5.0, 0.5, &clear, &mut with);
        assert_eq!(got, want, "from {p1:?} {h1} to {p2:?} {h2}");
        found += usize::from(want.is_some());
        none += usize::from(want.is_none());
    }
    assert!(found > 10 && none > 10, "{found} found, {none} not");
}
