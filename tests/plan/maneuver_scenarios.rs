//! The narrow-space manoeuvre scenarios of tools/maneuvers/: each must be found, reach the
//! goal pose, respect the curvature limits, reverse where the scenario demands it, and be
//! collision-free under an independent check: the map is read here with serde_json and every
//! vehicle rectangle sampled every 5 cm along the path is tested with the `geo` crate
//! (`Contains` for the boundary, `Intersects` for obstacles), not with agsteer's own collision
//! module or field reader.

use agsteer::config::{Config, CurveChoice};
use agsteer::field::load_local_map;
use agsteer::geo::Pose;
use agsteer::job::maneuver::{collision_map, plan_configured, pose_of};
use agsteer::plan::maneuver::collision::CollisionMap;
use agsteer::plan::maneuver::path::{CurvePath, PathSample};
use agsteer::plan::maneuver::search::{plan_maneuver, ManeuverResult};
use agsteer::plan::maneuver::steering::RsSteering;
use geo::{Contains, Coord, Intersects, LineString, Polygon};
use std::path::PathBuf;

#[derive(serde::Deserialize)]
struct Scenario {
    map: String,
    from: [f64; 3],
    to: [f64; 3],
    min_cusps: usize,
    set: Vec<String>,
}

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tools/maneuvers")
}

/// Every scenario: the `NAME.toml` files of tools/maneuvers/, sorted (a new scenario file is
/// checked without being listed here).
fn scenarios() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir())
        .unwrap()
        .filter_map(|e| {
            let path = e.unwrap().path();
            if path.extension()? != "toml" {
                return None;
            }
            Some(path.file_stem()?.to_str()?.to_owned())
        })
        .collect();
    names.sort();
    assert!(!names.is_empty(), "no scenarios in {}", dir().display());
    names
}

fn load(name: &str) -> (Scenario, String) {
    let s: Scenario =
        toml::from_str(&std::fs::read_to_string(dir().join(format!("{name}.toml"))).unwrap())
            .unwrap();
    let map = std::fs::read_to_string(dir().join(&s.map)).unwrap();
    (s, map)
}

/// The map as geo polygons, read straight from the GeoJSON: (boundary with holes, obstacles).
fn geo_map(text: &str) -> (Polygon<f64>, Vec<Polygon<f64>>) {
    let v: serde_json::Value = serde_json::from_str(text).unwrap();
    let ring = |r: &serde_json::Value| {
        LineString::from(
            r.as_array()
                .unwrap()
                .iter()
                .map(|p| Coord {
                    x: p[0].as_f64().unwrap(),
                    y: p[1].as_f64().unwrap(),
                })
                .collect::<Vec<_>>(),
        )
    };
    let mut boundary = None;
    let mut obstacles = Vec::new();
    for f in v["features"].as_array().unwrap() {
        let rings = f["geometry"]["coordinates"].as_array().unwrap();
        let exterior = ring(&rings[0]);
        let holes: Vec<LineString<f64>> = rings[1..].iter().map(ring).collect();
        if f["properties"]["obstacle"].as_bool() == Some(true) {
            obstacles.push(Polygon::new(exterior, vec![]));
        } else {
            for h in &holes {
                obstacles.push(Polygon::new(h.clone(), vec![]));
            }
            boundary = Some(Polygon::new(exterior, vec![]));
        }
    }
    (boundary.unwrap(), obstacles)
}

/// The bare vehicle rectangle (no clearance) at a pose, as a geo polygon.
fn rectangle(cfg: &Config, pose: &Pose) -> Polygon<f64> {
    let v = &cfg.vehicle;
    let (x0, x1) = (
        -v.rear_axle_from_rear_m,
        v.length_m - v.rear_axle_from_rear_m,
    );
    let w = 0.5 * v.width_m;
    let (s, c) = pose.heading.sin_cos();
    let at = |x: f64, y: f64| Coord {
        x: pose.pos.x + c * x - s * y,
        y: pose.pos.y + s * x + c * y,
    };
    Polygon::new(
        LineString::from(vec![
            at(x0, -w),
            at(x1, -w),
            at(x1, w),
            at(x0, w),
            at(x0, -w),
        ]),
        vec![],
    )
}

fn plan(name: &str, curve: CurveChoice) -> (Scenario, String, Config, ManeuverResult) {
    let (s, map_text) = load(name);
    let mut cfg = Config::parse_with("", &s.set).unwrap();
    assert!(cfg.validate().is_empty(), "{:?}", cfg.validate());
    cfg.maneuver.curve = curve;
    let field = load_local_map(&map_text).unwrap();
    let map = collision_map(&cfg.planning().maneuver, Some(&field)).unwrap();
    let r = plan_configured(
        &cfg.planning().maneuver,
        &map,
        curve,
        &pose_of(s.from),
        &pose_of(s.to),
    )
    .unwrap();
    (s, map_text, cfg, r)
}

fn check(name: &str, curve: CurveChoice) {
    let (s, map_text, cfg, r) = plan(name, curve);
    let path: &CurvePath = r
        .path
        .as_ref()
        .unwrap_or_else(|| panic!("{name} ({curve:?}): not found: {:?}", r.failure));
    // Ends where asked.
    let end = path.end_pose();
    let goal = pose_of(s.to);
    assert!(
        (end.pos - goal.pos).norm() < 0.02,
        "{name}: ends at {end:?}, goal {goal:?}"
    );
    assert!(
        agsteer::geo::wrap_angle(end.heading - goal.heading).abs() < 0.5f64.to_radians(),
        "{name}: end heading {}",
        end.heading.to_degrees()
    );
    // Curvature limits.
    let kappa_max = 1.0 / cfg.vehicle.r_min_m;
    assert!(path.max_curvature() <= kappa_max + 1e-6, "{name}");
    if curve == CurveChoice::Cc {
        assert!(
            path.max_curvature_rate() <= cfg.vehicle.max_curvature_rate_per_m2 + 1e-6,
            "{name}: curvature rate {}",
            path.max_curvature_rate()
        );
    }
    // Reversing where the scenario demands it.
    assert!(
        path.cusps() >= s.min_cusps,
        "{name}: {} cusps, at least {} expected",
        path.cusps(),
        s.min_cusps
    );
    // Independent collision check of the bare vehicle every 5 cm.
    if let Some(hit) = first_collision(&cfg, &map_text, path) {
        panic!("{name} ({curve:?}): {hit}");
    }
}

/// The first place where the bare vehicle, sampled every 5 cm along `path`, leaves the
/// boundary or meets an obstacle (geo crate predicates).
fn first_collision(cfg: &Config, map_text: &str, path: &CurvePath) -> Option<String> {
    let (boundary, obstacles) = geo_map(map_text);
    let mut samples: Vec<PathSample> = Vec::new();
    path.sample(0.05, &mut samples);
    assert!(samples.len() as f64 >= path.length() / 0.05);
    for smp in &samples {
        let rect = rectangle(cfg, &smp.pose);
        if !boundary.contains(&rect) {
            return Some(format!(
                "vehicle leaves the boundary at s = {:.2} m, {:?}",
                smp.s, smp.pose
            ));
        }
        for (i, o) in obstacles.iter().enumerate() {
            if o.intersects(&rect) {
                return Some(format!("vehicle hits obstacle {i} at s = {:.2} m", smp.s));
            }
        }
    }
    None
}

#[test]
fn independent_check_catches_collisions() {
    // The check itself must be able to fail: straight through the slalom hits wall 2, and a
    // straight out of the corridor leaves the boundary.
    use agsteer::geo::Direction;
    use agsteer::plan::maneuver::path::CurveSegment;
    let cfg = Config::default();
    let straight = |x: f64, y: f64, h: f64, len: f64| CurvePath {
        start: Pose::new(x, y, h),
        segments: vec![CurveSegment::line(Direction::Forward, len)],
    };
    let (_, slalom) = load("obstacle_slalom");
    let hit = first_collision(&cfg, &slalom, &straight(4.0, 10.5, 0.0, 60.0)).unwrap();
    assert!(hit.contains("obstacle 1"), "{hit}");
    let (_, corridor) = load("three_point_turn");
    let hit = first_collision(&cfg, &corridor, &straight(20.0, 3.5, 0.5, 20.0)).unwrap();
    assert!(hit.contains("boundary"), "{hit}");
    assert!(first_collision(&cfg, &corridor, &straight(5.0, 6.0, 0.0, 40.0)).is_none());
}

#[test]
fn scenarios_plain_reeds_shepp() {
    for name in scenarios() {
        check(&name, CurveChoice::Rs);
    }
}

#[test]
fn scenarios_continuous_curvature() {
    for name in scenarios() {
        check(&name, CurveChoice::Cc);
    }
}

#[test]
fn endpoint_in_an_obstacle_is_named() {
    let (_, map_text) = load("obstacle_slalom");
    let cfg = Config::default();
    let field = load_local_map(&map_text).unwrap();
    let map = CollisionMap::new(Some(field.boundary), field.obstacles, 2.0).unwrap();
    let steer = RsSteering { r_min_m: 5.0 };
    let err = plan_maneuver(
        &map,
        &steer,
        &cfg.maneuver_params(),
        &Pose::new(4.0, 10.5, 0.0),
        &Pose::new(36.0, 9.0, 0.0),
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "goal pose is invalid: the vehicle touches obstacle 1"
    );
}
