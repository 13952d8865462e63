//! Lost-motion compensation of the steering: an adaptive backlash inverse.
//!
//! Between the steering actuator and the wheels there is play (backlash), and the actuator's
//! own position loop stops inside a deadband. Together they are the steering's *lost motion*
//! `L`: a wheel pushed one way comes to rest `L` short of the command, and after a reversal
//! the actuator must travel `2·L` before the wheels move at all. Inside the lateral loop this
//! is a classic source of a limit cycle: on a straight line at 15 km/h, 0.5° of play and a
//! 0.1° deadband keep the tractor weaving by ±2 cm every few seconds while the command
//! hovers near zero and the wheels sit at the edge of the play.
//!
//! The inverse works on the measured wheel angle: while the wheels are more than a threshold
//! short of the demand one way, the command is pushed that way by the estimated lost motion,
//! and it stays pushed that way (holding the actuator against that side of the play) until the
//! wheels are beyond the demand by the threshold the other way. A wheel that stays short
//! after settling means the estimate is too small; one that comes to rest past the demand,
//! too large. The estimate learns from that settled residual, so it needs no calibration and
//! falls to zero on a vehicle without play. Reference: the adaptive backlash inverse of
//! Tao & Kokotović, *Adaptive Control of Systems with Actuator and Sensor Nonlinearities*
//! (Wiley 1996), here with the wheel-angle sensor closing the loop.

/// Lost-motion compensation parameters, SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LostMotionParams {
    /// Time constant of the estimate, s (0 = compensation off).
    pub tau: f64,
    /// The push direction changes only when the wheels are this far past the demand the
    /// other way, rad: above the wheel-angle sensor's noise.
    pub threshold: f64,
    /// Largest lost motion, rad.
    pub limit: f64,
    /// The estimate learns only this long after the push direction changed and while the
    /// demand is steady, s: the actuator has settled.
    pub settle: f64,
    /// The estimate a new job starts from, rad (calibration's measured lost motion).
    pub initial: f64,
}

/// Time constant of the demand's low-pass filter, s: about the actuator's dead time and lag,
/// so the filtered demand is where settled wheels would be.
const DEMAND_TAU: f64 = 0.2;
/// The demand is steady while its filtered value moves slower than this, rad/s (1°/s).
const STEADY_RATE: f64 = 0.0175;

/// The compensation's state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LostMotion {
    pub params: LostMotionParams,
    /// Estimated lost motion, rad (≥ 0).
    pub estimate: f64,
    /// Direction the wheels are being pushed: +1 left, −1 right, 0 not yet.
    push: f64,
    /// Time since the push direction last changed, s.
    since_flip: f64,
    /// The demand low-passed over [`DEMAND_TAU`], rad (NaN before the first update).
    demand_filtered: f64,
}

impl LostMotion {
    pub fn new(params: LostMotionParams, estimate: f64) -> Self {
        LostMotion {
            params,
            estimate: estimate.clamp(0.0, params.limit.max(0.0)),
            push: 0.0,
            since_flip: 0.0,
            demand_filtered: f64::NAN,
        }
    }

    /// New parameters; the learnt estimate (within the new limit) and the state are kept.
    pub fn set_params(&mut self, params: LostMotionParams) {
        self.params = params;
        self.estimate = self.estimate.clamp(0.0, params.limit.max(0.0));
    }

    /// The command (rad) for the `demand`ed sensed wheel angle (rad) given the latest
    /// `measured` one (rad), one control period `dt` (s) on; the estimate learns when
    /// `learning`. Non-finite inputs pass the demand through.
    pub fn command(&mut self, demand: f64, measured: f64, dt: f64, learning: bool) -> f64 {
        let p = self.params;
        if p.tau <= 0.0 || !(demand.is_finite() && measured.is_finite() && dt.is_finite()) {
            return demand;
        }
        let dt = dt.clamp(0.0, 1.0);
        let previous = self.demand_filtered;
        self.demand_filtered = if previous.is_finite() {
            previous + (demand - previous) * (dt / (DEMAND_TAU + dt))
        } else {
            demand
        };
        let steady =
            previous.is_finite() && (self.demand_filtered - previous).abs() <= STEADY_RATE * dt;
        let short = demand - measured;
        let push = if short > p.threshold {
            1.0
        } else if short < -p.threshold {
            -1.0
        } else {
            self.push
        };
        if push != self.push {
            self.push = push;
            self.since_flip = 0.0;
        } else {
            self.since_flip += dt;
        }
        if learning && steady && self.push != 0.0 && self.since_flip >= p.settle {
            // Settled: a wheel still short the pushed way means too little compensation.
            let residual = self.push * (self.demand_filtered - measured);
            self.estimate = (self.estimate + residual * dt / p.tau).clamp(0.0, p.limit);
        }
        demand + self.push * self.estimate
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Wheels behind play `play` (total) and an ideal actuator with a deadband `deadband`
    /// (half-width) reaching its target within one step.
    struct Steering {
        play: f64,
        deadband: f64,
        actuator: f64,
        wheel: f64,
    }

    impl Steering {
        fn step(&mut self, command: f64) {
            let err = command - self.actuator;
            if err.abs() > self.deadband {
                self.actuator = command - self.deadband * err.signum();
            }
            let half = 0.5 * self.play;
            if self.actuator - self.wheel > half {
                self.wheel = self.actuator - half;
            } else if self.actuator - self.wheel < -half {
                self.wheel = self.actuator + half;
            }
        }
    }

    fn params() -> LostMotionParams {
        LostMotionParams {
            tau: 2.0,
            threshold: 0.1f64.to_radians(),
            limit: 1f64.to_radians(),
            settle: 0.5,
            initial: 0.0,
        }
    }

    /// Drive a square wave of demands ±`amplitude` (period 6 s) through the steering for
    /// `time` s at 50 Hz; returns the compensation and the wheel's largest settled error.
    fn square_wave(steering: &mut Steering, amplitude: f64, time: f64) -> (LostMotion, f64) {
        let mut lm = LostMotion::new(params(), 0.0);
        let dt = 0.02;
        let mut worst: f64 = 0.0;
        for k in 0..(time / dt) as usize {
            let t = k as f64 * dt;
            let demand = if (t / 3.0) as usize % 2 == 0 {
                amplitude
            } else {
                -amplitude
            };
            let command = lm.command(demand, steering.wheel, dt, true);
            steering.step(command);
            // Settled error over the last second of each half period, late in the run.
            if t > time - 12.0 && t % 3.0 > 2.0 {
                worst = worst.max((steering.wheel - demand).abs());
            }
        }
        (lm, worst)
    }

    #[test]
    fn learns_the_lost_motion_and_puts_the_wheels_where_demanded() {
        let (play, deadband) = (0.5f64.to_radians(), 0.1f64.to_radians());
        let mut steering = Steering {
            play,
            deadband,
            actuator: 0.0,
            wheel: 0.0,
        };
        let (lm, worst) = square_wave(&mut steering, 1f64.to_radians(), 60.0);
        let lost = 0.5 * play + deadband;
        assert!(
            (lm.estimate - lost).abs() < 0.1 * lost,
            "estimate {:.3}° against {:.3}°",
            lm.estimate.to_degrees(),
            lost.to_degrees()
        );
        // Uncompensated, the wheels would rest 0.35° short.
        assert!(worst < 0.05f64.to_radians(), "{:.3}°", worst.to_degrees());
    }

    #[test]
    fn learns_nothing_on_steering_without_play() {
        let mut steering = Steering {
            play: 0.0,
            deadband: 0.0,
            actuator: 0.0,
            wheel: 0.0,
        };
        let (lm, worst) = square_wave(&mut steering, 1f64.to_radians(), 60.0);
        assert!(lm.estimate < 0.01f64.to_radians(), "{}", lm.estimate);
        assert!(worst < 1e-9);
    }

    #[test]
    fn an_overestimate_is_unlearnt() {
        let mut steering = Steering {
            play: 0.0,
            deadband: 0.0,
            actuator: 0.0,
            wheel: 0.0,
        };
        let mut lm = LostMotion::new(params(), 0.08f64.to_radians());
        for k in 0..3000 {
            let demand = if (k / 150) % 2 == 0 { 0.01 } else { -0.01 };
            let command = lm.command(demand, steering.wheel, 0.02, true);
            steering.step(command);
        }
        assert!(lm.estimate < 0.01f64.to_radians(), "{}", lm.estimate);
    }

    #[test]
    fn new_parameters_keep_the_estimate_within_the_new_limit() {
        let mut lm = LostMotion::new(params(), 0.5f64.to_radians());
        lm.set_params(LostMotionParams {
            tau: 10.0,
            ..params()
        });
        assert_eq!(lm.estimate, 0.5f64.to_radians());
        lm.set_params(LostMotionParams {
            limit: 0.2f64.to_radians(),
            ..params()
        });
        assert_eq!(lm.estimate, 0.2f64.to_radians());
    }

    #[test]
    fn off_or_bad_input_passes_the_demand_through() {
        let mut off = LostMotion::new(
            LostMotionParams {
                tau: 0.0,
                ..params()
            },
            0.01,
        );
        assert_eq!(off.command(0.1, 0.0, 0.02, true), 0.1);
        let mut on = LostMotion::new(params(), 0.01);
        assert_eq!(on.command(0.1, f64::NAN, 0.02, true), 0.1);
        assert!(on.command(f64::NAN, 0.0, 0.02, true).is_nan());
    }
}
