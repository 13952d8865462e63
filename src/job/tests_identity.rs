//! The plan's identity over every key of the configuration, and progress contents checked
//! against the plan (issue 20 points 1 and 2).

use super::resume::{load_saved, Saved};
use super::*;
use crate::geo::Vec2;
use crate::guidance::progress::{Phase, Progress, PROGRESS_VERSION};
use crate::plan::abline::AbPlan;
use crate::store::progress_file::{self, ProgressFileError};

/// The origin, and each line (or `u64::MAX` for a turn) with its points.
type Driven = (crate::geo::wgs84::LatLon, Vec<(u64, Vec<Vec2>)>);

/// What the AB job drives, computed from the plan itself (not from its parameters): the
/// origin, and every work line and turn in driving order, point by point.
fn driven(cfg: &Config) -> Option<Driven> {
    let planning = cfg.planning();
    let plan = AbPlan::new(planning.ab.clone()).ok()?;
    let mut out = Vec::new();
    let mut pos = Some((0u64, 0usize));
    let mut buf = Vec::new();
    while let Some((block, rank)) = pos {
        buf.clear();
        plan.work_line_points(block, rank, &mut buf);
        out.push((
            plan.line_of(block, rank),
            buf.iter().map(|p| p.pos).collect(),
        ));
        pos = plan.next_position(block, rank);
        if let Some(next) = pos {
            buf.clear();
            let _ = plan.turn_points((block, rank), next, &mut buf);
            out.push((u64::MAX, buf.iter().map(|p| p.pos).collect()));
        }
        if out.len() > 10_000 {
            return None;
        }
    }
    Some((planning.origin, out))
}

/// Every leaf key of a TOML table with its value.
fn leaves(prefix: &str, t: &toml::Table, out: &mut Vec<(String, toml::Value)>) {
    for (k, v) in t {
        let key = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        match v {
            toml::Value::Table(inner) => leaves(&key, inner, out),
            other => out.push((key, other.clone())),
        }
    }
}

fn set(root: &toml::Table, key: &str, value: toml::Value) -> toml::Table {
    let mut root = root.clone();
    let mut t = &mut root;
    let parts: Vec<&str> = key.split('.').collect();
    for p in &parts[..parts.len() - 1] {
        t = t.get_mut(*p).and_then(toml::Value::as_table_mut).unwrap();
    }
    t.insert(parts[parts.len() - 1].to_string(), value);
    root
}

/// Changed values to try for a key, nearest first.
fn variations(v: &toml::Value) -> Vec<toml::Value> {
    use toml::Value as V;
    match v {
        V::Float(x) if *x == 0.0 => vec![V::Float(0.5), V::Float(-0.5), V::Float(0.05)],
        V::Float(x) => vec![V::Float(x * 1.3), V::Float(x * 0.7), V::Float(x * 1.05)],
        V::Integer(i) => vec![V::Integer(i + 1), V::Integer(i - 1), V::Integer(i * 2)],
        V::Boolean(b) => vec![V::Boolean(!b)],
        V::Array(a) => match a.first() {
            Some(first) => variations(first)
                .into_iter()
                .map(|f| {
                    let mut a = a.clone();
                    a[0] = f;
                    V::Array(a)
                })
                .collect(),
            None => vec![],
        },
        _ => vec![],
    }
}

/// Property over every numeric, boolean and list key of the configuration: a change that
/// alters what the AB job drives (or where) changes the job's identity, so the progress of
/// the old plan is refused; a key of the tracker, the simulator, the bus or the daemon never
/// changes it.
#[test]
fn every_key_either_leaves_the_plan_identical_or_changes_the_identity() {
    let base = Config::default();
    let root = toml::Table::try_from(&base).unwrap();
    let mut keys = Vec::new();
    leaves("", &root, &mut keys);
    let base_job = prepare_config(&base).unwrap();
    let base_driven = driven(&base).unwrap();
    let (mut tried, mut plan_changed, mut id_changed, mut untried) = (0, 0, 0, Vec::new());
    for (key, value) in &keys {
        let changed = variations(value).into_iter().find_map(|v| {
            let cfg: Config = set(&root, key, v).try_into().ok()?;
            (cfg.validate().is_empty() && cfg != base).then_some(cfg)
        });
        let Some(cfg) = changed else {
            untried.push(key.clone());
            continue;
        };
        tried += 1;
        let job = prepare_config(&cfg);
        let Ok(job) = job else { continue };
        let same_plan = driven(&cfg).as_ref() == Some(&base_driven);
        let differences = job.definition.differences(&base_job.definition);
        if !same_plan {
            plan_changed += 1;
            assert!(
                !differences.is_empty(),
                "{key}: the driven plan changed but the identity did not"
            );
        }
        if !differences.is_empty() {
            id_changed += 1;
            let section = key.split('.').next().unwrap_or("");
            assert!(
                !["track", "sim", "bus", "daemon", "gnss", "envelope"].contains(&section),
                "{key} is no planning input but changed the identity: {differences:?}"
            );
        }
    }
    eprintln!(
        "{} keys: {tried} changed, {plan_changed} of them changed the plan, {id_changed} the identity; not varied (strings or no valid change): {untried:?}",
        keys.len()
    );
    assert!(tried > 100 && plan_changed >= 8, "{tried} {plan_changed}");
}

fn save_progress(
    job: &PreparedJob,
    block: u64,
    rank: u64,
    phase: Phase,
    lines_done: u64,
) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let p = Progress {
        version: PROGRESS_VERSION,
        job: job.definition.clone(),
        index_block: block,
        index_rank: rank,
        phase,
        lines_done,
        nudge_m: 0.0,
        line_worked_m: None,
    };
    progress_file::save(&progress_file::progress_path(dir.path()), &p).unwrap();
    dir
}

/// The resume into another plan: a faster speed (so a larger turn radius and another
/// block order), a lower lateral acceleration limit, a moved origin.
#[test]
fn resume_into_another_plan_is_refused_naming_what_changed() {
    let base = Config::default();
    let job = prepare_config(&base).unwrap();
    let dir = save_progress(&job, 0, 3, Phase::Work, 3);
    let path = progress_file::progress_path(dir.path());
    for (change, named) in [
        ("control.speed_kmh", "ab.r_min"),
        ("safety.a_lat_max_m_s2", "ab.r_min"),
        ("job.origin_lat_deg", "origin.lat_deg"),
    ] {
        let mut cfg = base.clone();
        match change {
            "control.speed_kmh" => cfg.control.speed_kmh = 20.0,
            "safety.a_lat_max_m_s2" => cfg.safety.a_lat_max_m_s2 = 0.5,
            _ => cfg.job.origin_lat_deg += 0.01,
        }
        let other = prepare_config(&cfg).unwrap();
        match load_saved(&other, &path).unwrap() {
            Saved::Foreign(changes) => assert!(
                changes.iter().any(|c| c.starts_with(named)),
                "{change}: {changes:?}"
            ),
            s => panic!("{change}: resumed {s:?}"),
        }
        let e = resume::require_resume(&other, &path, std::path::Path::new("demo.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(named) && e.contains("without --resume") && e.contains("restore"),
            "{e}"
        );
    }
    // Its own plan still resumes; the file was left in place.
    assert!(matches!(load_saved(&job, &path).unwrap(), Saved::Ours(_)));
}

/// The impossible contents with a valid checksum: each is moved aside as corrupt,
/// naming the file and the field.
#[test]
fn impossible_progress_is_moved_aside_naming_the_field() {
    let job = prepare_config(&Config::default()).unwrap();
    let JobPlan::Ab(plan) = &job.plan else {
        panic!("the default job is AB")
    };
    let block_len = plan.block_len(0) as u64;
    for (block, rank, phase, done, field) in [
        (0, 8.max(block_len), Phase::Work, 2, "index_rank"),
        (0, 2, Phase::Work, 100, "lines_done"),
        (0, 2, Phase::Work, u64::MAX, "lines_done"),
        (0, 0, Phase::Finished, 0, "finished"),
        (u64::MAX, 0, Phase::Turn, 0, "index_block"),
        (0, 1, Phase::Work, 0, "lines_done"),
    ] {
        let dir = save_progress(&job, block, rank, phase, done);
        let path = progress_file::progress_path(dir.path());
        match load_saved(&job, &path) {
            Err(e @ ProgressFileError::Corrupt { .. }) => {
                let msg = e.to_string();
                assert!(
                    msg.contains("progress.json") && msg.contains(field),
                    "{msg}"
                );
                assert!(!path.exists(), "moved aside");
            }
            other => panic!("({block}, {rank}, {phase:?}, {done}) accepted: {other:?}"),
        }
    }
    // A consistent one is taken.
    let dir = save_progress(&job, 0, 2, Phase::Turn, 2);
    let path = progress_file::progress_path(dir.path());
    assert!(matches!(load_saved(&job, &path).unwrap(), Saved::Ours(_)));
}
