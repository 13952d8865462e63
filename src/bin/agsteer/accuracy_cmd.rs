//! `agsteer accuracy`: the scenario suite, every tracker side by side (see
//! [`agsteer::demo::accuracy`]).

use agsteer::config::{Config, TrackerChoice};
use agsteer::demo::accuracy::{
    evaluate, markdown_table, xte_svg, ScenarioResult, XteSeries, TRACKERS,
};
use agsteer::exit::Exit;
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};

/// The scenarios: the given files, or every `*.toml` in `dir`, sorted by name.
fn scenarios(dir: &Path, files: &[PathBuf]) -> Result<Vec<PathBuf>> {
    if !files.is_empty() {
        return Ok(files.to_vec());
    }
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("scenario directory {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    v.sort();
    if v.is_empty() {
        bail!("no *.toml scenarios in {}", dir.display());
    }
    Ok(v)
}

pub(crate) fn trackers(name: &str) -> Result<Vec<TrackerChoice>> {
    if name == "all" {
        return Ok(TRACKERS.to_vec());
    }
    // A comma-separated list of registered trackers, the first judged (the envelope's default
    // column), e.g. `lqr,pure_pursuit,stanley`.
    name.split(',')
        .map(|n| {
            TrackerChoice::ALL
                .iter()
                .copied()
                .find(|k| agsteer::demo::accuracy::tracker_name(*k) == n.trim())
                .with_context(|| {
                    let names: Vec<&str> = TrackerChoice::ALL.iter().map(|k| k.name()).collect();
                    format!(
                        "unknown tracker {n:?} ({}, a comma-separated list, or all)",
                        names.join(", ")
                    )
                })
        })
        .collect()
}

type Outcome = (usize, usize, Result<(ScenarioResult, XteSeries)>);

/// Run the suite; prints the table (or JSON) and writes OUT/<scenario>.svg and
/// OUT/accuracy.json.
pub fn run(
    dir: &Path,
    files: &[PathBuf],
    tracker: &str,
    json: bool,
    out: &Path,
    set: &[String],
) -> Result<u8> {
    let kinds = trackers(tracker)?;
    let paths = scenarios(dir, files)?;
    let mut cfgs: Vec<(String, Config)> = Vec::new();
    for p in &paths {
        let name = p
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| p.display().to_string());
        let cfg = Config::load(p, set).with_context(|| format!("scenario {}", p.display()))?;
        cfgs.push((name, cfg));
    }
    // Every (scenario, tracker) run is independent: spread them over the cores.
    let jobs: Vec<(usize, usize)> = (0..cfgs.len())
        .flat_map(|i| (0..kinds.len()).map(move |k| (i, k)))
        .collect();
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .min(jobs.len())
        .max(1);
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut outcomes: Vec<Outcome> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                s.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let j = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(&(i, k)) = jobs.get(j) else {
                            break;
                        };
                        let (name, cfg) = &cfgs[i];
                        let r = evaluate(name, cfg, kinds[k])
                            .with_context(|| format!("scenario {name}"));
                        done.push((i, k, r));
                    }
                    done
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_default())
            .collect()
    });
    outcomes.sort_by_key(|o| (o.0, o.1));
    if outcomes.len() != jobs.len() {
        bail!("a scenario run panicked");
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut results = Vec::new();
    for (i, (name, _)) in cfgs.iter().enumerate() {
        let mut series: Vec<(&str, XteSeries)> = Vec::new();
        for o in outcomes.iter_mut().filter(|o| o.0 == i) {
            let r = std::mem::replace(&mut o.2, Err(anyhow::anyhow!("taken")))?;
            series.push((agsteer::demo::accuracy::tracker_name(kinds[o.1]), r.1));
            results.push(r.0);
        }
        let refs: Vec<(&str, &XteSeries)> = series.iter().map(|(n, s)| (*n, s)).collect();
        let svg_path = out.join(format!("{name}.svg"));
        std::fs::write(&svg_path, xte_svg(name, &refs))
            .with_context(|| format!("writing {}", svg_path.display()))?;
    }
    let text = serde_json::to_string_pretty(&results)?;
    let json_path = out.join("accuracy.json");
    std::fs::write(&json_path, &text)
        .with_context(|| format!("writing {}", json_path.display()))?;
    if json {
        println!("{text}");
    } else {
        print!("{}", markdown_table(&results));
        for r in &results {
            if let Some(f) = &r.rtk_float {
                println!(
                    "\n{} / {}: RTK float {:?} s; safety.rtk_float_tolerance_s = {} ({}): {} fix-quality disengagement(s), max |XTE| during the float {}",
                    r.scenario,
                    r.tracker,
                    f.windows_s,
                    f.tolerance_s,
                    f.behaviour,
                    f.fix_disengagements,
                    f.xte_max_during_float_m
                        .map_or("- (no work samples)".into(), |m| format!("{:.2} cm", 100.0 * m)),
                );
            }
        }
        eprintln!("SVGs and accuracy.json in {}", out.display());
    }
    Ok(verdict(&cfgs, &results, tracker).code())
}

/// Hold the runs of the tracker under test to their scenario's `[acceptance]` limits: the named
/// tracker, or with "all" each scenario's `track.kind` (the others are references, shown for
/// comparison). Prints every shortfall on stderr; the status is the first of not finished,
/// accuracy not met.
fn verdict(cfgs: &[(String, Config)], results: &[ScenarioResult], tracker: &str) -> Exit {
    let mut not_finished = Vec::new();
    let mut misses = Vec::new();
    let mut held = 0;
    for r in results {
        let Some((_, cfg)) = cfgs.iter().find(|(name, _)| *name == r.scenario) else {
            continue;
        };
        let held_name = if tracker == "all" {
            agsteer::demo::accuracy::tracker_name(cfg.track.kind)
        } else {
            // The first of a list is held.
            tracker.split(',').next().unwrap_or(tracker).trim()
        };
        if r.tracker != held_name {
            continue;
        }
        held += 1;
        if !r.finished {
            not_finished.push(format!(
                "{} / {}: the job did not finish (disengagements: {:?})",
                r.scenario, r.tracker, r.disengagements
            ));
        }
        for m in cfg.acceptance.misses(r.xte_rms_m, r.xte_p95_m, r.xte_max_m) {
            misses.push(format!(
                "{} / {}: accuracy not met: {m}",
                r.scenario, r.tracker
            ));
        }
    }
    for m in not_finished.iter().chain(&misses) {
        eprintln!("error: {m}");
    }
    if not_finished.is_empty() && misses.is_empty() {
        eprintln!(
            "accuracy: {held} run(s) held to their [acceptance] limits, all finished within them"
        );
    }
    if !not_finished.is_empty() {
        Exit::NotFinished
    } else if !misses.is_empty() {
        Exit::AccuracyNotMet
    } else {
        Exit::Success
    }
}

/// `agsteer accuracy --envelope` arguments.
pub struct EnvelopeArgs<'a> {
    pub dir: &'a Path,
    pub files: &'a [PathBuf],
    pub tracker: &'a str,
    pub json: bool,
    pub out: &'a Path,
    pub set: &'a [String],
    pub variations: &'a [String],
    pub calibration: &'a str,
    pub threads: Option<usize>,
}

/// The envelope: every scenario under every variation, for the trackers asked (the default
/// first, so that the references are compared with it).
pub fn run_envelope(a: &EnvelopeArgs) -> Result<u8> {
    use agsteer::demo::envelope::{self, Calibration, MATRIX};
    let kinds = trackers(a.tracker)?;
    let calibration = match a.calibration {
        "truth" => Calibration::Truth,
        "nominal" => Calibration::Nominal,
        other => bail!("unknown --calibration {other:?} (truth or nominal)"),
    };
    let vars: Vec<&envelope::Variation> = if a.variations.is_empty() {
        MATRIX.iter().collect()
    } else {
        a.variations
            .iter()
            .map(|n| {
                MATRIX.iter().find(|v| v.name == n).with_context(|| {
                    let names: Vec<&str> = MATRIX.iter().map(|v| v.name).collect();
                    format!("unknown variation {n:?} (one of {})", names.join(", "))
                })
            })
            .collect::<Result<_>>()?
    };
    let paths = scenarios(a.dir, a.files)?;
    let names: Vec<String> = paths
        .iter()
        .map(|p| {
            p.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| p.display().to_string())
        })
        .collect();
    let mut jobs = Vec::new();
    for v in &vars {
        for (p, n) in paths.iter().zip(&names) {
            let cfg = envelope::cell_config(p, v, a.set, calibration)
                .with_context(|| format!("variation {} on scenario {}", v.name, p.display()))?;
            jobs.push((v.name, n.as_str(), cfg));
        }
    }
    let threads = a.threads.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let start = std::time::Instant::now();
    eprintln!(
        "envelope: {} variations × {} scenarios × {} trackers on {threads} threads",
        vars.len(),
        names.len(),
        kinds.len()
    );
    let cells = envelope::parallel_map(
        &jobs,
        threads,
        &|(v, n, cfg)| envelope::run_cell(v, n, cfg, &kinds),
        &|done, total| {
            eprint!(
                "\r{done}/{total} cells, {:.0} s",
                start.elapsed().as_secs_f64()
            );
            if done == total {
                eprintln!();
            }
        },
    );
    std::fs::create_dir_all(a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let var_names: Vec<&str> = vars.iter().map(|v| v.name).collect();
    let sc_names: Vec<&str> = names.iter().map(String::as_str).collect();
    let table = envelope::markdown(&cells, &var_names, &sc_names);
    let svg = envelope::heat_map_svg(&cells, &var_names, &sc_names);
    let report = serde_json::json!({
        "calibration": calibration,
        "trackers": kinds.iter().map(|k| agsteer::demo::accuracy::tracker_name(*k)).collect::<Vec<_>>(),
        "set": a.set,
        "variations": vars,
        "cells": cells.iter().map(|c| {
            let mut j = serde_json::to_value(c).unwrap_or_default();
            if let Some(o) = j.as_object_mut() {
                o.insert("verdict".into(), serde_json::to_value(c.verdict()).unwrap_or_default());
                o.insert("meets_targets".into(), c.meets_targets().into());
            }
            j
        }).collect::<Vec<_>>(),
    });
    let text = serde_json::to_string_pretty(&report)?;
    for (file, body) in [
        ("envelope.md", table.as_str()),
        ("envelope.svg", svg.as_str()),
        ("envelope.json", text.as_str()),
    ] {
        let p = a.out.join(file);
        std::fs::write(&p, body).with_context(|| format!("writing {}", p.display()))?;
    }
    let refused = cells
        .iter()
        .filter(|c| c.verdict().refused_by_design)
        .count();
    let failed: Vec<String> = cells
        .iter()
        .filter(|c| !c.meets_targets() && !c.verdict().refused_by_design)
        .map(|c| format!("{}/{}", c.variation, c.scenario))
        .collect();
    if a.json {
        println!("{text}");
    } else {
        print!("{table}");
        println!(
            "\n{} of {} cells meet the targets, {refused} refused by design (line_unfollowable) ({} s); missed: {}",
            cells.len() - failed.len() - refused,
            cells.len(),
            start.elapsed().as_secs(),
            if failed.is_empty() {
                "none".to_string()
            } else {
                failed.join(", ")
            }
        );
        eprintln!(
            "envelope.md, envelope.svg and envelope.json in {}",
            a.out.display()
        );
    }
    Ok(0)
}
