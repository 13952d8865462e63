//! systemd notifications (Type=notify): READY once the bus is open, WATCHDOG pings only while
//! the control loop meets its deadlines. No-ops outside systemd.

use std::time::{Duration, Instant};

/// Tell systemd the daemon is ready.
pub fn ready() {
    let _ = sd_notify::notify(false, &[sd_notify::NotifyState::Ready]);
}

/// Pings the systemd watchdog at a quarter of `WatchdogSec`, and only when every control
/// period since the last ping met its deadline. Between pings it does nothing (no allocation,
/// no system call).
pub struct Watchdog {
    every: Option<Duration>,
    last: Instant,
    all_met: bool,
}

impl Watchdog {
    /// From systemd's `WATCHDOG_USEC` (none: disabled).
    pub fn from_env() -> Watchdog {
        let mut usec = 0u64;
        let every = if sd_notify::watchdog_enabled(false, &mut usec) && usec > 0 {
            Some(Duration::from_micros(usec / 4))
        } else {
            None
        };
        Watchdog {
            every,
            last: Instant::now(),
            all_met: true,
        }
    }

    /// Call once per control period.
    pub fn period(&mut self, deadline_met: bool) {
        let Some(every) = self.every else {
            return;
        };
        self.all_met &= deadline_met;
        if self.last.elapsed() >= every {
            if self.all_met {
                let _ = sd_notify::notify(false, &[sd_notify::NotifyState::Watchdog]);
            }
            self.last = Instant::now();
            self.all_met = true;
        }
    }
}
