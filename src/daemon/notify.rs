//! systemd notifications (Type=notify): READY once the bus is open, WATCHDOG pings only while
//! the control loop meets its deadlines. No-ops outside systemd.

/// Tell systemd the daemon is ready.
pub fn ready() {
    let _ = sd_notify::notify(false, &[sd_notify::NotifyState::Ready]);
}

/// Ping the systemd watchdog.
pub fn watchdog() {
    if std::env::var_os("NOTIFY_SOCKET").is_some() {
        let _ = sd_notify::notify(false, &[sd_notify::NotifyState::Watchdog]);
    }
}
