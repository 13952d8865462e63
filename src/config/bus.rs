//! `[bus]`: the CAN side (interface, source address, steering output, status).
//!
//! Owns the section's keys, their defaults and their range checks.

use super::check::Checker;
use serde::{Deserialize, Serialize};

/// What the steering output is (the node's type).
pub use crate::control::params::OutputKind;

/// `[bus]`: the CAN side.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BusConfig {
    /// SocketCAN interface, e.g. "can0" or "vcan0".
    pub interface: String,
    /// agsteer's J1939 source address (0..=253).
    pub source_address: u8,
    /// Steering output: "angle", "curvature" (ISOBUS) or "both".
    pub output: OutputKind,
    /// Guidance status frame period, s.
    pub status_period_s: f64,
    /// Unix socket answering status JSON ("" = none).
    pub status_socket: String,
}

impl Default for BusConfig {
    fn default() -> Self {
        BusConfig {
            interface: "can0".to_string(),
            source_address: 0x2A,
            output: OutputKind::Angle,
            status_period_s: 0.1,
            status_socket: "/run/agsteer/status.sock".to_string(),
        }
    }
}

impl BusConfig {
    /// Range checks of `[bus]`.
    pub(crate) fn validate(&self, c: &mut Checker) {
        let b = self;
        if b.interface.trim().is_empty() || b.interface.len() > 15 {
            c.push(
                "bus.interface",
                format!("{:?}", b.interface),
                "must be an interface name of 1 to 15 characters",
            );
        }
        if b.source_address > 253 {
            c.push(
                "bus.source_address",
                b.source_address.to_string(),
                "must be a J1939 address in 0..=253",
            );
        }
        c.range("bus.status_period_s", b.status_period_s, 0.01, 10.0);
    }
}
