//! `agsteerd`: the steering daemon on SocketCAN.

use agsteer::config::Config;
use agsteer::daemon::run::DaemonError;
use agsteer::exit::Exit;
use clap::Parser;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "agsteerd",
    version,
    about = "agsteer steering daemon (SocketCAN)",
    after_help = agsteer::exit::help_table()
)]
struct Args {
    /// Configuration file.
    #[arg(long, default_value = "/etc/agsteer/agsteer.toml")]
    config: PathBuf,
    /// Load everything the daemon loads at start-up, as it loads it (the configuration; a field
    /// or TASKDATA file read and planned; a manoeuvre map read and the manoeuvre planned; the
    /// NTRIP password file; the state directory, the saved progress and the status socket's
    /// path looked at, nothing written), say what the daemon would do, then exit (0 valid, 2
    /// invalid). Warnings (progress that could not be saved) do not fail the check.
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
            return Exit::Invalid.into();
        }
        Err(e) => {
            eprintln!("{}: {e}", args.config.display());
            return Exit::Invalid.into();
        }
    };
    if args.check {
        return check(&args, &cfg);
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
    match agsteer::daemon::run::run(cfg, source, bus_log) {
        Ok(()) => Exit::Success.into(),
        Err(e) => {
            let exit = exit_for(&e);
            eprintln!("error: {:#}", anyhow::Error::new(e).context("agsteerd"));
            exit.into()
        }
    }
}

/// The exit status of a daemon that stopped on `e`: what `--check` would have refused (the
/// configuration and what it names) is [`Exit::Invalid`], as there.
fn exit_for(e: &DaemonError) -> Exit {
    match e {
        DaemonError::Config(_) | DaemonError::Job(_) | DaemonError::Startup(_) => Exit::Invalid,
        DaemonError::ProgressNotSaved(_) => Exit::ProgressNotSaved,
        _ => Exit::Error,
    }
}

/// `--check`: [`agsteer::job::startup::load`], the daemon's own start-up, then what it would
/// do with the saved progress.
fn check(args: &Args, cfg: &Config) -> ExitCode {
    let name = args.config.display();
    let startup = match agsteer::job::startup::load(cfg) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{name}: {:#}", anyhow::Error::new(e));
            return Exit::Invalid.into();
        }
    };
    if let Some(planned) = agsteer::job::startup::planned(&startup.job) {
        println!("{name}: {planned}");
    }
    match agsteer::job::startup::progress_outlook(&startup) {
        Ok(outlook) => println!("{name}: progress: {outlook}"),
        Err(warning) => println!("{name}: warning: {warning}"),
    }
    for w in &startup.warnings {
        println!("{name}: warning: {w}");
    }
    println!("{name}: valid");
    Exit::Success.into()
}
