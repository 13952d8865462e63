//! kill -9 of the daemon under way, restarted each time (issue 16 point 8).

use super::support::*;
use std::time::{Duration, Instant};

/// kill -9 at random moments of a job (including during progress writes), restarting
/// each time: the daemon never auto-engages, no finished line is driven twice, none is
/// skipped, and the job finishes. Judged from the simulator's true trajectory, not from the
/// daemon's own bookkeeping ([`line_record`]): a line is driven when its middle is crossed in
/// its work direction, finished when it comes within `guidance.end_distance_m` of its end so, as
/// the daemon counts it (steered automatically or by the driver, who keeps straight while the
/// daemon is down: the implement works either way). A line
/// left mid-way and resumed out of the engage gate is driven again from its start (the
/// approach's design: it was not finished, so nothing is missed), which is allowed; a finished
/// line driven again, or a line finished without being driven, is not.
///
/// As on a real tractor (issue 16 point 8): when the commands stop, the simulated steering
/// controller leaves automatic steering after `sim.command_timeout_s` (250 ms) and the driver
/// centres the wheels; the operator stops the tractor. After the restart the operator drives
/// on and engages; where the tractor is out of the engage gate (a kill in a turn leaves it
/// heading off the turn) the daemon re-acquires the line with an approach path, at the default
/// engage gate. Also prints the restart time, exec → first command frame on the bus.
#[test]
fn i_kill_9_resume() {
    kill_9_resume(2, 4);
}

/// The full run (issue 16 point 8): 20 kills on a 7-line job, about 2 minutes on an idle host
/// (longer loaded), so not in the suite's default run:
/// `tools/vcan-vm -- i_kill_9_resume_20 --ignored`.
#[test]
#[ignore = "2 minutes or more; the suite runs i_kill_9_resume (4 kills)"]
fn i_kill_9_resume_20() {
    kill_9_resume(7, 20);
}

/// `kills` kill -9s at random moments of a job of `lines` lines.
fn kill_9_resume(lines: u64, kill_count: u32) {
    let Some(iface) = vcan() else { return };
    let set = format!("job.line_num={lines}");
    let _ = std::fs::remove_dir_all("/tmp/agsteer");
    let start = || {
        let p = Proc::spawn_logging("agsteerd", &["--config", CONFIG, "--set", &set], true);
        let end = Instant::now() + Duration::from_secs(10);
        while Instant::now() < end && status().is_none() {
            std::thread::sleep(Duration::from_millis(20));
        }
        p
    };
    let probe = StallProbe::start();
    let dump = Candump::start(&iface);
    let mut daemon = start();
    let traj = "/tmp/agsteer-kill9.csv";
    let _sim = start_sim(&iface, &["--set", &set, "--trajectory", traj]);
    let mut term = Terminal::new(&iface);
    assert!(term.engage(Duration::from_secs(10)));
    let mut x: u64 = 0x9E37_79B9;
    let mut kills = 0;
    // Wall-clock times (as candump stamps frames) of each restart's exec.
    let mut execs: Vec<f64> = Vec::new();
    let t0 = Instant::now();
    while kills < kill_count && t0.elapsed() < Duration::from_secs(240) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        std::thread::sleep(Duration::from_millis(200 + x % 1000));
        if status().is_some_and(|s| s["finished"] == true) {
            break;
        }
        daemon.signal(libc::SIGKILL);
        // The steering controller drops out 250 ms later and the driver keeps straight; the
        // operator notices and stops the tractor.
        term.direction(0);
        let _ = daemon.wait_for(Duration::from_secs(2));
        kills += 1;
        execs.push(wall_s());
        daemon = start();
        let st = status().expect("restarted daemon answers");
        assert_eq!(st["engaged"], false, "never auto-engages after a restart");
        // The daemon answers: the operator drives on and engages (ready needs the minimum
        // speed).
        term.direction(1);
        if !term.engage(Duration::from_secs(10)) {
            panic!(
                "not re-engaged after kill {kills}: status {:?}\nlog tail: {:#?}",
                status(),
                daemon_log_tail(15)
            );
        }
    }
    // The operator re-engages whenever something disengaged the system (a frozen guest can
    // make inputs stale) until the job is done, as in the closed-loop job test.
    let mut reengaged = 0;
    let end = Instant::now() + Duration::from_secs(180);
    let mut finished = false;
    while Instant::now() < end {
        match status() {
            Some(s) if s["finished"] == true => {
                finished = true;
                break;
            }
            Some(s) if s["state"] == "ready" && s["engaged"] == false => {
                reengaged += 1;
                term.send(1);
            }
            _ => {}
        }
        std::thread::sleep(Duration::from_millis(200));
    }
    // The daemon finishes the last line when its estimate is within `guidance.end_distance_m`
    // of the end; the simulator's trajectory (0.05 s samples, written by a process a frozen
    // guest may not have run yet) gets there a moment later: the tractor drives on past the
    // end, so wait (up to 10 s) for the file to show every line's end before judging them.
    let until = std::time::Instant::now() + Duration::from_secs(10);
    while std::time::Instant::now() < until
        && line_record(traj, &set)
            .lines
            .iter()
            .any(|l| l.finished_at.is_none())
    {
        std::thread::sleep(Duration::from_millis(200));
    }
    let cap = parse_candump(&dump.stop());
    let stalls = probe.stop();
    let cmds = steering_frames(&cap);
    // Restart time: exec of the new daemon → its first command frame on the bus.
    let mut restart: Vec<f64> = Vec::new();
    let mut restart_net: Vec<f64> = Vec::new();
    for &e in &execs {
        if let Some(&(t, _)) = cmds.iter().find(|(t, _)| *t >= e) {
            restart.push(t - e);
            restart_net.push(gap_less_stalls(e, t, &stalls));
        }
    }
    restart.sort_by(|a, b| a.total_cmp(b));
    restart_net.sort_by(|a, b| a.total_cmp(b));
    println!(
        "VCAN-KILL9-RESTART exec_to_first_command: median_ms={:.1} max_ms={:.1} less_stalls: median_ms={:.1} max_ms={:.1} over {} restarts; guest frozen {:.0} ms in all",
        pct(&restart, 0.5) * 1e3,
        restart.last().copied().unwrap_or(f64::NAN) * 1e3,
        pct(&restart_net, 0.5) * 1e3,
        restart_net.last().copied().unwrap_or(f64::NAN) * 1e3,
        restart.len(),
        stalls.iter().map(|s| s.to_s - s.from_s).sum::<f64>() * 1e3
    );
    let record = line_record(traj, &set);
    let driven: Vec<u32> = record.lines.iter().map(|l| l.driven).collect();
    let again: Vec<u32> = record.lines.iter().map(|l| l.driven_after_finish).collect();
    let finished_lines = record
        .lines
        .iter()
        .filter(|l| l.finished_at.is_some())
        .count();
    println!(
        "VCAN-KILL9 kills={kills} finished={finished} reengaged_after={reengaged} \
         driven_per_line={driven:?} driven_after_finish={again:?} lines_finished={finished_lines}"
    );
    if driven.iter().any(|c| *c != 1) || again.iter().any(|c| *c != 0) {
        // What to look at: each middle crossing (simulator time s, line, speed m/s, engaged,
        // in the work direction) and each restart (wall s, as candump stamps).
        println!(
            "VCAN-KILL9 crossings (t_s, line, speed_m_s, engaged, work_direction): {:?}; \
             lines {:?}; restarts at {execs:?}",
            record.crossings, record.lines
        );
    }
    assert!(
        kills >= kill_count,
        "only {kills} kills before the job ended"
    );
    assert!(finished, "job finishes");
    for (k, l) in record.lines.iter().enumerate() {
        assert!(l.finished_at.is_some(), "line {k} finished: {l:?}");
        assert!(l.driven >= 1, "line {k} driven before it finished: {l:?}");
        assert_eq!(
            l.driven_after_finish, 0,
            "line {k} not driven once finished: {l:?}"
        );
    }
}

/// One crossing of a line's middle: simulator time s, line, speed m/s, engaged, in the line's
/// work direction.
type Crossing = (f64, usize, f64, bool, bool);

/// One work line, from the trajectory.
#[derive(Debug, Default, Clone)]
struct LineRecord {
    /// Crossings of its middle in its work direction, before it was finished.
    driven: u32,
    /// The same after it was finished.
    driven_after_finish: u32,
    /// Simulator time its end was first reached in its work direction, s.
    finished_at: Option<f64>,
}

struct Record {
    lines: Vec<LineRecord>,
    crossings: Vec<Crossing>,
}

/// Each work line's record from the simulator's trajectory: a sample belongs to the nearest
/// line within half a line width; its work direction is the plan's driving direction.
fn line_record(path: &str, set: &str) -> Record {
    use agsteer::config::Config;
    use agsteer::plan::abline::AbPlan;
    let cfg = Config::load(std::path::Path::new(CONFIG), &[set.to_string()]).unwrap();
    let plan = AbPlan::new(cfg.ab_params()).unwrap();
    let n = cfg.job.line_num as usize;
    // Each line's start and end in its driving direction.
    let mut ends: Vec<Option<(agsteer::geo::Vec2, agsteer::geo::Vec2)>> = vec![None; n];
    let mut block = 0;
    while ends.iter().any(Option::is_none) && block <= n as u64 {
        for rank in 0..plan.block_len(block) {
            let line = plan.line_of(block, rank) as usize;
            if let Some(e) = ends.get_mut(line) {
                *e = Some(plan.line_endpoints(line as u64, plan.line_reversed(block, rank)));
            }
        }
        block += 1;
    }
    let ends: Vec<_> = ends
        .into_iter()
        .map(|e| e.expect("every line in the plan's order"))
        .collect();
    let length = plan.line_length();
    let half = length / 2.0;
    let mut lines = vec![LineRecord::default(); n];
    let mut crossings = Vec::new();
    let mut prev: Option<(usize, f64)> = None;
    let text = std::fs::read_to_string(path).unwrap();
    for l in text.lines().skip(1) {
        let v: Vec<f64> = l.split(',').filter_map(|x| x.parse().ok()).collect();
        if v.len() < 7 {
            continue;
        }
        // The columns: t_s, x_m, y_m, heading_rad, speed_m_s, wheel, engaged.
        let (t, speed, engaged) = (v[0], v[4], v[6] > 0.5);
        let p = agsteer::geo::v2(v[1], v[2]);
        let nearest = ends
            .iter()
            .enumerate()
            .map(|(k, (s, e))| {
                let dir = (e - s).normalize();
                (
                    k,
                    agsteer::geo::signed_offset(&p, s, &dir).abs(),
                    (p - s).dot(&dir),
                )
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let Some((k, _, along)) = nearest.filter(|n| n.1 < cfg.job.line_width_m / 2.0) else {
            prev = None;
            continue;
        };
        // Finished as the daemon counts it: within `guidance.end_distance_m` of the end.
        if along >= length - cfg.guidance.end_distance_m && lines[k].finished_at.is_none() {
            lines[k].finished_at = Some(t);
        }
        if let Some((_, pa)) = prev.filter(|p| p.0 == k) {
            if (pa < half) != (along < half) {
                let work = pa < half;
                crossings.push((t, k, speed, engaged, work));
                if work {
                    if lines[k].finished_at.is_some() {
                        lines[k].driven_after_finish += 1;
                    } else {
                        lines[k].driven += 1;
                    }
                }
            }
        }
        prev = Some((k, along));
    }
    Record { lines, crossings }
}
