//! `agsteer calibrate --interface IFACE`: calibration by the running agsteerd (its calibration
//! mode, README "Calibration"). The tool is a terminal: it sends the operator command
//! `calibrate` on the interface, waits for the daemon's OperatorReply (`started`, or why not),
//! follows the procedure on the daemon's status socket (what the operator is asked to do), and
//! when the daemon answers `done` prints the figures with their standard deviations and writes
//! the TOML fragment where asked. A refusal (`engaged`, `failed`, the procedure's reason)
//! exits with status 10.

use crate::calibrate_cmd::{report, REFUSED};
use crate::status_cmd::query;
use agsteer::calibrate::Figures;
use agsteer::can::bus::{CanBus, Filter, SocketCanBus};
use agsteer::can::codec::{
    OperatorCommand, OperatorCommandCommand, OperatorReply, OperatorReplyCommand,
    OperatorReplyResult, Packer,
};
use anyhow::{bail, Context, Result};
use std::path::Path;
use std::time::{Duration, Instant};

/// The terminal's source address (the DBC's OperatorCommand sender).
const TERMINAL_ADDRESS: u8 = 0x26;
/// How long the daemon has to answer the command, s (it answers with its next period).
const REPLY_WITHIN_S: f64 = 2.0;

/// What live calibration needs.
pub struct Live<'a> {
    pub interface: &'a str,
    /// agsteerd's status socket.
    pub socket: &'a Path,
    /// Give up after this long, s.
    pub timeout_s: f64,
}

/// The calibrate replies received since the last call: (command's result).
fn replies(bus: &mut SocketCanBus) -> Vec<OperatorReplyResult> {
    let mut out = Vec::new();
    while let Ok(Some(tf)) = bus.try_recv() {
        let Ok(d) = agsteer::can::codec::decode(tf.frame.id, tf.frame.payload()) else {
            continue;
        };
        if let Some(r) = d.to::<OperatorReply>() {
            if r.command == Some(OperatorReplyCommand::Calibrate) {
                out.extend(r.result);
            }
        }
    }
    out
}

/// The calibration part of a status reply.
fn calibration(socket: &Path) -> Option<serde_json::Value> {
    query(socket, 1.0)
        .ok()
        .and_then(|v| v.get("calibration").cloned())
}

pub fn calibrate_live(live: &Live, out: Option<&Path>) -> Result<u8> {
    if !(live.timeout_s.is_finite() && live.timeout_s > 0.0) {
        bail!(
            "--timeout-s {}: must be a positive number of seconds",
            live.timeout_s
        );
    }
    let iface = live.interface;
    let mut bus = SocketCanBus::open(
        iface,
        &[Filter {
            id: 0x00FF_4100,
            mask: 0x03FF_FF00,
        }],
    )
    .with_context(|| format!("opening CAN interface {iface}"))?;
    // The status socket must answer before anything is started: without it the procedure
    // cannot be followed.
    query(live.socket, 2.0).with_context(|| {
        format!(
            "agsteerd's status socket {} (is agsteerd running?)",
            live.socket.display()
        )
    })?;
    let mut packer = Packer::new(TERMINAL_ADDRESS);
    let frame = packer.pack(&OperatorCommand {
        command: Some(OperatorCommandCommand::Calibrate),
        nudge: Some(0.0),
        job: Some(0.0),
    })?;
    bus.send(&frame)
        .with_context(|| format!("sending the calibrate command on {iface}"))?;
    let t0 = Instant::now();
    let started = loop {
        if let Some(r) = replies(&mut bus).into_iter().next() {
            break r;
        }
        if t0.elapsed().as_secs_f64() > REPLY_WITHIN_S {
            bail!(
                "no agsteerd answered the calibrate command on {iface} within {REPLY_WITHIN_S} s"
            );
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    match started {
        OperatorReplyResult::Started => eprintln!("agsteerd calibrates (on {iface})"),
        OperatorReplyResult::Engaged => {
            eprintln!("calibration refused: agsteerd is engaged: disengage first");
            return Ok(REFUSED);
        }
        other => {
            eprintln!(
                "calibration refused: agsteerd answered {other:?} (a calibration under way, or \
                 the steering feedback is not the wheel-angle frame; its log says which)"
            );
            return Ok(REFUSED);
        }
    }
    let mut shown = String::new();
    let mut ended: Option<OperatorReplyResult> = None;
    loop {
        if t0.elapsed().as_secs_f64() > live.timeout_s {
            bail!(
                "the calibration did not end within {} s (--timeout-s); agsteerd still runs it",
                live.timeout_s
            );
        }
        if ended.is_none() {
            ended = replies(&mut bus).into_iter().next();
        }
        let c = calibration(live.socket);
        let state = c
            .as_ref()
            .and_then(|c| c["state"].as_str())
            .unwrap_or("")
            .to_string();
        if state == "running" {
            let c = c.clone().unwrap_or_default();
            let phase = c["phase"].as_str().unwrap_or("?");
            let line = format!(
                "{phase}: {}",
                match c["instruction"].as_str() {
                    Some("drive") => format!(
                        "drive ahead at about {:.0} km/h, hands off the wheel",
                        c["drive_speed_kmh"].as_f64().unwrap_or(f64::NAN)
                    ),
                    Some("stop") => "stop the tractor, hands off the wheel".to_string(),
                    Some("line") => format!(
                        "steer by hand along the marked line at about {:.0} km/h",
                        c["drive_speed_kmh"].as_f64().unwrap_or(f64::NAN)
                    ),
                    Some("turn") => "turn round and come back over the same line, the \
                                     wheels in the same tracks"
                        .to_string(),
                    _ => "take over".to_string(),
                }
            );
            if line != shown {
                eprintln!(
                    "{:7.1} s  {line}",
                    c["elapsed_s"].as_f64().unwrap_or(f64::NAN)
                );
                shown = line;
            }
        }
        // The outcome: the reply on the bus, then the status's result (the node answers once
        // the result is saved, so the status has it).
        if ended.is_some() || state == "done" || state == "refused" {
            let Some(c) = c.filter(|c| c["state"] == "done" || c["state"] == "refused") else {
                std::thread::sleep(Duration::from_millis(100));
                continue;
            };
            if c["state"] == "refused" {
                eprintln!(
                    "calibration refused: {}",
                    c["reason"].as_str().unwrap_or("(no reason given)")
                );
                return Ok(REFUSED);
            }
            if let Some(r) = c["reason"].as_str() {
                eprintln!("agsteerd: {r}");
            }
            let figures: Figures = serde_json::from_value(c["figures"].clone())
                .context("the calibration's figures in agsteerd's status")?;
            let fragment = c["fragment"].as_str().unwrap_or_default();
            report(&figures, fragment, out)?;
            if let Some(files) = c["files"].as_array() {
                for f in files.iter().filter_map(|f| f.as_str()) {
                    eprintln!("agsteerd wrote {f}");
                }
            }
            return Ok(0);
        }
        std::thread::sleep(Duration::from_millis(200));
    }
}
