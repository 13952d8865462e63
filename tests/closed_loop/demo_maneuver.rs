//! The demo manoeuvre (config/demo-maneuver.toml, issue 6 part 5): turning round in a 12 m
//! corridor with two reversals, planned by the seed-004 planner and driven closed-loop through
//! the real frames. Bounds are about twice what the run measured when they were set (in
//! brackets).

use agsteer::config::Config;
use agsteer::demo::{run, DemoOptions};
use agsteer::geo::Direction;
use agsteer::guidance::JobPlan;
use agsteer::job::maneuver as maneuver_file;
use agsteer::plan::maneuver::collision::CollisionMap;

#[test]
fn the_demo_manoeuvre_is_driven_to_its_goal() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/config/demo-maneuver.toml");
    let cfg = Config::load(std::path::Path::new(path), &[]).expect("config/demo-maneuver.toml");
    let (mj, map) = maneuver_file::load_config(&cfg).expect("the demo manoeuvre plans");
    let map = map.expect("the demo has a map");
    assert_eq!(mj.path.cusps(), 2, "two reversals");
    let directions: Vec<Direction> = mj.job.segments().iter().map(|s| s.direction).collect();
    assert_eq!(
        directions,
        vec![Direction::Forward, Direction::Reverse, Direction::Forward]
    );
    // The planned path is clear of the corridor walls (the planner's own map check).
    let cmap = CollisionMap::new(Some(map.boundary.clone()), map.obstacles.clone(), 5.0).unwrap();
    let mut samples = Vec::new();
    mj.path.sample(0.05, &mut samples);
    for s in &samples {
        assert!(
            cmap.pose_clear(&cfg.maneuver_params().footprint, &s.pose)
                .is_ok(),
            "{:?}",
            s.pose
        );
    }
    let r = run(
        &cfg,
        &DemoOptions {
            job: Some(JobPlan::Segments(mj.job.clone())),
            ..Default::default()
        },
        &mut |_| {},
        &mut |_, _| {},
    )
    .unwrap()
    .report;
    assert!(r.finished, "{r:?}");
    assert_eq!(r.lines_completed, 3);
    assert_eq!(r.segments.len(), 3, "every segment scored: {r:?}");
    for s in &r.segments {
        // [RMS 7–9 cm, max 12.6–15.1 cm]
        assert!(s.xte_rms_m < 0.2 && s.xte_max_m < 0.3, "segment {s:?}");
    }
    // [16.6 cm, 1.67°]
    let goal = r.goal_position_error_m.expect("goal error reported");
    let heading = r
        .goal_heading_error_deg
        .expect("goal heading error reported");
    assert!(goal < 0.35 && heading < 4.0, "goal {goal} m, {heading}°");
}
