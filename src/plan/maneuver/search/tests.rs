use super::*;
use crate::config::Config;
use crate::geo::rect;
use crate::geo::v2;
use crate::plan::maneuver::steering::RsSteering;
use std::f64::consts::{FRAC_PI_2, PI};

fn params() -> ManeuverParams {
    Config::default().maneuver_params()
}

const RS: RsSteering = RsSteering { r_min_m: 5.0 };

fn assert_clear(map: &CollisionMap, p: &ManeuverParams, path: &CurvePath) {
    let mut s = Vec::new();
    path.sample(0.02, &mut s);
    let mut bare = p.footprint;
    bare.margin_m = 0.0;
    for smp in &s {
        assert_eq!(map.pose_clear(&bare, &smp.pose), Ok(()), "at s = {}", smp.s);
    }
}

#[test]
fn free_space_is_one_direct_connection() {
    let r = plan_maneuver(
        &CollisionMap::free(),
        &RS,
        &params(),
        &Pose::new(0.0, 0.0, 0.0),
        &Pose::new(30.0, 10.0, FRAC_PI_2),
    )
    .unwrap();
    assert_eq!(r.method, Some(Method::Direct));
    assert_eq!(r.expansions, 0);
    let end = r.path.unwrap().end_pose();
    assert!((end.pos - v2(30.0, 10.0)).norm() < 1e-6);
}

#[test]
fn invalid_endpoints_are_named() {
    let map = CollisionMap::new(
        Some(rect(0.0, 0.0, 50.0, 20.0)),
        vec![rect(30.0, 5.0, 35.0, 15.0)],
        2.0,
    )
    .unwrap();
    let p = params();
    let ok = Pose::new(5.0, 10.0, 0.0);
    let e = plan_maneuver(&map, &RS, &p, &Pose::new(49.0, 10.0, 0.0), &ok).unwrap_err();
    assert_eq!(
        e,
        ManeuverError::Endpoint {
            endpoint: Endpoint::Start,
            reason: Blocked::OutsideBoundary
        }
    );
    let e = plan_maneuver(&map, &RS, &p, &ok, &Pose::new(31.0, 10.0, 0.0)).unwrap_err();
    assert_eq!(
        e.to_string(),
        "goal pose is invalid: the vehicle touches obstacle 0"
    );
    let e = plan_maneuver(&map, &RS, &p, &ok, &Pose::new(f64::NAN, 1.0, 0.0)).unwrap_err();
    assert_eq!(
        e,
        ManeuverError::NotFinite {
            endpoint: Endpoint::Goal
        }
    );
}

#[test]
fn corridor_u_turn_needs_reversing_and_stays_clear() {
    let map = CollisionMap::new(Some(rect(0.0, 0.0, 60.0, 12.0)), vec![], 2.0).unwrap();
    let p = params();
    let (start, goal) = (Pose::new(20.0, 3.5, 0.0), Pose::new(20.0, 8.5, PI));
    let r = plan_maneuver(&map, &RS, &p, &start, &goal).unwrap();
    let path = r.path.expect("found");
    assert!(path.cusps() >= 1, "a forward U-turn does not fit");
    let end = path.end_pose();
    assert!((end.pos - goal.pos).norm() < 1e-6);
    assert!(wrap_angle(end.heading - goal.heading).abs() < 1e-6);
    assert_clear(&map, &p, &path);
    // The same turn in an open yard needs no search at all.
    let open = CollisionMap::new(Some(rect(0.0, -30.0, 60.0, 42.0)), vec![], 2.0).unwrap();
    let r2 = plan_maneuver(&open, &RS, &p, &start, &goal).unwrap();
    assert_eq!(r2.method, Some(Method::Direct));
}

#[test]
fn walled_off_goal_is_not_found_and_says_why() {
    let map = CollisionMap::new(
        Some(rect(0.0, 0.0, 60.0, 20.0)),
        vec![rect(29.0, -1.0, 31.0, 21.0)],
        2.0,
    )
    .unwrap();
    let mut p = params();
    p.max_expansions = 300;
    let r = plan_maneuver(
        &map,
        &RS,
        &p,
        &Pose::new(10.0, 10.0, 0.0),
        &Pose::new(50.0, 10.0, 0.0),
    )
    .unwrap();
    assert!(r.path.is_none());
    assert!(r.expansions > 0 && r.expansions <= 300);
    let why = r.failure.unwrap();
    assert!(why.contains("expansions"), "{why}");
}

#[test]
fn fallback_searches_between_the_first_and_last_legs() {
    // The bay of tools/maneuvers with the direct search cut to one expansion and no
    // patterns: only the fallback can find the way, and its path is clear and exact.
    let mut boundary = vec![
        v2(0.0, 0.0),
        v2(50.0, 0.0),
        v2(50.0, 9.0),
        v2(26.6, 9.0),
        v2(26.6, 16.0),
        v2(23.0, 16.0),
        v2(23.0, 9.0),
        v2(0.0, 9.0),
    ];
    crate::geo::polygon::make_ccw(&mut boundary);
    let map = CollisionMap::new(Some(boundary), vec![], 2.0).unwrap();
    let mut p = params();
    p.goal_patterns.clear();
    p.search_max_expansions = 1;
    let (start, goal) = (Pose::new(5.0, 4.5, 0.0), Pose::new(24.8, 13.8, -FRAC_PI_2));
    let r = plan_maneuver(&map, &RS, &p, &start, &goal).unwrap();
    assert_eq!(r.method, Some(Method::Fallback), "{:?}", r.stages);
    let path = r.path.unwrap();
    let end = path.end_pose();
    assert!((end.pos - goal.pos).norm() < 1e-6);
    assert!(wrap_angle(end.heading - goal.heading).abs() < 1e-6);
    assert!((path.start.pos - start.pos).norm() < 1e-12);
    assert_clear(&map, &p, &path);
    assert!(r.stages.iter().any(|s| s.starts_with("fallback: found")));
}

#[test]
fn patterns_parse_and_are_laid_back_onto_the_goal() {
    assert_eq!(
        parse_pattern("lrlr_pnpn").unwrap(),
        vec![
            (1.0, Direction::Forward),
            (-1.0, Direction::Reverse),
            (1.0, Direction::Forward),
            (-1.0, Direction::Reverse)
        ]
    );
    for bad in ["lrl_pn", "lsl_pnp", "lr", "_", "lr_px"] {
        assert!(parse_pattern(bad).is_err(), "{bad}");
    }
    let map = CollisionMap::free();
    let p = params();
    let mut pl = Planner::new(&map, &RS, &p);
    let goal = Pose::new(3.0, -2.0, 0.4);
    let pat = parse_pattern("lrlr_pnpn").unwrap();
    for (mirror, sign) in [(false, 1.0), (true, -1.0)] {
        let path = pl
            .goal_pattern(&pat, mirror, sign * FRAC_PI_2, &goal)
            .unwrap();
        let end = path.end_pose();
        assert!((end.pos - goal.pos).norm() < 1e-6, "{end:?}");
        assert!(wrap_angle(end.heading - goal.heading).abs() < 1e-9);
        // lrlr_pnpn turns the vehicle left (CCW) by the whole turn; mirrored, right.
        assert!((wrap_angle(goal.heading - path.start.heading) - sign * FRAC_PI_2).abs() < 1e-9);
        assert_eq!(path.cusps(), 3);
    }
}

#[test]
fn approach_side_from_the_route() {
    let goal = Pose::new(0.0, 0.0, FRAC_PI_2);
    // Route comes from the west (the goal's left when heading north), then runs north.
    let left = RoughRoute {
        points: vec![v2(-20.0, -5.0), v2(0.0, -5.0), v2(0.0, 0.0)],
    };
    assert!((approach_turn(&left, &goal).unwrap() - FRAC_PI_2).abs() < 1e-9);
    let right = RoughRoute {
        points: vec![v2(20.0, -5.0), v2(0.0, -5.0), v2(0.0, 0.0)],
    };
    assert!((approach_turn(&right, &goal).unwrap() + FRAC_PI_2).abs() < 1e-9);
    let straight = RoughRoute {
        points: vec![v2(0.0, -9.0), v2(0.0, 0.0)],
    };
    assert_eq!(approach_turn(&straight, &goal), None);
}
