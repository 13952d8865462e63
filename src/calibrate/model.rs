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
//! Simulated exactly (the closed form of the rate-limited lag between events), the commands
//! held between their times (a zero-order hold, as the bus delivers them). Allocation-free:
//! the caller gives the output buffer.

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
    /// Advance `h` s towards `target`, held (exactly: the response of the rate-limited lag
    /// to a constant target has a closed form). Returns the time the rate limit bound it, s.
    ///
    /// With the deadband the actuator acts on the error less the deadband, so it heads for
    /// `goal` = target ∓ deadband and never crosses it. At a distance beyond `rate·tau` from
    /// `goal` the lag would ask for more than the rate: it moves at the rate until the distance
    /// is `rate·tau`, then decays exponentially (the lag's exact solution). The actuator moves
    /// one way within the step, so the wheels (after the play) follow its end point.
    fn advance(&mut self, m: &SteeringModel, target: f64, h: f64) -> f64 {
        let err = target - self.act;
        if h <= 0.0 || err.abs() <= m.deadband {
            return 0.0;
        }
        let goal = target - m.deadband * err.signum();
        let dist = (goal - self.act).abs();
        let dir = (goal - self.act).signum();
        let knee = m.rate * m.tau.max(0.0);
        let mut bound = 0.0;
        let mut left = h;
        if dist > knee {
            let t_rate = (dist - knee) / m.rate;
            bound = t_rate.min(h);
            self.act += dir * m.rate * bound;
            left = h - bound;
        }
        if left > 0.0 {
            self.act = if m.tau > 0.0 {
                goal + (self.act - goal) * (-left / m.tau).exp()
            } else {
                goal
            };
        }
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
/// into `out` (same length as `sample_times`). Returns the time the rate limit bound the
/// motion, s.
///
/// Exact (no integration step): between a sample and the next, and at each command's time
/// plus the dead time, the held target's response is the closed form of
/// [`State::advance`] (a zero-order hold of the commands, as the bus delivers them). One
/// exponential per sample: about ten times cheaper than the 1 ms Euler steps it replaces, and
/// the dead time is continuous rather than a multiple of the step.
pub fn simulate(
    model: &SteeringModel,
    commands: &[(f64, f64)],
    sample_times: &[f64],
    start: f64,
    approach: f64,
    out: &mut [f64],
) -> f64 {
    let Some(&t_first) = sample_times.first() else {
        return 0.0;
    };
    let mut s = State {
        act: start + 0.5 * model.backlash * approach.clamp(-1.0, 1.0),
        wheel: start,
    };
    let d = model.dead_time;
    // Commands in force (their time plus the dead time reached).
    let mut in_force = commands
        .iter()
        .take_while(|(tc, _)| tc + d <= t_first)
        .count();
    let mut bound = 0.0;
    let mut t = t_first;
    for (&ts, o) in sample_times.iter().zip(out.iter_mut()) {
        while t < ts {
            let target = match in_force {
                0 => start,
                k => commands[k - 1].1,
            };
            let switch = commands.get(in_force).map_or(f64::INFINITY, |c| c.0 + d);
            let end = ts.min(switch);
            bound += s.advance(model, target, end - t);
            t = end;
            while commands.get(in_force).is_some_and(|c| c.0 + d <= t) {
                in_force += 1;
            }
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
        simulate(&m, &[(0.0, 0.1)], &ts, 0.0, 0.0, &mut out);
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
        simulate(&m, &[(0.0, 0.2), (2.0, 0.1)], &ts, 0.0, 0.0, &mut out);
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
        simulate(&m, &[(0.0, 0.1)], &ts, 0.0, 0.0, &mut out);
        assert!((out[99] - 0.09).abs() < 1e-4, "{}", out[99]);
        let t = m.to_true(1.1);
        assert!((t.deadband - 0.01 / 1.1).abs() < 1e-12 && t.tau == 0.05);
    }
    /// The closed form against a fine Euler integration of the same equations (a step of
    /// 10 µs), with every part of the model at work: dead time, lag, rate limit, deadband,
    /// play, and commands between the samples.
    #[test]
    fn the_exact_response_matches_a_fine_euler_integration() {
        let m = SteeringModel {
            dead_time: 0.083,
            tau: 0.21,
            rate: 0.35,
            deadband: 0.004,
            backlash: 0.007,
        };
        let commands = [
            (0.013, 0.3),
            (2.005, -0.25),
            (4.3, 0.05),
            (4.347, 0.06),
            (6.0, 0.04),
            (7.5, 0.0),
        ];
        let ts = times(900, 0.01);
        let mut out = vec![0.0; ts.len()];
        simulate(&m, &commands, &ts, 0.0, 1.0, &mut out);
        // The Euler reference.
        let h = 1e-5;
        let (mut act, mut wheel): (f64, f64) = (0.5 * m.backlash, 0.0);
        let mut t = 0.0;
        let mut max_diff: f64 = 0.0;
        for (ts, o) in ts.iter().zip(&out) {
            while t + 0.5 * h < *ts {
                let target = commands
                    .iter()
                    .rev()
                    .find(|c| c.0 + m.dead_time <= t)
                    .map_or(0.0, |c| c.1);
                let mut err = target - act;
                err = if err.abs() <= m.deadband {
                    0.0
                } else {
                    err - m.deadband * err.signum()
                };
                act += (err / m.tau).clamp(-m.rate, m.rate) * h;
                let half = 0.5 * m.backlash;
                wheel = wheel.clamp(act - half, act + half);
                t += h;
            }
            max_diff = max_diff.max((wheel - o).abs());
        }
        assert!(max_diff < 1e-4, "{max_diff}");
    }
}
