//! When the control loop runs a period: every dt on the timer, and at once when a GNSS fix
//! enters the controller (issue 16 point 7: the command that follows a fix leaves within about
//! a millisecond of its arrival).
//!
//! A fix's period restarts the timer (the next period is dt after it), so the timer locks to
//! the fixes' phase. When the fix period is a multiple of dt (10 Hz GNSS, dt 10 or 20 ms) the
//! timer's period then falls where the next fix arrives: whenever that fix is read a little
//! late, the timer's period runs first and the fix waits behind it. The schedule therefore
//! learns the fixes' period and phase (a phase-locked loop over their receive times) and
//! holds back a timer period due within a window around the next expected fix until the end
//! of that window: the fix, arriving in the window, runs the period instead. A fix that does
//! not come costs one period half a dt late at most — the window is a fraction of dt
//! ([`HOLD_EARLY`], [`HOLD_LATE`]), so command periods stay within 1.5·dt — and after it the
//! timer runs every dt as before: a missing fix never stops the loop.
//!
//! Pure: times are monotonic seconds passed in, so the schedule is tested without a clock.

/// A timer period due this fraction of dt before the expected fix is held.
pub const HOLD_EARLY: f64 = 0.125;
/// … until this fraction of dt after it (the fix is read late more often than early).
pub const HOLD_LATE: f64 = 0.375;
/// Gain of the fix phase estimate on each fix's timing error.
const PHASE_GAIN: f64 = 0.25;
/// Gain of the fix period estimate on each fix's timing error.
const PERIOD_GAIN: f64 = 1.0 / 32.0;
/// A fix this far (fraction of the period) from the expected time breaks the lock.
const LOCK_TOLERANCE: f64 = 0.25;
/// Fixes out of lock in a row after which the period is learnt again.
const RELEARN_AFTER: u32 = 3;
/// Fix periods longer than this are not learnt (s): such a source is too slow to matter.
const MAX_FIX_PERIOD_S: f64 = 2.0;

/// The control loop's schedule.
#[derive(Debug, Clone)]
pub struct TickSchedule {
    dt: f64,
    /// The timer's next period (monotonic s).
    next: f64,
    /// The last fix's receive time.
    last_fix: Option<f64>,
    /// The learnt fix period, s.
    period: Option<f64>,
    /// When the next fix is expected.
    expected: Option<f64>,
    out_of_lock: u32,
    /// Timer periods held back for an expected fix.
    pub held: u64,
}

impl TickSchedule {
    /// Periods every `dt` from `now`.
    pub fn new(dt: f64, now: f64) -> TickSchedule {
        TickSchedule {
            dt,
            next: now + dt,
            last_fix: None,
            period: None,
            expected: None,
            out_of_lock: 0,
            held: 0,
        }
    }

    /// When the timer's next period is due.
    pub fn next(&self) -> f64 {
        self.next
    }

    /// The learnt fix period, s.
    pub fn fix_period(&self) -> Option<f64> {
        self.period
    }

    /// When the next fix is expected.
    pub fn expected_fix(&self) -> Option<f64> {
        self.expected
    }

    /// The timer's period ran at `now`: the next is dt after the one due (periods missed
    /// while late are skipped, on the same grid).
    pub fn on_timer(&mut self, now: f64) {
        let mut next = self.next + self.dt;
        if next <= now {
            next += ((now - next) / self.dt).floor() * self.dt + self.dt;
        }
        self.next = self.hold(next);
    }

    /// A fix received at `t_fix` ran its period at `t`: the timer restarts from it.
    pub fn on_fix(&mut self, t_fix: f64, t: f64) {
        self.learn(t_fix);
        self.next = self.hold(t + self.dt);
    }

    /// A period due at `next` moves to the end of the window around the expected fix when it
    /// falls in it.
    fn hold(&mut self, next: f64) -> f64 {
        match self.expected {
            Some(e) if next >= e - HOLD_EARLY * self.dt && next < e + HOLD_LATE * self.dt => {
                self.held += 1;
                e + HOLD_LATE * self.dt
            }
            _ => next,
        }
    }

    /// The fixes' period and phase from their receive times: a second-order phase-locked
    /// loop, so one fix read late moves the next expectation by a quarter of its lateness.
    fn learn(&mut self, t_fix: f64) {
        let smoothed = match (self.expected, self.period) {
            (Some(e), Some(p)) => {
                // Fixes missed since the expected one keep the lock (same grid).
                let missed = ((t_fix - e) / p).round().max(0.0);
                let due = e + missed * p;
                let err = t_fix - due;
                // Fixes missing in a row (a slower receiver on the same grid) or out of
                // lock: the period is learnt again.
                let smoothed = if err.abs() <= LOCK_TOLERANCE * p {
                    self.period = Some(p + PERIOD_GAIN * err / (missed + 1.0));
                    due + PHASE_GAIN * err
                } else {
                    t_fix
                };
                if err.abs() <= LOCK_TOLERANCE * p && missed == 0.0 {
                    self.out_of_lock = 0;
                } else {
                    self.out_of_lock += 1;
                }
                if self.out_of_lock >= RELEARN_AFTER {
                    self.out_of_lock = 0;
                    self.period = None;
                }
                smoothed
            }
            _ => t_fix,
        };
        if self.period.is_none() {
            self.period = self
                .last_fix
                .map(|l| t_fix - l)
                .filter(|iv| *iv > 0.0 && *iv <= MAX_FIX_PERIOD_S);
        }
        self.last_fix = Some(t_fix);
        self.expected = self.period.map(|p| smoothed + p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs the loop from 0 to `end` s with fixes received at `fixes` (each period taking
    /// no time) and returns the periods: (time, was it a fix's).
    fn periods(dt: f64, fixes: &[f64], end: f64) -> Vec<(f64, bool)> {
        let mut s = TickSchedule::new(dt, 0.0);
        let mut out = Vec::new();
        let mut fi = 0;
        loop {
            let fix = fixes.get(fi).copied().filter(|f| *f <= s.next());
            let t = fix.unwrap_or(s.next());
            if t > end {
                return out;
            }
            match fix {
                Some(f) => {
                    s.on_fix(f, f);
                    fi += 1;
                }
                None => s.on_timer(t),
            }
            out.push((t, fix.is_some()));
        }
    }

    fn max_gap(p: &[(f64, bool)]) -> f64 {
        p.windows(2).map(|w| w[1].0 - w[0].0).fold(0.0, f64::max)
    }

    /// No timer period within `before`..`after` s of a fix (the fix would wait behind it or
    /// it would be a wasted period right after it).
    fn timer_periods_near_fixes(p: &[(f64, bool)], fixes: &[f64], before: f64) -> usize {
        p.iter()
            .filter(|(t, fix)| !fix && fixes.iter().any(|f| *t <= *f && *t > f - before))
            .count()
    }

    #[test]
    fn the_timer_keeps_out_of_the_way_of_10_hz_fixes_read_late() {
        let dt = 0.01;
        // 10 Hz fixes read up to 2 ms late (a pseudo-random lateness, fixed seed).
        let mut x: u32 = 12345;
        let fixes: Vec<f64> = (1..100)
            .map(|k| {
                x = x.wrapping_mul(1_103_515_245).wrapping_add(12345);
                0.1 * k as f64 + 0.002 * ((x >> 16) as f64 / 65536.0)
            })
            .collect();
        let p = periods(dt, &fixes, 10.0);
        // Without the hold the timer, restarted by each fix, is due as the next one arrives.
        let learnt: Vec<f64> = fixes.iter().copied().filter(|f| *f > 0.35).collect();
        let near = timer_periods_near_fixes(&p, &learnt, 0.002);
        assert_eq!(near, 0, "timer periods just before a fix: {near}");
        // One period per dt on average, none longer than 1.5·dt.
        let n = p.iter().filter(|(t, _)| *t > 1.0).count() as f64;
        assert!((n - 900.0).abs() < 15.0, "{n} periods in 9 s");
        assert!(max_gap(&p) <= 1.5 * dt + 1e-9, "gap {}", max_gap(&p));
        assert!(p.iter().filter(|(_, f)| *f).count() == fixes.len());
    }

    #[test]
    fn missing_fixes_cost_half_a_period_at_most_and_never_stop_the_loop() {
        let dt = 0.01;
        // 10 Hz, then nothing from 3 s to 6 s, then 10 Hz again; one fix missing at 7 s.
        let fixes: Vec<f64> = (1..100)
            .map(|k| 0.1 * k as f64 + 0.0005)
            .filter(|f| !(3.0..6.0).contains(f) && (f - 7.0005).abs() > 1e-6)
            .collect();
        let p = periods(dt, &fixes, 10.0);
        assert!(max_gap(&p) <= 1.5 * dt + 1e-9, "gap {}", max_gap(&p));
        let quiet = p.iter().filter(|(t, _)| (3.5..5.5).contains(t)).count();
        assert!((199..=201).contains(&quiet), "{quiet} timer periods in 2 s");
    }

    #[test]
    fn the_period_and_phase_are_learnt_and_relearnt() {
        let mut s = TickSchedule::new(0.01, 0.0);
        for k in 1..20 {
            let t = 0.1 * k as f64 + if k % 2 == 0 { 0.001 } else { 0.0 };
            s.on_fix(t, t);
        }
        let p = s.fix_period().unwrap();
        assert!((p - 0.1).abs() < 0.002, "period {p}");
        // The receiver changes to 5 Hz: learnt again after a few fixes.
        for k in 0..8 {
            let t = 2.0 + 0.2 * k as f64;
            s.on_fix(t, t);
        }
        let p = s.fix_period().unwrap();
        assert!((p - 0.2).abs() < 0.005, "period {p}");
        let e = s.expected_fix().unwrap();
        assert!((e - 3.6).abs() < 0.005, "expected {e}");
    }

    #[test]
    fn a_fix_period_not_a_multiple_of_dt_is_left_alone() {
        // dt 30 ms, 10 Hz: the timer period before each fix is 10 ms ahead of it.
        let fixes: Vec<f64> = (1..50).map(|k| 0.1 * k as f64).collect();
        let p = periods(0.03, &fixes, 5.0);
        let s = {
            let mut s = TickSchedule::new(0.03, 0.0);
            for f in &fixes {
                s.on_fix(*f, *f);
            }
            s
        };
        assert_eq!(s.held, 0);
        assert!(max_gap(&p) <= 0.03 + 1e-9);
    }
}
