//! Tests of [`super::Rings`]: transits along the rings.

use super::*;
use crate::geo::v2;

/// The corners of a U (arms 20 m wide, bay 60 m wide and 80 m deep), closed.
fn u_corners() -> [Vec2; 9] {
    [
        v2(0.0, 0.0),
        v2(100.0, 0.0),
        v2(100.0, 100.0),
        v2(80.0, 100.0),
        v2(80.0, 20.0),
        v2(20.0, 20.0),
        v2(20.0, 100.0),
        v2(0.0, 100.0),
        v2(0.0, 0.0),
    ]
}

/// [`Rings::transit_with`] with one store of ends for many transits (some from one pose
/// to several goals, some from several poses to one goal, some asked twice) gives the
/// answer it gives with a store of its own, point for point.
#[test]
fn kept_ends_give_the_same_transits() {
    use rand::{Rng, SeedableRng};
    let corners = u_corners();
    let inner = [
        v2(10.0, 10.0),
        v2(90.0, 10.0),
        v2(90.0, 90.0),
        v2(10.0, 90.0),
        v2(10.0, 10.0),
    ];
    let tracks = [
        crate::geo::polygon::resample(&corners, 1.0),
        crate::geo::polygon::resample(&inner, 1.0),
    ];
    // Clear within 10.5 m of the U's track, but not in a square in its bottom arm.
    let clear = |q: &Vec2| {
        corners
            .windows(2)
            .any(|s| crate::geo::polygon::point_segment_distance(q, &s[0], &s[1]) <= 10.5)
            && !(q.x > 45.0 && q.x < 55.0 && q.y > 2.0 && q.y < 8.0)
    };
    let rings = Rings::new(&tracks, &clear, f64::INFINITY);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut pose = || {
        let q = v2(rng.gen_range(0.0..100.0), rng.gen_range(0.0..100.0));
        (q, rng.gen_range(-3.1..3.1))
    };
    let mut ends = Ends::default();
    let (mut found, mut none) = (0, 0);
    let mut asked = Vec::new();
    for k in 0..40 {
        let (a, b) = (pose(), pose());
        asked.push((a, b));
        // From the last start to a new goal, from a new start to the last goal, and again.
        if k % 3 == 1 {
            let (last, _) = asked[k - 1];
            asked.push((last, b));
            asked.push((a, asked[k - 1].1));
        }
        if k % 5 == 2 {
            asked.push(asked[k / 2]);
        }
    }
    for &((p1, h1), (p2, h2)) in &asked {
        let want = rings.transit_with(p1, h1, p2, h2, 3.0, 0.5, &clear, &mut Ends::default());
        let got = rings.transit_with(p1, h1, p2, h2, 3.0, 0.5, &clear, &mut ends);
        assert_eq!(got, want, "from {p1:?} to {p2:?}");
        found += usize::from(want.is_some());
        none += usize::from(want.is_none());
    }
    assert!(found > 10 && none > 2, "{found} found, {none} not");
}

/// The track round the U of [`u_corners`], points 1 m apart (its corners square).
fn u_track() -> Vec<Vec2> {
    crate::geo::polygon::resample(&u_corners(), 1.0)
}

/// Clear: within 10.5 m of [`u_track`] (a corridor), sharp corners allowed for the tests.
fn near_u_track(q: &Vec2) -> bool {
    u_corners()
        .windows(2)
        .any(|s| crate::geo::polygon::point_segment_distance(q, &s[0], &s[1]) <= 10.5)
}

/// A U-shaped field's ring: the way from one arm's tip to the other's goes round the bay,
/// where a direct curve would cross it.
#[test]
fn a_transit_follows_the_ring_round_a_bay() {
    let (track, near_track) = (u_track(), near_u_track);
    let rings = Rings::new(&[track], &near_track, f64::INFINITY);
    // From one arm's tip heading up it to the other's heading down, at r 3 m, points 0.5 m apart.
    let (from, to) = (v2(10.0, 90.0), v2(90.0, 90.0));
    let (h1, h2, r, step) = (
        std::f64::consts::FRAC_PI_2,
        -std::f64::consts::FRAC_PI_2,
        3.0,
        0.5,
    );
    let pts = rings
        .transit_with(from, h1, to, h2, r, step, &near_track, &mut Ends::default())
        .expect("a way round the bay");
    assert!(pts.iter().all(near_track));
    assert!((pts[0] - from).norm() < 1e-9);
    assert!((pts[pts.len() - 1] - to).norm() < 1e-9);
    // It went round the bottom of the U: it crosses the bay's middle (x = 50) only below
    // the bay's mouth of clear ground (the bottom strip, y 0–20, and 10.5 m beyond it).
    let crossings: Vec<f64> = pts
        .windows(2)
        .filter(|s| (s[0].x - 50.0) * (s[1].x - 50.0) <= 0.0)
        .map(|s| s[0].y)
        .collect();
    assert!(!crossings.is_empty());
    assert!(crossings.iter().all(|&y| y < 30.5), "{crossings:?}");
    // A direct curve would cross the bay.
    let (direct, ok) = transit(from, h1, to, h2, r, step, &near_track).unwrap();
    assert!(!ok && !direct.is_empty());
}

/// A ring's points that turn tighter than the limit are not followed: the U's track with
/// its square corners (three-point curvature 1.41 /m at 1 m spacing) gives, with the limit
/// of r_min 3 m, a way (if any) that turns no tighter than that anywhere; without the limit
/// the way round the bay follows the corners.
#[test]
fn a_transit_does_not_follow_a_ring_round_a_corner_tighter_than_r_min() {
    let (track, near_track) = (u_track(), near_u_track);
    let limit = crate::plan::coverage::metrics::checks::curvature_limit(3.0);
    let tightest = |pts: &[Vec2]| {
        pts.windows(3)
            .map(|w| crate::plan::coverage::metrics::three_point_curvature(&w[0], &w[1], &w[2]))
            .fold(0.0, f64::max)
    };
    let way = |max_curvature: f64| {
        Rings::new(std::slice::from_ref(&track), &near_track, max_curvature).transit_with(
            v2(10.0, 90.0),
            std::f64::consts::FRAC_PI_2,
            v2(90.0, 90.0),
            -std::f64::consts::FRAC_PI_2,
            3.0,
            0.5,
            &near_track,
            &mut Ends::default(),
        )
    };
    let unlimited = way(f64::INFINITY).expect("a way round the bay");
    assert!(tightest(&unlimited) > 1.0);
    if let Some(pts) = way(limit) {
        assert!(tightest(&pts) <= limit, "{} /m", tightest(&pts));
    }
}
