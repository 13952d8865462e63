//! Reverse driving closed-loop (docs/METHODS.md, Manoeuvres at work; issue 6 part 5c): a segment
//! job with two cusps — forward, reverse on a curve, forward again — through the real frames. The
//! node requests stop before each cusp, waits for the speed frame to show the vehicle stopped and
//! turned, and steers the reverse segment about the rear axle; the simulator obeys the requests.

use agsteer::config::Config;
use agsteer::demo::{run, DemoOptions, DemoRun};
use agsteer::geo::{v2, Direction, Vec2};
use agsteer::guidance::{Event, JobPlan};
use agsteer::plan::coverage::SegmentKind;
use agsteer::plan::job::{JobSegment, SegmentJob};

fn seg(direction: Direction, points: Vec<Vec2>) -> JobSegment {
    JobSegment {
        kind: SegmentKind::Work,
        direction,
        cell: 0,
        points,
    }
}

/// Forward east along y = 0 from x = 0 to 40 m, points 0.5 m apart.
fn forward_40_m() -> Vec<Vec2> {
    (0..=80).map(|i| v2(i as f64 * 0.5, 0.0)).collect()
}

/// `job` driven closed-loop with `cfg`, its trace recorded, each guidance event given to
/// `on_event`.
fn drive(cfg: &Config, job: SegmentJob, on_event: &mut dyn FnMut(f64, &Event)) -> DemoRun {
    let options = DemoOptions {
        job: Some(JobPlan::Segments(job)),
        record_trace: true,
        ..Default::default()
    };
    run(cfg, &options, &mut |_| {}, on_event).unwrap()
}

/// Forward east along y = 0 for 40 m; reverse west along a gentle S (a cosine from y = 0 to
/// y = 4 m over 40 m: curvature ≤ 0.025 /m); forward east along y = 4 for 40 m.
fn job() -> SegmentJob {
    let n = 80;
    let forward = forward_40_m();
    let reverse: Vec<Vec2> = (0..=n)
        .map(|i| {
            let s = i as f64 / n as f64;
            v2(
                40.0 - 40.0 * s,
                2.0 - 2.0 * (std::f64::consts::PI * s).cos(),
            )
        })
        .collect();
    let again: Vec<Vec2> = (0..=n).map(|i| v2(i as f64 * 0.5, 4.0)).collect();
    SegmentJob::new(vec![
        seg(Direction::Forward, forward),
        seg(Direction::Reverse, reverse),
        seg(Direction::Forward, again),
    ])
    .unwrap()
}

#[test]
fn drives_a_job_with_two_cusps_closed_loop() {
    let mut cfg = Config::default();
    cfg.control.speed_kmh = 5.0;
    let mut events = Vec::new();
    let run = drive(&cfg, job(), &mut |t, e| events.push((t, e.clone())));
    let r = &run.report;
    assert!(r.finished, "{r:?}");
    assert_eq!(r.lines_completed, 3);
    // The only end of engagement is the end of the job (nothing left to steer by).
    let job_end = events
        .iter()
        .find(|(_, e)| matches!(e, Event::JobFinished { .. }))
        .map(|(t, _)| *t)
        .expect("job finished");
    assert!(
        run.disengage_events
            .iter()
            .all(|(t, why)| *t >= job_end && why == "no_guidance"),
        "no fault at the cusps: {:?}",
        run.disengage_events
    );
    // True XTE on all three segments (from 10 m after each start), reverse included.
    assert!(r.xte_rms_m < 0.05, "rms {}", r.xte_rms_m);
    assert!(r.xte_max_m < 0.15, "max {}", r.xte_max_m);
    // Every segment scored, the reverse one included, and the vehicle stopped at the goal.
    assert_eq!(r.segments.len(), 3, "{:?}", r.segments);
    assert_eq!(r.segments[1].direction, Direction::Reverse);
    for s in &r.segments {
        assert!(
            s.xte_max_m < 0.15,
            "segment {}: max {}",
            s.index,
            s.xte_max_m
        );
    }
    let goal = r.goal_position_error_m.expect("goal error reported");
    assert!(goal < 0.1, "goal position error {goal} m");
    let finished: Vec<u64> = events
        .iter()
        .filter_map(|(_, e)| match e {
            Event::LineFinished { line, .. } => Some(*line),
            _ => None,
        })
        .collect();
    assert_eq!(finished, vec![0, 1, 2]);
    // The vehicle really reversed: the trace runs west between the cusps.
    let xs: Vec<f64> = run.trace.points.iter().map(|p| p.pos.x).collect();
    let max_x = xs.iter().cloned().fold(f64::MIN, f64::max);
    let min_after = xs
        .iter()
        .skip_while(|x| **x < max_x)
        .cloned()
        .fold(f64::MAX, f64::min);
    assert!(
        max_x > 38.0 && min_after < 2.0,
        "max x {max_x}, then min {min_after}"
    );
}

/// Forward east along y = 0 for 40 m, then on east for `stub` m (a short piece of swath), then
/// backing out along a quarter circle of radius 10 m that bends north (the tractor's rear
/// going north-west).
fn job_with_a_short_piece_before_the_cusp(stub: f64) -> SegmentJob {
    let forward = forward_40_m();
    let piece = vec![v2(40.0, 0.0), v2(40.0 + stub, 0.0)];
    let r = 10.0;
    let back: Vec<Vec2> = (0..=30)
        .map(|i| {
            let a = std::f64::consts::FRAC_PI_2 * i as f64 / 30.0;
            v2(40.0 + stub - r * a.sin(), r - r * a.cos())
        })
        .collect();
    SegmentJob::new(vec![
        seg(Direction::Forward, forward),
        seg(Direction::Forward, piece),
        seg(Direction::Reverse, back),
    ])
    .unwrap()
}

/// A cusp at the end of a piece shorter than the braking distance is braked for from the
/// segment before it: at 10 km/h and the default 0.5 m/s² the tractor needs 7.7 m to stop,
/// and a 0.5 m piece gave it none. It rolled on past the cusp steering for the backing-out
/// curve and was 2.6 m off it on a real field's plan (`at_invekos_concave`, w 3 m r_min 8 m).
#[test]
fn a_cusp_after_a_piece_shorter_than_the_braking_distance_is_stopped_at() {
    let mut cfg = Config::default();
    cfg.control.speed_kmh = 10.0;
    let stub = 0.5;
    let run = drive(
        &cfg,
        job_with_a_short_piece_before_the_cusp(stub),
        &mut |_, _| {},
    );
    let r = &run.report;
    assert!(r.finished, "{r:?}");
    // Stopped within the capture distance (1 m) of the cusp, not a braking distance past it.
    let max_x = run
        .trace
        .points
        .iter()
        .map(|p| p.pos.x)
        .fold(f64::MIN, f64::max);
    assert!(max_x < 40.0 + stub + 1.0, "rolled on to x = {max_x:.2} m");
    let back = r
        .segments
        .iter()
        .find(|s| s.direction == Direction::Reverse)
        .expect("the backing-out segment scored");
    assert!(back.xte_max_m < 0.3, "backing out: {back:?}");
}
