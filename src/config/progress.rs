//! `[progress]`: where job progress is kept across power loss.
//!
//! Owns the section's keys, their defaults and their range checks.

use super::check::Checker;
use serde::{Deserialize, Serialize};

/// `[progress]`: where job progress is kept across power loss.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ProgressConfig {
    /// Directory of the progress file (the daemon's state directory).
    pub state_dir: String,
}

impl Default for ProgressConfig {
    fn default() -> Self {
        ProgressConfig {
            state_dir: "/var/lib/agsteer".to_string(),
        }
    }
}

impl ProgressConfig {
    /// Checks of `[progress]`.
    pub(crate) fn validate(&self, c: &mut Checker) {
        if self.state_dir.trim().is_empty() {
            c.push("progress.state_dir", "\"\"".into(), "must not be empty");
        }
    }
}
