//! The closed-loop demo: the controller and the simulator in one process, faster than real
//! time, scored against the simulator's ground truth (never the estimate).
//!
//! Memory does not grow with the job: XTE statistics use a fixed histogram, and the trace for
//! the SVG is recorded only on request.

pub mod accuracy;
pub mod calibrate;
pub mod envelope;
mod score;
pub mod svg;

use crate::can::bus::{CanBus, MemBus};
use crate::can::codec::{OperatorCommand, Packer};
use crate::can::Frame;
use crate::config::{Config, JobKind, TrackerChoice};
use crate::geo::{left_normal, v2, Pose, Vec2};
use crate::guidance::progress::{Phase, Progress};
use crate::guidance::{Event, JobPlan};
use crate::job::JobError;
use crate::safety::SafetyState;
use crate::sim::can_node::{Scenario, SimAddresses, SimNode};
use crate::sim::Simulator;
use serde::Serialize;

pub use score::XteStats;
pub(crate) use score::{cumulative_lengths, nearest_on_polyline};
use score::{ScoredPath, SegmentScore};

/// Work-line samples closer than this to the line start are excluded from the XTE figures, m.
pub const ACQUISITION_SKIP_M: f64 = 10.0;
/// Acquisition is judged between [`ACQUISITION_SKIP_M`] and this distance along the line, m.
pub const ACQUISITION_END_M: f64 = 20.0;
/// Trace points for the SVG are recorded every this many metres driven.
const TRACE_SPACING_M: f64 = 0.5;

/// The simulator's parameters from the configuration ([`Config::sim_params`]).
pub fn sim_params(cfg: &Config) -> crate::sim::SimParams {
    cfg.sim_params()
}

/// The demo report (`report.json`).
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub finished: bool,
    /// Lines in the job (for a field plan: segments, turns included); `null` when unlimited.
    pub lines_planned: Option<u64>,
    pub lines_completed: u64,
    /// RMS |XTE| on work lines, excluding the first 10 m of each line, m.
    pub xte_rms_m: f64,
    pub xte_p95_m: f64,
    pub xte_max_m: f64,
    /// Largest |XTE| between 10 m and 20 m of each line after a turn, m.
    pub acquisition_xte_max_m: f64,
    pub turns: u64,
    pub distance_m: f64,
    pub max_wheel_angle_deg: f64,
    pub max_wheel_rate_deg_s: f64,
    /// The steering's lost motion (backlash + actuator deadband) the default tracker learnt by
    /// the end, degrees (0 for the reference trackers).
    pub steering_lost_motion_deg: f64,
    pub sim_time_s: f64,
    pub wall_time_s: f64,
    pub tracker: String,
    /// Fraction of control periods steered by agsteer (engaged).
    pub engaged_fraction: f64,
    /// The run ended here: the steering was given back with a held tracking fault (`off_line`,
    /// `tracking_unstable`, `off_path`, `path_gap`) that only a line change or the operator
    /// clears, and a driver takes over (`None` when the run went on to its end).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub given_back: Option<GivenBack>,
    /// Frames on the in-memory bus (both directions).
    pub frames: u64,
    /// Why agsteer stopped steering, by fault, counted per disengagement.
    pub disengagements: std::collections::BTreeMap<String, u64>,
    /// Engages the supervisor refused for a reason about the line (`line_unfollowable`),
    /// counted once per refusal that starts.
    #[serde(skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub refusals: std::collections::BTreeMap<String, u64>,
    /// Segment jobs (field plans, manoeuvres): true |XTE| on every segment driven.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub segments: Vec<SegmentReport>,
    /// Segment jobs: distance from the true rear-axle position to the last point of the job
    /// when it finished, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub goal_position_error_m: Option<f64>,
    /// Segment jobs: true heading at the finish against the last segment's, degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub goal_heading_error_deg: Option<f64>,
    /// Field jobs: the plan that was driven (metrics and planning time). Filled in by the
    /// caller, which planned it; `run` leaves it empty.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plan: Option<crate::field::output::PlanSummary>,
}

/// Where a run ended with the steering given back ([`Report::given_back`]).
#[derive(Debug, Clone, Serialize)]
pub struct GivenBack {
    /// The held fault's configuration name.
    pub fault: String,
    /// Simulated time, s.
    pub t_s: f64,
    /// True distance of the rear axle from the path then, m (`null` with no path).
    pub path_distance_m: Option<f64>,
}

/// Tracking on one segment of a segment job, from the simulator's true pose over the whole
/// segment (no acquisition skip).
#[derive(Debug, Clone, Serialize)]
pub struct SegmentReport {
    pub index: usize,
    pub kind: crate::plan::coverage::SegmentKind,
    pub direction: crate::geo::Direction,
    pub length_m: f64,
    pub xte_rms_m: f64,
    pub xte_max_m: f64,
}

/// What to record and where to start.
#[derive(Debug, Clone, Default)]
pub struct DemoOptions {
    /// Continue this saved progress instead of starting the job afresh (the vehicle starts at
    /// the current path's start, `sim.start_offset_m` left of it, turned by
    /// `sim.start_heading_deg`).
    pub resume: Option<Progress>,
    /// Stop (as at a power loss) once this many lines have been finished in this run.
    pub stop_after_lines: Option<u64>,
    /// Record the trace and the turns for the SVG.
    pub record_trace: bool,
    /// Faults scripted into the simulator.
    pub scenario: Scenario,
    /// The simulated operator never presses engage again after the first engagement ends
    /// (fault scenarios); by default they re-engage whenever the system is ready.
    pub no_reengage: bool,
    /// The job as set up by [`crate::job::prepare`]; `None` = set it up here (from `job`, or
    /// the configuration's).
    pub prepared: Option<crate::job::PreparedJob>,
    /// The job to drive (a field plan as a segment job); `None` = the configuration's job.
    pub job: Option<JobPlan>,
    /// Outlines drawn under the trace in the SVG (field boundary, obstacles, headland).
    pub outlines: Vec<Vec<Vec2>>,
    /// ENU origin of the job's coordinates when it is not `job.origin_*` (a field plan:
    /// [`FieldJob::origin`](crate::field::job::FieldJob::origin)).
    pub origin: Option<crate::geo::wgs84::LatLon>,
    /// Record every work pass's nominal path and the true XTE at every control period (for
    /// the accuracy report: pass-to-pass, acquisition, XTE over distance).
    pub record_work: bool,
    /// The field approach paths must stay in (local ENU, as the job).
    pub field: Option<crate::plan::coverage::Field>,
    /// Drive on after the steering was given back with a held tracking fault (the simulated
    /// driver holds the wheel and waits for the next line). By default the run ends there, as
    /// a driver takes over: the report then names the fault ([`Report::given_back`]).
    pub drive_on_after_held_fault: bool,
}

/// One work pass as driven (recorded with [`DemoOptions::record_work`]).
#[derive(Debug, Clone, Default)]
pub struct WorkPass {
    /// The nominal path, local ENU m, in driving order.
    pub nominal: Vec<Vec2>,
    /// The pass began after a turn (not the job's first line).
    pub after_turn: bool,
    pub samples: Vec<WorkSample>,
}

/// The true pose against a work pass, one control period.
#[derive(Debug, Clone, Copy)]
pub struct WorkSample {
    /// Simulated time, s.
    pub t: f64,
    /// Distance along the nominal path, m.
    pub along_m: f64,
    /// Signed cross-track error, m (positive = left of the path).
    pub xte_m: f64,
    /// True rear-axle position, local ENU m.
    pub pos: Vec2,
}

/// A recorded point of the true trajectory.
#[derive(Debug, Clone, Copy)]
pub struct TracePoint {
    pub pos: Vec2,
    /// |XTE| at this point when on a work line, m; `None` in turns.
    pub xte_abs: Option<f64>,
}

/// What the SVG draws.
#[derive(Debug, Clone, Default)]
pub struct Trace {
    pub points: Vec<TracePoint>,
    pub turns: Vec<Vec<Vec2>>,
    /// Every work line or work segment driven, as planned.
    pub lines: Vec<Vec<Vec2>>,
    /// Field outlines drawn under the trace (boundary, obstacles, headland), local m.
    pub outlines: Vec<Vec<Vec2>>,
}

/// A finished run.
#[derive(Debug, Clone)]
pub struct DemoRun {
    pub report: Report,
    pub trace: Trace,
    /// Lines finished in this run, in order.
    pub finished_lines: Vec<u64>,
    /// Progress at the end of the run.
    pub progress: Progress,
    /// Every end of an engagement: (simulated time s, fault).
    pub disengage_events: Vec<(f64, String)>,
    /// The work passes driven, when [`DemoOptions::record_work`].
    pub work: Vec<WorkPass>,
}

/// A fault's configuration name (`off_line`), as the status and the reports spell it.
fn fault_name(fault: crate::safety::FaultCode) -> String {
    serde_json::to_value(fault)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_else(|| format!("{fault:?}"))
}

/// The configuration name of a tracker (`track.kind`).
pub fn tracker_name(kind: TrackerChoice) -> &'static str {
    kind.name()
}

/// A default time budget: three times the time to drive every line and turn at `speed`.
fn default_max_time(cfg: &Config, speed: f64) -> f64 {
    let ab = v2(
        cfg.job.point_b_m[0] - cfg.job.point_a_m[0],
        cfg.job.point_b_m[1] - cfg.job.point_a_m[1],
    )
    .norm();
    let lines = if cfg.job.line_num == 0 {
        100
    } else {
        cfg.job.line_num
    } as f64;
    let per_line = ab + 4.0 * cfg.turn_radius() + 20.0 * cfg.job.line_width_m;
    60.0 + 3.0 * lines * per_line / speed
}

/// Run the job closed-loop. `on_progress` is called at every line change and work checkpoint with the snapshot to
/// persist; `on_event` with every guidance event.
pub fn run(
    cfg: &Config,
    opts: &DemoOptions,
    on_progress: &mut dyn FnMut(&Progress),
    on_event: &mut dyn FnMut(f64, &Event),
) -> Result<DemoRun, JobError> {
    let wall = std::time::Instant::now();
    let resolved = cfg.resolved();
    // The job given, or the configured one, set up as agsteerd sets it up.
    let job = match (&opts.prepared, &opts.job) {
        (Some(prepared), _) => prepared.clone(),
        (None, Some(plan)) => crate::job::given(
            &resolved.planning,
            plan.clone(),
            opts.origin,
            opts.field.clone(),
        ),
        (None, None) => crate::job::prepare(&resolved.planning)?,
    };
    // Segment jobs are scored segment by segment (arcs, driven as lines, by line).
    let scored = match &job.plan {
        JobPlan::Segments(s) if opts.job.is_some() || resolved.planning.kind != JobKind::Arcs => {
            Some(s)
        }
        _ => None,
    };
    let mut node = crate::job::build_node(&resolved, &job, opts.resume.as_ref())?;
    let sim_setup = &resolved.sim;
    let speed = sim_setup.speed;
    let segment_job = matches!(
        node.controller().guidance().job_plan(),
        JobPlan::Segments(_)
    );
    // A segment job or a resumed one starts at its current path's start (a resumed turn: the
    // turn's), offset and turned as configured; a new AB job at A.
    let path_start = match &opts.resume {
        Some(_) => node.controller().path_start(),
        None if segment_job => node.controller().path_start(),
        None => None,
    };
    let start = path_start
        .map(|(p, _)| {
            let normal = left_normal(&crate::geo::heading_vec(p.heading));
            let pos = p.pos + normal * sim_setup.start_offset;
            Pose::new(pos.x, pos.y, p.heading + sim_setup.start_heading)
        })
        .unwrap_or_else(|| {
            let ab = &resolved.planning.ab;
            let dir = (ab.point_b - ab.point_a).normalize();
            let p = ab.point_a + left_normal(&dir) * sim_setup.start_offset;
            Pose::new(p.x, p.y, dir.y.atan2(dir.x) + sim_setup.start_heading)
        });
    // Started on a path, the simulated driver has been steering along it: the wheels start at
    // the path's curvature at its start (an arc's steering, not straight), forwards.
    let start_curvature = path_start.map(|(_, k)| k).filter(|_| {
        node.controller()
            .guidance()
            .global_path()
            .first()
            .is_some_and(|p| p.direction == crate::geo::Direction::Forward)
    });
    let mut simulator = Simulator::new(sim_setup.params.clone(), start, speed);
    if let Some(curvature) = start_curvature {
        simulator.hold_curvature(curvature);
    }
    let mut sim = SimNode::new(
        simulator,
        *node.enu(),
        SimAddresses::default(),
        opts.scenario.clone(),
    )
    .with_speed_profile(sim_setup.speed_profile)
    .with_command_timeout(sim_setup.command_timeout);
    // With the ISO curvature output the tractor is a steer-ready one (ISO 11783-7 only).
    if cfg.bus.output == crate::config::OutputKind::Curvature {
        sim = sim.with_steer_ready();
    }
    // The controller and the simulator talk only through frames on an in-memory bus.
    let mut bus_ctrl = MemBus::new();
    let mut bus_sim = bus_ctrl.node();
    let mut terminal_bus = bus_ctrl.node();
    let mut terminal = Packer::new(0x26);
    let dt = resolved.control.dt;
    // The time budget at the slowest speed the driver keeps: with a speed profile the turns
    // are driven at its minimum (at 20 km/h the turns of 19 m radius are most of a block's
    // length, and at 4 km/h they took more than three times the job at the job speed).
    let budget_speed = sim_setup
        .speed_profile
        .map_or(speed, |p| p.min.min(speed))
        .max(0.1);
    let max_time = if sim_setup.max_time > 0.0 {
        sim_setup.max_time
    } else if let JobPlan::Segments(job) = node.controller().guidance().job_plan() {
        let length: f64 = job.segments().iter().map(|s| s.length()).sum();
        60.0 + 3.0 * length / budget_speed
    } else {
        default_max_time(cfg, budget_speed)
    };

    let mut stats = XteStats::default();
    let mut scored_path = ScoredPath::default();
    // Segment jobs: every segment scored on its own, whatever its kind.
    let mut segment_path = ScoredPath::default();
    let segment_count = scored.map_or(0, |job| job.len());
    let mut segment_scores = vec![SegmentScore::default(); segment_count];
    let mut finished_at: Option<f64> = None;
    let mut acquisition_max: f64 = 0.0;
    let mut turns = 0u64;
    let mut finished_lines = Vec::new();
    let mut lines_this_run = 0u64;
    let mut after_turn = opts.resume.is_some();
    let mut sim_frames: Vec<(f64, Frame)> = Vec::with_capacity(64);
    let mut ctrl_frames: Vec<Frame> = Vec::with_capacity(8);
    let mut trace = Trace {
        outlines: opts.outlines.clone(),
        ..Trace::default()
    };
    let mut work: Vec<WorkPass> = Vec::new();
    let mut distance = 0.0;
    let mut next_trace_at = 0.0;
    let mut max_wheel: f64 = 0.0;
    let mut max_rate: f64 = 0.0;
    let mut last_wheel = sim.sim().true_state().wheel_angle;
    let mut engaged_ticks = 0u64;
    let mut was_engaged = false;
    let mut engagements = 0u64;
    let mut frames = 0u64;
    let mut disengagements = std::collections::BTreeMap::new();
    let mut disengage_events = Vec::new();
    let mut refusals = std::collections::BTreeMap::new();
    let mut last_refusal = crate::safety::FaultCode::None;
    let mut t = 0.0;
    let mut k: u64 = 0;
    let mut stopped = false;
    let mut given_back = None;

    while t <= max_time {
        t = k as f64 * dt;
        k += 1;
        // Simulator → bus, each frame stamped with its delivery time.
        sim_frames.clear();
        sim.advance_to(t, &mut sim_frames);
        for (ts, f) in &sim_frames {
            bus_sim.set_time(*ts);
            let _ = bus_sim.send(f);
        }
        frames += sim_frames.len() as u64;
        // The operator presses engage when the system is ready.
        let st = node.status();
        if st.state == SafetyState::Ready && !(opts.no_reengage && engagements > 0) {
            if let Ok(f) = terminal.pack(&OperatorCommand {
                command: Some(crate::can::codec::OperatorCommandCommand::Engage),
                nudge: Some(0.0),
                job: Some(0.0),
            }) {
                terminal_bus.set_time(t);
                let _ = terminal_bus.send(&f);
            }
        }
        while let Ok(Some(tf)) = bus_ctrl.try_recv() {
            node.on_frame(&tf);
        }
        ctrl_frames.clear();
        let cmd = node.tick(t, &mut ctrl_frames);
        bus_ctrl.set_time(t);
        for f in &ctrl_frames {
            let _ = bus_ctrl.send(f);
        }
        frames += ctrl_frames.len() as u64;
        while let Ok(Some(tf)) = bus_sim.try_recv() {
            sim.on_frame(&tf);
        }
        while let Ok(Some(_)) = terminal_bus.try_recv() {}
        if cmd.engaged {
            engaged_ticks += 1;
            if !was_engaged {
                engagements += 1;
            }
        } else if was_engaged {
            let name = fault_name(cmd.fault);
            *disengagements.entry(name.clone()).or_insert(0) += 1;
            tracing::info!(t_s = format_args!("{t:.2}"), fault = %name, "disengaged");
            disengage_events.push((t, name));
            // A held tracking fault: the driver takes over, the run ends here (once this
            // period's events are handed on).
            if let Some(held) = node
                .supervisor()
                .tracking_fault()
                .filter(|_| !opts.drive_on_after_held_fault)
            {
                let truth = sim.sim().true_state();
                given_back = Some(GivenBack {
                    fault: fault_name(held),
                    t_s: t,
                    path_distance_m: node.controller().guidance().distance_from_path(&truth.pose),
                });
            }
        }
        was_engaged = cmd.engaged;
        let refusal = node.supervisor().last_refusal();
        if refusal != last_refusal {
            last_refusal = refusal;
            if refusal == crate::safety::FaultCode::LineUnfollowable {
                *refusals.entry(fault_name(refusal)).or_insert(0) += 1;
            }
        }

        // Progress is saved at line changes and work checkpoints along a line, as the daemon does.
        let checkpoint = node.controller_mut().guidance_mut().take_checkpoint();
        let had_events = node.controller().guidance().has_events();
        if had_events || checkpoint {
            on_progress(&node.controller().guidance().progress());
        }
        if had_events {
            let g = node.controller_mut().guidance_mut();
            let mut turn_started = false;
            for ev in g.drain_events() {
                match ev {
                    Event::TurnStarted { .. } => {
                        turns += 1;
                        turn_started = true;
                    }
                    Event::LineFinished { line, .. } => {
                        finished_lines.push(line);
                        lines_this_run += 1;
                    }
                    _ => {}
                }
                on_event(t, &ev);
            }
            if turn_started {
                after_turn = true;
                if opts.record_trace {
                    trace.turns.push(
                        node.controller()
                            .guidance()
                            .global_path()
                            .iter()
                            .map(|p| p.pos)
                            .collect(),
                    );
                }
            }
            if opts.stop_after_lines.is_some_and(|n| lines_this_run >= n) {
                stopped = true;
                break;
            }
        }
        if given_back.is_some() {
            break;
        }
        if node.controller().guidance().is_finished() {
            // A segment job ends with a stop request: let the vehicle come to rest (within
            // 30 s) so that the goal error is where it stands, not where it passed.
            let rolling = sim.sim().true_state().speed.abs() >= cfg.guidance.stopped_speed_mps;
            if segment_count == 0 || !rolling || t > finished_at.get_or_insert(t).to_owned() + 30.0
            {
                break;
            }
            continue;
        }

        // Ground truth scoring.
        let truth = sim.sim().true_state();
        distance += truth.speed.abs() * dt;
        max_wheel = max_wheel.max(truth.wheel_angle.abs());
        if k > 1 {
            max_rate = max_rate.max((truth.wheel_angle - last_wheel).abs() / dt);
        }
        last_wheel = truth.wheel_angle;
        let g = node.controller().guidance();
        let mut xte_abs = None;
        let scored_segment = (!g.is_approaching())
            .then(|| segment_scores.get_mut(g.index_rank()))
            .flatten();
        if let Some(score) = scored_segment {
            if !segment_path.is_current(g) {
                segment_path.set(g);
            }
            if let Some((_, xte)) = segment_path.locate(&truth.pose.pos, g.index_global()) {
                score.count += 1;
                score.sum_sq += xte * xte;
                score.max = score.max.max(xte.abs());
            }
        }
        if g.phase() == Phase::Work {
            if !scored_path.is_current(g) {
                scored_path.set(g);
                if opts.record_trace {
                    trace.lines.push(scored_path.points.clone());
                }
                if opts.record_work {
                    work.push(WorkPass {
                        nominal: scored_path.points.clone(),
                        after_turn,
                        samples: Vec::new(),
                    });
                }
            }
            if let Some((along, xte)) = scored_path.locate(&truth.pose.pos, g.index_global()) {
                if let Some(pass) = work.last_mut().filter(|_| opts.record_work) {
                    pass.samples.push(WorkSample {
                        t,
                        along_m: along,
                        xte_m: xte,
                        pos: truth.pose.pos,
                    });
                }
                if (ACQUISITION_SKIP_M..=scored_path.length()).contains(&along) {
                    stats.add(xte);
                    if after_turn && along <= ACQUISITION_END_M {
                        acquisition_max = acquisition_max.max(xte.abs());
                    }
                }
                xte_abs = Some(xte.abs());
            }
        }
        if opts.record_trace && distance >= next_trace_at {
            trace.points.push(TracePoint {
                pos: truth.pose.pos,
                xte_abs,
            });
            next_trace_at = distance + TRACE_SPACING_M;
        }
    }

    let ctrl = node.controller();
    let finished = ctrl.guidance().is_finished() && !stopped;
    let (segments, goal_position_error_m, goal_heading_error_deg) = match scored {
        Some(job) => {
            let segments = job
                .segments()
                .iter()
                .zip(&segment_scores)
                .enumerate()
                .filter(|(_, (_, sc))| sc.count > 0)
                .map(|(index, (s, sc))| SegmentReport {
                    index,
                    kind: s.kind,
                    direction: s.direction,
                    length_m: s.length(),
                    xte_rms_m: (sc.sum_sq / sc.count as f64).sqrt(),
                    xte_max_m: sc.max,
                })
                .collect();
            let last = job.segments().last();
            let goal = last.and_then(|s| {
                let n = s.points.len();
                let d = s.points[n - 1] - s.points[n - 2];
                let travel = d.y.atan2(d.x);
                let heading = match s.direction {
                    crate::geo::Direction::Forward => travel,
                    crate::geo::Direction::Reverse => travel + std::f64::consts::PI,
                };
                let truth = sim.sim().true_state().pose;
                finished.then(|| {
                    (
                        (truth.pos - s.points[n - 1]).norm(),
                        crate::geo::wrap_angle(truth.heading - heading)
                            .to_degrees()
                            .abs(),
                    )
                })
            });
            (segments, goal.map(|g| g.0), goal.map(|g| g.1))
        }
        None => (Vec::new(), None, None),
    };
    let report = Report {
        finished,
        lines_planned: match scored {
            Some(job) => Some(job.len() as u64),
            None => (cfg.job.line_num > 0).then_some(cfg.job.line_num),
        },
        lines_completed: ctrl.guidance().lines_done(),
        xte_rms_m: stats.rms(),
        xte_p95_m: stats.quantile(0.95),
        xte_max_m: stats.max(),
        acquisition_xte_max_m: acquisition_max,
        turns,
        distance_m: distance,
        max_wheel_angle_deg: max_wheel.to_degrees(),
        max_wheel_rate_deg_s: max_rate.to_degrees(),
        steering_lost_motion_deg: node.controller().lost_motion().to_degrees(),
        sim_time_s: t,
        wall_time_s: wall.elapsed().as_secs_f64(),
        tracker: tracker_name(cfg.track.kind).to_string(),
        engaged_fraction: engaged_ticks as f64 / k.max(1) as f64,
        given_back,
        frames,
        disengagements,
        refusals,
        segments,
        goal_position_error_m,
        goal_heading_error_deg,
        plan: None,
    };
    Ok(DemoRun {
        report,
        trace,
        finished_lines,
        progress: ctrl.guidance().progress(),
        disengage_events,
        work,
    })
}
