//! Closed-loop demo: tracking regression bounds (2× the acceptance figures) and resume after a
//! simulated power loss through the real progress file.

use agsteer::config::{Config, TrackerChoice};
use agsteer::demo::{run, DemoOptions};
use agsteer::store::progress_file;

fn demo_config() -> Config {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/config/demo.toml");
    Config::load(std::path::Path::new(path), &[]).expect("config/demo.toml is valid")
}

#[test]
fn default_tracker_holds_the_line() {
    let cfg = demo_config();
    assert_eq!(cfg.track.kind, TrackerChoice::Predictive);
    let r = run(&cfg, &DemoOptions::default(), &mut |_| {}, &mut |_, _| {})
        .unwrap()
        .report;
    assert!(r.finished, "{r:?}");
    assert_eq!(r.lines_completed, 12);
    // Acceptance: rms ≤ 2.5 cm, p95 ≤ 5 cm, acquisition ≤ 5 cm. Regression bound: 2×.
    assert!(r.xte_rms_m <= 0.05, "rms {}", r.xte_rms_m);
    assert!(r.xte_p95_m <= 0.10, "p95 {}", r.xte_p95_m);
    assert!(
        r.acquisition_xte_max_m <= 0.10,
        "acq {}",
        r.acquisition_xte_max_m
    );
    assert!(r.max_wheel_angle_deg <= 35.0 + 1e-9);
}

#[test]
fn resume_after_power_loss_finishes_the_same_lines() {
    let cfg = demo_config();
    let full = run(&cfg, &DemoOptions::default(), &mut |_| {}, &mut |_, _| {}).unwrap();

    let dir = tempfile::tempdir().unwrap();
    let path = progress_file::progress_path(dir.path());
    let mut save = |p: &agsteer::guidance::progress::Progress| {
        progress_file::save(&path, p).unwrap();
    };
    let half = run(
        &cfg,
        &DemoOptions {
            stop_after_lines: Some(6),
            ..Default::default()
        },
        &mut save,
        &mut |_, _| {},
    )
    .unwrap();
    assert!(!half.report.finished);
    // Everything in memory is dropped; only the file remains.
    // Only the file carries progress into the second run.
    let saved = progress_file::load(&path)
        .unwrap()
        .expect("progress was saved");
    assert_eq!(saved.lines_done, 6);
    let rest = run(
        &cfg,
        &DemoOptions {
            resume: Some(saved),
            ..Default::default()
        },
        &mut save,
        &mut |_, _| {},
    )
    .unwrap();
    assert!(rest.report.finished, "{:?}", rest.report);
    let mut driven = half.finished_lines.clone();
    driven.extend(&rest.finished_lines);
    assert_eq!(driven, full.finished_lines, "no line twice, none skipped");
}

#[test]
fn corrupt_progress_is_not_trusted() {
    let dir = tempfile::tempdir().unwrap();
    let path = progress_file::progress_path(dir.path());
    std::fs::write(&path, b"{\"version\":1}\ncrc32c 00000000 13\n").unwrap();
    assert!(matches!(
        progress_file::load(&path),
        Err(progress_file::ProgressFileError::Corrupt { .. })
    ));
    assert!(!path.exists(), "moved aside");
}
