//! Tracking supervision: a fault instead of a weave (issue 15, point 5) or a lost turn.
//!
//! While the supervisor is engaged it watches how the path is being tracked; the first three
//! checks on a work line, the last on every other path:
//!
//! - `tracking_unstable`: a sustained oscillation — the cross-track error swinging from beyond
//!   +`unstable_xte` to beyond −`unstable_xte` (or the wheel angle, about its own moving mean,
//!   from beyond +`unstable_wheel` to beyond −`unstable_wheel`) `unstable_swings` times within
//!   `unstable_window`, no swing's peak below [`DECAY_RATIO`] of the one before. A swing is
//!   counted when the signal crosses the band on the side opposite to the previous swing, so
//!   noise inside the band counts nothing, one step (a curve entry: the wheel angle leaves its
//!   mean once and comes back) counts one swing, and a damped overshoot (an acquisition) whose
//!   swings shrink restarts the count: only a limit cycle or a growing weave trips. A swing
//!   of the cross-track error that starts after the path itself bent the other way (its
//!   curvature at the vehicle changed side, or came out of or went into a bend) restarts the
//!   count too: on a headland pass of S-bends at r_min the error leaves the band on the outside
//!   of each bend, one side and then the other, by the path's design and not the tracker's
//!   (a 305 m pass of `f2c_nl_field_188` at w 6 m, r_min 8 m was given back as unstable after
//!   75 s while tracked at 5.8 cm RMS);
//! - `off_line`: |XTE| beyond `off_line` for longer than `off_line_time`, once the line has been
//!   acquired (|XTE| below `off_line` since the line started: a turn's exit error is not an
//!   offset); or the line not acquired within `off_line_acquire` m driven on it (a vehicle
//!   engaged near the limit, or out of a turn, that never converges);
//! - `off_path`: on every other path the tractor is steered along — turns, transits,
//!   approaches, anything driven in reverse — the distance from the path (to its nearest
//!   segment, not to a segment's extension; beyond the path's ends, to the end segment's
//!   extension, where the tractor rolls on past a cusp) beyond `off_path` for longer than
//!   `off_line_time`.
//!   Those paths are short and curved, and an error there is not an offset to hold on to: a
//!   plant that cannot turn as tight as the plan, or loses the path at a cusp, would otherwise
//!   be steered on after it, the work-line checks waiting for a line it never reaches. No
//!   acquisition: a manoeuvre starts where the vehicle is (a line's end, a cusp, the approach's
//!   start).
//!
//! And before engaging, the line itself: `line_unfollowable` when the line's sharpest curve
//! needs more than the command limits allow at the current speed (the wheel angle limit, the
//! lateral acceleration v²·κ), or when the steering rate makes its entry leave the line by more
//! than `off_line` even with perfect anticipation: the wheels sweep from straight to
//! δ = atan(L·κ) in δ/rate seconds, so the vehicle drives a clothoid of length
//! s = v·δ/rate through the entry, which is s²·κ/24 off the line-and-arc it replaces (the
//! clothoid's shift, a standard result of road design).
//!
//! Everything is a pure function of the inputs and the times given: fixed-size state, no
//! allocation.

use crate::geo::{cross, Vec2};

/// Thresholds of the tracking supervision, SI (`[safety]` keys in `config/demo.toml`).
#[derive(Debug, Clone, PartialEq)]
pub struct TrackingParams {
    /// |XTE| beyond this for longer than `off_line_time` is `off_line`, m (0 = off).
    pub off_line: f64,
    /// s.
    pub off_line_time: f64,
    /// The line must be acquired (|XTE| below `off_line` once) within this distance driven
    /// on it, m.
    pub off_line_acquire: f64,
    /// XTE swing band, m (0 = XTE not watched for oscillation).
    pub unstable_xte: f64,
    /// Wheel-angle swing band about the angle's moving mean, rad (0 = not watched).
    pub unstable_wheel: f64,
    /// Alternate swings that make an oscillation (0 = off; at most [`MAX_SWINGS`]).
    pub unstable_swings: usize,
    /// … within this long, s.
    pub unstable_window: f64,
    /// Time constant of the wheel angle's moving mean, s.
    pub wheel_mean_tau: f64,
    /// Distance from a turn's, transit's, approach's or reversing path beyond this for longer
    /// than `off_line_time` is `off_path`, m (0 = off).
    pub off_path: f64,
}

/// The largest `unstable_swings` (the size of the swing history).
pub const MAX_SWINGS: usize = 16;

impl Default for TrackingParams {
    fn default() -> Self {
        TrackingParams {
            off_line: 2.0,
            off_line_time: 0.5,
            off_line_acquire: 30.0,
            unstable_xte: 0.2,
            unstable_wheel: 3f64.to_radians(),
            unstable_swings: 4,
            unstable_window: 40.0,
            wheel_mean_tau: 2.0,
            off_path: 4.0,
        }
    }
}

/// A path whose curvature at the vehicle is beyond this bends there, 1/m (a radius of 100 m:
/// the wheels about 1.5° off straight on a 2.8 m wheelbase).
pub const BEND_CURVATURE: f64 = 0.01;

/// What the monitor found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrackingVerdict {
    Ok,
    Unstable,
    OffLine,
    OffPath,
}

/// A swing whose peak is below this fraction of the previous swing's peak is a decaying
/// (damped) oscillation — an acquisition's overshoot, not a limit cycle: the count restarts.
pub const DECAY_RATIO: f64 = 0.8;

/// Counts alternate excursions of a signal beyond ±band whose peaks do not decay.
#[derive(Debug, Clone)]
struct SwingCounter {
    /// Side of the current swing: +1, −1, or 0 (none yet).
    side: i8,
    /// Largest |x| of the current swing so far.
    peak: f64,
    /// Peak of the previous (completed) swing.
    prev_peak: Option<f64>,
    /// Start times of the swings of the current non-decaying run.
    times: [f64; MAX_SWINGS],
    len: usize,
    head: usize,
    /// The next swing begins a new run ([`SwingCounter::restart_at_next_swing`]).
    restart: bool,
}

impl SwingCounter {
    fn new() -> Self {
        SwingCounter {
            side: 0,
            peak: 0.0,
            prev_peak: None,
            times: [0.0; MAX_SWINGS],
            len: 0,
            head: 0,
            restart: false,
        }
    }

    /// The next swing begins a new run: the signal's cause changed since the last one.
    fn restart_at_next_swing(&mut self) {
        self.restart = true;
    }

    /// Feed `x` at `t`; true when `swings` alternate, non-decaying swings started within
    /// `window`.
    fn update(&mut self, t: f64, x: f64, band: f64, swings: usize, window: f64) -> bool {
        if band <= 0.0 || swings == 0 {
            return false;
        }
        if f64::from(self.side) * x > 0.0 {
            self.peak = self.peak.max(x.abs());
        }
        let side = if x > band {
            1
        } else if x < -band {
            -1
        } else {
            return false;
        };
        if side == self.side {
            return false;
        }
        let restart = std::mem::take(&mut self.restart);
        if restart {
            self.len = 0;
        }
        if self.side != 0 {
            // The swing that just ended: a decaying one restarts the run from itself.
            if !restart && self.prev_peak.is_some_and(|p| self.peak < DECAY_RATIO * p) {
                self.len = 1;
            }
            self.prev_peak = Some(self.peak);
        }
        self.side = side;
        self.peak = x.abs();
        self.times[self.head] = t;
        self.head = (self.head + 1) % MAX_SWINGS;
        self.len = (self.len + 1).min(MAX_SWINGS);
        let n = swings.min(MAX_SWINGS);
        if self.len < n {
            return false;
        }
        // The n-th newest swing (the newest is at head − 1).
        let oldest = self.times[(self.head + MAX_SWINGS - n) % MAX_SWINGS];
        t - oldest <= window
    }
}

/// The tracking monitor: one per supervisor.
#[derive(Debug, Clone)]
pub struct TrackingMonitor {
    xte_swings: SwingCounter,
    wheel_swings: SwingCounter,
    /// The wheel angle's moving mean, rad (None until the first sample).
    wheel_mean: Option<f64>,
    /// The path's bend at the vehicle in the last period: +1 left, −1 right, 0 straight.
    path_bend: i8,
    /// The line has been acquired (|XTE| below `off_line` since the line started).
    acquired: bool,
    /// Distance driven on the line while not acquired, m.
    unacquired: f64,
    off_since: Option<f64>,
    /// Since when the vehicle has been beyond `off_path` of a manoeuvre's path.
    off_path_since: Option<f64>,
}

impl Default for TrackingMonitor {
    fn default() -> Self {
        Self::new()
    }
}

impl TrackingMonitor {
    pub fn new() -> Self {
        TrackingMonitor {
            xte_swings: SwingCounter::new(),
            wheel_swings: SwingCounter::new(),
            wheel_mean: None,
            path_bend: 0,
            acquired: false,
            unacquired: 0.0,
            off_since: None,
            off_path_since: None,
        }
    }

    /// Forget everything (engaged anew, another line).
    pub fn reset(&mut self) {
        *self = Self::new();
    }

    /// One engaged period on a work line at `t`, `dt` after the previous one: the cross-track
    /// error (m, when known), the measured wheel angle (rad) and the speed (m/s). The wheel
    /// angle's swings are counted only when `watch_wheel` (a straight line: on a curved one,
    /// a headland pass round a field's corners, the wheels leave their mean at every bend by
    /// design, and only the cross-track error tells a weave). `path_bend`: the path's bend at
    /// the vehicle, +1 left, −1 right, 0 straight (or not known).
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        p: &TrackingParams,
        t: f64,
        dt: f64,
        xte: Option<f64>,
        wheel_angle: f64,
        watch_wheel: bool,
        path_bend: i8,
        speed: f64,
    ) -> TrackingVerdict {
        if path_bend != self.path_bend {
            self.path_bend = path_bend;
            self.xte_swings.restart_at_next_swing();
        }
        let mean = match self.wheel_mean {
            Some(m) if p.wheel_mean_tau > 0.0 => {
                m + (wheel_angle - m) * (dt / p.wheel_mean_tau).min(1.0)
            }
            Some(_) => wheel_angle,
            None => wheel_angle,
        };
        self.wheel_mean = Some(mean);
        let mut verdict = TrackingVerdict::Ok;
        if watch_wheel
            && self.wheel_swings.update(
                t,
                wheel_angle - mean,
                p.unstable_wheel,
                p.unstable_swings,
                p.unstable_window,
            )
        {
            verdict = TrackingVerdict::Unstable;
        }
        let Some(x) = xte.filter(|x| x.is_finite()) else {
            return verdict;
        };
        if self
            .xte_swings
            .update(t, x, p.unstable_xte, p.unstable_swings, p.unstable_window)
        {
            verdict = TrackingVerdict::Unstable;
        }
        if p.off_line > 0.0 {
            let beyond = x.abs() > p.off_line;
            if !beyond {
                self.acquired = true;
            } else if !self.acquired && speed.is_finite() {
                self.unacquired += speed.abs() * dt;
            }
            let late = !self.acquired && self.unacquired > p.off_line_acquire;
            if late && verdict == TrackingVerdict::Ok {
                return TrackingVerdict::OffLine;
            }
            if beyond && self.acquired {
                let since = *self.off_since.get_or_insert(t);
                if t - since >= p.off_line_time && verdict == TrackingVerdict::Ok {
                    verdict = TrackingVerdict::OffLine;
                }
            } else {
                self.off_since = None;
            }
        }
        verdict
    }

    /// One engaged period at `t` on a path that is not a work line (a turn, a transit, an
    /// approach, reversing): `distance` from the path, m (None: no path or no pose, which
    /// restarts the timing).
    pub fn update_manoeuvre(
        &mut self,
        p: &TrackingParams,
        t: f64,
        distance: Option<f64>,
    ) -> TrackingVerdict {
        let beyond = p.off_path > 0.0 && distance.is_some_and(|d| d.is_finite() && d > p.off_path);
        if !beyond {
            self.off_path_since = None;
            return TrackingVerdict::Ok;
        }
        let since = *self.off_path_since.get_or_insert(t);
        if t - since >= p.off_line_time {
            TrackingVerdict::OffPath
        } else {
            TrackingVerdict::Ok
        }
    }
}

/// Is a line whose sharpest curvature is `max_curvature` (1/m) unfollowable at `speed` (m/s)?
/// `wheelbase` m, `max_wheel_angle` rad, `a_lat_max` m/s², `rate` the steering rate (rad/s,
/// the slower of the actuator and the command limit), `off_line` m (0 = no entry check).
pub fn line_unfollowable(
    max_curvature: f64,
    speed: f64,
    wheelbase: f64,
    max_wheel_angle: f64,
    a_lat_max: f64,
    rate: f64,
    off_line: f64,
) -> bool {
    let k = max_curvature.abs();
    if !k.is_finite() || k <= 0.0 {
        return false;
    }
    let v = speed.abs();
    let delta = (wheelbase * k).atan();
    if delta > max_wheel_angle || v * v * k > a_lat_max {
        return true;
    }
    if off_line > 0.0 && rate > 0.0 {
        let s = v * delta / rate;
        return s * s * k / 24.0 > off_line;
    }
    false
}

/// The sharpest curvature along a path, 1/m: the circle through three points whose chords are
/// each at least `chord` m long (closer points measure the spacing's noise, not the line).
pub fn sharpest_curvature(points: impl IntoIterator<Item = Vec2>, chord: f64) -> f64 {
    let mut it = points.into_iter();
    let Some(mut a) = it.next() else {
        return 0.0;
    };
    let mut b: Option<Vec2> = None;
    let mut best = 0.0f64;
    for p in it {
        match b {
            None => {
                if (p - a).norm() >= chord {
                    b = Some(p);
                }
            }
            Some(bb) => {
                if (p - bb).norm() >= chord {
                    let (ab, bc, ca) = ((bb - a).norm(), (p - bb).norm(), (a - p).norm());
                    let denom = ab * bc * ca;
                    if denom > 0.0 {
                        best = best.max((2.0 * cross(&(bb - a), &(p - bb)) / denom).abs());
                    }
                    a = bb;
                    b = Some(p);
                }
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f64 = 0.02;

    fn run(
        p: &TrackingParams,
        secs: f64,
        f: impl Fn(f64) -> (f64, f64),
    ) -> Option<(f64, TrackingVerdict)> {
        let mut m = TrackingMonitor::new();
        let mut t = 0.0;
        while t < secs {
            let (x, w) = f(t);
            let v = m.update(p, t, DT, Some(x), w, true, 0, 2.5);
            if v != TrackingVerdict::Ok {
                return Some((t, v));
            }
            t += DT;
        }
        None
    }

    #[test]
    fn a_weave_is_unstable_within_its_swings() {
        let p = TrackingParams::default();
        // ±0.4 m at a period of 8 s: a swing every 4 s, the 4th at about 12.7 s.
        let r = run(&p, 120.0, |t| {
            (0.4 * (std::f64::consts::TAU * t / 8.0).sin(), 0.0)
        });
        let (t, v) = r.expect("a weave must trip");
        assert_eq!(v, TrackingVerdict::Unstable);
        assert!((10.0..15.0).contains(&t), "{t}");
    }

    #[test]
    fn a_wheel_limit_cycle_is_unstable_even_with_a_small_xte() {
        let p = TrackingParams::default();
        let r = run(&p, 120.0, |t| {
            let s = (std::f64::consts::TAU * t / 3.0).sin();
            (0.03 * s, 6f64.to_radians() * s)
        });
        assert_eq!(r.map(|r| r.1), Some(TrackingVerdict::Unstable));
    }

    #[test]
    fn noise_inside_the_band_and_a_curve_entry_count_nothing() {
        let p = TrackingParams::default();
        // XTE noise of ±18 cm, a wheel step of 12° at 30 s and back at 60 s.
        let r = run(&p, 120.0, |t| {
            let noise = 0.18 * (t * 37.0).sin() * (t * 3.1).cos();
            let wheel = if (30.0..60.0).contains(&t) { 0.21 } else { 0.0 };
            (noise, wheel)
        });
        assert_eq!(r, None);
    }

    #[test]
    fn a_damped_overshoot_counts_nothing() {
        let p = TrackingParams::default();
        // An acquisition from 1.5 m ringing down at 0.6 per swing, period 8 s.
        let r = run(&p, 120.0, |t| {
            let w = std::f64::consts::TAU * t / 8.0;
            (1.5 * w.cos() * 0.6f64.powf(t / 4.0), 0.0)
        });
        assert_eq!(r, None);
        // The same growing by 1.1 per swing trips.
        let r = run(&p, 120.0, |t| {
            let w = std::f64::consts::TAU * t / 8.0;
            (0.3 * w.cos() * 1.1f64.powf(t / 4.0), 0.0)
        });
        assert_eq!(r.map(|r| r.1), Some(TrackingVerdict::Unstable));
    }

    #[test]
    fn slow_swings_outside_the_window_count_nothing() {
        let p = TrackingParams::default();
        // A swing every 15 s: 4 swings take 45 s > 40 s.
        let r = run(&p, 200.0, |t| {
            (0.4 * (std::f64::consts::TAU * t / 30.0).sin(), 0.0)
        });
        assert_eq!(r, None);
    }

    #[test]
    fn a_persistent_offset_is_off_line_after_its_time() {
        let p = TrackingParams::default();
        // On the line, then 2.5 m off from 10 s.
        let r = run(&p, 60.0, |t| (if t < 10.0 { 0.02 } else { 2.5 }, 0.0));
        let (t, v) = r.expect("an offset must trip");
        assert_eq!(v, TrackingVerdict::OffLine);
        assert!((t - 10.5).abs() < 2.0 * DT, "{t}");
        // Before the line is acquired, an offset is an approach (a turn's exit error) …
        let r = run(&p, 10.0, |_| (3.0, 0.0));
        assert_eq!(r, None);
        // … until 30 m have been driven at 2.5 m/s without acquiring it.
        let (t, v) = run(&p, 60.0, |_| (2.5, 0.0)).expect("never acquired");
        assert_eq!(v, TrackingVerdict::OffLine);
        assert!((t - 12.0).abs() < 2.0 * DT, "{t}");
    }

    #[test]
    fn zero_thresholds_switch_the_checks_off() {
        let p = TrackingParams {
            off_line: 0.0,
            unstable_swings: 0,
            ..TrackingParams::default()
        };
        let r = run(&p, 120.0, |t| {
            (5.0 * (std::f64::consts::TAU * t / 8.0).sin(), 0.0)
        });
        assert_eq!(r, None);
    }

    #[test]
    fn sharpest_curvature_of_an_arc_and_a_line() {
        let arc = (0..200).map(|i| {
            let a = i as f64 * 0.02;
            crate::geo::v2(15.0 * a.cos(), 15.0 * a.sin())
        });
        let k = sharpest_curvature(arc, 1.0);
        assert!((k - 1.0 / 15.0).abs() < 1e-3, "{k}");
        let line = (0..100).map(|i| crate::geo::v2(i as f64 * 0.3, 2.0));
        assert_eq!(sharpest_curvature(line, 1.0), 0.0);
        assert_eq!(sharpest_curvature(std::iter::empty(), 1.0), 0.0);
    }

    #[test]
    fn unfollowable_lines() {
        let wb = 3.0;
        let amax = 35f64.to_radians();
        let rate = 30f64.to_radians();
        // Straight: always followable.
        assert!(!line_unfollowable(0.0, 7.0, wb, amax, 2.0, rate, 0.5));
        // R 15 m at 10 km/h: a_lat 0.51 m/s², entry 3 mm off: followable.
        assert!(!line_unfollowable(
            1.0 / 15.0,
            10.0 / 3.6,
            wb,
            amax,
            2.0,
            rate,
            0.5
        ));
        // R 15 m at 25 km/h: a_lat 3.2 m/s² > 2.
        assert!(line_unfollowable(
            1.0 / 15.0,
            25.0 / 3.6,
            wb,
            amax,
            2.0,
            rate,
            0.5
        ));
        // R 4 m: beyond 35° of wheel angle at any speed.
        assert!(line_unfollowable(0.25, 1.0, wb, amax, 2.0, rate, 0.5));
        // R 30 m at 25 km/h (a_lat 1.6) with a 3 °/s motor: the entry sweeps 5.7° over 13 m,
        // 0.24 m off; with off_line 0.2 m that is unfollowable.
        assert!(line_unfollowable(
            1.0 / 30.0,
            25.0 / 3.6,
            wb,
            amax,
            2.0,
            3f64.to_radians(),
            0.2
        ));
        assert!(!line_unfollowable(
            1.0 / 30.0,
            25.0 / 3.6,
            wb,
            amax,
            2.0,
            3f64.to_radians(),
            0.5
        ));
    }
}
