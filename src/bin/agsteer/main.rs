//! `agsteer`: the technician's and developer's tool.

mod accuracy_cmd;
mod calibrate_cmd;
mod calibrate_live;
mod dbc_cmd;
mod demo_cmd;
mod maneuver_cmd;
mod plan_cmd;
mod replay_cmd;
mod sim_cmd;
mod sim_gnss;
mod status_cmd;

use agsteer::config::Config;
use agsteer::exit::Exit;
use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "agsteer",
    version,
    about = "agsteer: automatic steering for tractors",
    after_help = agsteer::exit::help_table()
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// Options shared by every subcommand that reads a configuration.
#[derive(Args, Clone)]
struct ConfigArgs {
    /// Override a configuration key without editing the file, e.g. `--set track.kind=pure_pursuit`.
    #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
    set: Vec<String>,
}

#[derive(Subcommand)]
enum Command {
    /// Run a whole job closed-loop against the simulator, faster than real time. Exit status 6
    /// when the job does not finish (not when --stop-after stops it), 7 when the true XTE on
    /// work lines is beyond an [acceptance] limit, 8 when progress could not be saved.
    #[command(after_help = agsteer::exit::help_table())]
    Demo {
        /// Configuration file.
        #[arg(long, default_value = "config/demo.toml")]
        config: PathBuf,
        /// Output directory for trace.svg, report.json and progress.json.
        #[arg(long, default_value = "out/demo")]
        out: PathBuf,
        /// Print the report JSON on stdout.
        #[arg(long)]
        json: bool,
        /// Continue from OUT/progress.json instead of starting afresh.
        #[arg(long)]
        resume: bool,
        /// Stop after this many lines, as a power loss would (for trying --resume).
        #[arg(long, value_name = "LINES")]
        stop_after: Option<u64>,
        #[command(flatten)]
        cfg: ConfigArgs,
    },
    /// The accuracy report: every scenario in tools/scenarios/ (or the given files) with the
    /// default tracker, pure pursuit and Stanley; XTE, 95 % class, pass-to-pass after
    /// ISO 12188-2, acquisition after turns, RTK-float behaviour; OUT/<scenario>.svg of XTE
    /// over distance and OUT/accuracy.json. Exit status 6 when a run of the tracker held to
    /// the limits (the one named, or each scenario's track.kind with "all") does not finish, 7
    /// when its true XTE on work lines is beyond an [acceptance] limit of its scenario.
    #[command(after_help = agsteer::exit::help_table())]
    Accuracy {
        /// Tracker: predictive, pure_pursuit, stanley, lqr, a comma-separated list of them
        /// (the first held to the limits; in the envelope, the one judged) or all (the
        /// default tracker, pure pursuit and Stanley).
        #[arg(long, default_value = "all")]
        tracker: String,
        /// Print the results as JSON instead of the Markdown table.
        #[arg(long)]
        json: bool,
        /// Output directory for the SVGs and accuracy.json.
        #[arg(long, default_value = "out/accuracy")]
        out: PathBuf,
        /// Scenario directory (every *.toml in it).
        #[arg(long, default_value = "tools/scenarios")]
        scenarios: PathBuf,
        /// Run these scenario files instead of the directory.
        #[arg(long)]
        config: Vec<PathBuf>,
        /// Run the envelope: every scenario under every plant variation of the matrix
        /// (src/demo/envelope.rs); writes OUT/envelope.md, OUT/envelope.svg (heat map) and
        /// OUT/envelope.json, progress on stderr.
        #[arg(long)]
        envelope: bool,
        /// Envelope: only these variations (comma-separated names; default all).
        #[arg(long, value_delimiter = ',')]
        variations: Vec<String>,
        /// Envelope: what the controller knows of the steering that calibration measures:
        /// "truth" (the plant's values) or "nominal" (its configuration as it is).
        #[arg(long, default_value = "truth")]
        calibration: String,
        /// Worker threads (default: the available cores).
        #[arg(long)]
        threads: Option<usize>,
        #[command(flatten)]
        cfg: ConfigArgs,
    },
    /// Run the vehicle simulator on a CAN interface in real time.
    Sim {
        /// CAN interface (default: the config's bus.interface).
        #[arg(long)]
        iface: Option<String>,
        /// Configuration file.
        #[arg(long, default_value = "config/demo.toml")]
        config: PathBuf,
        /// Fault scenario (TOML with [[fault]] kind, at_s, duration_s).
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// Write the true trajectory (CSV) here, for scoring.
        #[arg(long)]
        trajectory: Option<PathBuf>,
        /// Stop after this many seconds (default: run until killed).
        #[arg(long)]
        duration: Option<f64>,
        /// SCHED_FIFO priority (1..=99; 0 = normal), so a loaded test machine does not starve
        /// the simulated sensors.
        #[arg(long, default_value_t = 0)]
        rt_priority: u8,
        /// Be a serial GNSS receiver: make a pseudo-terminal and a symbolic link LINK to its
        /// device (agsteerd's `gnss.device = LINK`); GNSS leaves there as NMEA 0183 or UBX
        /// (`--gnss-messages`) instead of NMEA 2000 frames on the bus.
        #[arg(long, value_name = "LINK")]
        gnss_pty: Option<PathBuf>,
        /// Be a UDP GNSS receiver: one datagram per epoch to ADDR (e.g. 127.0.0.1:9999;
        /// agsteerd's `gnss.transport = "udp"`), instead of NMEA 2000 frames on the bus.
        #[arg(long, value_name = "ADDR", conflicts_with = "gnss_pty")]
        gnss_udp: Option<std::net::SocketAddr>,
        /// Messages of an epoch, in sending order: gga, rmc, vtg, hdt, paogi (NMEA 0183),
        /// nav-pvt, nav-hpposllh, nav-relposned (UBX).
        #[arg(long, value_name = "LIST", default_value = "gga,rmc,hdt")]
        gnss_messages: String,
        /// With --gnss-pty or --gnss-udp: write each epoch's send time (UTC s) here (CSV).
        #[arg(long, value_name = "FILE")]
        gnss_log: Option<PathBuf>,
        #[command(flatten)]
        cfg: ConfigArgs,
    },
    /// Run the controller offline on a recorded bus log (`agsteerd --bus-log`, or any candump
    /// log), faster than real time: prints its status track (CSV) on stdout and, for a log of
    /// agsteerd's, how many control periods send the same frames as the daemon did. Exit
    /// status 9 with --strict when one differs.
    Replay {
        /// Log files in time order (rotated ones first: FILE.2 FILE.1 FILE).
        #[arg(required = true)]
        logs: Vec<PathBuf>,
        /// The daemon's configuration.
        #[arg(long, default_value = "/etc/agsteer/agsteer.toml")]
        config: PathBuf,
        /// Progress file the daemon resumed from, if it did.
        #[arg(long)]
        progress: Option<PathBuf>,
        /// Write the frames the controller would send here (candump -L).
        #[arg(long)]
        frames: Option<PathBuf>,
        /// Control periods every dt and at each fix, even when the log holds the daemon's.
        #[arg(long)]
        timer: bool,
        /// Status track: one line every N control periods (0: none; differing ones always).
        #[arg(long, default_value_t = 1)]
        every: u64,
        /// Print only a JSON summary.
        #[arg(long)]
        json: bool,
        /// Exit status 9 when a control period differs from the log.
        #[arg(long)]
        strict: bool,
        #[command(flatten)]
        cfg: ConfigArgs,
    },
    /// Print the running daemon's status (state, fix, XTE, line, block, loop timing).
    Status {
        /// Status socket (default: the config's bus.status_socket).
        #[arg(long)]
        socket: Option<PathBuf>,
        /// Configuration file naming the socket.
        #[arg(long, default_value = "/etc/agsteer/agsteer.toml")]
        config: PathBuf,
        /// Overall deadline for connecting and reading the whole reply, s (the reply is also
        /// limited to 1 MiB).
        #[arg(long, default_value_t = 2.0)]
        timeout_s: f64,
    },
    /// The DBC codec: decode candump logs, encode frames, print the frame table.
    Dbc {
        #[command(subcommand)]
        cmd: dbc_cmd::DbcCommand,
    },
    /// Plan coverage of a field (GeoJSON or ISO 11783-10 TASKDATA.XML): writes OUT/plan.geojson,
    /// OUT/plan.svg and OUT/metrics.json. Exit status 4 when the plan breaks a guarantee, 5 when
    /// no swath fits.
    Plan {
        /// Field boundary: GeoJSON (WGS-84) or TASKDATA.XML.
        #[arg(long)]
        field: PathBuf,
        /// Configuration file ([field], job.line_width_m, vehicle.r_min_m, guidance.point_spacing_m).
        #[arg(long, default_value = "config/demo.toml")]
        config: PathBuf,
        /// Output directory.
        #[arg(long, default_value = "out/plan")]
        out: PathBuf,
        /// Print the metrics JSON on stdout.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        options: plan_cmd::PlanOptions,
        #[command(flatten)]
        cfg: ConfigArgs,
    },
    /// Plan a manoeuvre with reversing between two poses (local metres) on a map: prints the
    /// path's length, cusps and segments; exit status 3 when no path is found.
    Maneuver {
        /// Configuration file ([maneuver], [vehicle]).
        #[arg(long, default_value = "config/demo.toml")]
        config: PathBuf,
        /// Map: GeoJSON in local metres; a Polygon's exterior is the boundary, its holes and
        /// Features with "obstacle": true are obstacles. Without it the space is free.
        #[arg(long)]
        map: Option<PathBuf>,
        /// Start pose x,y,heading_deg (metres, degrees CCW from East).
        #[arg(long, allow_hyphen_values = true, required_unless_present = "batch")]
        from: Option<String>,
        /// Goal pose x,y,heading_deg.
        #[arg(long, allow_hyphen_values = true, required_unless_present = "batch")]
        to: Option<String>,
        /// Curve family: cc (continuous curvature) or rs (plain Reeds-Shepp); default
        /// maneuver.curve.
        #[arg(long, value_parser = parse_curve)]
        curve: Option<agsteer::config::CurveChoice>,
        /// Draw the map and path into this SVG file.
        #[arg(long)]
        svg: Option<PathBuf>,
        /// Print the result as JSON.
        #[arg(long)]
        json: bool,
        /// JSON lines {"from":[x,y,deg],"to":[x,y,deg]}: one JSON result per line on stdout.
        #[arg(long, conflicts_with_all = ["from", "to", "svg"])]
        batch: Option<PathBuf>,
        #[command(flatten)]
        cfg: ConfigArgs,
    },
    /// Identify the steering (dead time, lag, rate limit, deadband/backlash) and the
    /// wheel-angle sensor (gain, offset) on the simulated tractor of the configuration's
    /// [sim] over the in-memory bus; prints them with their uncertainty and writes the TOML
    /// fragment of the keys calibration owns. Exit status 10 when it refuses (reason printed).
    Calibrate {
        /// Configuration file (its [vehicle] geometry and [calibration]; [sim] is the tractor;
        /// with --interface, the daemon's: its bus.status_socket).
        #[arg(long, default_value = "config/demo.toml")]
        config: PathBuf,
        /// Write the TOML fragment here (default: print it only).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Calibrate the tractor on this CAN interface: the running agsteerd does it in its
        /// calibration mode (started by the operator command `calibrate`, followed on its
        /// status socket). Without it, the simulator of [sim] on the in-memory bus.
        #[arg(long)]
        interface: Option<String>,
        /// agsteerd's status socket (default: the config's bus.status_socket).
        #[arg(long)]
        socket: Option<PathBuf>,
        /// With --interface: give up after this long, s.
        #[arg(long, default_value_t = 900.0)]
        timeout_s: f64,
        #[command(flatten)]
        cfg: ConfigArgs,
    },
    /// Validate a configuration: print it resolved, or every problem (exit status 2).
    CheckConfig {
        /// Configuration file.
        file: PathBuf,
        #[command(flatten)]
        cfg: ConfigArgs,
    },
}

fn init_logging() {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_target(false)
        .try_init();
}

fn main() -> ExitCode {
    init_logging();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Accuracy {
            tracker,
            json,
            out,
            scenarios,
            config,
            envelope,
            variations,
            calibration,
            threads,
            cfg,
        } => {
            if envelope {
                accuracy_cmd::run_envelope(&accuracy_cmd::EnvelopeArgs {
                    dir: &scenarios,
                    files: &config,
                    tracker: &tracker,
                    json,
                    out: &out,
                    set: &cfg.set,
                    variations: &variations,
                    calibration: &calibration,
                    threads,
                })
            } else {
                accuracy_cmd::run(&scenarios, &config, &tracker, json, &out, &cfg.set)
            }
        }
        Command::Demo {
            config,
            out,
            json,
            resume,
            stop_after,
            cfg,
        } => demo_cmd::run_demo(&config, &out, json, resume, stop_after, &cfg.set),
        Command::CheckConfig { file, cfg } => check_config(&file, &cfg.set),
        Command::Plan {
            field,
            config,
            out,
            json,
            options,
            cfg,
        } => {
            load_config(&config, &cfg.set).and_then(|c| run_plan(&field, &c, &out, json, &options))
        }
        Command::Dbc { cmd } => dbc_cmd::run(cmd),
        Command::Maneuver {
            config,
            map,
            from,
            to,
            curve,
            svg,
            json,
            batch,
            cfg,
        } => load_config(&config, &cfg.set).and_then(|c| {
            maneuver_cmd::run(
                &c,
                &maneuver_cmd::ManeuverArgs {
                    map: map.as_deref(),
                    from: from.as_deref(),
                    to: to.as_deref(),
                    curve,
                    svg: svg.as_deref(),
                    json,
                    batch: batch.as_deref(),
                },
            )
        }),
        Command::Calibrate {
            config,
            out,
            interface,
            socket,
            timeout_s,
            cfg,
        } => load_config(&config, &cfg.set).and_then(|c| match interface {
            Some(interface) => {
                let socket = socket.unwrap_or_else(|| PathBuf::from(&c.bus.status_socket));
                let live = calibrate_live::Live {
                    interface: &interface,
                    socket: &socket,
                    timeout_s,
                };
                calibrate_live::calibrate_live(&live, out.as_deref())
            }
            None => calibrate_cmd::calibrate(&c, out.as_deref()),
        }),
        Command::Sim {
            iface,
            config,
            scenario,
            trajectory,
            duration,
            rt_priority,
            gnss_pty,
            gnss_udp,
            gnss_messages,
            gnss_log,
            cfg,
        } => load_config(&config, &cfg.set).and_then(|c| {
            let iface = iface.unwrap_or_else(|| c.bus.interface.clone());
            let gnss = sim_cmd::SimGnssArgs {
                pty: gnss_pty,
                udp: gnss_udp,
                messages: agsteer::sim::gnss_stream::parse_messages(&gnss_messages)
                    .context("--gnss-messages")?,
                log: gnss_log,
            };
            sim_cmd::run(
                &iface,
                &c,
                scenario.as_deref(),
                trajectory.as_deref(),
                duration,
                rt_priority,
                &gnss,
            )
        }),
        Command::Replay {
            logs,
            config,
            progress,
            frames,
            timer,
            every,
            json,
            strict,
            cfg,
        } => load_config(&config, &cfg.set).and_then(|c| {
            replay_cmd::run(
                &c,
                &replay_cmd::ReplayArgs {
                    logs: &logs,
                    progress: progress.as_deref(),
                    frames_out: frames.as_deref(),
                    timer,
                    json,
                    every,
                    strict,
                },
            )
        }),
        Command::Status {
            socket,
            config,
            timeout_s,
        } => {
            let path = match socket {
                Some(p) => Ok(p),
                None => load_config(&config, &[]).map(|c| PathBuf::from(c.bus.status_socket)),
            };
            path.and_then(|p| status_cmd::status(&p, timeout_s))
        }
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("error: {e:#}");
            exit_for_error(&e).into()
        }
    }
}

/// The status of a failed command: [`Exit::Invalid`] when an invalid configuration (or
/// `--set`) caused it, [`Exit::PlanViolation`] when a field job's plan breaks a guarantee
/// (refused, not driven), [`Exit::NoSwath`] when it has nothing to drive, [`Exit::Error`]
/// otherwise (a file that cannot be read included).
fn exit_for_error(e: &anyhow::Error) -> Exit {
    use agsteer::config::ConfigError;
    use agsteer::job::field::FieldJobError;
    match e.chain().find_map(|c| c.downcast_ref::<FieldJobError>()) {
        Some(FieldJobError::Violates { .. }) => return Exit::PlanViolation,
        Some(FieldJobError::Empty { .. }) => return Exit::NoSwath,
        _ => {}
    }
    let invalid = e.chain().any(|c| {
        matches!(
            c.downcast_ref::<ConfigError>(),
            Some(ConfigError::Invalid(_) | ConfigError::Parse(_) | ConfigError::BadOverride(_))
        )
    });
    if invalid {
        Exit::Invalid
    } else {
        Exit::Error
    }
}

fn run_plan(
    field: &Path,
    cfg: &Config,
    out: &Path,
    json: bool,
    options: &plan_cmd::PlanOptions,
) -> Result<u8> {
    plan_cmd::run(
        field,
        cfg,
        out,
        json,
        options,
        agsteer::plan::coverage::plan_field,
    )
}

fn parse_curve(s: &str) -> Result<agsteer::config::CurveChoice, String> {
    match s {
        "cc" => Ok(agsteer::config::CurveChoice::Cc),
        "rs" => Ok(agsteer::config::CurveChoice::Rs),
        other => Err(format!("`{other}`: expected cc or rs")),
    }
}

/// The controller node exactly as agsteerd builds it at start: the configured job prepared
/// (a field read and planned), resuming `progress` when it belongs to this job.
fn daemon_node(
    cfg: &Config,
    progress: Option<&Path>,
) -> Result<agsteer::control::node::ControllerNode> {
    let resolved = cfg.resolve().context("configuration")?;
    let job = agsteer::job::prepare(&resolved.planning).context("preparing the job")?;
    let resume = progress.and_then(|p| agsteer::job::resume::resume_or_start(&job, p));
    if progress.is_some() && resume.is_none() {
        anyhow::bail!("--progress: no progress of this job to resume");
    }
    agsteer::job::build_node(&resolved, &job, resume.as_ref()).context("building the controller")
}

fn load_config(path: &Path, set: &[String]) -> Result<Config> {
    Config::load(path, set).with_context(|| format!("configuration {}", path.display()))
}

fn check_config(path: &Path, set: &[String]) -> Result<u8> {
    match Config::load(path, set) {
        Ok(cfg) => {
            print!("{}", cfg.to_toml());
            Ok(Exit::Success.code())
        }
        Err(agsteer::config::ConfigError::Invalid(problems)) => {
            eprintln!("{}: {} problem(s)", path.display(), problems.len());
            for p in problems {
                eprintln!("  {p}");
            }
            Ok(Exit::Invalid.code())
        }
        Err(e) => {
            eprintln!("{}: {e}", path.display());
            Ok(Exit::Invalid.code())
        }
    }
}
