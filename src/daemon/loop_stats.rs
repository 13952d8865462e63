//! The control loop's timing for the status socket (`loop` in `agsteer status`): periods,
//! lateness, step times, and where each GNSS fix's receive → command time went.

use serde::Serialize;

/// Upper edges of [`LoopStats::fix_to_command_counts`], µs.
pub const FIX_TO_COMMAND_EDGES_US: [f64; 7] =
    [100.0, 200.0, 500.0, 1000.0, 2000.0, 5000.0, 10000.0];

/// Upper edges of [`FixPhases`]' counts, µs.
pub const FIX_PHASE_EDGES_US: [f64; 7] = [20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0];

/// A fix's receive → command time in its parts, each counted by [`FIX_PHASE_EDGES_US`] (and
/// beyond the last): which part a slow fix spent its time in.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct FixPhases {
    /// Read → the loop takes it: the reader's queue (inputs read with it, taken first).
    pub queue: [u64; FIX_PHASE_EDGES_US.len() + 1],
    /// The fix into the node and the control period computed (its frames ready).
    pub compute: [u64; FIX_PHASE_EDGES_US.len() + 1],
    /// The period's frames handed to the socket.
    pub send: [u64; FIX_PHASE_EDGES_US.len() + 1],
}

/// Count `us` into `counts` by `edges` (the last count: beyond the last edge).
pub fn count_by(counts: &mut [u64], edges: &[f64], us: f64) {
    let i = edges.iter().position(|e| us <= *e).unwrap_or(edges.len());
    if let Some(c) = counts.get_mut(i) {
        *c += 1;
    }
}

/// Control-loop timing, for the status socket.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct LoopStats {
    pub ticks: u64,
    /// Ticks that started more than one period late.
    pub deadline_misses: u64,
    pub max_late_ms: f64,
    pub mean_late_ms: f64,
    /// Duration of the last control step, µs.
    pub last_step_us: f64,
    pub max_step_us: f64,
    pub frames_in: u64,
    pub send_errors: u64,
    pub bus_up: bool,
    /// Control periods run at once on a GNSS fix (the rest ran on the timer).
    pub fix_ticks: u64,
    /// A fix's receive time to its command handed to the socket: last and largest, µs.
    pub fix_to_command_us: f64,
    pub max_fix_to_command_us: f64,
    /// Fixes by receive-to-command time, µs: counts up to each of
    /// [`FIX_TO_COMMAND_EDGES_US`] and beyond the last (the daemon's own share of the
    /// latency, without the wait before the frame is read).
    pub fix_to_command_counts: [u64; FIX_TO_COMMAND_EDGES_US.len() + 1],
    /// Where the fixes' receive → command time went: counts by [`FIX_PHASE_EDGES_US`].
    pub fix_phases: FixPhases,
    /// Timer periods held back for an expected fix ([`super::tick`]).
    pub held_ticks: u64,
    /// The fixes' period as learnt, ms (0: not learnt).
    pub fix_period_ms: f64,
}
