//! The vehicle's own lag: how much later than the wheels its heading turns.
//!
//! The kinematic bicycle model turns the heading at `v·tan(δ)/L` the moment the wheels are at
//! `δ`. On real tyres the heading follows later: each tyre builds its side force over its
//! relaxation length, and the yaw inertia takes the moment to turn the vehicle. At 15 km/h on
//! soft tyres that lag is a few tenths of a second, as much as a slow steering's, and it is
//! not the steering's (the wheel-angle sensor sees the wheels at `δ` already), so calibration,
//! which measures the steering, does not see it. Left out, the default law's turns exit late
//! and every line after a 15 km/h turn starts 0.6–1 m off (docs/envelope.md, Session 26: a
//! side draft's crab as the vehicle keeps it, the vehicle's own lag led on).
//!
//! It is measured here, on every fix interval the observer learns from: a bank of first-order
//! lags `τ_k = k · LAG_STEP_S` (k = 0 … `LAGS` − 1) filters the kinematic yaw rate of the
//! measured wheel angles, each filter's integral over the interval is compared with the
//! heading change the fixes measured, and the lag whose filtered rates explain the headings
//! best, with a gain of their own (an understeering vehicle turns less than the model: a gain,
//! not a lag), is the vehicle's lag. The sums are forgotten over [`MEMORY_FIXES`] fixes, and
//! the lag is given only once the turns have moved the heading enough to tell the lags apart
//! ([`MIN_EXCITATION_RAD2`]); on a straight line nothing is learnt and the last lag stays.
//!
//! Contract: fixed arrays, no allocation; a few hundred multiply-adds per fix.

/// Step between the lags of the bank, s.
pub const LAG_STEP_S: f64 = 0.05;
/// Lags in the bank (0 to 0.6 s).
pub const LAGS: usize = 13;
/// The sums keep about this many fixes (each fix weighs `1 − 1/MEMORY_FIXES` less at the next).
pub const MEMORY_FIXES: f64 = 2000.0;
/// The least sum of squared heading changes (rad²) before a lag is given: a headland turn of
/// 180° at 10 Hz fixes brings about 0.2.
pub const MIN_EXCITATION_RAD2: f64 = 0.1;

/// The bank's state and its sums.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct YawLag {
    /// Each filter's yaw rate at the end of the last interval, rad/s.
    rates: [f64; LAGS],
    /// The time the last interval ended, s (NaN: none).
    t_end: f64,
    /// Per lag: Σ x² and Σ x·m over the intervals (x the filter's heading change, m the
    /// measured one), forgotten.
    sxx: [f64; LAGS],
    sxm: [f64; LAGS],
    /// Σ m², forgotten.
    smm: f64,
    /// The lag the sums give, found once per interval (the control period asks for it).
    lag: Option<f64>,
}

impl Default for YawLag {
    fn default() -> Self {
        YawLag {
            rates: [0.0; LAGS],
            t_end: f64::NAN,
            sxx: [0.0; LAGS],
            sxm: [0.0; LAGS],
            smm: 0.0,
            lag: None,
        }
    }
}

impl YawLag {
    /// One interval from `t_start` (s) of `steps` steps of `h` s, the model's yaw rate at each
    /// step's middle from `rate(i)` (rad/s), against the heading change the fixes measured,
    /// `measured` (rad). An interval that does not start where the last one ended starts the
    /// filters at its first rate.
    pub fn interval(
        &mut self,
        t_start: f64,
        steps: usize,
        h: f64,
        mut rate: impl FnMut(usize) -> f64,
        measured: f64,
    ) {
        if steps == 0 || h.is_nan() || h <= 0.0 || !measured.is_finite() {
            return;
        }
        let mut x = [0.0; LAGS];
        // (False after no interval: `t_end` NaN.)
        let continues = (t_start - self.t_end).abs() < 0.5 * h;
        for i in 0..steps {
            let r = rate(i);
            if !r.is_finite() {
                self.t_end = f64::NAN;
                return;
            }
            if i == 0 && !continues {
                self.rates = [r; LAGS];
            }
            for (k, (y, x)) in self.rates.iter_mut().zip(x.iter_mut()).enumerate() {
                // Backward Euler: stable for any lag, exact at lag 0.
                *y += (r - *y) * h / (k as f64 * LAG_STEP_S + h);
                *x += *y * h;
            }
        }
        self.t_end = t_start + steps as f64 * h;
        let keep = 1.0 - 1.0 / MEMORY_FIXES;
        for (k, x) in x.iter().enumerate() {
            self.sxx[k] = keep * self.sxx[k] + x * x;
            self.sxm[k] = keep * self.sxm[k] + x * measured;
        }
        self.smm = keep * self.smm + measured * measured;
        self.lag = self.fit();
    }

    /// The vehicle's lag, s: the bank's best, refined between its neighbours by a parabola;
    /// `None` until the turns have moved the heading enough.
    pub fn lag(&self) -> Option<f64> {
        self.lag
    }

    /// [`YawLag::lag`] from the sums.
    fn fit(&self) -> Option<f64> {
        if self.smm < MIN_EXCITATION_RAD2 {
            return None;
        }
        // The squared error left with each lag's best gain.
        let sse = |k: usize| {
            let (sxx, sxm) = (self.sxx[k], self.sxm[k]);
            if sxx > 0.0 {
                self.smm - sxm * sxm / sxx
            } else {
                self.smm
            }
        };
        let best = (0..LAGS).min_by(|&a, &b| sse(a).total_cmp(&sse(b)))?;
        let mut lag = best as f64 * LAG_STEP_S;
        if best > 0 && best + 1 < LAGS {
            let (a, b, c) = (sse(best - 1), sse(best), sse(best + 1));
            let curvature = a - 2.0 * b + c;
            if curvature > 0.0 {
                lag += 0.5 * (a - c) / curvature * LAG_STEP_S;
            }
        }
        Some(lag)
    }
}

impl super::Estimator {
    /// Learn the vehicle's lag from the fix interval of innovation `i` (its heading change
    /// against the model's, through the wheel angles the prediction used), moving at
    /// `v_new` m/s. Before the observer's gates: a turn's heading innovations are what the
    /// lag is learnt from.
    pub(super) fn learn_yaw_lag(&mut self, i: &super::Innovation, v_new: f64) {
        let o = &self.params.observer;
        let v = self.fix_speed;
        let Some(previous) = self.fix_pose else {
            return;
        };
        if !self.learn
            || i.dt > super::LONGEST_FIX_INTERVAL
            || v.abs() < o.min_speed
            || v_new.abs() < o.min_speed
        {
            return;
        }
        let measured = crate::geo::wrap_angle(i.heading + (i.predicted.heading - previous.heading));
        // (Taken out while the model's rates borrow the estimator.)
        let mut bank = std::mem::take(&mut self.yaw_lag);
        let (steps, h, yaw_rate) = self.model_yaw_rates(v, i.t_prev, i.dt);
        bank.interval(i.t_prev, steps, h, yaw_rate, measured);
        self.yaw_lag = bank;
    }

    /// The bicycle model's yaw rate over `span` s from `t0` at speed `v` (m/s), in the
    /// prediction's steps (at most [`super::PREDICT_STEP`]): the step count, the step (s) and
    /// the rate (rad/s) at step `i`'s middle from the measured wheel angles less the
    /// estimated offset, asked for in order (`propagate` and the bank above use the same).
    pub(super) fn model_yaw_rates(
        &self,
        v: f64,
        t0: f64,
        span: f64,
    ) -> (usize, f64, impl FnMut(usize) -> f64 + '_) {
        let steps = (span / super::PREDICT_STEP).ceil() as usize;
        let h = span / steps.max(1) as f64;
        // The steps' times only grow: the first sample they need is found once, by bisection,
        // not by a scan of the whole ring (2.56 s of samples at 100 Hz).
        let mut cursor = self.first_wheel_sample_at(t0 + 0.5 * h);
        let l = self.params.wheelbase;
        let rate = move |i: usize| {
            let t_mid = t0 + (i as f64 + 0.5) * h;
            v * (self.wheel_angle_from(t_mid, &mut cursor) - self.bias).tan() / l
        };
        (steps, h, rate)
    }

    /// The vehicle's lag learnt so far, s (0 until learnt: [the module](self)).
    pub fn vehicle_lag(&self) -> f64 {
        self.yaw_lag.lag().unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Headings turned by a true lag `true_lag` (s) of the model's rate through a slalom of
    /// wheel angles, fixes every 0.1 s, heading noise `noise` rad: the lag found.
    fn found(true_lag: f64, gain: f64, noise: f64) -> Option<f64> {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let mut bank = YawLag::default();
        let h = 0.005;
        let steps = 20;
        let mut truth = 0.0;
        let mut heading_prev = 0.0;
        for fix in 0..600 {
            let t0 = fix as f64 * steps as f64 * h;
            let model = |t: f64| 0.4 * (0.8 * t).sin() + 0.2 * (2.1 * t).sin();
            let mut turned = 0.0;
            for i in 0..steps {
                let r = model(t0 + (i as f64 + 0.5) * h);
                truth += (gain * r - truth) * h / (true_lag + h);
                turned += truth * h;
            }
            let heading = heading_prev + turned;
            let measured = heading - heading_prev + noise * (rng.gen::<f64>() - 0.5);
            heading_prev = heading;
            bank.interval(t0, steps, h, |i| model(t0 + (i as f64 + 0.5) * h), measured);
        }
        bank.lag()
    }

    #[test]
    fn the_lag_of_the_headings_is_found_with_any_gain() {
        for true_lag in [0.0, 0.12, 0.3, 0.45] {
            for gain in [1.0, 0.8] {
                let lag = found(true_lag, gain, 0.002).expect("turned enough");
                assert!(
                    (lag - true_lag).abs() < 0.03,
                    "lag {true_lag} gain {gain}: {lag}"
                );
            }
        }
    }

    #[test]
    fn nothing_before_the_heading_has_turned() {
        let mut bank = YawLag::default();
        for fix in 0..100 {
            bank.interval(fix as f64 * 0.1, 20, 0.005, |_| 0.0, 0.001);
        }
        assert_eq!(bank.lag(), None);
        bank.interval(10.0, 20, 0.005, |_| f64::NAN, 0.1);
        assert_eq!(bank.lag(), None);
    }
}
