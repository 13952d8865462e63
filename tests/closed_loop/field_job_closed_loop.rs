//! The demo field job (config/demo-field.toml: an L-shaped field with a power pole, 12 m
//! implement, r_min 6 m) planned and driven to the end in the in-process demo, scored against
//! the simulator's ground truth.
//!
//! Bounds are about twice what the run measured when they were set (in brackets), so a real
//! regression fails while noise does not.

use agsteer::config::Config;
use agsteer::demo::{run, DemoOptions, Report};
use agsteer::guidance::progress::Progress;
use agsteer::job::field as field_file;
use agsteer::job::field::FieldJob;
use agsteer::plan::coverage::SegmentKind;
use agsteer::store::progress_file;

/// The demo-field configuration. `job.field_path` is relative to the working directory, the
/// package root under `cargo test`.
fn field_job() -> (Config, FieldJob) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/config/demo-field.toml");
    let cfg = Config::load(std::path::Path::new(path), &[]).expect("config/demo-field.toml");
    let job = field_file::load_config(&cfg).expect("the demo field loads and plans");
    (cfg, job)
}

fn options(job: &FieldJob) -> DemoOptions {
    DemoOptions {
        job: Some(job.job_plan()),
        outlines: job.outlines(),
        origin: Some(job.origin()),
        ..Default::default()
    }
}

fn check_tracking(r: &Report, segments: usize) {
    assert!(r.finished, "not finished: {r:?}");
    assert_eq!(r.lines_planned, Some(segments as u64));
    assert_eq!(r.lines_completed, segments as u64);
    assert_eq!(
        r.segments.len(),
        segments,
        "every segment is driven and scored"
    );
    // Work phases (headland passes and swaths, first 10 m of each skipped).
    assert!(
        r.segments.iter().any(|s| s.kind == SegmentKind::Detour),
        "the pole is passed on a detour"
    );
    // Measured figures in brackets (the detour round the pole counts as work).
    assert!(r.xte_rms_m < 0.05, "work XTE RMS {} m [0.024]", r.xte_rms_m);
    assert!(r.xte_p95_m < 0.10, "work XTE p95 {} m [0.044]", r.xte_p95_m);
    assert!(r.xte_max_m < 0.35, "work XTE max {} m [0.16]", r.xte_max_m);
    assert!(
        r.acquisition_xte_max_m < 0.30,
        "acquisition {} m [0.131]",
        r.acquisition_xte_max_m
    );
    // Every segment over its whole length (acquisition included). Turns are planned at
    // r_min, where the wheels saturate: they are followed less tightly than the lines.
    for s in &r.segments {
        let (rms_bound, max_bound) = match s.kind {
            SegmentKind::Work | SegmentKind::Headland => (0.2, 0.8), // [0.095, 0.36]
            _ => (0.75, 1.2),                                        // [0.37, 0.61]
        };
        assert!(
            s.xte_rms_m < rms_bound && s.xte_max_m < max_bound,
            "segment {} ({:?}, {:.1} m): RMS {} m, max {} m",
            s.index,
            s.kind,
            s.length_m,
            s.xte_rms_m,
            s.xte_max_m
        );
    }
    let pos = r.goal_position_error_m.expect("goal error");
    let heading = r.goal_heading_error_deg.expect("goal heading error");
    assert!(pos < 0.15, "goal position error {pos} m [0.028]");
    assert!(heading < 2.0, "goal heading error {heading}° [0.10]");
    assert!(
        r.engaged_fraction > 0.99,
        "engaged {} [0.9993]",
        r.engaged_fraction
    );
}

#[test]
fn demo_field_job_is_driven_to_the_end() {
    let (cfg, job) = field_job();
    let r = run(&cfg, &options(&job), &mut |_| {}, &mut |_, _| {})
        .expect("the demo runs")
        .report;
    check_tracking(&r, job.job.len());
}

#[test]
fn demo_field_job_resumes_its_own_plan_and_refuses_another() {
    let (cfg, job) = field_job();
    let dir = tempfile::tempdir().unwrap();
    let path = progress_file::progress_path(dir.path());
    let mut save = |p: &Progress| progress_file::save(&path, p).unwrap();
    let half = run(
        &cfg,
        &DemoOptions {
            stop_after_lines: Some(20),
            ..options(&job)
        },
        &mut save,
        &mut |_, _| {},
    )
    .unwrap();
    assert!(!half.report.finished);
    assert_eq!(half.finished_lines.len(), 20);
    let saved = progress_file::load(&path).unwrap().expect("progress saved");
    // A segment job counts every segment (turns and transits too) as a line done.
    assert_eq!(saved.lines_done, half.report.lines_completed);
    assert!(saved.lines_done >= 20);
    assert_eq!(saved.job, job.job_definition(&cfg));

    // Another plan of the same field (three headland passes: one and two both give the turns'
    // minimum, four break a guarantee and are refused at set-up) must not take this progress.
    let overrides = ["field.headland_passes=3".to_string()];
    let other_cfg = Config::load(
        std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/config/demo-field.toml"
        )),
        &overrides,
    )
    .unwrap();
    let other = field_file::load_config(&other_cfg).unwrap();
    assert_ne!(other.job.checksum(), job.job.checksum());
    let refused = run(
        &other_cfg,
        &DemoOptions {
            resume: Some(saved.clone()),
            ..options(&other)
        },
        &mut |_| {},
        &mut |_, _| {},
    );
    assert!(refused.is_err(), "progress of another plan was resumed");

    let rest = run(
        &cfg,
        &DemoOptions {
            resume: Some(saved),
            ..options(&job)
        },
        &mut |_| {},
        &mut |_, _| {},
    )
    .unwrap();
    assert!(rest.report.finished, "{:?}", rest.report);
    assert_eq!(rest.report.lines_completed, job.job.len() as u64);
    // The work segments finished across both runs are those of an uninterrupted run, once.
    let full = run(&cfg, &options(&job), &mut |_| {}, &mut |_, _| {}).unwrap();
    let mut both = half.finished_lines.clone();
    both.extend(&rest.finished_lines);
    assert_eq!(both, full.finished_lines);
}

/// A real parcel (`tools/fields/real/f2c_nl_field_188.geojson`, 0.8 ha, two blocks) at w 6 m,
/// r_min 8 m: headland passes of S-bends at r_min and K-turns at the swath ends where no
/// forward turn fits. Driven to the end, engaged throughout, the reversing legs tracked.
/// Before session 21 the supervisor gave the first headland pass back as `tracking_unstable`
/// after 75 s (its cross-track error leaving ±0.2 m on the outside of each bend) and the job
/// stopped with no line done; with K-turns whose short forward first part is not refused
/// (`reverse::turn_lead_in`), a reversing leg was 1.4 m RMS off. Bounds about twice the
/// measured figures (in brackets).
#[test]
fn a_real_parcel_with_s_bends_and_k_turns_is_driven_to_the_end() {
    let config = concat!(env!("CARGO_MANIFEST_DIR"), "/config/demo-field.toml");
    let field = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tools/fields/real/f2c_nl_field_188.geojson"
    );
    let overrides = [
        format!("job.field_path={field}"),
        "job.line_width_m=6".to_string(),
        "vehicle.r_min_m=8".to_string(),
    ];
    let cfg = Config::load(std::path::Path::new(config), &overrides).expect("the config loads");
    let job = field_file::load_config(&cfg).expect("the parcel loads and plans");
    let r = run(&cfg, &options(&job), &mut |_| {}, &mut |_, _| {})
        .expect("the demo runs")
        .report;
    assert!(r.finished, "not finished: {:?}", r.disengagements);
    assert_eq!(r.lines_completed, job.job.len() as u64);
    assert!(r.engaged_fraction > 0.99, "engaged {}", r.engaged_fraction);
    assert!(r.xte_rms_m < 0.09, "work XTE RMS {} m [0.044]", r.xte_rms_m);
    assert!(r.xte_max_m < 0.45, "work XTE max {} m [0.202]", r.xte_max_m);
    let backing: Vec<_> = r
        .segments
        .iter()
        .filter(|s| s.direction == agsteer::geo::Direction::Reverse)
        .collect();
    assert!(backing.len() >= 4, "{} reversing legs [12]", backing.len());
    for s in backing {
        assert!(
            s.xte_rms_m < 0.15,
            "reversing leg {} ({:.1} m): RMS {} m [≤ 0.064]",
            s.index,
            s.length_m,
            s.xte_rms_m
        );
    }
}
