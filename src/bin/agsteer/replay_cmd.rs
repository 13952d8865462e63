//! `agsteer replay LOG... --config FILE`: the controller run offline on a recorded bus log
//! (`agsteerd --bus-log`, or any candump log), faster than real time; prints the commands it
//! would send and its status track, and how they compare with the daemon's own commands when
//! the log holds them (see `agsteer::control::replay`).

use agsteer::can::candump::{format_line, parse_line};
use agsteer::can::Frame;
use agsteer::config::Config;
use agsteer::control::replay::{ticks_for, Replay, ReplayTick, Ticks};
use anyhow::{Context, Result};
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};

pub struct ReplayArgs<'a> {
    pub logs: &'a [PathBuf],
    /// Progress file to resume from (as the daemon did at start).
    pub progress: Option<&'a Path>,
    /// Write the frames the node would send here, in `candump -L` form.
    pub frames_out: Option<&'a Path>,
    /// Use a timer every dt (and a period at each fix) even if the log holds commands.
    pub timer: bool,
    /// Print the summary as JSON only.
    pub json: bool,
    /// Status track: one line every this many periods (0: none).
    pub every: u64,
    /// Exit status 9 when a period differs from the log.
    pub strict: bool,
}

/// The log's frames in file order. A last line without its newline (the daemon was killed
/// while writing) is left out.
fn read_logs(paths: &[PathBuf]) -> Result<(Vec<(f64, Frame)>, u64)> {
    let mut frames = Vec::new();
    let mut unreadable = 0;
    for path in paths {
        let file = std::fs::File::open(path).with_context(|| format!("{}", path.display()))?;
        let mut reader = std::io::BufReader::new(file);
        let mut line = String::new();
        let mut number = 0u64;
        loop {
            line.clear();
            let n = reader
                .read_line(&mut line)
                .with_context(|| format!("{} line {}", path.display(), number + 1))?;
            if n == 0 {
                break;
            }
            number += 1;
            if !line.ends_with('\n') {
                unreadable += 1;
                break;
            }
            match parse_line(&line) {
                Some(l) => match l.t {
                    Some(t) => frames.push((t, l.frame)),
                    None => unreadable += 1,
                },
                None if line.trim().is_empty() || line.trim_start().starts_with('#') => {}
                None => unreadable += 1,
            }
        }
    }
    Ok((frames, unreadable))
}

pub fn run(cfg: &Config, args: &ReplayArgs) -> Result<u8> {
    let (frames, unreadable) = read_logs(args.logs)?;
    anyhow::ensure!(
        !frames.is_empty(),
        "{}: no time-stamped frames",
        args.logs
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let own = cfg.bus.source_address;
    let ticks = if args.timer {
        Ticks::Timer {
            dt: cfg.dt(),
            on_fix: true,
        }
    } else {
        ticks_for(frames.iter().map(|(_, f)| f), own, cfg.dt(), true)
    };
    // Offline: the address is the one the log shows, not claimed again.
    let node = crate::daemon_node(cfg, args.progress)?.without_address_claim();
    let mut out_frames = match args.frames_out {
        Some(p) => Some(std::io::BufWriter::new(
            std::fs::File::create(p).with_context(|| format!("{}", p.display()))?,
        )),
        None => None,
    };
    let stdout = std::io::stdout();
    let mut stdout = stdout.lock();
    let track = !args.json && args.every > 0;
    if track {
        writeln!(
            stdout,
            "t_s,state,engaged,fault,fix,xte_m,heading_error_deg,line,lines_done,wheel_angle_deg,curvature_1pm,frames,matches_log"
        )?;
    }
    let mut k = 0u64;
    let mut error: Option<std::io::Error> = None;
    let iface = cfg.bus.interface.clone();
    let on_tick = |tick: &ReplayTick| {
        if error.is_some() {
            return;
        }
        let r = (|| -> std::io::Result<()> {
            if let Some(w) = out_frames.as_mut() {
                for f in tick.sent {
                    writeln!(w, "{}", format_line(tick.t, &iface, f))?;
                }
            }
            for ev in tick.events.iter().filter(|_| !args.json) {
                eprintln!("{:.6} {ev}", tick.t);
            }
            // Every period that differs from the log is printed.
            if track && (k % args.every == 0 || tick.matches() == Some(false)) {
                let s = &tick.status;
                let opt = |v: Option<f64>, digits: usize| {
                    v.map_or(String::new(), |x| format!("{x:.digits$}"))
                };
                writeln!(
                    stdout,
                    "{:.6},{},{},{},{},{},{},{},{},{:.3},{:.6},{},{}",
                    tick.t,
                    s.state.code(),
                    s.engaged,
                    s.fault as u8,
                    serde_json::to_value(s.fix)
                        .ok()
                        .and_then(|v| v.as_str().map(str::to_string))
                        .unwrap_or_default(),
                    opt(s.xte_m, 4),
                    opt(s.heading_error_deg, 2),
                    s.line,
                    s.lines_done,
                    tick.command.wheel_angle.to_degrees(),
                    tick.command.curvature,
                    tick.sent.len(),
                    match tick.matches() {
                        Some(true) => "yes",
                        Some(false) => "no",
                        None => "",
                    }
                )?;
            }
            Ok(())
        })();
        if let Err(e) = r {
            error = Some(e);
        }
        k += 1;
    };
    let start = std::time::Instant::now();
    let mut replay = Replay::new(node, own, ticks, on_tick);
    for (t, f) in &frames {
        replay.push(*t, f);
    }
    let (node, mut summary) = replay.finish();
    if let Some(e) = error {
        return Err(e).context("writing the replay");
    }
    if let Some(mut w) = out_frames {
        w.flush().context("writing the frames")?;
    }
    summary.unreadable_lines = unreadable;
    let span = frames.last().map_or(0.0, |l| l.0) - frames.first().map_or(0.0, |f| f.0);
    let wall = start.elapsed().as_secs_f64();
    let report = serde_json::json!({
        "ticks_from": match ticks { Ticks::Logged => "log", Ticks::Timer { .. } => "timer" },
        "summary": summary,
        "log_span_s": span,
        "replay_s": wall,
        "final": node.status(),
    });
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        eprintln!(
            "replayed {} frames in, {} control periods over {span:.1} s of log in {wall:.2} s ({:.0}× real time); ticks from the {}{}",
            summary.frames_in,
            summary.ticks,
            span / wall.max(1e-9),
            if ticks == Ticks::Logged { "log" } else { "timer" },
            if ticks == Ticks::Logged {
                format!(
                    ": {} periods equal the log, {} differ{}",
                    summary.matching,
                    summary.differing,
                    summary
                        .first_difference_t
                        .map_or(String::new(), |t| format!(" (first at {t:.6} s)"))
                )
            } else {
                String::new()
            }
        );
        if unreadable > 0 {
            eprintln!("{unreadable} lines were not frames and were skipped");
        }
    }
    Ok(if args.strict && summary.differing > 0 {
        agsteer::exit::Exit::ReplayDiffers.code()
    } else {
        agsteer::exit::Exit::Success.code()
    })
}
