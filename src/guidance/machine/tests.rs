//! Tests of the job state machine.

use super::*;
use crate::config::Config;

fn ab_params(cfg: &Config) -> crate::plan::abline::AbParams {
    cfg.ab_params()
}

fn guidance_params(cfg: &Config) -> GuidanceParams {
    cfg.control_params().guidance
}
use crate::plan::job::SegmentJob;

/// Drive an ideal vehicle along whatever path the machine hands out and return the lines
/// in the order they were finished.
fn drive(
    cfg: &Config,
    resume: Option<&Progress>,
    stop_after: Option<usize>,
) -> (Vec<u64>, Progress) {
    let plan = AbPlan::new(ab_params(cfg)).unwrap();
    let job = cfg.job_definition();
    let mut g = match resume {
        Some(p) => Guidance::resume(plan, job, guidance_params(cfg), p).unwrap(),
        None => Guidance::new(plan, job, guidance_params(cfg)).unwrap(),
    };
    let mut finished = Vec::new();
    for _ in 0..2_000_000 {
        if g.is_finished() || stop_after.is_some_and(|n| finished.len() >= n) {
            break;
        }
        let path = g.global_path();
        let i = (g.index_global() + 3).min(path.len() - 1);
        let d = path[i].pos - path[i - 1].pos;
        let pose = Pose::new(path[i].pos.x, path[i].pos.y, d.y.atan2(d.x));
        g.update(&pose).unwrap();
        for ev in g.drain_events() {
            if let Event::LineFinished { line, .. } = ev {
                finished.push(line);
            }
        }
    }
    (finished, g.progress())
}

fn cfg_with_lines(n: u64) -> Config {
    let mut cfg = Config::default();
    cfg.job.line_num = n;
    cfg.job.point_b_m = [0.0, 20.0];
    cfg
}

#[test]
fn visits_every_line_exactly_once() {
    let n_block = AbPlan::new(ab_params(&Config::default()))
        .unwrap()
        .block_size() as u64;
    for count in [1, n_block - 1, n_block, n_block + 1, 2 * n_block + 3, 100] {
        let cfg = cfg_with_lines(count);
        let (mut lines, progress) = drive(&cfg, None, None);
        assert_eq!(
            progress.phase,
            Phase::Finished,
            "{count} lines: not finished"
        );
        assert_eq!(lines.len() as u64, count, "{count} lines: {lines:?}");
        lines.sort_unstable();
        assert_eq!(lines, (0..count).collect::<Vec<_>>(), "{count} lines");
    }
}

#[test]
fn resume_drives_no_line_twice() {
    let cfg = cfg_with_lines(23);
    let (full, _) = drive(&cfg, None, None);
    for stop in [1usize, 5, 11, 22] {
        let (first, saved) = drive(&cfg, None, Some(stop));
        let (second, end) = drive(&cfg, Some(&saved), None);
        assert_eq!(end.phase, Phase::Finished);
        let mut all = first.clone();
        all.extend(&second);
        assert_eq!(all, full, "stop after {stop}");
    }
}

/// A segment job: two swaths joined by a semicircle, driven by an ideal vehicle.
fn segment_job() -> SegmentJob {
    use crate::geo::{v2, Direction};
    use crate::plan::coverage::SegmentKind;
    use crate::plan::job::JobSegment;
    let line = |x: f64, up: bool| -> Vec<Vec2> {
        let ys: Vec<f64> = (0..=30).map(|i| i as f64).collect();
        let pts = ys.iter().map(|&y| v2(x, y));
        if up {
            pts.collect()
        } else {
            pts.rev().collect()
        }
    };
    let arc: Vec<Vec2> = (0..=18)
        .map(|i| {
            let a = std::f64::consts::PI * (1.0 - i as f64 / 18.0);
            v2(5.0 + 5.0 * a.cos(), 30.0 + 5.0 * a.sin())
        })
        .collect();
    let seg = |kind, points| JobSegment {
        kind,
        direction: Direction::Forward,
        cell: 0,
        points,
    };
    SegmentJob::new(vec![
        seg(SegmentKind::Work, line(0.0, true)),
        seg(SegmentKind::Turn, arc),
        seg(SegmentKind::Work, line(10.0, false)),
    ])
    .unwrap()
}

fn drive_segments(resume: Option<&Progress>, stop_after: usize) -> (Vec<u64>, Progress) {
    let cfg = Config::default();
    let plan = JobPlan::from(segment_job());
    let job = cfg.job_definition().with_plan(&plan);
    let mut g = match resume {
        Some(p) => Guidance::resume(plan, job, guidance_params(&cfg), p).unwrap(),
        None => Guidance::new(plan, job, guidance_params(&cfg)).unwrap(),
    };
    let mut finished = Vec::new();
    let mut started = 0;
    for _ in 0..100_000 {
        if g.is_finished() || started > stop_after {
            break;
        }
        let path = g.global_path();
        let i = (g.index_global() + 1).min(path.len() - 1);
        let d = path[i].pos - path[i - 1].pos;
        g.update(&Pose::new(path[i].pos.x, path[i].pos.y, d.y.atan2(d.x)))
            .unwrap();
        for ev in g.drain_events() {
            match ev {
                Event::LineFinished { line, .. } => finished.push(line),
                Event::LineStarted { .. } | Event::TurnStarted { .. } => started += 1,
                _ => {}
            }
        }
    }
    (finished, g.progress())
}

#[test]
fn segment_job_drives_every_segment_in_order_and_resumes_per_segment() {
    let (finished, end) = drive_segments(None, usize::MAX);
    assert_eq!(end.phase, Phase::Finished);
    assert_eq!(finished, vec![0, 2], "work segments finished in order");
    assert_eq!(end.lines_done, 3, "every segment counts");
    // Stop after the turn has started: the saved progress points at the turn segment.
    let (first, saved) = drive_segments(None, 1);
    assert_eq!(first, vec![0]);
    assert_eq!((saved.index_rank, saved.phase), (1, Phase::Turn));
    assert!(saved.job.plan_checksum.is_some());
    let (second, end) = drive_segments(Some(&saved), usize::MAX);
    assert_eq!(second, vec![2], "resume drives no segment twice");
    assert_eq!(end.phase, Phase::Finished);
    // Another plan refuses the saved progress.
    let cfg = Config::default();
    let mut other = segment_job().segments().to_vec();
    other[2].points[0].x += 0.5;
    let other = JobPlan::from(SegmentJob::new(other).unwrap());
    let job = cfg.job_definition().with_plan(&other);
    let err = Guidance::resume(other, job, guidance_params(&cfg), &saved).err();
    assert_eq!(err, Some(GuidanceError::DifferentJob));
}

#[test]
fn resume_refuses_another_job() {
    let cfg = cfg_with_lines(10);
    let (_, saved) = drive(&cfg, None, Some(3));
    let mut other = cfg.clone();
    other.job.line_width_m = 4.0;
    let plan = AbPlan::new(ab_params(&other)).unwrap();
    let err = Guidance::resume(
        plan,
        other.job_definition(),
        guidance_params(&other),
        &saved,
    )
    .err();
    assert_eq!(err, Some(GuidanceError::DifferentJob));
}

#[test]
fn distance_from_path_is_to_the_path_not_to_a_segment_extension() {
    let cfg = Config::default();
    let plan = JobPlan::from(segment_job());
    let job = cfg.job_definition().with_plan(&plan);
    let mut g = Guidance::new(plan, job, guidance_params(&cfg)).unwrap();
    let up = std::f64::consts::FRAC_PI_2;
    // To the end of the first line: the turn (a semicircle of radius 5 from (0, 30)) starts.
    for y in 0..=30 {
        g.update(&Pose::new(0.0, y as f64, up)).unwrap();
    }
    assert_eq!(g.phase(), Phase::Turn);
    // 2 m short of the turn's start along its first chord (rolled past it before a cusp): on
    // the chord's extension, 0 m; 1.5 m beside that, 1.5 m.
    let d = |g: &Guidance, x: f64, y: f64| g.distance_from_path(&Pose::new(x, y, up)).unwrap();
    let (a, b) = (g.global_path()[0].pos, g.global_path()[1].pos);
    let u = (b - a) / (b - a).norm();
    let back = a - u * 2.0;
    let left = Vec2::new(-u.y, u.x);
    assert!(d(&g, back.x, back.y) < 1e-9, "{}", d(&g, back.x, back.y));
    let beside = back + left * 1.5;
    assert!((d(&g, beside.x, beside.y) - 1.5).abs() < 1e-9);
    // At the top of the arc, 2 m outside it: 2 m (to the chords, a little more).
    g.update(&Pose::new(5.0, 35.0, 0.0)).unwrap();
    assert!(
        (d(&g, 5.0, 37.0) - 2.0).abs() < 0.05,
        "{}",
        d(&g, 5.0, 37.0)
    );
    // 50 m away along the chord there: the cross-track error to the chord's line is 0, the
    // distance from the path is not.
    let i = g.index_global();
    let (a, b) = (g.global_path()[i].pos, g.global_path()[i + 1].pos);
    let p = a + (b - a) / (b - a).norm() * 50.0;
    let far = Pose::new(p.x, p.y, 0.0);
    let (xte, _) = g.errors(&far).unwrap();
    assert!(xte.abs() < 1e-9, "{xte}");
    assert!(g.distance_from_path(&far).unwrap() > 40.0);
    // Finished: no path.
    for _ in 0..100 {
        let path = g.global_path();
        let p = path[path.len() - 1].pos;
        g.update(&Pose::new(p.x, p.y, -up)).unwrap();
        if g.is_finished() {
            break;
        }
    }
    assert!(g.is_finished());
    assert_eq!(g.distance_from_path(&far), None);
}

#[test]
fn a_gap_between_segments_is_reported_where_the_segment_after_it_starts() {
    let cfg = Config::default();
    let mut segments = segment_job().segments().to_vec();
    // The last swath moved 4 m east: 4 m from the turn's end to its start.
    for p in &mut segments[2].points {
        p.x += 4.0;
    }
    let plan = JobPlan::from(crate::plan::job::SegmentJob::new(segments).unwrap());
    let job = cfg.job_definition().with_plan(&plan);
    let mut g = Guidance::new(plan, job, guidance_params(&cfg)).unwrap();
    let mut seen = Vec::new();
    for _ in 0..100_000 {
        if g.is_finished() {
            break;
        }
        seen.push((g.index_rank(), g.gap_before()));
        let path = g.global_path();
        let i = (g.index_global() + 1).min(path.len() - 1);
        let d = path[i].pos - path[i - 1].pos;
        g.update(&Pose::new(path[i].pos.x, path[i].pos.y, d.y.atan2(d.x)))
            .unwrap();
    }
    seen.dedup();
    assert_eq!(seen.len(), 3, "{seen:?}");
    assert_eq!(seen[0], (0, None));
    assert_eq!(seen[1], (1, None), "the turn starts where the swath ends");
    assert_eq!(seen[2].0, 2);
    assert!((seen[2].1.expect("a gap") - 4.0).abs() < 1e-9, "{seen:?}");
    // The job as planned joins everywhere: none.
    let plan = JobPlan::from(segment_job());
    let job = cfg.job_definition().with_plan(&plan);
    let mut g = Guidance::new(plan, job, guidance_params(&cfg)).unwrap();
    while !g.is_finished() {
        assert_eq!(g.gap_before(), None, "segment {}", g.index_rank());
        let path = g.global_path();
        let i = (g.index_global() + 1).min(path.len() - 1);
        let d = path[i].pos - path[i - 1].pos;
        g.update(&Pose::new(path[i].pos.x, path[i].pos.y, d.y.atan2(d.x)))
            .unwrap();
    }
}

#[test]
fn the_segments_driven_the_same_way_count_up_to_the_next_cusp_or_the_end() {
    use crate::geo::{v2, Direction};
    use crate::plan::coverage::SegmentKind;
    use crate::plan::job::{JobSegment, SegmentJob};
    let cfg = Config::default();
    let seg = |direction, x0: f64, x1: f64| JobSegment {
        kind: SegmentKind::Work,
        direction,
        cell: 0,
        points: vec![v2(x0, 0.0), v2(x1, 0.0)],
    };
    // Forward 20 m, forward 0.5 m and 1.5 m (short pieces), back 10 m, forward 10 m.
    let job = SegmentJob::new(vec![
        seg(Direction::Forward, 0.0, 20.0),
        seg(Direction::Forward, 20.0, 20.5),
        seg(Direction::Forward, 20.5, 22.0),
        seg(Direction::Reverse, 22.0, 12.0),
        seg(Direction::Forward, 12.0, 22.0),
    ])
    .unwrap();
    let plan = JobPlan::from(job);
    let definition = cfg.job_definition().with_plan(&plan);
    let mut g = Guidance::new(plan, definition, guidance_params(&cfg)).unwrap();
    let mut seen = Vec::new();
    while seen.len() < 5 {
        seen.push((g.index_rank(), g.stop_after_within(100.0)));
        // Farther than asked: none.
        if g.index_rank() < 2 {
            assert_eq!(g.stop_after_within(0.4), None, "segment {}", g.index_rank());
        }
        g.advance_segment();
    }
    assert_eq!(g.index_rank(), 4);
    let expected = [
        (0, (2.0, true)),
        (1, (1.5, true)),
        (2, (0.0, true)),
        (3, (0.0, true)),
        (4, (0.0, false)),
    ];
    for ((rank, after), (want_rank, (want_length, want_cusp))) in seen.iter().zip(expected) {
        let (length, cusp) = after.expect("a segment job");
        assert_eq!(*rank, want_rank);
        assert!((length - want_length).abs() < 1e-9, "{seen:?}");
        assert_eq!(cusp, want_cusp, "{seen:?}");
    }
}
