//! Telling a loaded host's stalls from the controller's own faults in the real-time GNSS tests
//! (`tests/io/gnss_closed_loop.rs`).
//!
//! A serial receiver's bytes reach their reader through the kernel: a write to a tty (a pty's
//! master here, a USB CDC-ACM or UART driver on a tractor) only queues them in the tty's flip
//! buffer, and a kernel worker thread at normal priority (the flip buffer's work item on the
//! unbound workqueue, `flush_to_ldisc`) moves them into the line discipline, where read(2)
//! and poll(2) see them. On a saturated 2-core host that worker waits for a CPU like any
//! other thread: traced with `perf record -e workqueue:workqueue_queue_work,
//! workqueue:workqueue_execute_start` beside `stress-ng --cpu 2` and three of these tests,
//! `flush_to_ldisc` ran a median 0.08 ms after it was queued but 192 ms at the p99 and
//! 571 ms at worst, while the control loops kept running their periods (every test process
//! saw the same gap at the same instant). A gap longer than `safety.gnss_timeout_s` then
//! trips the GNSS timeout, rightly: the controller's newest fix is too old.
//!
//! So the simulator watches the tty from the reader's side: `TIOCINQ` on a second,
//! never-read descriptor of the slave counts the bytes the kernel has delivered and the
//! reader has not read yet. A GNSS timeout is the controller's doing when, in the gap before
//! it, delivered bytes waited unread for longer than [`READER_SLACK_S`] while its loop ran
//! (a lost wake-up, a reader not polled): never excused. Otherwise it is the host's when the
//! control loop missed its periods for longer than [`THREAD_STALL_S`] (its thread was
//! descheduled), or the simulator wrote no epoch for that long beyond its period (its thread
//! was), or epochs were written and the kernel held them (a tty).

use std::fs::File;
use std::os::fd::AsRawFd;
use std::path::Path;

/// Delivered bytes left unread this long count against the reader, s.
pub const READER_SLACK_S: f64 = 0.05;
/// A thread that missed its work this long was descheduled, s.
pub const THREAD_STALL_S: f64 = 0.1;

/// A descriptor of a tty's slave that is never read: its input queue, as the reader sees it.
pub struct TtyWatch(File);

impl TtyWatch {
    pub fn open(slave: &Path) -> std::io::Result<TtyWatch> {
        use std::os::unix::fs::OpenOptionsExt;
        std::fs::OpenOptions::new()
            .read(true)
            .custom_flags(libc::O_NOCTTY | libc::O_NONBLOCK)
            .open(slave)
            .map(TtyWatch)
    }

    /// Bytes delivered to the line discipline and not yet read.
    pub fn unread(&self) -> usize {
        let mut n: libc::c_int = 0;
        // SAFETY: TIOCINQ writes one int to the pointer given; the descriptor is ours.
        let r = unsafe { libc::ioctl(self.0.as_raw_fd(), libc::TIOCINQ, &mut n) };
        if r == 0 {
            n.max(0) as usize
        } else {
            0
        }
    }
}

/// Stretches of time (monotonic s) during which delivered bytes waited unread.
#[derive(Debug, Default, Clone)]
pub struct Backlog {
    pub stretches: Vec<(f64, f64)>,
    open: Option<f64>,
}

impl Backlog {
    /// One sample at `t`: `unread` bytes waiting.
    pub fn sample(&mut self, t: f64, unread: usize) {
        match (self.open, unread > 0) {
            (None, true) => self.open = Some(t),
            (Some(from), false) => {
                self.stretches.push((from, t));
                self.open = None;
            }
            _ => {}
        }
    }

    /// The parts of the waits within `[from, to]`.
    fn within(&self, from: f64, to: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        let open = self.open.map(|o| (o, f64::MAX));
        self.stretches
            .iter()
            .copied()
            .chain(open)
            .map(move |(a, b)| (a.max(from), b.min(to)))
            .filter(|(a, b)| b > a)
    }

    /// The longest wait within `[from, to]`, s.
    pub fn longest_within(&self, from: f64, to: f64) -> f64 {
        self.within(from, to)
            .map(|(a, b)| b - a)
            .fold(0.0, f64::max)
    }

    /// The longest wait within `[from, to]` during which the control loop ran (its periods,
    /// `periods`, came; a gap between them beyond `2·dt` is time the thread did not run), s.
    pub fn longest_while_running(&self, from: f64, to: f64, periods: &[f64], dt: f64) -> f64 {
        self.within(from, to)
            .map(|(a, b)| {
                let off: f64 = periods
                    .windows(2)
                    .map(|w| (w[0].max(a), w[1].min(b), w[1] - w[0]))
                    .filter(|(x, y, g)| y > x && *g > 2.0 * dt)
                    .map(|(x, y, g)| (y - x) * (g - 2.0 * dt) / g)
                    .sum();
                b - a - off
            })
            .fold(0.0, f64::max)
    }
}

/// Why the host explains a GNSS timeout, if it does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HostStall {
    /// The epochs were written but held in the kernel: never left unread by the reader.
    KernelHeld,
    /// The control loop's thread missed its periods.
    LoopDescheduled,
    /// The simulator's thread wrote no epoch for a period and more.
    SimDescheduled,
}

/// Why a GNSS timeout tripped at `t` with the last position input at `last_input`: `periods`
/// are the control loop's period times (every `dt`), `sends` the simulator's epoch writes,
/// `backlog` the tty's unread stretches (`None` off a tty), `gnss_period_s` the receiver's
/// period. `None`: the controller's doing (delivered bytes left unread while its loop ran, or
/// epochs written and not taken off a socket that delivers at once).
pub fn explain(
    t: f64,
    last_input: f64,
    (periods, dt): (&[f64], f64),
    sends: &[f64],
    backlog: Option<&Backlog>,
    gnss_period_s: f64,
) -> Option<HostStall> {
    if backlog.is_some_and(|b| b.longest_while_running(last_input, t, periods, dt) > READER_SLACK_S)
    {
        return None;
    }
    let gaps = |times: &[f64], from: f64, to: f64| -> f64 {
        let inside: Vec<f64> = std::iter::once(from)
            .chain(times.iter().copied().filter(|x| *x > from && *x < to))
            .chain(std::iter::once(to))
            .collect();
        inside.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max)
    };
    if gaps(periods, last_input, t) > THREAD_STALL_S {
        return Some(HostStall::LoopDescheduled);
    }
    // Epochs are written every period; one missing beyond it is the simulator's stall.
    if gaps(sends, last_input, t) > gnss_period_s + THREAD_STALL_S {
        return Some(HostStall::SimDescheduled);
    }
    let written = sends.iter().any(|s| *s > last_input && *s < t);
    (backlog.is_some() && written).then_some(HostStall::KernelHeld)
}

/// A run's GNSS as the controller saw it: position inputs' arrivals (monotonic s, RTK fixed),
/// the simulator's epoch writes, the tty's unread stretches (`None` off a tty), the receiver's
/// period (s).
pub struct GnssRun<'a> {
    pub arrivals: &'a [(f64, bool)],
    pub sends: &'a [f64],
    pub backlog: Option<&'a Backlog>,
    pub period_s: f64,
}

/// The disengagements of a run (`ticks`: each control period's time, engaged, fault; every
/// `dt`) that a host stall explains, as (trip, re-engage) spans with their causes:
/// - a GNSS timeout judged unexpected by `gnss_timeout_counts`, by [`explain`];
/// - a wheel-angle timeout when the simulator's thread sent no wheel angle (`wheel`: its sends,
///   and the timeout, s) for longer than the timeout before it (descheduled: nothing in these
///   tests silences that sensor); one sent in time and not taken is the controller's doing.
pub fn excused_trips(
    ticks: &[(f64, bool, agsteer::safety::FaultCode)],
    dt: f64,
    gnss: &GnssRun,
    (wheel_sends, wheel_timeout_s): (&[f64], f64),
    gnss_timeout_counts: impl Fn(f64) -> bool,
) -> (Vec<(f64, f64)>, Vec<HostStall>) {
    use agsteer::safety::FaultCode;
    let periods: Vec<f64> = ticks.iter().map(|k| k.0).collect();
    let last_before = |times: &mut dyn Iterator<Item = f64>, t: f64| {
        times.filter(|x| *x <= t).fold(f64::MIN, f64::max)
    };
    let (mut spans, mut causes) = (Vec::new(), Vec::new());
    for (k, w) in ticks.windows(2).enumerate() {
        let (t, engaged, fault) = w[1];
        if !w[0].1 || engaged {
            continue;
        }
        let cause = match fault {
            FaultCode::GnssTimeout if gnss_timeout_counts(t) => {
                let last_input = last_before(&mut gnss.arrivals.iter().map(|a| a.0), t);
                let run = (periods.as_slice(), dt);
                explain(t, last_input, run, gnss.sends, gnss.backlog, gnss.period_s)
            }
            FaultCode::WheelAngleTimeout => {
                let last_sent = last_before(&mut wheel_sends.iter().copied(), t);
                (t - last_sent > wheel_timeout_s).then_some(HostStall::SimDescheduled)
            }
            _ => None,
        };
        if let Some(c) = cause {
            let back = ticks[k + 1..]
                .iter()
                .find(|k| k.1)
                .map_or(f64::MAX, |k| k.0);
            spans.push((t, back));
            causes.push(c);
        }
    }
    (spans, causes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reader_that_leaves_bytes_unread_is_never_excused() {
        let periods: Vec<f64> = (0..100).map(|k| k as f64 * 0.01).collect();
        let sends = [0.1, 0.2, 0.3, 0.4, 0.5];
        let mut held = Backlog::default();
        held.sample(0.0, 0);
        assert_eq!(
            explain(0.45, 0.1, (&periods, 0.01), &sends, Some(&held), 0.1),
            Some(HostStall::KernelHeld)
        );
        let mut unread = Backlog::default();
        unread.sample(0.2, 300);
        unread.sample(0.4, 0);
        assert_eq!(
            explain(0.45, 0.1, (&periods, 0.01), &sends, Some(&unread), 0.1),
            None
        );
        // … unless its thread did not run meanwhile.
        let without = |from: f64, to: f64| -> Vec<f64> {
            let kept = periods.iter().copied();
            kept.filter(|p| *p < from || *p > to).collect()
        };
        assert_eq!(
            explain(
                0.45,
                0.1,
                (&without(0.2, 0.38), 0.01),
                &sends,
                Some(&unread),
                0.1
            ),
            Some(HostStall::LoopDescheduled)
        );
        // Off a tty only the threads' stalls explain a timeout.
        assert_eq!(
            explain(0.45, 0.1, (&periods, 0.01), &sends, None, 0.1),
            None
        );
        assert_eq!(
            explain(0.45, 0.1, (&without(0.2, 0.35), 0.01), &sends, None, 0.1),
            Some(HostStall::LoopDescheduled)
        );
        assert_eq!(
            explain(0.45, 0.1, (&periods, 0.01), &[0.1], None, 0.1),
            Some(HostStall::SimDescheduled)
        );
    }

    #[test]
    fn a_wheel_angle_timeout_is_excused_only_when_the_sender_was_silent() {
        use agsteer::safety::FaultCode;
        // Engaged every 10 ms until 1.0 s, then a wheel-angle timeout, engaged again at 1.5 s.
        let ticks: Vec<(f64, bool, FaultCode)> = (0..200)
            .map(|k| {
                let t = k as f64 * 0.01;
                let off = (1.0..1.5).contains(&t);
                let fault = if off {
                    FaultCode::WheelAngleTimeout
                } else {
                    FaultCode::None
                };
                (t, !off, fault)
            })
            .collect();
        let gnss = GnssRun {
            arrivals: &[],
            sends: &[],
            backlog: None,
            period_s: 0.1,
        };
        // The simulator sent nothing from 0.85 s: silent 150 ms at the trip, excused.
        let silent: Vec<f64> = (0..85).map(|k| k as f64 * 0.01).collect();
        let (spans, causes) = excused_trips(&ticks, 0.01, &gnss, (&silent, 0.1), |_| true);
        assert_eq!(causes, vec![HostStall::SimDescheduled]);
        assert!((spans[0].0 - 1.0).abs() < 1e-9 && (spans[0].1 - 1.5).abs() < 1e-9);
        // It sent every 10 ms: the frames were there, the controller's doing.
        let sent: Vec<f64> = (0..200).map(|k| k as f64 * 0.01).collect();
        let (spans, causes) = excused_trips(&ticks, 0.01, &gnss, (&sent, 0.1), |_| true);
        assert!(spans.is_empty() && causes.is_empty());
    }
}
