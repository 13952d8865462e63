//! Approach paths when a job is resumed away from where it stopped (issue 16 point 8): after a
//! restart in a turn the approach leads to the next line's start and replaces the rest of the
//! turn; no finished line is driven again.

use super::machine::{Event, Guidance};
use super::progress::Phase;
use crate::config::Config;
use crate::geo::{v2, Direction, Pose};
use crate::plan::abline::AbPlan;
use crate::plan::coverage::SegmentKind;
use crate::plan::job::JobSegment;

fn config() -> Config {
    let mut cfg = Config::default();
    cfg.job.line_num = 3;
    cfg.job.point_b_m = [0.0, 20.0];
    cfg
}

fn new_guidance(cfg: &Config) -> Guidance {
    let plan = AbPlan::new(cfg.ab_params()).unwrap();
    Guidance::new(plan, cfg.job_definition(), cfg.control_params().guidance).unwrap()
}

/// Drive an ideal vehicle along the machine's paths until `until` holds or the job ends;
/// returns the lines finished on the way.
fn drive(g: &mut Guidance, until: &dyn Fn(&Guidance) -> bool) -> Vec<u64> {
    let mut finished = Vec::new();
    for _ in 0..1_000_000 {
        if g.is_finished() || until(g) {
            break;
        }
        let path = g.global_path();
        let i = (g.index_global() + 3).min(path.len() - 1);
        let d = path[i].pos - path[i - 1].pos;
        g.update(&Pose::new(path[i].pos.x, path[i].pos.y, d.y.atan2(d.x)))
            .unwrap();
        for ev in g.drain_events() {
            if let Event::LineFinished { line, .. } = ev {
                finished.push(line);
            }
        }
    }
    finished
}

#[test]
fn resumed_in_a_turn_the_approach_leads_to_the_next_line_and_replaces_the_turn() {
    let cfg = config();
    let mut g = new_guidance(&cfg);
    assert_eq!(drive(&mut g, &|g| g.phase() == Phase::Turn), vec![0]);
    let saved = g.progress();
    let plan = AbPlan::new(cfg.ab_params()).unwrap();
    let mut r = Guidance::resume(
        plan.clone(),
        cfg.job_definition(),
        cfg.control_params().guidance,
        &saved,
    )
    .unwrap();
    assert_eq!(r.phase(), Phase::Turn);
    // Before issue 16 point 8 only the first line of a job could be approached.
    assert!(
        r.approach_allowed(),
        "an approach re-acquires a resumed job"
    );
    let target = r.approach_target().unwrap();
    let mut line1 = Vec::new();
    plan.work_line_points(0, 1, &mut line1);
    let dir = line1[1].pos - line1[0].pos;
    assert!((target.pos - line1[0].pos).norm() < 1e-9, "{target:?}");
    assert!((target.heading - dir.y.atan2(dir.x)).abs() < 1e-9);
    // Not the turn's start, where the regenerated turn path begins.
    assert!((target.pos - r.global_path()[0].pos).norm() > 1.0);
    // An approach from off the turn (facing away from the field) to the line start.
    let from = target.pos + v2(-6.0, -8.0);
    let approach = JobSegment {
        kind: SegmentKind::Transit,
        direction: Direction::Forward,
        cell: 0,
        points: (0..=20)
            .map(|k| from + (target.pos - from) * (k as f64 / 20.0))
            .collect(),
    };
    assert!(r.set_approach(vec![approach]));
    assert!(r.is_approaching());
    assert!(!r.approach_allowed(), "not while approaching");
    // The rest of the job: lines 1 and 2, none twice, line 0 not again.
    assert_eq!(drive(&mut r, &|_| false), vec![1, 2]);
    assert!(r.is_finished());
    assert!(!r.approach_allowed(), "not once finished");
}

#[test]
fn resumed_on_a_work_line_the_approach_leads_to_its_start() {
    let cfg = config();
    let mut g = new_guidance(&cfg);
    drive(&mut g, &|g| g.lines_done() == 1 && g.phase() == Phase::Work);
    assert_eq!(g.current_line(), 1);
    assert!(g.approach_allowed());
    let target = g.approach_target().unwrap();
    assert!((target.pos - g.global_path()[0].pos).norm() < 1e-9);
}

/// Drive line 0 of the job (20 m) on the line, marking it worked as the controller does inside
/// the engage gate, until `station` m; returns the machine there.
fn worked_to(cfg: &Config, station: f64) -> Guidance {
    let mut g = new_guidance(cfg);
    let start = g.global_path()[0].pos;
    let mut s = 0.0;
    while s <= station {
        let p = start + v2(0.0, s);
        g.update(&Pose::new(p.x, p.y, std::f64::consts::FRAC_PI_2))
            .unwrap();
        g.mark_worked();
        s += 0.1;
    }
    g.drain_events().for_each(drop);
    g
}

#[test]
fn resumed_on_a_worked_line_the_approach_rejoins_where_the_work_stopped() {
    let cfg = config();
    let mut g = worked_to(&cfg, 12.05);
    assert_eq!((g.current_line(), g.phase()), (0, Phase::Work));
    let worked = g.worked_m().unwrap();
    assert!((worked - 12.0).abs() < 1e-9, "{worked}");
    // The driver took the tractor 5 m off the line, facing away, and on: the approach leads
    // back to where the work stopped, facing along the line.
    let start = g.global_path()[0].pos;
    g.update(&Pose::new(start.x + 5.0, start.y + 17.0, 0.0))
        .unwrap();
    // (Out of the engage gate the controller does not mark the line worked.)
    let target = g.approach_target().unwrap();
    let line_dir = std::f64::consts::FRAC_PI_2;
    assert!(
        (target.pos - (start + v2(0.0, 12.0))).norm() < 1e-9,
        "{target:?}"
    );
    assert!((target.heading - line_dir).abs() < 1e-9);
    // Driven there: the line goes on from 12 m, is finished once, and nothing before 12 m is
    // driven again.
    let approach = JobSegment {
        kind: SegmentKind::Transit,
        direction: Direction::Forward,
        cell: 0,
        points: vec![target.pos - v2(3.0, 3.0), target.pos],
    };
    assert!(g.set_approach(vec![approach]));
    assert_eq!(
        g.progress().phase,
        Phase::Work,
        "saved as the line it rejoins"
    );
    assert_eq!(g.progress().line_worked_m, Some(worked));
    g.update(&Pose::new(target.pos.x, target.pos.y, line_dir))
        .unwrap();
    assert!(!g.is_approaching());
    assert_eq!((g.current_line(), g.phase()), (0, Phase::Work));
    assert_eq!(g.worked_m(), Some(worked));
    assert!(
        (g.global_path()[g.index_global()].pos - target.pos).norm() < 1e-9,
        "the line is taken up at the rejoin point"
    );
    assert_eq!(drive(&mut g, &|_| false), vec![0, 1, 2]);
}

#[test]
fn the_approach_rejoins_where_the_work_stopped_wherever_the_vehicle_is() {
    let cfg = config();
    let mut g = worked_to(&cfg, 15.0);
    let start = g.global_path()[0].pos;
    // Reversed along the line to 6 m (the work is never marked back), then off it and away.
    for k in 0..=90 {
        let p = start + v2(0.0, 15.0 - k as f64 * 0.1);
        g.update(&Pose::new(p.x, p.y, std::f64::consts::FRAC_PI_2))
            .unwrap();
        g.mark_worked();
    }
    assert!((g.worked_m().unwrap() - 15.0).abs() < 1e-9, "never back");
    for p in [v2(-4.0, 6.0), v2(5.0, -3.0), v2(2.0, 19.5)] {
        g.update(&Pose::new(start.x + p.x, start.y + p.y, 3.0))
            .unwrap();
        let target = g.approach_target().unwrap();
        assert!(
            (target.pos - (start + v2(0.0, 15.0))).norm() < 1e-9,
            "from {p:?}: {target:?}"
        );
    }
}

#[test]
fn the_worked_distance_is_saved_at_checkpoints_and_restored() {
    use super::machine::CHECKPOINT_STEP_M;
    let cfg = config();
    let mut g = new_guidance(&cfg);
    let start = g.global_path()[0].pos;
    let mut checkpoints = Vec::new();
    for k in 0..=180 {
        let p = start + v2(0.0, k as f64 * 0.1);
        g.update(&Pose::new(p.x, p.y, std::f64::consts::FRAC_PI_2))
            .unwrap();
        g.mark_worked();
        if g.take_checkpoint() {
            checkpoints.push(g.progress().line_worked_m.unwrap());
        }
        assert!(!g.take_checkpoint(), "taken once");
    }
    assert_eq!(
        checkpoints,
        vec![
            CHECKPOINT_STEP_M,
            2.0 * CHECKPOINT_STEP_M,
            3.0 * CHECKPOINT_STEP_M
        ]
    );
    // Saved mid-line and resumed (a restart): the approach rejoins at the saved distance.
    let saved = g.progress();
    assert_eq!(saved.line_worked_m, Some(18.0));
    let plan = AbPlan::new(cfg.ab_params()).unwrap();
    let params = cfg.control_params().guidance;
    let mut r =
        Guidance::resume(plan.clone(), cfg.job_definition(), params.clone(), &saved).unwrap();
    assert_eq!(r.worked_m(), Some(18.0));
    r.update(&Pose::new(start.x + 3.0, start.y + 19.0, 0.0))
        .unwrap();
    let target = r.approach_target().unwrap();
    assert!(
        (target.pos - (start + v2(0.0, 18.0))).norm() < 1e-9,
        "{target:?}"
    );
    // In a turn the next line's start, as before: nothing was worked on it.
    assert_eq!(drive(&mut r, &|g| g.phase() == Phase::Turn), vec![0]);
    assert_eq!(r.progress().line_worked_m, None);
    // A saved distance beyond the line is refused, naming it.
    let mut bad = saved.clone();
    bad.line_worked_m = Some(25.0);
    let e = Guidance::resume(plan, cfg.job_definition(), params, &bad)
        .err()
        .unwrap();
    assert!(e.to_string().contains("line_worked_m 25"), "{e}");
}

#[test]
fn a_headland_ring_resumed_out_of_the_gate_is_rejoined_where_its_work_stopped() {
    use crate::plan::job::{JobPlan, SegmentJob};
    // A closed 20 × 20 m ring (a headland pass: it ends where it starts), then a line.
    let mut ring = Vec::new();
    for (a, b) in [
        (v2(0.0, 0.0), v2(20.0, 0.0)),
        (v2(20.0, 0.0), v2(20.0, 20.0)),
        (v2(20.0, 20.0), v2(0.0, 20.0)),
        (v2(0.0, 20.0), v2(0.0, 0.5)),
    ] {
        let n = ((b - a).norm() / 0.5).round() as usize;
        ring.extend((0..n).map(|k| a + (b - a) * (k as f64 / n as f64)));
    }
    ring.push(v2(0.0, 0.5));
    let seg = |kind, points| JobSegment {
        kind,
        direction: Direction::Forward,
        cell: 0,
        points,
    };
    let line: Vec<_> = (0..=20).map(|k| v2(5.0, 5.0 + k as f64 * 0.5)).collect();
    let plan = JobPlan::from(
        SegmentJob::new(vec![
            seg(SegmentKind::Work, ring.clone()),
            seg(SegmentKind::Transit, vec![v2(0.0, 0.5), v2(5.0, 5.0)]),
            seg(SegmentKind::Work, line),
        ])
        .unwrap(),
    );
    let cfg = Config::default();
    let job = cfg.job_definition().with_plan(&plan);
    let params = cfg.control_params().guidance;
    let mut g = Guidance::new(plan.clone(), job.clone(), params.clone()).unwrap();
    // Worked along the ring to the third side's middle (50 m), marked as inside the gate.
    for p in &ring[..=100] {
        g.update(&Pose::new(p.x, p.y, 0.0)).unwrap();
        g.mark_worked();
    }
    let worked = g.worked_m().unwrap();
    assert!((worked - 50.0).abs() < 0.6, "{worked}");
    // Saved, restarted, and the tractor is beside the ring's start (which is also its end):
    // the rejoin is where the work stopped, not the nearest point of the ring.
    let saved = g.progress();
    let mut r = Guidance::resume(plan, job, params, &saved).unwrap();
    r.update(&Pose::new(-3.0, 1.0, 0.0)).unwrap();
    let target = r.approach_target().unwrap();
    assert!((target.pos - v2(10.0, 20.0)).norm() < 0.6, "{target:?}");
    assert!(
        (target.heading.abs() - std::f64::consts::PI).abs() < 1e-9,
        "{target:?}"
    );
    assert!(r.set_approach(vec![seg(
        SegmentKind::Transit,
        vec![v2(-3.0, 1.0), target.pos]
    )]));
    r.update(&Pose::new(target.pos.x, target.pos.y, target.heading))
        .unwrap();
    assert!(!r.is_approaching());
    // Driven on from there to the ring's end: finished once, then the rest of the job.
    let mut finished = Vec::new();
    for p in &ring[100..] {
        r.update(&Pose::new(p.x, p.y, 0.0)).unwrap();
        for ev in r.drain_events() {
            if let Event::LineFinished { line, .. } = ev {
                finished.push(line);
            }
        }
        if !finished.is_empty() {
            break;
        }
        assert_eq!(r.index_rank(), 0, "still the ring at {p:?}");
    }
    assert_eq!(finished, vec![0]);
}

#[test]
fn a_segment_job_resumed_in_a_turn_is_approached_to_its_next_work_segment() {
    use crate::plan::job::{JobPlan, SegmentJob};
    let seg = |kind, points| JobSegment {
        kind,
        direction: Direction::Forward,
        cell: 0,
        points,
    };
    let up: Vec<_> = (0..=30).map(|y| v2(0.0, y as f64)).collect();
    let down: Vec<_> = (0..=30).rev().map(|y| v2(20.0, y as f64)).collect();
    // A long transit and a reversing manoeuvre between the two work segments.
    let transit: Vec<_> = (0..=40)
        .map(|k| v2(k as f64 * 0.5, 30.0 + k as f64 * 0.25))
        .collect();
    let back = vec![v2(20.0, 40.0), v2(20.0, 35.0), v2(20.0, 30.0)];
    let mut reverse = seg(SegmentKind::Turn, back);
    reverse.direction = Direction::Reverse;
    let plan = JobPlan::from(
        SegmentJob::new(vec![
            seg(SegmentKind::Work, up),
            seg(SegmentKind::Transit, transit),
            reverse,
            seg(SegmentKind::Work, down),
        ])
        .unwrap(),
    );
    let cfg = Config::default();
    let job = cfg.job_definition().with_plan(&plan);
    let params = cfg.control_params().guidance;
    let mut g = Guidance::new(plan.clone(), job.clone(), params.clone()).unwrap();
    assert_eq!(drive(&mut g, &|g| g.index_rank() == 1), vec![0]);
    assert_eq!((g.phase(), g.lines_done()), (Phase::Turn, 1));
    let saved = g.progress();
    // Where no clear way leads there, the fallback: back to the transit's own start, which is
    // then driven (and the manoeuvre) before the work segment.
    let mut f = Guidance::resume(plan.clone(), job.clone(), params.clone(), &saved).unwrap();
    f.update(&Pose::new(8.0, 20.0, 0.0)).unwrap();
    assert!(f.approach_can_skip());
    let back = f.approach_target_with(false).unwrap();
    assert!((back.pos - v2(0.0, 30.0)).norm() < 1e-9, "{back:?}");
    assert!(f.set_approach_with(
        vec![seg(SegmentKind::Transit, vec![v2(8.0, 20.0), back.pos])],
        false
    ));
    f.update(&Pose::new(back.pos.x, back.pos.y, back.heading))
        .unwrap();
    assert_eq!(
        (f.index_rank(), f.phase(), f.lines_done()),
        (1, Phase::Turn, 1)
    );
    assert_eq!(drive(&mut f, &|_| false), vec![3]);
    let mut r = Guidance::resume(plan, job, params, &saved).unwrap();
    // Off the transit: the approach leads to the next work segment's start, facing down it.
    r.update(&Pose::new(8.0, 20.0, 0.0)).unwrap();
    let target = r.approach_target().unwrap();
    assert!((target.pos - v2(20.0, 30.0)).norm() < 1e-9, "{target:?}");
    assert!((target.heading + std::f64::consts::FRAC_PI_2).abs() < 1e-9);
    assert!(r.set_approach(vec![seg(
        SegmentKind::Transit,
        vec![v2(8.0, 20.0), v2(14.0, 34.0), target.pos]
    )]));
    assert_eq!(
        r.next_direction(),
        Some(Direction::Forward),
        "the work segment's"
    );
    assert_eq!(
        r.progress().index_rank,
        1,
        "saved as the turn until the approach ends"
    );
    r.update(&Pose::new(target.pos.x, target.pos.y, target.heading))
        .unwrap();
    assert!(!r.is_approaching());
    // The transit and the manoeuvre are replaced and count as done; the work segment is next.
    assert_eq!(
        (r.index_rank(), r.phase(), r.lines_done()),
        (3, Phase::Work, 3)
    );
    let p = r.progress();
    assert!(
        super::progress::check_against_plan(&p, r.job_plan()).is_ok(),
        "{p:?}"
    );
    assert_eq!(drive(&mut r, &|_| false), vec![3]);
    assert!(r.is_finished());
}

/// An approach set on an engage the supervisor then refused (or the operator gave back before
/// it was driven) is dropped: the job is back on the path it was on, where it was, and the
/// next engage plans a new approach from wherever the vehicle is then (before, the stale
/// approach kept the gate measuring XTE to it: every later engage was refused).
#[test]
fn a_cancelled_approach_leaves_the_job_as_it_was() {
    let cfg = config();
    let mut g = worked_to(&cfg, 12.05);
    let start = g.global_path()[0].pos;
    let line_before = g.global_path().to_vec();
    let off = Pose::new(start.x + 5.0, start.y + 17.0, 0.0);
    g.update(&off).unwrap();
    let (index_before, saved_before) = (g.index_global(), g.progress());
    let target = g.approach_target().unwrap();
    let approach = JobSegment {
        kind: SegmentKind::Transit,
        direction: Direction::Forward,
        cell: 0,
        points: vec![off.pos, target.pos - v2(0.0, 3.0), target.pos],
    };
    assert!(g.set_approach(vec![approach]));
    g.update(&off).unwrap();
    assert!(g.is_approaching());
    assert!(!g.approach_allowed());
    g.cancel_approach();
    assert!(!g.is_approaching());
    assert!(g.approach_allowed(), "the next engage may plan again");
    assert_eq!(g.global_path(), &line_before[..]);
    assert_eq!((g.phase(), g.index_global()), (Phase::Work, index_before));
    assert_eq!(g.progress(), saved_before);
    assert_eq!(
        g.approach_target().unwrap(),
        target,
        "still where the work stopped"
    );
    // The local path follows the line again, not the dropped approach (one cycle).
    g.update(&off).unwrap();
    let near_line = g
        .local_path()
        .points()
        .iter()
        .all(|p| (p.x - start.x).abs() < 0.05);
    assert!(
        near_line,
        "local path on the line: {:?}",
        g.local_path().points()
    );
    // Nothing to cancel: a no-op.
    g.cancel_approach();
    assert_eq!(g.global_path(), &line_before[..]);
}

/// The local path is rebuilt whenever the global path is replaced, even where the nearest
/// point's index stays the same (an approach set where the vehicle is nearest the line's first
/// point: both indices 0).
#[test]
fn the_local_path_follows_an_approach_set_at_index_zero() {
    let cfg = config();
    let mut g = new_guidance(&cfg);
    let start = g.global_path()[0].pos;
    // Behind the line's start and 6 m to its side: nearest the line's first point.
    let off = Pose::new(start.x + 6.0, start.y - 4.0, 0.0);
    g.update(&off).unwrap();
    assert_eq!(g.index_global(), 0);
    let target = g.approach_target().unwrap();
    let approach = JobSegment {
        kind: SegmentKind::Transit,
        direction: Direction::Forward,
        cell: 0,
        points: (0..=20)
            .map(|k| off.pos + (target.pos - off.pos) * (k as f64 / 20.0))
            .collect(),
    };
    assert!(g.set_approach(vec![approach]));
    g.update(&off).unwrap();
    assert_eq!(g.index_global(), 0);
    let first = g.local_path().points()[0];
    assert!(
        (first - off.pos).norm() < 1.0,
        "the local path starts at the approach's start {:?}, not the line's: {first:?}",
        off.pos
    );
}
