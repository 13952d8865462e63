//! The steering model calibration fits, in the wheel-angle sensor's terms.
//!
//! The steering controller servos the sensor's reading to the command (a command is "what the
//! sensor should read"), so from the bus the steering is a map from commanded to sensed angle:
//! a dead time `d`, then a first-order lag `τ` whose rate is bounded by `R`, an actuator that
//! ignores errors inside its deadband `±b`, and play `p` between the actuator and the wheels
//! (the sensor reads the wheels: after a reversal it sees nothing until the actuator has taken
//! up the play). With the sensor reading `g·δ + o`, every angle here is the true one times `g`;
//! [`SteeringModel::to_true`] divides it out once the gain is known.
//!
//! Simulated with a fixed Euler step, the commands held between their times (a zero-order
//! hold, as the bus delivers them). Allocation-free: the caller gives the output buffer.

/// Dead time, lag, rate limit, deadband and backlash, SI (angles in rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteeringModel {
    /// Dead time from command to motion, s.
    pub dead_time: f64,
    /// First-order lag, s.
    pub tau: f64,
    /// Largest rate, rad/s.
    pub rate: f64,
    /// Deadband (half-width) of the actuator's servo, rad.
    pub deadband: f64,
    /// Backlash (full play) between actuator and wheels, rad.
    pub backlash: f64,
}

impl SteeringModel {
    /// The same steering in true wheel angles, for a sensor of gain `gain` (angles divided by
    /// it; times unchanged).
    pub fn to_true(&self, gain: f64) -> SteeringModel {
        let g = if gain.is_finite() && gain > 0.0 {
            gain
        } else {
            1.0
        };
        SteeringModel {
            rate: self.rate / g,
            deadband: self.deadband / g,
            backlash: self.backlash / g,
            ..*self
        }
    }
}

/// The model's state: actuator and wheel (sensor terms), rad.
#[derive(Debug, Clone, Copy)]
struct State {
    act: f64,
    wheel: f64,
}

impl State {
    /// One step towards `target`; whether the rate limit bound it.
    fn step(&mut self, m: &SteeringModel, target: f64, h: f64) -> bool {
        let mut err = target - self.act;
        if m.deadband > 0.0 {
            err = if err.abs() <= m.deadband {
                0.0
            } else {
                err - m.deadband * err.signum()
            };
        }
        let rate = if m.tau > 0.0 { err / m.tau } else { err / h };
        let bound = rate.abs() > m.rate;
        let rate = rate.clamp(-m.rate, m.rate);
        self.act += rate * h;
        let half = 0.5 * m.backlash;
        if half > 0.0 {
            if self.act - self.wheel > half {
                self.wheel = self.act - half;
            } else if self.act - self.wheel < -half {
                self.wheel = self.act + half;
            }
        } else {
            self.wheel = self.act;
        }
        bound
    }
}

/// The sensed angle `model` predicts at each of `sample_times` (increasing, s) for the
/// `commands` ((time, angle) in time order, each held until the next), starting at rest with
/// the wheels at `start` at the first sample, having come there from below (`approach` +1:
/// the actuator half the play ahead), from above (−1) or with the play centred (0). Written
/// into `out` (same length as `sample_times`). Euler step `h` s. Returns the time the rate
/// limit bound the motion, s.
pub fn simulate(
    model: &SteeringModel,
    commands: &[(f64, f64)],
    sample_times: &[f64],
    start: f64,
    approach: f64,
    h: f64,
    out: &mut [f64],
) -> f64 {
    let Some(&t_first) = sample_times.first() else {
        return 0.0;
    };
    let mut s = State {
        act: start + 0.5 * model.backlash * approach.clamp(-1.0, 1.0),
        wheel: start,
    };
    let mut bound = 0.0;
    let mut t = t_first;
    // The command in force at `t - dead_time`, searched forward with a cursor.
    let mut ci = 0usize;
    let mut command_at = |tc: f64| -> f64 {
        while ci + 1 < commands.len() && commands[ci + 1].0 <= tc {
            ci += 1;
        }
        match commands.get(ci) {
            Some(&(t0, c)) if t0 <= tc => c,
            _ => start,
        }
    };
    for (ts, o) in sample_times.iter().zip(out.iter_mut()) {
        while t + 0.5 * h < *ts {
            let target = command_at(t - model.dead_time);
            if s.step(model, target, h) {
                bound += h;
            }
            t += h;
        }
        *o = s.wheel;
    }
    bound
}

#[cfg(test)]
mod tests {
    use super::*;

    fn times(n: usize, dt: f64) -> Vec<f64> {
        (0..n).map(|i| i as f64 * dt).collect()
    }

    #[test]
    fn a_step_is_delayed_then_first_order() {
        let m = SteeringModel {
            dead_time: 0.1,
            tau: 0.2,
            rate: 10.0,
            deadband: 0.0,
            backlash: 0.0,
        };
        let ts = times(200, 0.01);
        let mut out = vec![0.0; ts.len()];
        simulate(&m, &[(0.0, 0.1)], &ts, 0.0, 0.0, 0.0005, &mut out);
        assert!(out[9].abs() < 1e-9, "nothing before the dead time");
        // One time constant after the dead time: 1 - 1/e of the step.
        let at = out[30];
        assert!((at - 0.1 * (1.0 - (-1f64).exp())).abs() < 0.002, "{at}");
    }

    #[test]
    fn the_rate_limit_bounds_the_slope_and_play_delays_a_reversal() {
        let m = SteeringModel {
            dead_time: 0.0,
            tau: 0.05,
            rate: 0.2,
            deadband: 0.0,
            backlash: 0.02,
        };
        let ts = times(400, 0.01);
        let mut out = vec![0.0; ts.len()];
        simulate(
            &m,
            &[(0.0, 0.2), (2.0, 0.1)],
            &ts,
            0.0,
            0.0,
            0.0005,
            &mut out,
        );
        // Rising at 0.2 rad/s: 0.1 s of play taken up first (0.01 rad at 0.2 rad/s = 0.05 s).
        let slope = (out[60] - out[40]) / 0.2;
        assert!((slope - 0.2).abs() < 1e-6, "{slope}");
        // Settled 0.01 short (half the play); after the reversal the wheels wait for the play.
        assert!((out[199] - 0.19).abs() < 1e-3, "{}", out[199]);
        assert!((out[205] - out[199]).abs() < 1e-9, "play: no motion yet");
        assert!((out[399] - 0.11).abs() < 1e-3, "{}", out[399]);
    }

    #[test]
    fn a_deadband_stops_short() {
        let m = SteeringModel {
            dead_time: 0.0,
            tau: 0.05,
            rate: 1.0,
            deadband: 0.01,
            backlash: 0.0,
        };
        let ts = times(100, 0.01);
        let mut out = vec![0.0; ts.len()];
        simulate(&m, &[(0.0, 0.1)], &ts, 0.0, 0.0, 0.0005, &mut out);
        assert!((out[99] - 0.09).abs() < 1e-4, "{}", out[99]);
        let t = m.to_true(1.1);
        assert!((t.deadband - 0.01 / 1.1).abs() < 1e-12 && t.tau == 0.05);
    }
}
