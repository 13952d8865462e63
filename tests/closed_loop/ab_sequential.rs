//! AB jobs with sequential lines closer than 2·r_min (issue 6 part 5a): every line is driven
//! in turn, joined by fishtail turns with a reversal, closed-loop through the real frames.

use agsteer::config::{Config, LineOrder};
use agsteer::demo::{run, DemoOptions};
use agsteer::geo::Direction;
use agsteer::guidance::JobPlan;

fn config() -> Config {
    let mut cfg = Config::default();
    cfg.job.line_order = LineOrder::Sequential;
    cfg.job.point_a_m = [0.0, 0.0];
    cfg.job.point_b_m = [0.0, 40.0];
    cfg.job.line_width_m = 3.0;
    cfg.job.line_num = 4;
    cfg.control.speed_kmh = 6.0;
    cfg
}

#[test]
fn sequential_lines_closer_than_two_radii_use_fishtails() {
    let cfg = config();
    assert!(cfg.job.line_width_m < 2.0 * cfg.vehicle.r_min_m);
    let JobPlan::Segments(job) = agsteer::job::ab_plan(&cfg.planning()).unwrap() else {
        panic!("a sequential AB job is a segment job");
    };
    // 4 lines, 3 fishtails of (forward, reverse, forward).
    assert_eq!(job.len(), 4 + 3 * 3);
    let reverse = job
        .segments()
        .iter()
        .filter(|s| s.direction == Direction::Reverse)
        .count();
    assert_eq!(reverse, 3);
    let run = run(&cfg, &DemoOptions::default(), &mut |_| {}, &mut |_, _| {}).unwrap();
    let r = &run.report;
    assert!(r.finished, "{r:?}");
    // Every segment (work lines and turn parts) is completed in order.
    assert_eq!(r.lines_completed, job.len() as u64, "{r:?}");
    assert_eq!(r.segments.len(), job.len());
    assert!(r.xte_rms_m < 0.05, "rms {}", r.xte_rms_m);
    for s in &r.segments {
        assert!(s.xte_max_m < 0.25, "segment {}: {}", s.index, s.xte_max_m);
    }
}

/// Largest tracking error on the turn parts of the sequential job.
fn turn_error(cfg: &Config) -> f64 {
    let run = run(cfg, &DemoOptions::default(), &mut |_| {}, &mut |_, _| {}).unwrap();
    assert!(run.report.finished);
    run.report
        .segments
        .iter()
        .filter(|s| s.kind == agsteer::plan::coverage::SegmentKind::Turn)
        .map(|s| s.xte_max_m)
        .fold(0.0, f64::max)
}

#[test]
fn continuous_curvature_fishtails_are_tracked_closer_than_arc_fishtails() {
    let cc = config();
    assert!(cc.vehicle.max_curvature_rate_per_m2 > 0.0);
    let mut arcs = config();
    arcs.vehicle.max_curvature_rate_per_m2 = 0.0;
    let (e_cc, e_arcs) = (turn_error(&cc), turn_error(&arcs));
    // Arcs need a wheel-angle step at each end the 30°/s actuator cannot make.
    assert!(e_cc < 0.7 * e_arcs, "CC {e_cc} m vs arcs {e_arcs} m");
}

#[test]
fn sequential_needs_a_finite_line_count() {
    let mut cfg = config();
    cfg.job.line_num = 0;
    let problems = cfg.validate();
    assert!(
        problems.iter().any(|p| p.key == "job.line_num"),
        "{problems:?}"
    );
}
