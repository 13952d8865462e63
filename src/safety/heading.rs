//! Heading against course over ground: a GNSS heading that disagrees with the direction the
//! antenna moves (a receiver's heading 90° off, a magnetic heading taken as true, a swapped
//! antenna pair) steers the tractor off the line at speed before any tracking check can tell;
//! this check catches it from the two GNSS outputs alone, in about `time` s.
//!
//! The course over ground of an antenna at (forward f, left l) from the rear axle, on a
//! kinematic bicycle (yaw rate ω = v·tan δ / L, v the signed rear-axle speed), is the heading
//! plus the direction of its body-frame velocity (v − ω·l, ω·f):
//!
//! ```text
//! course = heading + atan2(sign(v)·tan δ·f / L, sign(v)·(1 − tan δ·l / L))
//! ```
//!
//! independent of |v|, and π off when reversing. What the model leaves out (tyre slip, a side
//! slope, course noise at low speed) must fit within `limit`; below `min_speed` the course is
//! too noisy to judge. The mismatch must last `time` s (every fresh pair of heading and course
//! beyond the limit) before the supervisor gives the steering back, `heading_mismatch`.

use crate::geo::wrap_angle;

/// Tuning of the heading check, SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadingCheckParams {
    /// Largest |course − expected course| tolerated, rad (0: the check is off).
    pub limit: f64,
    /// … for at most this long, s.
    pub time: f64,
    /// Judged only above this speed over ground, m/s.
    pub min_speed: f64,
    /// Antenna position from the rear-axle centre (forward, left), m.
    pub antenna_forward: f64,
    pub antenna_left: f64,
}

impl Default for HeadingCheckParams {
    fn default() -> Self {
        HeadingCheckParams {
            limit: 30f64.to_radians(),
            time: 1.0,
            min_speed: 2.0 / 3.6,
            antenna_forward: 0.0,
            antenna_left: 0.0,
        }
    }
}

/// The course the antenna should move along for `heading` (rad), the measured wheel angle
/// `wheel_angle` (rad), wheelbase `wheelbase` (m) and the direction of travel (`reversing`).
pub fn expected_course(
    p: &HeadingCheckParams,
    heading: f64,
    wheel_angle: f64,
    wheelbase: f64,
    reversing: bool,
) -> f64 {
    let s = if reversing { -1.0 } else { 1.0 };
    let k = wheel_angle.tan() / wheelbase.max(1e-3);
    wrap_angle(heading + (s * k * p.antenna_forward).atan2(s * (1.0 - k * p.antenna_left)))
}

/// The check's state: the latest heading and course and since when they disagree.
#[derive(Debug, Clone, Copy, Default)]
pub struct HeadingCheck {
    heading: Option<(f64, f64)>,
    /// (time, course, speed over ground).
    course: Option<(f64, f64, f64)>,
    since: Option<f64>,
    /// The largest mismatch of the latest judged pair, rad (for status and tests).
    last_mismatch: f64,
}

impl HeadingCheck {
    pub fn new() -> Self {
        Self::default()
    }

    /// A GNSS heading (rad, CCW from East) at `t`.
    pub fn on_heading(&mut self, t: f64, heading: f64) {
        if t.is_finite() && heading.is_finite() {
            self.heading = Some((t, heading));
        }
    }

    /// A course (rad, CCW from East) and speed over ground (m/s) at `t`.
    pub fn on_course(&mut self, t: f64, course: f64, speed: f64) {
        if t.is_finite() && course.is_finite() && speed.is_finite() {
            self.course = Some((t, course, speed.abs()));
        }
    }

    /// The latest judged mismatch, rad (0 when nothing was judged).
    pub fn mismatch(&self) -> f64 {
        self.last_mismatch
    }

    /// Judge at `t`: true when the heading has disagreed with the course beyond the limit for
    /// longer than the allowed time. Heading and course older than `max_age` s, or taken more
    /// than `max_age` apart, or a speed below the minimum, are not judged (and restart the
    /// timer).
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        p: &HeadingCheckParams,
        t: f64,
        max_age: f64,
        wheel_angle: f64,
        wheelbase: f64,
        reversing: bool,
    ) -> bool {
        if p.limit.is_nan() || p.limit <= 0.0 {
            self.since = None;
            return false;
        }
        let fresh = |tx: f64| t - tx <= max_age && tx - t <= 1.0;
        let judged = match (self.heading, self.course) {
            (Some((th, h)), Some((tc, c, v)))
                if fresh(th) && fresh(tc) && (th - tc).abs() <= max_age && v >= p.min_speed =>
            {
                let want = expected_course(p, h, wheel_angle, wheelbase, reversing);
                Some(wrap_angle(c - want).abs())
            }
            _ => None,
        };
        match judged {
            Some(m) if m > p.limit => {
                self.last_mismatch = m;
                let since = *self.since.get_or_insert(t);
                t - since >= p.time
            }
            Some(m) => {
                self.last_mismatch = m;
                self.since = None;
                false
            }
            None => {
                self.since = None;
                false
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_expected_course_of_an_offset_antenna_in_a_turn() {
        let p = HeadingCheckParams {
            antenna_forward: 1.5,
            antenna_left: 0.0,
            ..Default::default()
        };
        // Straight: the heading; reversing: the heading + π.
        assert!((expected_course(&p, 0.3, 0.0, 3.0, false) - 0.3).abs() < 1e-12);
        let back = expected_course(&p, 0.3, 0.0, 3.0, true);
        assert!((wrap_angle(back - 0.3 - std::f64::consts::PI)).abs() < 1e-12);
        // Turning left (κ = tan δ / L): the antenna ahead of the axle moves left of the
        // heading by atan(κ·f).
        let d = 20f64.to_radians();
        let want = (d.tan() / 3.0 * 1.5).atan();
        assert!((expected_course(&p, 0.0, d, 3.0, false) - want).abs() < 1e-12);
    }

    #[test]
    fn a_mismatch_trips_after_the_time_and_not_below_the_speed() {
        let p = HeadingCheckParams::default();
        let mut c = HeadingCheck::new();
        let mut tripped_at = None;
        for i in 0..40 {
            let t = i as f64 * 0.1;
            c.on_heading(t, 1.0 + std::f64::consts::FRAC_PI_2);
            c.on_course(t, 1.0, 2.0);
            if c.update(&p, t, 0.3, 0.0, 3.0, false) && tripped_at.is_none() {
                tripped_at = Some(t);
            }
        }
        assert!((tripped_at.expect("tripped") - p.time).abs() < 1e-9);
        // The same at a crawl: not judged.
        let mut c = HeadingCheck::new();
        for i in 0..40 {
            let t = i as f64 * 0.1;
            c.on_heading(t, 1.0 + std::f64::consts::FRAC_PI_2);
            c.on_course(t, 1.0, 0.3);
            assert!(!c.update(&p, t, 0.3, 0.0, 3.0, false));
        }
        // Within the limit (a 20° crab): never.
        let mut c = HeadingCheck::new();
        for i in 0..40 {
            let t = i as f64 * 0.1;
            c.on_heading(t, 1.0 + 20f64.to_radians());
            c.on_course(t, 1.0, 2.0);
            assert!(!c.update(&p, t, 0.3, 0.0, 3.0, false));
        }
    }
}
