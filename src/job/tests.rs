use super::resume::resume_or_start as load_progress;
use super::*;
use crate::guidance::progress::{Phase, PROGRESS_VERSION};
use crate::store::progress_file;
use std::path::Path;

/// config/demo-field.toml; `job.field_path` is relative to the working directory, which
/// is the package root under `cargo test`.
fn demo_field_config(overrides: &[&str]) -> Config {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/config/demo-field.toml");
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    Config::load(Path::new(path), &overrides).expect("config/demo-field.toml is valid")
}

fn progress(job: &JobDefinition) -> Progress {
    Progress {
        version: PROGRESS_VERSION,
        job: job.clone(),
        index_block: 0,
        index_rank: 3,
        phase: Phase::Work,
        lines_done: 3,
        nudge_m: 0.0,
        line_worked_m: None,
    }
}

#[test]
fn field_job_is_planned_and_its_progress_resumed() {
    let cfg = demo_field_config(&[]);
    let job = prepare_config(&cfg).expect("the demo field plans");
    assert!(matches!(job.plan, JobPlan::Segments(_)));
    assert!(job.definition.plan_checksum.is_some());
    let dir = tempfile::tempdir().unwrap();
    let path = progress_file::progress_path(dir.path());
    progress_file::save(&path, &progress(&job.definition)).unwrap();
    let resume = load_progress(&job, &path).expect("same plan resumes");
    let node = build_node(&cfg.resolve().unwrap(), &job, Some(&resume)).expect("node resumes");
    assert_eq!(node.controller().guidance().lines_done(), 3);
    // GNSS positions are converted about the field's origin, not job.origin_*.
    let fj = field::load_config(&cfg).unwrap();
    assert_eq!(*node.enu(), crate::geo::wgs84::EnuFrame::new(fj.origin()));
    assert_ne!(fj.origin().lat_deg, cfg.job.origin_lat_deg);
}

#[test]
fn progress_saved_with_another_plan_checksum_is_not_resumed() {
    let cfg = demo_field_config(&[]);
    let job = prepare_config(&cfg).unwrap();
    // Three headland passes instead of two (more than the turns need, so the plan changes):
    // every job key is the same, only the plan differs.
    let other_cfg = demo_field_config(&["field.headland_passes=3"]);
    let other = prepare_config(&other_cfg).unwrap();
    assert_ne!(other.definition.plan_checksum, job.definition.plan_checksum);
    let changes = other.definition.differences(&job.definition);
    assert!(
        changes.iter().all(|c| c.starts_with("plan")),
        "only the plan differs: {changes:?}"
    );

    let dir = tempfile::tempdir().unwrap();
    let path = progress_file::progress_path(dir.path());
    progress_file::save(&path, &progress(&other.definition)).unwrap();
    assert_eq!(load_progress(&job, &path), None);
    // The file is left alone (not corrupt), and is still good for its own plan.
    assert!(load_progress(&other, &path).is_some());
    // Progress of an AB job (no checksum) does not resume a field job either.
    progress_file::save(&path, &progress(&cfg.job_definition())).unwrap();
    assert_eq!(load_progress(&job, &path), None);
    // And the controller itself refuses it too.
    let saved = progress(&other.definition);
    assert!(build_node(&cfg.resolve().unwrap(), &job, Some(&saved)).is_err());
}

#[test]
fn ab_job_definition_is_the_configured_one() {
    let cfg = Config::default();
    let job = prepare_config(&cfg).unwrap();
    assert!(job.origin.is_none());
    // The configured job keys, and the plan's identity on top.
    let mut keys = job.definition.clone();
    keys.identity.clear();
    assert_eq!(keys, cfg.job_definition());
    assert!(job.definition.identity.contains_key("ab.r_min"));
}

#[test]
fn an_unreadable_field_stops_the_daemon_naming_the_file() {
    let cfg = demo_field_config(&["job.field_path=\"/nonexistent/agsteer/field.geojson\""]);
    let e = prepare_config(&cfg).unwrap_err();
    let text = format!("{:#}", anyhow::Error::new(e));
    assert!(
        text.contains("/nonexistent/agsteer/field.geojson"),
        "{text}"
    );
    assert!(text.contains("job.field_path"), "{text}");
}

#[test]
fn a_missing_maneuver_map_is_named() {
    let cfg = Config::parse_with(
        "[job]\nkind = \"maneuver\"\nmaneuver_map_path = \"/nonexistent/agsteer/map.geojson\"\n",
        &[],
    )
    .unwrap();
    let e = prepare_config(&cfg).unwrap_err();
    let text = format!("{:#}", anyhow::Error::new(e));
    assert!(text.contains("/nonexistent/agsteer/map.geojson"), "{text}");
    assert!(text.contains("job.maneuver_map_path"), "{text}");
}

#[test]
fn the_demo_maneuver_is_planned_on_its_map() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/config/demo-maneuver.toml");
    let cfg = Config::load(Path::new(path), &[]).expect("config/demo-maneuver.toml is valid");
    let job = prepare_config(&cfg).expect("the demo manoeuvre plans");
    assert!(matches!(job.detail, JobDetail::Maneuver(_, Some(_))));
    assert!(job.definition.plan_checksum.is_some());
    assert!(job.origin.is_none() && job.field.is_none());
}
