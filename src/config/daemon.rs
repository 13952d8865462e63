//! `[daemon]`: the agsteerd process (log level, real-time priority).
//!
//! Owns the section's keys, their defaults and their range checks.

use super::check::Checker;
use serde::{Deserialize, Serialize};

/// `[daemon]`: the agsteerd process.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DaemonConfig {
    /// Log filter when RUST_LOG is not set: "error", "warn", "info", "debug" or "trace".
    pub log_level: String,
    /// SCHED_FIFO priority of the control loop (1..=99); 0 = the normal scheduler. Needs root
    /// or CAP_SYS_NICE.
    pub realtime_priority: u8,
}

impl Default for DaemonConfig {
    fn default() -> Self {
        DaemonConfig {
            log_level: "info".to_string(),
            realtime_priority: 0,
        }
    }
}

impl DaemonConfig {
    /// Checks of `[daemon]`.
    pub(crate) fn validate(&self, c: &mut Checker) {
        if !["error", "warn", "info", "debug", "trace"].contains(&self.log_level.as_str()) {
            c.push(
                "daemon.log_level",
                format!("{:?}", self.log_level),
                "must be one of error, warn, info, debug, trace",
            );
        }
        if self.realtime_priority > 99 {
            c.push(
                "daemon.realtime_priority",
                self.realtime_priority.to_string(),
                "must be in 0..=99 (0 = normal scheduling)",
            );
        }
    }
}
