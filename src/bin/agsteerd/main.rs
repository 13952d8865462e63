//! `agsteerd`: the steering daemon on SocketCAN.

use agsteer::config::Config;
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
    /// Validate the configuration and exit (0 valid, 2 invalid).
    #[arg(long)]
    check: bool,
    /// Override a configuration key, e.g. `--set bus.interface=vcan0`.
    #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
    set: Vec<String>,
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
        if cfg.job.kind == agsteer::config::JobKind::Field {
            // The field must load and plan too, or the daemon would not start.
            match agsteer::daemon::field_file::load(&cfg) {
                Ok(fj) => println!(
                    "{}: field {} plans into {} segments (checksum {:08x})",
                    args.config.display(),
                    fj.path.display(),
                    fj.job.len(),
                    fj.job.checksum()
                ),
                Err(e) => {
                    eprintln!("{}: {:#}", args.config.display(), anyhow::Error::new(e));
                    return ExitCode::from(2);
                }
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
    match agsteer::daemon::run::run(cfg, source).context("agsteerd") {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}
