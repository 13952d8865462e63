//! The agsteerd runtime: SocketCAN in and out, the control loop on a timer, the status
//! socket, progress saving, signals.
//!
//! One single-threaded tokio runtime. A reader task turns SocketCAN frames into messages on a
//! bounded channel; the main loop selects over that channel, the control timer, status-socket
//! connections and signals. The control step itself never waits on I/O: frames are sent with a
//! non-blocking write, and progress is handed to a writer thread through a bounded channel
//! (a full channel skips a save rather than stall the loop; the next line change saves again).
//!
//! A control period runs on the timer every dt, and at once when a GNSS fix enters the node
//! (issue 16 point 7: the command that follows a fix leaves within about a millisecond of its
//! arrival instead of waiting up to dt for the timer); the timer then restarts from that
//! period, so the periods stay dt apart and phase-lock to the fixes, and it holds back a period
//! due just around the next expected fix ([`super::tick`]), which would otherwise run first and
//! make the fix wait. Frames already read when the timer is due are taken first, so a fix
//! among them runs the period. Times given to the node
//! are whole microseconds ([`log_time`]), so that `--bus-log` records exactly what the node
//! saw and `agsteer replay` reproduces its decisions.

use super::bus_log::{BusLog, BusLogError, BusLogParams, BusLogStats};
use super::loop_stats::{count_by, LoopStats, FIX_PHASE_EDGES_US, FIX_TO_COMMAND_EDGES_US};
use super::tick::TickSchedule;
use crate::can::bus::{monotonic_s, AsyncSocketCan, BusError, Filter};
use crate::can::candump::log_time;
use crate::can::{Frame, TimedFrame};
use crate::config::{Config, ConfigError};
use crate::control::node::{ControllerNode, NodeStatus};
use crate::control::ControlError;
use crate::guidance::progress::Progress;
use crate::job::startup::{Startup, StartupError};
use crate::job::{JobDetail, JobError};
use crate::store::progress_file;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::mpsc;
use std::time::Duration;
use tokio::io::AsyncWriteExt;
use tokio::sync::mpsc as tmpsc;

/// Errors that stop the daemon.
#[derive(Debug, thiserror::Error)]
pub enum DaemonError {
    #[error("opening CAN interface {iface}: {source}")]
    Open { iface: String, source: BusError },
    #[error("status socket {path}: {source}")]
    Status {
        path: String,
        source: std::io::Error,
    },
    #[error(transparent)]
    Config(#[from] ConfigError),
    #[error(transparent)]
    Job(#[from] JobError),
    #[error(transparent)]
    Startup(#[from] StartupError),
    #[error(transparent)]
    Control(#[from] ControlError),
    #[error("runtime: {0}")]
    Runtime(std::io::Error),
    #[error(transparent)]
    BusLog(#[from] BusLogError),
    /// The progress could not be saved at shutdown: a restart would resume from an older
    /// position (`agsteerd` exits with status 8).
    #[error("progress not saved at shutdown: {0}")]
    ProgressNotSaved(#[source] progress_file::ProgressFileError),
}

#[derive(Serialize)]
struct StatusReply<'a> {
    #[serde(flatten)]
    node: NodeStatus,
    #[serde(rename = "loop")]
    timing: &'a LoopStats,
    interface: &'a str,
    dt_s: f64,
    /// The GNSS byte stream and NTRIP client, when `gnss.source` is one.
    #[serde(skip_serializing_if = "Option::is_none")]
    gnss: Option<super::gnss::GnssStatusReply>,
    /// Every GNSS source seen and the one each input is locked on.
    sources: super::sources::SourcesReply,
    /// `--bus-log`, when on.
    #[serde(skip_serializing_if = "Option::is_none")]
    bus_log: Option<BusLogStats>,
    /// The steering calibration under way or the last one's result.
    #[serde(skip_serializing_if = "Option::is_none")]
    calibration: Option<super::calibration::CalibrationReply<'a>>,
}

enum BusEvent {
    Frame(TimedFrame),
    Down(String),
}

/// The frames agsteerd listens to (by PGN, any source address): the DBC's inputs, and the
/// ISO 11783-5 Request and Address Claimed (to any destination).
pub fn receive_filters() -> Vec<Filter> {
    use crate::can::isobus::{PGN_ADDRESS_CLAIMED, PGN_REQUEST};
    crate::can::codec::MESSAGES
        .iter()
        .filter(|m| m.transmitter != "AGSTEER")
        .map(|m| Filter {
            id: m.id,
            mask: if m.pdu1 { 0x03FF_0000 } else { 0x03FF_FF00 },
        })
        .chain([PGN_REQUEST, PGN_ADDRESS_CLAIMED].map(|pgn| Filter {
            id: pgn << 8,
            mask: 0x03FF_0000,
        }))
        .collect()
}

fn spawn_progress_writer(path: PathBuf) -> mpsc::SyncSender<Progress> {
    let (tx, rx) = mpsc::sync_channel::<Progress>(4);
    std::thread::Builder::new()
        .name("agsteer-progress".into())
        .spawn(move || {
            for p in rx {
                if let Err(e) = progress_file::save(&path, &p) {
                    tracing::error!("saving progress: {e}");
                }
            }
        })
        .ok();
    tx
}

/// The job book's writer thread (the control loop never writes a file).
fn spawn_jobs_writer(path: PathBuf) -> mpsc::SyncSender<crate::store::jobs_file::JobBook> {
    let (tx, rx) = mpsc::sync_channel::<crate::store::jobs_file::JobBook>(4);
    std::thread::Builder::new()
        .name("agsteer-jobs".into())
        .spawn(move || {
            for b in rx {
                if let Err(e) = crate::store::jobs_file::save(&path, &b) {
                    tracing::error!("saving the job book: {e}");
                }
            }
        })
        .ok();
    tx
}

/// Load what the daemon starts with ([`crate::job::startup::load`], shared with `agsteerd
/// --check`) and log what was planned and what will be lost. For `job.kind = "field"` this
/// reads `job.field_path` and plans its coverage, for `"maneuver"` it reads the map and plans
/// the manoeuvre: blocking work, done once at start-up, never in the control loop.
pub fn start_up(cfg: &Config) -> Result<Startup, StartupError> {
    let startup = crate::job::startup::load(cfg)?;
    match &startup.job.detail {
        JobDetail::Field(fj) => tracing::info!(
            field = %fj.title(),
            origin_lat_deg = fj.origin().lat_deg,
            origin_lon_deg = fj.origin().lon_deg,
            cells = fj.plan.cells,
            swaths = fj.plan.swaths,
            segments = fj.job.len(),
            checksum = format_args!("{:08x}", fj.job.checksum()),
            plan_ms = format_args!("{:.0}", fj.plan_time.as_secs_f64() * 1e3),
            "field job planned from {}",
            fj.path.display()
        ),
        JobDetail::Maneuver(mj, _) => tracing::info!(
            length_m = format_args!("{:.1}", mj.path.length()),
            cusps = mj.path.cusps(),
            segments = mj.job.len(),
            "manoeuvre planned"
        ),
        JobDetail::Lines => {}
    }
    for w in &startup.warnings {
        tracing::warn!("{w}");
    }
    Ok(startup)
}

/// Run this thread under SCHED_FIFO at `priority` (0 = leave it alone).
pub fn set_realtime_priority(priority: u8) {
    if priority == 0 {
        return;
    }
    let param = libc::sched_param {
        sched_priority: priority as i32,
    };
    // SAFETY: sched_setscheduler on the calling thread with a valid parameter.
    let rc = unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) };
    if rc == 0 {
        tracing::info!(priority, "control loop runs under SCHED_FIFO");
    } else {
        tracing::warn!(
            "cannot set SCHED_FIFO priority {priority}: {} (needs root or CAP_SYS_NICE)",
            std::io::Error::last_os_error()
        );
    }
}

/// The calling thread under the normal scheduler at `nice`: a thread spawned by the control
/// loop's inherits its SCHED_FIFO priority (`daemon.realtime_priority`) and would otherwise run
/// its work ahead of, or level with, the control loop and every simulated or real sender below.
pub(super) fn normal_scheduling(nice: i32) -> std::io::Result<()> {
    let param = libc::sched_param { sched_priority: 0 };
    // SAFETY: both calls act on the calling thread (Linux: pid/who 0 is the caller's thread
    // id) with valid arguments; failure leaves the thread as it was.
    let (rc, nice_rc) = unsafe {
        (
            libc::sched_setscheduler(0, libc::SCHED_OTHER, &param),
            libc::setpriority(libc::PRIO_PROCESS, 0, nice),
        )
    };
    if rc != 0 || nice_rc != 0 {
        return Err(std::io::Error::last_os_error());
    }
    Ok(())
}

/// Send a control period's frames at `t` (each logged, sent or not: the log holds what the
/// node decided).
fn send_all(
    bus: &AsyncSocketCan,
    t: f64,
    frames: &[Frame],
    stats: &mut LoopStats,
    log: Option<&BusLog>,
) -> bool {
    let mut ok = true;
    for f in frames {
        let sent = bus.try_send(f);
        if let Some(l) = log {
            l.record(t, f);
        }
        if let Err(e) = sent {
            stats.send_errors += 1;
            if stats.send_errors.is_power_of_two() {
                tracing::warn!("sending {:08X}: {e}", f.id);
            }
            ok = false;
        }
    }
    ok
}

/// Where the configuration came from, for SIGHUP.
#[derive(Debug, Clone)]
pub struct ConfigSource {
    pub path: PathBuf,
    pub overrides: Vec<String>,
}

/// Apply a re-read configuration: all at once when valid and when nothing that defines the
/// running job changed; otherwise the running configuration stays and the reason is logged.
fn apply_reload(
    cfg: &mut Config,
    source: &ConfigSource,
    node: &mut ControllerNode,
    loaded: Result<Config, ConfigError>,
) {
    let (new, resolved) = match loaded.and_then(|c| c.resolve().map(|r| (c, r))) {
        Ok(c) => c,
        Err(e) => {
            tracing::error!(
                "SIGHUP: {} is not valid, keeping the running configuration: {e}",
                source.path.display()
            );
            return;
        }
    };
    let fixed = cfg.fixed_key_changes(&new);
    if !fixed.is_empty() {
        tracing::error!(
            "SIGHUP: refused: {} cannot change while the daemon runs a job (restart agsteerd to change them); keeping the running configuration",
            fixed.join(", ")
        );
        return;
    }
    node.apply_tuning(&resolved.control, &resolved.safety, &resolved.bus);
    *cfg = new;
    tracing::info!(
        "SIGHUP: configuration reloaded from {}",
        source.path.display()
    );
}

/// Run the daemon until SIGTERM or SIGINT, logging every frame to `bus_log` when given.
pub fn run(
    cfg: Config,
    source: ConfigSource,
    bus_log: Option<BusLogParams>,
) -> Result<(), DaemonError> {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        // The blocking pool's threads (a SIGHUP's configuration read) start after the control
        // loop's thread took SCHED_FIFO and would inherit it: back to the normal scheduler.
        .on_thread_start(|| {
            if let Err(e) = normal_scheduling(0) {
                tracing::warn!("a helper thread keeps the control loop's scheduling: {e}");
            }
        })
        .build()
        .map_err(DaemonError::Runtime)?;
    rt.block_on(run_async(cfg, source, bus_log))
}

/// A control period's outputs: frames to the bus (and the log), the bus state, progress.
struct Outputs {
    bus: std::rc::Rc<AsyncSocketCan>,
    frames: Vec<Frame>,
    bus_up: bool,
    iface: String,
    progress: mpsc::SyncSender<Progress>,
    log: Option<BusLog>,
    calibration: super::calibration::CalibrationRunner,
    /// `AGSTEER_FIX_TRACE`: each fix's times to a file.
    trace: Option<super::fix_trace::FixTrace>,
}

impl Outputs {
    /// One control period at `t`: its frames computed and handed to the socket, then the
    /// bookkeeping. True when it had guidance events (a line change).
    fn step(&mut self, node: &mut ControllerNode, t: f64, stats: &mut LoopStats) -> bool {
        let sent = self.compute_and_send(node, t, stats);
        self.after_send(node, sent, stats)
    }

    /// The node's period at `t` and its frames to the socket; whether they were sent.
    fn compute_and_send(
        &mut self,
        node: &mut ControllerNode,
        t: f64,
        stats: &mut LoopStats,
    ) -> bool {
        self.frames.clear();
        node.tick(t, &mut self.frames);
        send_all(&self.bus, t, &self.frames, stats, self.log.as_ref())
    }

    /// What a period does once its frames have left: the link's state, the calibration's
    /// thread, progress saved and guidance events logged at a line change (true then).
    fn after_send(&mut self, node: &mut ControllerNode, sent: bool, stats: &mut LoopStats) -> bool {
        self.calibration.poll(node);
        // A period without frames (claiming) says nothing of the link.
        if sent && !self.bus_up && !self.frames.is_empty() {
            tracing::info!(
                "CAN interface {} is back; claiming the address again",
                self.iface
            );
            self.bus_up = true;
            node.supervisor_mut().on_bus(true);
            node.on_link_up();
        } else if !sent && self.bus_up {
            tracing::error!("CAN interface {} is down", self.iface);
            self.bus_up = false;
            node.supervisor_mut().on_bus(false);
        }
        stats.bus_up = self.bus_up;
        let had_events = node.controller().guidance().has_events();
        // A line change, or the work advanced a checkpoint along the line.
        let checkpoint = node.controller_mut().guidance_mut().take_checkpoint();
        if had_events || checkpoint {
            let p = node.controller().guidance().progress();
            if self.progress.try_send(p).is_err() {
                tracing::warn!("progress writer busy; this save is skipped");
            }
        }
        if had_events {
            for ev in node.controller_mut().guidance_mut().drain_events() {
                tracing::info!("{ev}");
            }
        }
        stats.ticks += 1;
        had_events
    }

    /// A GNSS fix read at `fix.read` entered the node (the loop took it at `fix.taken`): its
    /// command now, then the bookkeeping, the timer restarted.
    fn on_fix(
        &mut self,
        node: &mut ControllerNode,
        fix: FixArrival,
        stats: &mut LoopStats,
        schedule: &mut TickSchedule,
    ) {
        let start = std::time::Instant::now();
        let t = log_time(monotonic_s());
        self.frames.clear();
        node.tick(t, &mut self.frames);
        let ready = monotonic_s();
        let sent = send_all(&self.bus, t, &self.frames, stats, self.log.as_ref());
        let left = monotonic_s();
        self.after_send(node, sent, stats);
        schedule.on_fix(fix.read, t);
        stats.held_ticks = schedule.held;
        stats.fix_period_ms = schedule.fix_period().unwrap_or(0.0) * 1e3;
        stats.fix_ticks += 1;
        stats.fix_to_command_us = (left - fix.read).max(0.0) * 1e6;
        stats.max_fix_to_command_us = stats.max_fix_to_command_us.max(stats.fix_to_command_us);
        count_by(
            &mut stats.fix_to_command_counts,
            &FIX_TO_COMMAND_EDGES_US,
            stats.fix_to_command_us,
        );
        let us = |a: f64, b: f64| (b - a).max(0.0) * 1e6;
        let p = &mut stats.fix_phases;
        count_by(&mut p.queue, &FIX_PHASE_EDGES_US, us(fix.read, fix.taken));
        count_by(&mut p.compute, &FIX_PHASE_EDGES_US, us(fix.taken, ready));
        count_by(&mut p.send, &FIX_PHASE_EDGES_US, us(ready, left));
        stats.last_step_us = start.elapsed().as_secs_f64() * 1e6;
        stats.max_step_us = stats.max_step_us.max(stats.last_step_us);
        if let Some(trace) = &self.trace {
            trace.record(super::fix_trace::FixRecord {
                read: fix.read,
                taken: fix.taken,
                ready,
                left,
                utc_offset: super::fix_trace::utc_offset(),
            });
        }
    }
}

/// When a GNSS fix was read (its receive time) and when the loop took it (monotonic s).
#[derive(Debug, Clone, Copy)]
struct FixArrival {
    read: f64,
    taken: f64,
}

/// Frames taken from the reader's queue when the timer is due, at most (a flood never delays
/// the timer's period by more than this many frames' decoding).
const DRAIN_AT_TICK: usize = 64;

/// One event from the bus reader: a frame into the node (and the bus log), or the link down.
/// Its arrival when a GNSS fix entered the controller.
fn on_bus_event(
    ev: BusEvent,
    node: &mut ControllerNode,
    out: &mut Outputs,
    stats: &mut LoopStats,
    iface: &str,
) -> Option<FixArrival> {
    match ev {
        BusEvent::Frame(mut tf) => {
            let taken = monotonic_s();
            stats.frames_in += 1;
            tf.t = log_time(tf.t);
            let fix = node
                .on_frame(&tf)
                .then_some(FixArrival { read: tf.t, taken });
            if let Some(l) = &out.log {
                l.record(tf.t, &tf.frame);
            }
            fix
        }
        BusEvent::Down(e) => {
            if out.bus_up {
                tracing::error!("CAN interface {iface}: {e}");
                out.bus_up = false;
                node.supervisor_mut().on_bus(false);
            }
            None
        }
    }
}

/// Set B / select job: planned here (an AB job is planned in microseconds), the book saved
/// by its writer thread.
fn apply_operator_request(
    node: &mut ControllerNode,
    resolved: &crate::config::Resolved,
    configured: &crate::job::PreparedJob,
    book: &mut crate::store::jobs_file::JobBook,
    jobs_tx: &mpsc::SyncSender<crate::store::jobs_file::JobBook>,
) {
    if crate::job::operator::apply_request(node, resolved, configured, book)
        && jobs_tx.try_send(book.clone()).is_err()
    {
        tracing::warn!("job book writer busy; this save is skipped");
    }
}

async fn run_async(
    mut cfg: Config,
    source: ConfigSource,
    bus_log: Option<BusLogParams>,
) -> Result<(), DaemonError> {
    use tokio::signal::unix::{signal, SignalKind};
    // The job is set up here (the field or map read and planned, the password file read, the
    // state directory checked), before the bus is opened and the loop starts.
    let Startup {
        resolved,
        job,
        progress_path,
        ntrip_password,
        ..
    } = start_up(&cfg)?;
    // The operator's job book: a restart drives the job selected last (issue 16 point 5).
    let jobs_path = crate::store::jobs_file::jobs_path(&resolved.daemon.state_dir);
    let mut book = crate::store::jobs_file::load(&jobs_path).unwrap_or_else(|e| {
        tracing::warn!("{e}; driving the configured job");
        Default::default()
    });
    let configured = job.clone();
    let job = if book.selected == 0 {
        job
    } else {
        match crate::job::operator::selected_job(&resolved, job, &book) {
            Ok(j) => {
                tracing::info!(
                    job = book.selected,
                    "driving the line recorded by set A / set B"
                );
                j
            }
            Err(e) => {
                tracing::warn!(
                    "job {} of {}: {e}; driving the configured job",
                    book.selected,
                    jobs_path.display()
                );
                book.selected = 0;
                configured.clone()
            }
        }
    };
    let iface = resolved.daemon.interface.clone();
    let bus = std::rc::Rc::new(AsyncSocketCan::open(&iface, &receive_filters()).map_err(
        |source| DaemonError::Open {
            iface: iface.clone(),
            source,
        },
    )?);
    let resume = crate::job::resume::resume_or_start(&job, &progress_path);
    // The node is built once; a SIGHUP only retunes it (apply_reload), so the plan is kept.
    let mut node = crate::job::build_node(&resolved, &job, resume.as_ref())?;
    node.set_job_number(book.selected);
    let progress_tx = spawn_progress_writer(progress_path.clone());
    let jobs_tx = spawn_jobs_writer(jobs_path);
    let bus_log = match bus_log {
        Some(p) => {
            tracing::info!(
                path = %p.path.display(),
                max_bytes = p.max_bytes,
                files = p.files,
                "logging every frame in and out"
            );
            Some(BusLog::start(p)?)
        }
        None => None,
    };
    let fix_trace = super::fix_trace::FixTrace::from_env();
    // Helper threads exist now; only the control loop's thread gets real-time priority.
    set_realtime_priority(resolved.daemon.realtime_priority);

    let status_socket = resolved.daemon.status_socket.clone();
    let listener = if let Some(path) = &status_socket {
        if let Some(dir) = path.parent() {
            let _ = std::fs::create_dir_all(dir);
        }
        remove_stale_socket(path);
        let l = tokio::net::UnixListener::bind(path).map_err(|source| DaemonError::Status {
            path: path.display().to_string(),
            source,
        })?;
        use std::os::unix::fs::PermissionsExt;
        let _ = std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o660));
        Some(l)
    } else {
        None
    };

    // Reader task: frames → channel; errors → Down, with a back-off, never ending.
    let (tx, mut rx) = tmpsc::channel::<BusEvent>(4096);
    let reader_bus = bus.clone();
    let local = tokio::task::LocalSet::new();
    local.spawn_local(async move {
        loop {
            match reader_bus.recv().await {
                Ok(tf) => {
                    // A full channel drops the frame: inputs are periodic, the next one comes.
                    let _ = tx.try_send(BusEvent::Frame(tf));
                }
                Err(e) => {
                    let _ = tx.try_send(BusEvent::Down(e.to_string()));
                    tokio::time::sleep(Duration::from_millis(50)).await;
                }
            }
        }
    });

    // GNSS over a serial port, USB, UDP or TCP, and the NTRIP client ([gnss]).
    let mut gnss = ntrip_password.and_then(|password| super::gnss::spawn(&cfg, password, &local));

    let dt = resolved.control.dt;
    // The schedule in monotonic seconds (the node's clock), the timer on tokio's.
    let mut schedule = TickSchedule::new(dt, monotonic_s());
    let anchor = (tokio::time::Instant::now(), monotonic_s());
    let deadline = |at: f64| anchor.0 + Duration::from_secs_f64((at - anchor.1).max(0.0));
    let timer = tokio::time::sleep_until(deadline(schedule.next()));
    tokio::pin!(timer);
    let mut sigterm = signal(SignalKind::terminate()).map_err(DaemonError::Runtime)?;
    let mut sigint = signal(SignalKind::interrupt()).map_err(DaemonError::Runtime)?;
    let mut sighup = signal(SignalKind::hangup()).map_err(DaemonError::Runtime)?;
    let mut out = Outputs {
        bus: bus.clone(),
        frames: Vec::with_capacity(8),
        bus_up: true,
        iface: iface.clone(),
        progress: progress_tx,
        log: bus_log,
        calibration: super::calibration::CalibrationRunner::new(resolved.daemon.state_dir.clone()),
        trace: fix_trace,
    };
    let mut stats = LoopStats {
        bus_up: true,
        ..Default::default()
    };
    let mut late_sum = 0.0;
    tracing::info!(interface = %iface, dt_s = dt, "agsteerd running");
    let mut watchdog = crate::daemon::notify::Watchdog::from_env();
    let mut reloading: Option<tokio::task::JoinHandle<Result<Config, ConfigError>>> = None;
    crate::daemon::notify::ready();

    local
        .run_until(async {
            loop {
                tokio::select! {
                    biased;
                    _ = sigterm.recv() => break,
                    _ = sigint.recv() => break,
                    _ = sighup.recv() => {
                        // The file is read on the blocking pool, never in the control loop.
                        let src = source.clone();
                        reloading = Some(tokio::task::spawn_blocking(move || {
                            Config::load(&src.path, &src.overrides)
                        }));
                    }
                    loaded = async {
                        match reloading.as_mut() {
                            Some(h) => h.await,
                            None => std::future::pending().await,
                        }
                    } => {
                        reloading = None;
                        match loaded {
                            Ok(l) => apply_reload(&mut cfg, &source, &mut node, l),
                            Err(e) => tracing::error!("SIGHUP: reading the configuration failed: {e}"),
                        }
                    }
                    _ = &mut timer => {
                        // Frames and GNSS inputs already read go first: a fix among them runs
                        // this period.
                        let mut fix = None;
                        for _ in 0..DRAIN_AT_TICK {
                            let Ok(ev) = rx.try_recv() else { break };
                            fix = on_bus_event(ev, &mut node, &mut out, &mut stats, &iface);
                            if fix.is_some() {
                                break;
                            }
                        }
                        if let Some(g) = gnss.as_mut().filter(|_| fix.is_none()) {
                            for _ in 0..DRAIN_AT_TICK {
                                let Ok(i) = g.inputs.try_recv() else { break };
                                let taken = monotonic_s();
                                if node.on_input(&i) {
                                    fix = Some(FixArrival { read: i.t(), taken });
                                    break;
                                }
                            }
                        }
                        apply_operator_request(&mut node, &resolved, &configured, &mut book, &jobs_tx);
                        if let Some(f) = fix {
                            out.on_fix(&mut node, f, &mut stats, &mut schedule);
                            timer.as_mut().reset(deadline(schedule.next()));
                            continue;
                        }
                        let late = (monotonic_s() - schedule.next()).max(0.0);
                        let start = std::time::Instant::now();
                        let t = log_time(monotonic_s());
                        let had_events = out.step(&mut node, t, &mut stats);
                        schedule.on_timer(t);
                        stats.held_ticks = schedule.held;
                        timer.as_mut().reset(deadline(schedule.next()));
                        if late > dt {
                            stats.deadline_misses += 1;
                        }
                        late_sum += late;
                        stats.max_late_ms = stats.max_late_ms.max(late * 1e3);
                        stats.mean_late_ms = late_sum / stats.ticks as f64 * 1e3;
                        stats.last_step_us = start.elapsed().as_secs_f64() * 1e6;
                        if stats.last_step_us > dt * 0.5e6 {
                            tracing::warn!(
                                step_us = stats.last_step_us,
                                tick = stats.ticks,
                                line_change = had_events,
                                "slow control step"
                            );
                        }
                        stats.max_step_us = stats.max_step_us.max(stats.last_step_us);
                        watchdog.period(late <= dt);
                    }
                    ev = rx.recv() => {
                        let Some(mut ev) = ev else { break };
                        // This frame and those read with it, up to a fix (its period runs at
                        // once) or DRAIN_AT_TICK: one pass of the loop, not one per frame.
                        for _ in 0..DRAIN_AT_TICK {
                            if let Some(f) = on_bus_event(ev, &mut node, &mut out, &mut stats, &iface) {
                                out.on_fix(&mut node, f, &mut stats, &mut schedule);
                                timer.as_mut().reset(deadline(schedule.next()));
                                break;
                            }
                            let Ok(next) = rx.try_recv() else { break };
                            ev = next;
                        }
                        apply_operator_request(&mut node, &resolved, &configured, &mut book, &jobs_tx);
                    }
                    input = async {
                        match gnss.as_mut() {
                            Some(g) => g.inputs.recv().await,
                            None => std::future::pending().await,
                        }
                    } => {
                        // This input and those decoded with it, up to a fix (as frames above).
                        let mut input = input;
                        for _ in 0..DRAIN_AT_TICK {
                            let Some(i) = input.take() else { break };
                            let taken = monotonic_s();
                            if node.on_input(&i) {
                                let f = FixArrival { read: i.t(), taken };
                                out.on_fix(&mut node, f, &mut stats, &mut schedule);
                                timer.as_mut().reset(deadline(schedule.next()));
                                break;
                            }
                            input = gnss.as_mut().and_then(|g| g.inputs.try_recv().ok());
                        }
                    }
                    conn = async {
                        match &listener {
                            Some(l) => l.accept().await,
                            None => std::future::pending().await,
                        }
                    } => {
                        if let Ok((mut stream, _)) = conn {
                            let reply = StatusReply {
                                node: node.status(),
                                timing: &stats,
                                interface: &iface,
                                dt_s: dt,
                                gnss: gnss.as_ref().map(|g| g.status(monotonic_s())),
                                sources: super::sources::sources_reply(node.sources(), monotonic_s()),
                                bus_log: out.log.as_ref().map(BusLog::stats),
                                calibration: out.calibration.reply(&node),
                            };
                            let mut text = serde_json::to_string(&reply).unwrap_or_default();
                            text.push('\n');
                            // A slow reader gets a short deadline, never the control loop.
                            let _ = tokio::time::timeout(
                                Duration::from_millis(5),
                                stream.write_all(text.as_bytes()),
                            )
                            .await;
                        }
                    }
                }
            }
        })
        .await;

    // Shut down: a disengaged command goes out last, progress is saved.
    tracing::info!("stopping: sending a disengaged command and saving progress");
    node.supervisor_mut().request_disengage();
    for _ in 0..2 {
        let t = log_time(monotonic_s());
        out.frames.clear();
        node.tick(t, &mut out.frames);
        send_all(&out.bus, t, &out.frames, &mut stats, out.log.as_ref());
    }
    let Outputs { progress, log, .. } = out;
    drop(progress);
    if let Some(l) = log {
        l.finish(Duration::from_secs(2));
    }
    let p = node.controller().guidance().progress();
    let saved = progress_file::save(&progress_path, &p);
    if let Some(path) = &status_socket {
        remove_stale_socket(path);
    }
    saved.map_err(DaemonError::ProgressNotSaved)
}

/// Remove the status socket left by an earlier run: only a socket, never another file that
/// `bus.status_socket` might name by mistake (the configuration itself, say); binding then
/// fails with the path named.
fn remove_stale_socket(path: &std::path::Path) {
    use std::os::unix::fs::FileTypeExt;
    if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_socket()) {
        let _ = std::fs::remove_file(path);
    }
}
