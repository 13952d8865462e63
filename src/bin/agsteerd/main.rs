//! `agsteerd`: the steering daemon on SocketCAN.

use agsteer::config::Config;
use agsteer::job::JobDetail;
use anyhow::Context;
use clap::Parser;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "agsteerd",
    version,
    about = "agsteer steering daemon (SocketCAN)"
)]
struct Args {
    /// Configuration file.
    #[arg(long, default_value = "/etc/agsteer/agsteer.toml")]
    config: PathBuf,
    /// Validate the configuration and everything it names (a field is read and planned, a
    /// manoeuvre map read and the manoeuvre planned), then exit (0 valid, 2 invalid).
    #[arg(long)]
    check: bool,
    /// Override a configuration key, e.g. `--set bus.interface=vcan0`.
    #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
    set: Vec<String>,
    /// Log every CAN frame in and out to FILE in `candump -L` form (for `agsteer replay`,
    /// `canplayer`, `agsteer dbc decode`). Off by default. Never slows the control loop: frames
    /// the writer cannot keep up with are dropped and counted in `agsteer status`.
    #[arg(long, value_name = "FILE")]
    bus_log: Option<PathBuf>,
    /// Rotate the bus log when a file would pass this size, MB (1..=4096).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u64).range(1..=4096))]
    bus_log_size_mb: u64,
    /// Bus log files kept, the current one included (FILE, FILE.1, …) (1..=1000).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    bus_log_files: u32,
}

fn main() -> ExitCode {
    let args = Args::parse();
    let cfg = match Config::load(&args.config, &args.set) {
        Ok(c) => c,
        Err(agsteer::config::ConfigError::Invalid(problems)) => {
            eprintln!("{}: {} problem(s)", args.config.display(), problems.len());
            for p in problems {
                eprintln!("  {p}");
            }
            return ExitCode::from(2);
        }
        Err(e) => {
            eprintln!("{}: {e}", args.config.display());
            return ExitCode::from(2);
        }
    };
    if args.check {
        // Everything the daemon loads at start-up, set up as it sets it up: the field or the
        // manoeuvre map read and planned too, or the daemon would not start.
        let prepared = cfg
            .resolve()
            .map_err(anyhow::Error::new)
            .and_then(|r| agsteer::job::prepare(&r.planning).map_err(anyhow::Error::new));
        match prepared {
            Ok(job) => match &job.detail {
                JobDetail::Field(fj) => println!(
                    "{}: field {} plans into {} segments (checksum {:08x})",
                    args.config.display(),
                    fj.path.display(),
                    fj.job.len(),
                    fj.job.checksum()
                ),
                JobDetail::Maneuver(mj, map) => println!(
                    "{}: manoeuvre on {} plans into {} segments ({:.1} m, {} cusps, checksum {:08x})",
                    args.config.display(),
                    if map.is_some() { "its map" } else { "free space" },
                    mj.job.len(),
                    mj.path.length(),
                    mj.path.cusps(),
                    mj.job.checksum()
                ),
                JobDetail::Lines => {}
            },
            Err(e) => {
                eprintln!("{}: {e:#}", args.config.display());
                return ExitCode::from(2);
            }
        }
        println!("{}: valid", args.config.display());
        return ExitCode::SUCCESS;
    }
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(&cfg.daemon.log_level));
    // Logs go through a background thread: a slow stderr (a serial console, a stalled
    // journal) must never stall the control loop. When its buffer is full, lines are dropped.
    let (writer, _guard) = tracing_appender::non_blocking::NonBlockingBuilder::default()
        .buffered_lines_limit(1024)
        .lossy(true)
        .finish(std::io::stderr());
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(writer)
        .with_ansi(false)
        .try_init();
    let source = agsteer::daemon::run::ConfigSource {
        path: args.config.clone(),
        overrides: args.set.clone(),
    };
    let bus_log = args
        .bus_log
        .as_ref()
        .map(|path| agsteer::daemon::bus_log::BusLogParams {
            path: path.clone(),
            interface: cfg.bus.interface.clone(),
            max_bytes: args.bus_log_size_mb * 1_000_000,
            files: args.bus_log_files,
        });
    match agsteer::daemon::run::run(cfg, source, bus_log).context("agsteerd") {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}
