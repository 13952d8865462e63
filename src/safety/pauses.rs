//! The control loop's own pauses, so that an input is judged stale only on time the loop was
//! running to read it.
//!
//! Contract: [`LoopPauses::record`] is told each interval in which the control loop could not
//! run (a period that woke up late: `from` = when it was due, `to` = when it ran, both s on the
//! loop's clock). [`LoopPauses::age`] is then the age of an input last read at `last`, judged at
//! `now`, less the part of those intervals that falls between the two, each interval counting
//! for at most `cap` seconds.
//!
//! Why: frames are stamped when the loop reads them. On a tractor a sensor keeps sending while
//! the gateway's loop is held up (an interrupt storm, a higher-priority task): its frames wait
//! in the socket and are read, freshly stamped, on the late period, so the credit changes
//! nothing. Where the sender is held up too (every process on one frozen virtual CPU, a shared
//! processor), the late period would otherwise find the last frame older than the freeze and
//! give the steering back for a pause of the loop's, not a silent sensor. The cap (the input's
//! own timeout) keeps the meaning of the timeouts: a loop held up for longer than that gives the
//! steering back, as a sensor silent that long would. A sensor that really went quiet is
//! detected later by at most the credited pauses since its last frame (at most `cap` each).
//!
//! Only the last [`KEPT`] pauses are kept: forgetting one only makes an input look older.

/// Pauses remembered: more than fit, at one per late period, into any input timeout in use.
pub const KEPT: usize = 16;

/// A ring of the loop's recent pauses.
#[derive(Debug, Clone, Default)]
pub struct LoopPauses {
    intervals: [(f64, f64); KEPT],
    len: usize,
    head: usize,
}

impl LoopPauses {
    /// The loop could not run from `from` until `to` (s). Empty, reversed or non-finite
    /// intervals are ignored.
    pub fn record(&mut self, from: f64, to: f64) {
        if !(from.is_finite() && to.is_finite() && to > from) {
            return;
        }
        self.intervals[self.head] = (from, to);
        self.head = (self.head + 1) % KEPT;
        self.len = (self.len + 1).min(KEPT);
    }

    /// Age at `now` of an input last read at `last`, s, less the loop's pauses in between
    /// (each counted for at most `cap` s). Never negative; `now - last` if no pause overlaps.
    pub fn age(&self, last: f64, now: f64, cap: f64) -> f64 {
        let raw = now - last;
        if !raw.is_finite() || raw <= 0.0 {
            return raw;
        }
        let cap = cap.max(0.0);
        let credit: f64 = self.intervals[..self.len]
            .iter()
            .map(|&(from, to)| (to.min(now) - from.max(last)).clamp(0.0, cap))
            .sum();
        (raw - credit).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_pause_leaves_the_age_alone() {
        let p = LoopPauses::default();
        assert_eq!(p.age(1.0, 1.25, 0.1), 0.25);
    }

    #[test]
    fn a_pause_after_the_last_frame_is_discounted() {
        let mut p = LoopPauses::default();
        // Last frame at 10.000 s; the loop was due at 10.010 s and ran at 10.087 s.
        p.record(10.010, 10.087);
        let age = p.age(10.000, 10.087, 0.1);
        assert!((age - 0.010).abs() < 1e-9, "{age}");
    }

    #[test]
    fn a_pause_before_the_last_frame_does_not_count() {
        let mut p = LoopPauses::default();
        p.record(10.010, 10.087);
        // A frame read after the pause: its age is its own.
        let age = p.age(10.090, 10.200, 0.1);
        assert!((age - 0.110).abs() < 1e-9, "{age}");
    }

    #[test]
    fn only_the_overlap_counts() {
        let mut p = LoopPauses::default();
        p.record(10.000, 10.050);
        // Last frame at 10.030: 20 ms of the pause came after it.
        let age = p.age(10.030, 10.150, 1.0);
        assert!((age - 0.100).abs() < 1e-9, "{age}");
    }

    #[test]
    fn a_long_pause_counts_for_at_most_the_cap() {
        let mut p = LoopPauses::default();
        p.record(10.010, 10.510);
        let age = p.age(10.000, 10.510, 0.1);
        assert!((age - 0.410).abs() < 1e-9, "{age}");
    }

    #[test]
    fn several_pauses_add_and_old_ones_are_forgotten() {
        let mut p = LoopPauses::default();
        for k in 0..KEPT + 4 {
            let from = 1.0 + 0.1 * k as f64;
            p.record(from, from + 0.02);
        }
        // Only the last KEPT pauses remain: the first four (1.0–1.32 s) are gone.
        let age = p.age(1.0, 1.0 + 0.1 * (KEPT + 4) as f64, 1.0);
        let kept = 0.02 * KEPT as f64;
        assert!(
            (age - (0.1 * (KEPT + 4) as f64 - kept)).abs() < 1e-9,
            "{age}"
        );
    }

    #[test]
    fn bad_intervals_are_ignored() {
        let mut p = LoopPauses::default();
        p.record(2.0, 1.0);
        p.record(f64::NAN, 1.0);
        p.record(1.0, f64::INFINITY);
        assert_eq!(p.age(0.0, 3.0, 10.0), 3.0);
    }
}
