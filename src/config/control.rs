//! `[control]`: the control period and the driving speed.
//!
//! Owns the section's keys, their defaults and their range checks.

use super::check::Checker;
use serde::{Deserialize, Serialize};

/// `[control]`: the control loop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ControlConfig {
    /// Control period, s (0.005..=0.3).
    pub dt_s: f64,
    /// Driving speed in the simulator and demo, km/h.
    pub speed_kmh: f64,
}

impl Default for ControlConfig {
    fn default() -> Self {
        ControlConfig {
            dt_s: 0.02,
            speed_kmh: 10.0,
        }
    }
}

impl ControlConfig {
    /// Range checks of `[control]`.
    pub(crate) fn validate(&self, c: &mut Checker) {
        // 0.4 s made the demo weave until tracking_unstable; 0.3 s tracked within 1.7 cm.
        c.range("control.dt_s", self.dt_s, 0.005, 0.3);
        c.range("control.speed_kmh", self.speed_kmh, 0.5, 30.0);
    }
}
