//! `agsteer demo`: the configured job closed-loop against the simulator, judged: the exit
//! status says whether the job finished, within the documented accuracy (`[acceptance]`), with
//! its progress saved ([`agsteer::exit::Exit`]).

use agsteer::config::{Config, JobKind};
use agsteer::demo::{self, DemoOptions};
use agsteer::exit::Exit;
use agsteer::field::output::PlanSummary;
use agsteer::guidance::Event;
use agsteer::job::{JobDetail, PreparedJob};
use agsteer::store::progress_file;
use anyhow::{Context, Result};
use std::path::Path;

fn log_event(t: f64, ev: &Event) {
    tracing::info!(t_s = format_args!("{t:.2}"), "{ev}");
}

/// The configured job set up as agsteerd sets it up (timed, with progress on stderr), and for
/// a field job the plan's summary for the report.
fn prepare_demo_job(
    resolved: &agsteer::config::Resolved,
) -> Result<(PreparedJob, Option<PlanSummary>)> {
    let what = match resolved.planning.kind {
        JobKind::Maneuver => "planning the manoeuvre",
        JobKind::Ab | JobKind::Arcs | JobKind::Field => "planning",
    };
    let (job, ms) = crate::plan_cmd::timed(what, || agsteer::job::prepare(&resolved.planning));
    let job = job?;
    let summary = match &job.detail {
        JobDetail::Field(fj) => {
            let ((metrics, (findings, _)), metrics_time) =
                crate::plan_cmd::timed("metrics", || {
                    let m = fj.metrics();
                    let f = agsteer::field::findings::plan_findings(
                        &fj.loaded,
                        &fj.plan,
                        &m,
                        fj.params.line_width,
                        fj.params.r_min,
                        &fj.plan.warnings,
                    );
                    (m, f)
                });
            Some(PlanSummary::new(
                &fj.loaded,
                &fj.plan,
                &metrics,
                &findings,
                fj.plan_time,
                metrics_time,
            ))
        }
        JobDetail::Maneuver(mj, _) => {
            tracing::info!(
                "manoeuvre: {:.1} m, {} cusps, {:.1} m in reverse, {} segments, planned in {:.0} ms",
                mj.path.length(),
                mj.path.cusps(),
                mj.path.reverse_length(),
                mj.job.len(),
                ms.as_secs_f64() * 1e3
            );
            None
        }
        JobDetail::Lines => None,
    };
    Ok((job, summary))
}

pub fn run_demo(
    config: &Path,
    out: &Path,
    json: bool,
    resume: bool,
    stop_after: Option<u64>,
    set: &[String],
) -> Result<u8> {
    let cfg = crate::load_config(config, set)?;
    let resolved = cfg.resolve()?;
    let (job, summary) = prepare_demo_job(&resolved)
        .with_context(|| format!("setting up the job of {}", config.display()))?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let progress_path = out.join(progress_file::PROGRESS_FILE_NAME);
    let resume_from = if resume {
        Some(agsteer::job::resume::require_resume(
            &job,
            &progress_path,
            config,
        )?)
    } else {
        None
    };
    let field = match &job.detail {
        JobDetail::Field(fj) => Some(fj.as_ref()),
        _ => None,
    };
    let opts = DemoOptions {
        resume: resume_from,
        stop_after_lines: stop_after,
        record_trace: true,
        outlines: match &job.detail {
            JobDetail::Field(fj) => fj.outlines(),
            JobDetail::Maneuver(_, Some(map)) => std::iter::once(map.boundary.clone())
                .chain(map.obstacles.iter().cloned())
                .collect(),
            _ => Vec::new(),
        },
        prepared: Some(job.clone()),
        ..Default::default()
    };
    // The latest save's error (a later save that succeeds leaves the file current) and how
    // many saves failed.
    let mut save_error = None;
    let mut failed_saves = 0u64;
    let mut on_progress = |p: &agsteer::guidance::progress::Progress| {
        save_error = progress_file::save(&progress_path, p).err();
        failed_saves += u64::from(save_error.is_some());
    };
    let mut run =
        demo::run(&cfg, &opts, &mut on_progress, &mut log_event).context("running the demo job")?;
    let progress_lost = save_error.map(|e| {
        format!(
            "progress not saved: {} is not current ({failed_saves} save(s) failed, the last: {e}); a resume would repeat or skip lines",
            progress_path.display()
        )
    });
    if progress_lost.is_none() && failed_saves > 0 {
        tracing::warn!(
            "{failed_saves} progress save(s) to {} failed; the last one succeeded",
            progress_path.display()
        );
    }
    run.report.plan = summary.clone();
    let report_json = serde_json::to_string_pretty(&run.report)?;
    std::fs::write(out.join("report.json"), format!("{report_json}\n"))
        .with_context(|| format!("writing {}/report.json", out.display()))?;
    std::fs::write(
        out.join("trace.svg"),
        demo::svg::demo_svg(&run.trace, &run.report),
    )
    .with_context(|| format!("writing {}/trace.svg", out.display()))?;
    if json {
        println!("{report_json}");
    } else {
        let r = &run.report;
        if let (Some(fj), Some(p)) = (field, &summary) {
            println!(
                "plan of {}: {} cells, {} swaths, {} segments, {:.0} m ({:.0} m work, {:.0} m turns, {:.0} m transit); field worked {:.2} %, outside {:.3} m²; planned in {:.0} ms",
                fj.title(),
                p.cells,
                p.swaths,
                fj.job.len(),
                p.total_length_m,
                p.work_length_m,
                p.turn_length_m,
                p.transit_length_m,
                100.0 * p.covered_fraction,
                p.outside_area_m2,
                p.plan_time_ms
            );
        }
        println!(
            "{}: {}/{} lines, {} turns, {:.0} m in {:.0} s simulated ({:.2} s wall)",
            if r.finished {
                "finished"
            } else {
                "NOT finished"
            },
            r.lines_completed,
            r.lines_planned
                .map(|n| n.to_string())
                .unwrap_or_else(|| "unlimited".into()),
            r.turns,
            r.distance_m,
            r.sim_time_s,
            r.wall_time_s
        );
        println!(
            "true XTE on work lines: RMS {:.1} cm, p95 {:.1} cm, max {:.1} cm; acquisition max {:.1} cm (tracker {})",
            r.xte_rms_m * 100.0,
            r.xte_p95_m * 100.0,
            r.xte_max_m * 100.0,
            r.acquisition_xte_max_m * 100.0,
            r.tracker
        );
        let worst = |by: fn(&demo::SegmentReport) -> f64| {
            r.segments
                .iter()
                .max_by(|a, b| by(a).total_cmp(&by(b)))
                .map(|s| {
                    format!(
                        "segment {} ({:?}, {:?}, {:.0} m): RMS {:.1} cm, max {:.1} cm",
                        s.index,
                        s.kind,
                        s.direction,
                        s.length_m,
                        s.xte_rms_m * 100.0,
                        s.xte_max_m * 100.0
                    )
                })
        };
        if matches!(job.detail, JobDetail::Maneuver(..)) {
            for s in &r.segments {
                println!(
                    "segment {} ({:?}, {:.1} m): XTE RMS {:.1} cm, max {:.1} cm",
                    s.index,
                    s.direction,
                    s.length_m,
                    s.xte_rms_m * 100.0,
                    s.xte_max_m * 100.0
                );
            }
        } else if let (Some(rms), Some(max)) = (worst(|s| s.xte_rms_m), worst(|s| s.xte_max_m)) {
            println!("worst RMS on {rms}; worst max on {max}");
        }
        if let (Some(pos), Some(hdg)) = (r.goal_position_error_m, r.goal_heading_error_deg) {
            println!("goal error: {:.1} cm, {:.2}°", pos * 100.0, hdg);
        }
        println!("wrote {}/trace.svg and report.json", out.display());
    }
    let asked_stop = stop_after.is_some_and(|n| run.finished_lines.len() as u64 >= n);
    let maneuver = matches!(job.detail, JobDetail::Maneuver(..));
    Ok(verdict(&cfg, &run.report, asked_stop, maneuver, progress_lost).code())
}

/// Judge a demo run: print what failed on stderr (what was asked and what fell short) and
/// return the exit status, the first of progress not saved, not finished, accuracy not met.
fn verdict(
    cfg: &Config,
    r: &demo::Report,
    asked_stop: bool,
    maneuver: bool,
    progress_lost: Option<String>,
) -> Exit {
    let mut exit = Exit::Success;
    let mut fail = |e: Exit, message: String| {
        eprintln!("error: {message}");
        if exit == Exit::Success {
            exit = e;
        }
    };
    if let Some(m) = progress_lost {
        fail(Exit::ProgressNotSaved, m);
    }
    if !r.finished {
        if asked_stop {
            eprintln!(
                "stopped after {} line(s) as asked (--stop-after); continue with --resume",
                r.lines_completed
            );
        } else if let Some(planned) = r.lines_planned {
            let why: Vec<String> = r
                .disengagements
                .iter()
                .filter(|(k, _)| k.as_str() != "no_guidance")
                .map(|(k, n)| format!("{k} {n}"))
                .collect();
            let given_back = r.given_back.as_ref().map_or(String::new(), |g| {
                format!(
                    "; the steering was given back ({}) at {:.1} s{} and the run ends there: a driver takes over",
                    g.fault,
                    g.t_s,
                    g.path_distance_m
                        .map_or(String::new(), |d| format!(", {d:.1} m from the path"))
                )
            });
            fail(
                Exit::NotFinished,
                format!(
                    "the job did not finish: {}/{planned} lines in {:.0} s simulated (disengagements: {}){given_back}",
                    r.lines_completed,
                    r.sim_time_s,
                    if why.is_empty() { "none".to_string() } else { why.join(", ") }
                ),
            );
        }
    }
    if !maneuver {
        for m in cfg.acceptance.misses(r.xte_rms_m, r.xte_p95_m, r.xte_max_m) {
            fail(Exit::AccuracyNotMet, format!("accuracy not met: {m}"));
        }
    }
    exit
}
