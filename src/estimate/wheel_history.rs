//! The wheel-angle history: the measured front-wheel angles of the last 2.56 s ([`super::RING`]
//! samples), in time order, which the prediction integrates.

use super::{Estimator, RING};

impl Estimator {
    /// A measured front-wheel angle (rad) at `t` (s).
    pub fn on_wheel_angle(&mut self, t: f64, angle: f64) {
        if !t.is_finite() || !angle.is_finite() {
            return;
        }
        // The ring stays in time order (the prediction bisects it): a sample older than the
        // newest is dropped.
        if self.wheel_len > 0 && t < self.wheel_sample(self.wheel_len - 1).0 {
            return;
        }
        self.wheel[self.wheel_head] = (t, angle);
        self.wheel_head = (self.wheel_head + 1) % RING;
        self.wheel_len = (self.wheel_len + 1).min(RING);
    }

    /// The i-th oldest wheel sample.
    pub(super) fn wheel_sample(&self, i: usize) -> (f64, f64) {
        let start = (self.wheel_head + RING - self.wheel_len) % RING;
        self.wheel[(start + i) % RING]
    }

    /// The newest measured wheel angle, rad (`None` before the first).
    pub fn latest_wheel_angle(&self) -> Option<f64> {
        (self.wheel_len > 0).then(|| self.wheel_sample(self.wheel_len - 1).1)
    }

    /// The measured wheel angle at `t`, interpolated (held before the first and after the
    /// last sample).
    pub fn wheel_angle_at(&self, t: f64) -> f64 {
        self.wheel_angle_from(t, &mut 1)
    }

    /// The index of the first wheel sample at or after `t` (at least 1: a start for
    /// [`Estimator::wheel_angle_from`], every sample before it is older than `t`).
    pub(super) fn first_wheel_sample_at(&self, t: f64) -> usize {
        let (mut lo, mut hi) = (0, self.wheel_len);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if self.wheel_sample(mid).0 < t {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        lo.max(1)
    }

    /// [`Estimator::wheel_angle_at`] for times that do not decrease from call to call (the
    /// prediction's steps): the search starts at sample `*cursor` (start with 1) and leaves it
    /// at the sample found, so the steps of one prediction scan the ring once between them
    /// instead of once each. Every sample before the cursor is older than the previous time,
    /// hence than `t`: the result is the same as a search from the start.
    pub(super) fn wheel_angle_from(&self, t: f64, cursor: &mut usize) -> f64 {
        if self.wheel_len == 0 {
            return 0.0;
        }
        let first = self.wheel_sample(0);
        if t <= first.0 {
            return first.1;
        }
        for i in (*cursor).max(1)..self.wheel_len {
            let (t1, a1) = self.wheel_sample(i);
            if t <= t1 {
                *cursor = i;
                let (t0, a0) = self.wheel_sample(i - 1);
                let span = t1 - t0;
                return if span > 0.0 {
                    a0 + (a1 - a0) * (t - t0) / span
                } else {
                    a1
                };
            }
        }
        *cursor = self.wheel_len;
        self.wheel_sample(self.wheel_len - 1).1
    }
}
