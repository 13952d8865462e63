//! The one TOML configuration file a service technician edits.
//!
//! Every section is `deny_unknown_fields` and every key has a default, so a file only needs the
//! keys it changes. Edge units (degrees, km/h) are converted to SI by the accessor methods, in
//! this one place. [`Config::validate`] reports every problem at once, each naming the key, the
//! value and the rule. `--set key.path=value` overrides are applied to the TOML tree before it
//! is deserialised, so they go through exactly the same checks as the file.
//!
//! One file per section (`job.rs`, `guidance.rs`, `vehicle.rs`, `control.rs`, `track.rs`,
//! `sim.rs`, `bus.rs`, `isobus.rs`, `safety.rs`, `daemon.rs`, `progress.rs`, `field.rs`, `maneuver.rs`,
//! `gnss.rs`, `sources.rs`, `acceptance.rs`, `calibration.rs`), each
//! holding the section's struct, its defaults and its validation; [`check`] holds the
//! range-check helpers. This module holds the whole [`Config`], loading, `--set` overrides and
//! the errors. It does no I/O but reading the file named to [`Config::load`].
//!
//! To add a key: add the field (doc comment with unit and range) to its section's struct and
//! its `Default`, a check to the section's `validate` (every float finite and in range, the
//! message naming the key), and document it in `config/demo.toml`.

mod acceptance;
mod bus;
mod calibration;
pub(crate) mod check;
mod control;
mod daemon;
mod envelope;
mod field;
mod gnss;
mod guidance;
mod isobus;
mod job;
mod maneuver;
mod planners;
mod progress;
mod resolve;
mod safety;
mod sim;
mod sources;
mod track;
mod vehicle;

pub use acceptance::{AcceptanceConfig, AccuracyMiss};
pub use bus::{BusConfig, OutputKind};
pub use calibration::CalibrationConfig;
pub use control::ControlConfig;
pub use daemon::DaemonConfig;
pub use field::{FieldConfig, FieldOrigin, SwathAngleChoice};
pub use gnss::{GnssConfig, GnssSource, TransportKind};
pub use guidance::GuidanceConfig;
pub use isobus::IsobusConfig;
pub use job::{JobConfig, JobKind, LineOrder, LineSide};
pub use maneuver::{CurveChoice, ManeuverConfig};
pub use progress::ProgressConfig;
pub use resolve::{DaemonParams, FieldPlanning, ManeuverPlanning, Planning, Resolved, SimSetup};
pub use safety::SafetyConfig;
pub use sim::SimConfig;
pub use sources::SourcesConfig;
pub use track::{TrackConfig, TrackerChoice};
pub use vehicle::VehicleConfig;

use check::Checker;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::Path;

/// Everything that can go wrong loading a configuration.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("cannot read {path}: {source}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("{0}")]
    Parse(String),
    #[error("bad override `{0}`: expected key.path=value")]
    BadOverride(String),
    #[error("{}", .0.iter().map(|p| p.to_string()).collect::<Vec<_>>().join("\n"))]
    Invalid(Vec<Problem>),
}

/// One validation problem: `key = value: rule`.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    pub key: String,
    pub value: String,
    pub rule: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {}: {}", self.key, self.value, self.rule)
    }
}

/// The whole configuration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct Config {
    pub job: JobConfig,
    pub guidance: GuidanceConfig,
    pub vehicle: VehicleConfig,
    pub control: ControlConfig,
    pub track: TrackConfig,
    pub sim: SimConfig,
    pub progress: ProgressConfig,
    pub bus: BusConfig,
    pub isobus: IsobusConfig,
    pub safety: SafetyConfig,
    pub daemon: DaemonConfig,
    pub field: FieldConfig,
    pub maneuver: ManeuverConfig,
    pub gnss: GnssConfig,
    pub sources: SourcesConfig,
    pub acceptance: AcceptanceConfig,
    pub calibration: CalibrationConfig,
}

/// Apply `key.path=value` overrides to a TOML tree. The value is parsed as a TOML value
/// (`3`, `2.5`, `true`, `[1, 2]`, `"text"`); anything that does not parse is taken as a string.
pub fn apply_overrides(root: &mut toml::Table, overrides: &[String]) -> Result<(), ConfigError> {
    for ov in overrides {
        let (key, raw) = ov
            .split_once('=')
            .ok_or_else(|| ConfigError::BadOverride(ov.clone()))?;
        let key = key.trim();
        if key.is_empty() || key.split('.').any(|p| p.trim().is_empty()) {
            return Err(ConfigError::BadOverride(ov.clone()));
        }
        let raw = raw.trim();
        let value = match format!("v = {raw}").parse::<toml::Table>() {
            Ok(mut t) => t
                .remove("v")
                .unwrap_or(toml::Value::String(raw.to_string())),
            Err(_) => toml::Value::String(raw.to_string()),
        };
        let parts: Vec<&str> = key.split('.').map(str::trim).collect();
        let (last, parents) = parts
            .split_last()
            .ok_or_else(|| ConfigError::BadOverride(ov.clone()))?;
        let mut table = &mut *root;
        for p in parents {
            let entry = table
                .entry(p.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            table = entry.as_table_mut().ok_or_else(|| {
                ConfigError::Parse(format!("override `{ov}`: `{p}` is not a section"))
            })?;
        }
        table.insert(last.to_string(), value);
    }
    Ok(())
}

/// Edit distance between two keys (for "did you mean").
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != *cb))
                .min(prev[j + 1] + 1)
                .min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// Add "did you mean `key`?" to serde's unknown-field messages.
fn suggest_nearest(msg: String) -> String {
    let Some(start) = msg.find("unknown field `") else {
        return msg;
    };
    let rest = &msg[start + "unknown field `".len()..];
    let Some(end) = rest.find('`') else {
        return msg;
    };
    let unknown = &rest[..end];
    // serde says "expected `a`", "expected `a` or `b`" or "expected one of `a`, `b`, …".
    let Some(list) = rest.find("expected ").map(|i| &rest[i..]) else {
        return msg;
    };
    let list = list.lines().next().unwrap_or("");
    let best = list
        .split('`')
        .skip(1)
        .step_by(2)
        .min_by_key(|k| edit_distance(unknown, k));
    match best {
        Some(k) => {
            // Put the hint on the first line, before serde's "in `section`" line.
            let (first, more) = msg.split_once('\n').unwrap_or((msg.as_str(), ""));
            let more = more.trim();
            if more.is_empty() {
                format!("{first}; did you mean `{k}`?")
            } else {
                format!("{first}; did you mean `{k}`? ({more})")
            }
        }
        None => msg,
    }
}

/// The range of each integer type a key can have, as a technician reads it.
const INTEGER_RANGES: [(&str, &str); 10] = [
    ("u8", "0..=255"),
    ("u16", "0..=65535"),
    ("u32", "0..=4294967295"),
    ("u64", "0..=18446744073709551615"),
    ("usize", "0..=18446744073709551615"),
    ("i8", "-128..=127"),
    ("i16", "-32768..=32767"),
    ("i32", "-2147483648..=2147483647"),
    ("i64", "-9223372036854775808..=9223372036854775807"),
    ("isize", "-9223372036854775808..=9223372036854775807"),
];

/// serde's message for an integer that does not fit its key's type ("invalid value: integer
/// `4294967297`, expected u32 in `gnss.baud`"; a number beyond TOML's 64 bits arrives from
/// `--set` as a string) becomes `key = value: must be an integer in lo..=hi`. The section's
/// own range check, which may be narrower, runs once the value fits.
fn integer_range(msg: String) -> String {
    let between = |text: &str, open: &str, close: char| -> Option<String> {
        let start = text.find(open)? + open.len();
        let len = text[start..].find(close)?;
        Some(text[start..start + len].to_string())
    };
    let value = between(&msg, "integer `", '`').or_else(|| {
        between(&msg, "string \"", '"').filter(|v| {
            !v.is_empty()
                && v.trim_start_matches('-')
                    .bytes()
                    .all(|b| b.is_ascii_digit())
        })
    });
    let range = between(&msg, "expected ", '\n')
        .or_else(|| msg.split("expected ").nth(1).map(|t| t.trim().to_string()))
        .and_then(|ty| {
            INTEGER_RANGES
                .iter()
                .find(|(name, _)| ty.trim() == *name)
                .map(|(_, r)| *r)
        });
    match (between(&msg, "in `", '`'), value, range) {
        (Some(key), Some(value), Some(range)) => {
            format!("{key} = {value}: must be an integer in {range}")
        }
        _ => msg,
    }
}

impl Config {
    /// Parse TOML text with overrides, without validating.
    pub fn parse_with(text: &str, overrides: &[String]) -> Result<Config, ConfigError> {
        let mut root: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| ConfigError::Parse(e.to_string()))?;
        apply_overrides(&mut root, overrides)?;
        Config::deserialize(root)
            .map_err(|e| ConfigError::Parse(integer_range(suggest_nearest(e.to_string()))))
    }

    /// Read, override and validate a configuration file.
    pub fn load(path: &Path, overrides: &[String]) -> Result<Config, ConfigError> {
        let text =
            crate::envelope::read_text(path, crate::envelope::FileKind::Config).map_err(|e| {
                ConfigError::Read {
                    path: path.display().to_string(),
                    source: e.into_io(),
                }
            })?;
        let cfg = Config::parse_with(&text, overrides)?;
        let problems = cfg.validate();
        if problems.is_empty() {
            Ok(cfg)
        } else {
            Err(ConfigError::Invalid(problems))
        }
    }

    /// Every problem in the configuration, all at once, in the order of the sections (the
    /// vehicle's body after `[safety]`, as it always was).
    pub fn validate(&self) -> Vec<Problem> {
        let mut c = Checker::default();
        self.job.validate(&mut c);
        self.field.validate(self.job.line_width_m, &mut c);
        self.guidance.validate(&mut c);
        self.vehicle.validate_steering(&mut c);
        self.control.validate(&mut c);
        self.track.validate(&mut c);
        self.sim.validate(&mut c);
        self.sim.validate_plant(self.vehicle.wheelbase_m, &mut c);
        self.sim.validate_command_timeout(self.control.dt_s, &mut c);
        self.bus.validate(&mut c);
        self.isobus.validate(&mut c);
        self.safety.validate(&mut c);
        self.vehicle.validate_body(&mut c);
        self.maneuver.validate(&self.vehicle, &mut c);
        self.daemon.validate(&mut c);
        self.progress.validate(&mut c);
        self.gnss.validate(&mut c);
        self.sources.validate(&mut c);
        self.acceptance.validate(&mut c);
        self.calibration.validate(&mut c);
        envelope::validate(self, &mut c);
        c.problems
    }

    /// The keys that cannot change while the daemon runs a job: those defining the job (the
    /// field planning of `[field]` included), the bus identity and the control period.
    /// Returns the ones that differ in `new`.
    pub fn fixed_key_changes(&self, new: &Config) -> Vec<&'static str> {
        let mut v = Vec::new();
        let mut check = |key: &'static str, same: bool| {
            if !same {
                v.push(key);
            }
        };
        check("job", self.job == new.job);
        check("field", self.field == new.field);
        check("guidance", self.guidance == new.guidance);
        check(
            "vehicle.r_min_m",
            self.vehicle.r_min_m == new.vehicle.r_min_m,
        );
        check("control.dt_s", self.control.dt_s == new.control.dt_s);
        check("bus.interface", self.bus.interface == new.bus.interface);
        check(
            "bus.source_address",
            self.bus.source_address == new.bus.source_address,
        );
        check("isobus", self.isobus == new.isobus);
        check(
            "bus.status_socket",
            self.bus.status_socket == new.bus.status_socket,
        );
        check("gnss", self.gnss == new.gnss);
        check(
            "progress.state_dir",
            self.progress.state_dir == new.progress.state_dir,
        );
        v
    }

    /// The resolved configuration as TOML text.
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self).unwrap_or_else(|e| format!("# cannot print: {e}"))
    }
}

#[cfg(test)]
mod tests;
