//! The steering actuator of the true vehicle: the steering controller servos the wheel-angle
//! sensor's reading to the command, through a dead time, a first-order lag bounded by a rate
//! limit, an optional deadband, the angle limit and an optional backlash between the actuator
//! and the wheels.

use super::SimParams;
use std::collections::VecDeque;

#[derive(Debug, Clone)]
pub(super) struct Actuator {
    /// The latest command, rad (in the sensor's terms: what the sensor should read).
    command: f64,
    /// Commands waiting out the dead time, one per integration step.
    delay: VecDeque<f64>,
    /// Actuator position before the backlash, rad (equal to `wheel` without backlash).
    act: f64,
    /// True front-wheel angle, rad.
    wheel: f64,
}

impl Actuator {
    pub(super) fn new(p: &SimParams) -> Self {
        let delay_len = (p.dead_time / p.step).round() as usize;
        Actuator {
            command: 0.0,
            delay: std::iter::repeat_n(0.0, delay_len).collect(),
            act: 0.0,
            wheel: 0.0,
        }
    }

    pub(super) fn wheel(&self) -> f64 {
        self.wheel
    }

    pub(super) fn set_command(&mut self, angle: f64) {
        self.command = angle;
    }

    /// Hold the actuator where it is (the driver holds the wheels): command what the sensor
    /// reads at the actuator's position.
    pub(super) fn hold(&mut self, p: &SimParams) {
        self.command = p.was_gain * self.act + p.dist.was_bias;
    }

    /// Put the wheels (and the actuator behind them) at the true angle `angle` (rad, clamped to
    /// the angle limit) and hold them there, as a driver who has been steering at it.
    pub(super) fn set_wheel(&mut self, p: &SimParams, angle: f64) {
        let angle = angle.clamp(-p.max_wheel_angle, p.max_wheel_angle);
        self.act = angle;
        self.wheel = angle;
        self.hold(p);
        let command = self.command;
        self.delay.iter_mut().for_each(|c| *c = command);
    }

    /// One integration step of `p.step` s.
    pub(super) fn step(&mut self, p: &SimParams) {
        let h = p.step;
        let delayed = if self.delay.is_empty() {
            self.command
        } else {
            let d = self.delay.pop_front().unwrap_or(self.command);
            self.delay.push_back(self.command);
            d
        };
        // The steering controller servos the sensed angle (gain · true + offset) to the
        // command.
        let target =
            ((delayed - p.dist.was_bias) / p.was_gain).clamp(-p.max_wheel_angle, p.max_wheel_angle);
        let mut err = target - self.act;
        let db = p.dist.deadband;
        if db > 0.0 {
            // The actuator does not act on errors inside its deadband.
            err = if err.abs() <= db {
                0.0
            } else {
                err - db * err.signum()
            };
        }
        let rate = if p.tau > 0.0 { err / p.tau } else { err / h };
        let rate = rate.clamp(-p.max_rate, p.max_rate);
        self.act = (self.act + rate * h).clamp(-p.max_wheel_angle, p.max_wheel_angle);
        let play = p.dist.backlash;
        if play > 0.0 {
            // The wheels follow the actuator only once it has taken up the play.
            let half = 0.5 * play;
            if self.act - self.wheel > half {
                self.wheel = self.act - half;
            } else if self.act - self.wheel < -half {
                self.wheel = self.act + half;
            }
        } else {
            self.wheel = self.act;
        }
    }
}
