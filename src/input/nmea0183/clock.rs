//! Time of a byte stream's fixes: receipt time stamps, the latency rule, and the freshness of
//! each epoch. Shared by the NMEA 0183 and UBX converters.
//!
//! **Latency rule.** A fix's latency is the host's UTC at receipt minus the fix's time of
//! validity as the receiver stamped it. NMEA sentences mostly carry the UTC time of day only:
//! the day is taken as the one that puts the fix nearest the receipt time (so a fix stamped
//! 23:59:59.9 received at 00:00:00.05 is 0.15 s old). Sentences with a full date (`$KSXT`,
//! UBX NAV-PVT with valid date and time) use it. The result is trusted only in
//! [`LATENCY_MIN_S`, `LATENCY_MAX_S`]: outside it the host clock and GNSS time disagree (no
//! NTP, or an undisciplined clock), the latency is reported as unknown (`None`, the consumer
//! falls back to its configured latency) and counted; small negative values (host clock
//! slightly behind) read as 0. The host clock is only meaningful when it is disciplined
//! (chrony or NTP, ideally from the receiver's PPS).
//!
//! **Freshness.** Independently of the host's UTC, each stream's fixes are checked against
//! the receiver's own clock: for each new epoch (a newer time of validity) the offset
//! `receipt time − time of validity` is compared with the smallest offset seen (which is
//! allowed to creep up by [`CLOCK_DRIFT`] per second, for the two clocks' rate difference).
//! An epoch arriving more than `max_delay_s` later than the best the link has shown was held
//! up somewhere (a buffer flushed after a stall, a replay) and is stale: its inputs are
//! dropped, never passed on as fresh. So is a sentence of the current epoch arriving that late (a
//! replay of the last epoch), with the epoch's sentences without a time after it. A time of
//! validity older than the current epoch is a replay or out of order, also dropped. A jump of more
//! than [`CLOCK_JUMP_S`] either way is a receiver clock reset: the reference starts again from it.

/// When bytes arrived.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Receipt {
    /// Controller monotonic clock, s.
    pub t: f64,
    /// Host UTC at the same instant, s since 1970-01-01, when the daemon uses its clock.
    pub utc_s: Option<f64>,
}

impl Receipt {
    /// A receipt on the monotonic clock only (no host UTC: latency unknown).
    pub fn at(t: f64) -> Self {
        Receipt { t, utc_s: None }
    }
}

/// Latencies below this disagree with the host clock (negative: a fix from the future).
pub const LATENCY_MIN_S: f64 = -0.25;
/// Latencies above this are taken as a host clock that disagrees with GNSS time.
pub const LATENCY_MAX_S: f64 = 2.0;
/// Rate at which the freshness reference may creep up (the two clocks' rate difference), s/s.
pub const CLOCK_DRIFT: f64 = 2e-4;
/// A change of the sender's clock beyond this, s, is a clock reset, not a delay.
pub const CLOCK_JUMP_S: f64 = 10.0;
/// Seconds in a day.
pub const DAY_S: f64 = 86_400.0;

/// Outcome of the latency rule.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Latency {
    /// No host UTC or no time in the sentence.
    Unknown,
    /// Within the trusted window, s.
    Known(f64),
    /// Outside the window: host clock and GNSS time disagree.
    ClockMismatch,
}

impl Latency {
    pub fn seconds(self) -> Option<f64> {
        match self {
            Latency::Known(s) => Some(s),
            _ => None,
        }
    }
}

fn window(d: f64) -> Latency {
    if (LATENCY_MIN_S..=LATENCY_MAX_S).contains(&d) {
        Latency::Known(d.max(0.0))
    } else {
        Latency::ClockMismatch
    }
}

/// Wrap `x` into [-period/2, period/2).
pub fn wrap_half(x: f64, period: f64) -> f64 {
    (x + period / 2.0).rem_euclid(period) - period / 2.0
}

/// Latency of a fix stamped with a UTC time of day (s since midnight).
pub fn latency_from_time_of_day(receipt: &Receipt, tod_s: f64) -> Latency {
    match receipt.utc_s {
        Some(utc) => window(wrap_half(utc - tod_s, DAY_S)),
        None => Latency::Unknown,
    }
}

/// Latency of a fix stamped with a full UTC time (s since 1970-01-01).
pub fn latency_from_utc(receipt: &Receipt, fix_utc_s: f64) -> Latency {
    match receipt.utc_s {
        Some(utc) => window(utc - fix_utc_s),
        None => Latency::Unknown,
    }
}

/// What the freshness check made of a time of validity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Epoch {
    /// A new epoch, on time.
    New,
    /// Another sentence of the current epoch (`fresh` as the epoch was judged).
    Same { fresh: bool },
    /// A new epoch that arrived late: stale.
    Late,
    /// Older than the current epoch: a replay or out of order.
    Old,
    /// The sender's clock jumped: a new epoch, the reference restarted.
    ClockJump,
}

impl Epoch {
    /// Whether inputs of this epoch may be passed on.
    pub fn fresh(self) -> bool {
        match self {
            Epoch::New | Epoch::ClockJump => true,
            Epoch::Same { fresh } => fresh,
            Epoch::Late | Epoch::Old => false,
        }
    }
}

/// The freshness check of one stream's epochs (see the module doc).
#[derive(Debug, Clone)]
pub struct EpochClock {
    /// The sender's clock wraps at this (a day for NMEA times of day, a week for GPS iTOW), s.
    period: f64,
    /// Delay beyond the link's best at which an epoch is stale, s.
    max_delay_s: f64,
    current: Option<f64>,
    current_fresh: bool,
    /// Smallest `t − time of validity` seen (continuous across the sender's wrap).
    best_offset: Option<f64>,
    last_t: f64,
}

/// Two times of validity closer than this are the same epoch, s.
const SAME_EPOCH_S: f64 = 5e-4;

impl EpochClock {
    pub fn new(period: f64, max_delay_s: f64) -> Self {
        EpochClock {
            period,
            max_delay_s,
            current: None,
            current_fresh: true,
            best_offset: None,
            last_t: 0.0,
        }
    }

    /// Whether the current epoch (inputs without a time of their own belong to it) is fresh.
    pub fn current_fresh(&self) -> bool {
        self.current_fresh
    }

    /// The current epoch's time of validity.
    pub fn current(&self) -> Option<f64> {
        self.current
    }

    /// Judge a sentence with time of validity `fix_time` received at `t`.
    pub fn observe(&mut self, t: f64, fix_time: f64) -> Epoch {
        if let Some(c) = self.current {
            let d = wrap_half(fix_time - c, self.period);
            if d.abs() < SAME_EPOCH_S {
                // A sentence of the current epoch held up beyond `max_delay_s` (a replay of the
                // last epoch): stale, and so is the rest of the epoch (its sentences without a
                // time of their own).
                let late = self.best_offset.is_some_and(|best| {
                    let best = best + CLOCK_DRIFT * (t - self.last_t).max(0.0);
                    wrap_half(t - fix_time - best, self.period) > self.max_delay_s
                });
                if late {
                    self.current_fresh = false;
                }
                return Epoch::Same {
                    fresh: self.current_fresh,
                };
            }
            if d < 0.0 && d > -CLOCK_JUMP_S {
                return Epoch::Old;
            }
        }
        let offset = t - fix_time;
        let verdict = match self.best_offset {
            None => {
                self.best_offset = Some(offset);
                Epoch::New
            }
            Some(best) => {
                let best = best + CLOCK_DRIFT * (t - self.last_t).max(0.0);
                let excess = wrap_half(offset - best, self.period);
                if excess.abs() > CLOCK_JUMP_S {
                    self.best_offset = Some(offset);
                    Epoch::ClockJump
                } else if excess < 0.0 {
                    self.best_offset = Some(best + excess);
                    Epoch::New
                } else {
                    self.best_offset = Some(best);
                    if excess > self.max_delay_s {
                        Epoch::Late
                    } else {
                        Epoch::New
                    }
                }
            }
        };
        self.current = Some(fix_time);
        self.current_fresh = verdict.fresh();
        self.last_t = t;
        verdict
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn latency_rule() {
        let r = Receipt {
            t: 5.0,
            utc_s: Some(1_600_000_000.0 + 0.08),
        };
        let tod = 1_600_000_000.0_f64.rem_euclid(DAY_S);
        assert!(
            matches!(latency_from_time_of_day(&r, tod), Latency::Known(l) if (l - 0.08).abs() < 1e-6)
        );
        // Across midnight: fix 23:59:59.9, receipt 00:00:00.05.
        let r = Receipt {
            t: 0.0,
            utc_s: Some(19_000.0 * DAY_S + 0.05),
        };
        assert!(
            matches!(latency_from_time_of_day(&r, DAY_S - 0.1), Latency::Known(l) if (l - 0.15).abs() < 1e-6)
        );
        // Host clock 37 s off (no NTP): unknown, flagged.
        let r = Receipt {
            t: 0.0,
            utc_s: Some(19_000.0 * DAY_S + 100.0),
        };
        assert_eq!(latency_from_time_of_day(&r, 63.0), Latency::ClockMismatch);
        assert_eq!(
            latency_from_time_of_day(&r, 100.1),
            Latency::Known(0.0),
            "slightly ahead reads 0"
        );
        assert_eq!(latency_from_utc(&Receipt::at(1.0), 5.0), Latency::Unknown);
    }

    #[test]
    fn late_epochs_are_stale_and_replays_old() {
        let mut c = EpochClock::new(DAY_S, 0.3);
        // 10 Hz, 50 ms link latency with jitter.
        for k in 0..50 {
            let fix = 1000.0 + k as f64 * 0.1;
            let jitter = if k % 3 == 0 { 0.02 } else { 0.0 };
            assert_eq!(
                c.observe(fix - 1000.0 + 0.05 + jitter, fix),
                Epoch::New,
                "{k}"
            );
            assert_eq!(
                c.observe(fix - 1000.0 + 0.06, fix),
                Epoch::Same { fresh: true }
            );
        }
        // A stall: the next three epochs arrive together 0.8 s late.
        let t = 5.0 + 0.8;
        assert_eq!(c.observe(t, 1005.0), Epoch::Late);
        assert_eq!(c.observe(t, 1005.0), Epoch::Same { fresh: false });
        assert_eq!(c.observe(t, 1005.1), Epoch::Late);
        assert!(!c.current_fresh());
        // Then on time again.
        assert_eq!(c.observe(5.25, 1005.2), Epoch::New);
        // The same epoch's sentence again, held up 0.4 s beyond the best: a replay, stale, and
        // the epoch's sentences without a time after it too.
        assert_eq!(c.observe(5.28, 1005.2), Epoch::Same { fresh: true });
        assert_eq!(c.observe(5.25 + 0.41, 1005.2), Epoch::Same { fresh: false });
        assert!(!c.current_fresh());
        assert_eq!(c.observe(5.35, 1005.3), Epoch::New);
        // A replayed older epoch.
        assert_eq!(c.observe(5.3, 1004.0), Epoch::Old);
        // The receiver's clock resets.
        assert_eq!(c.observe(5.4, 20.0), Epoch::ClockJump);
        assert_eq!(c.observe(5.5, 20.1), Epoch::New);
    }

    #[test]
    fn midnight_and_slow_drift_are_not_stale() {
        let mut c = EpochClock::new(DAY_S, 0.3);
        let mut t = 0.0;
        let mut fix = DAY_S - 50.0;
        // One hour at 1 Hz with the host clock 100 ppm fast, across midnight.
        for _ in 0..3600 {
            assert!(c.observe(t + 0.05, fix).fresh(), "t {t} fix {fix}");
            t += 1.0001;
            fix = (fix + 1.0).rem_euclid(DAY_S);
        }
    }
}
