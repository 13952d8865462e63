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
