//! GNSS off the bus: the simulator speaks NMEA 0183 on a pseudo-terminal
//! (`agsteer sim --gnss-pty`) or in UDP datagrams (`--gnss-udp`), agsteerd reads it as a
//! serial or UDP receiver (`[gnss]`), and wheel angle, speed, operator and steering frames stay
//! on vcan. The reference is the same AB job with GNSS as NMEA 2000 frames on vcan in the same
//! VM run: `a_closed_loop_job_on_vcan`'s, or run here when that test did not run.

use super::support::*;
use super::xte_from_trajectory;
use std::time::{Duration, Instant};

/// The simulator's pseudo-terminal link (the daemon's `gnss.device`).
const GNSS_LINK: &str = "/tmp/gnss-receiver";
const GNSS_UDP_PORT: u16 = 9999;

pub(super) struct JobRun {
    /// (rms, p95, max, samples, samples expected), m.
    pub(super) xte: (f64, f64, f64, usize, f64),
    pub(super) finished: bool,
    pub(super) reengaged: u32,
    pub(super) capture: Vec<String>,
    pub(super) status: serde_json::Value,
}

/// The AB job of config/vcan.toml, closed-loop, until finished (150 s at most).
pub(super) fn run_job(
    iface: &str,
    label: &str,
    daemon_extra: &[&str],
    sim_extra: &[&str],
) -> JobRun {
    let traj = format!("/tmp/agsteer-trajectory-{label}.csv");
    let daemon = start_daemon(daemon_extra);
    let dump = Candump::start(iface);
    let mut sim_args = vec!["--trajectory", traj.as_str()];
    sim_args.extend_from_slice(sim_extra);
    let sim = start_sim(iface, &sim_args);
    let mut term = Terminal::new(iface);
    assert!(
        term.engage(Duration::from_secs(15)),
        "{label}: engaged; status {:?}",
        status()
    );
    let t0 = Instant::now();
    let mut reengaged = 0;
    let mut finished = false;
    while t0.elapsed() < Duration::from_secs(150) {
        match status() {
            Some(s) if s["finished"] == true => {
                finished = true;
                break;
            }
            Some(s) if s["state"] == "ready" && s["engaged"] == false => {
                println!("GNSS-VCAN {label}: operator re-engages after: {s}");
                reengaged += 1;
                term.send(1);
            }
            _ => {}
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let last = status().unwrap_or_default();
    let capture = dump.stop();
    drop(sim);
    drop(daemon);
    JobRun {
        xte: xte_from_trajectory(&traj),
        finished,
        reengaged,
        capture,
        status: last,
    }
}

fn print(label: &str, r: &JobRun) {
    let (rms, p95, max, n, expected) = r.xte;
    println!(
        "VCAN-GNSS-JOB-XTE {label}: rms_m={rms:.4} p95_m={p95:.4} max_m={max:.4} samples={n} of \
         ~{expected:.0} finished={} reengaged={}",
        r.finished, r.reengaged
    );
}

/// Each epoch's send time (UTC s) from `agsteer sim --gnss-log` → the next steering command
/// frame in the candump capture (same guest clock): (median, p99, count), s.
fn epoch_to_command(log: &str, capture: &[String]) -> (f64, f64, usize) {
    let cmds: Vec<f64> = steering_frames(&parse_candump(capture))
        .iter()
        .map(|c| c.0)
        .collect();
    let mut lat: Vec<f64> = next_after(&gnss_log_times(log), &cmds)
        .iter()
        .map(|(s, c)| c - s)
        .collect();
    lat.sort_by(|a, b| a.total_cmp(b));
    (pct(&lat, 0.5), pct(&lat, 0.99), lat.len())
}

/// The AB job three ways: GNSS as NMEA 2000 on vcan (the reference, recorded by
/// `a_closed_loop_job_on_vcan` in this boot), NMEA 0183 on a pseudo-terminal, NMEA 0183 over
/// UDP. The serial and UDP runs' true XTE RMS is within twice the reference's, taken at least
/// `XTE_REFERENCE_FLOOR_M` (the short job's run-to-run spread, see there).
#[test]
fn k_gnss_on_a_pty_and_udp_closed_loop() {
    let Some(iface) = vcan() else { return };
    let (can_rms, _, source) = super::isobus::angle_mode_xte(&iface);
    println!("VCAN-GNSS-JOB-XTE can: rms_m={can_rms:.4} ({source})");

    let device = format!("gnss.device=\"{GNSS_LINK}\"");
    let serial_log = "/tmp/agsteer-gnss-serial.csv";
    let pty = run_job(
        &iface,
        "pty",
        &serial_gnss_args(&device),
        &["--gnss-pty", GNSS_LINK, "--gnss-log", serial_log],
    );
    print("pty", &pty);
    let (median, p99, n) = epoch_to_command(serial_log, &pty.capture);
    println!(
        "GNSS-SERIAL-TO-COMMAND dt_ms=10 median_ms={:.2} p99_ms={:.2} over {n}",
        median * 1e3,
        p99 * 1e3
    );
    println!("GNSS-VCAN pty stream: {}", pty.status["gnss"]);

    let port = format!("gnss.udp_port={GNSS_UDP_PORT}");
    let to = format!("127.0.0.1:{GNSS_UDP_PORT}");
    let udp_log = "/tmp/agsteer-gnss-udp.csv";
    let udp = run_job(
        &iface,
        "udp",
        &[
            "--set",
            "gnss.source=\"nmea0183\"",
            "--set",
            "gnss.transport=\"udp\"",
            "--set",
            "gnss.udp_bind=\"127.0.0.1\"",
            "--set",
            &port,
        ],
        &["--gnss-udp", &to, "--gnss-log", udp_log],
    );
    print("udp", &udp);
    let (median, p99, n) = epoch_to_command(udp_log, &udp.capture);
    println!(
        "GNSS-UDP-TO-COMMAND dt_ms=10 median_ms={:.2} p99_ms={:.2} over {n}",
        median * 1e3,
        p99 * 1e3
    );
    println!("GNSS-VCAN udp stream: {}", udp.status["gnss"]);

    for (label, r) in [("pty", &pty), ("udp", &udp)] {
        assert!(r.finished, "{label}: job finished: {}", r.status);
        assert!(
            r.xte.3 as f64 > 0.6 * r.xte.4,
            "{label}: {} trajectory samples on the lines",
            r.xte.3
        );
    }
    let reference = can_rms.max(super::support::XTE_REFERENCE_FLOOR_M.0);
    assert!(
        pty.xte.0 <= 2.0 * reference,
        "pty XTE RMS {} vs all-CAN {}",
        pty.xte.0,
        can_rms
    );
    assert!(
        udp.xte.0 <= 2.0 * reference,
        "udp XTE RMS {} vs all-CAN {}",
        udp.xte.0,
        can_rms
    );
    for (label, r) in [("pty", &pty), ("udp", &udp)] {
        let decoded = r.status["gnss"]["stream"]["decoded"].as_u64().unwrap_or(0);
        assert!(decoded > 100, "{label}: sentences decoded: {}", r.status);
    }
}
