//! The vehicle simulator (docs/METHODS.md, The simulator), in process: the true vehicle at a fine
//! internal step, a steering actuator with dead time, first-order lag, rate and angle limits, GNSS
//! with noise, rate and latency, and a noisy wheel-angle sensor. Deterministic for a given seed.
//!
//! The plant is not the controller's model: the true wheelbase, antenna position and
//! wheel-angle sensor gain and offset are the simulator's own ([`SimParams`]), and the body is
//! a kinematic bicycle or, with [`LateralDynamics`], a dynamic single-track model whose tyres
//! slip more the harder it turns and the faster it goes, with an optional implement side
//! draft ([`vehicle`](self) has the equations).
//!
//! Disturbances, each off by default ([`Disturbances`]): correlated GNSS error (first-order
//! Gauss-Markov), multipath jumps, RTK-float windows (larger error, float fix status),
//! terrain roll and pitch (the antenna height moves the measured position, an IMU reports the
//! attitude), side-slope slip, wheel-angle sensor bias, actuator deadband and backlash. They
//! draw from their own random stream, so switching one on leaves the others' noise unchanged.
//!
//! Ground truth ([`Simulator::true_state`]) is the model's own state: scoring uses it, never an
//! estimate. The same model drives the simulator on CAN.

mod actuator;
pub mod can_node;
mod gnss_error;
pub mod gnss_stream;
mod params;
pub mod steer_ready;
mod vehicle;

pub use params::{Disturbances, LateralDynamics, SimError, SimParams};

use crate::geo::{wrap_angle, Pose, Vec2};
use actuator::Actuator;
use gnss_error::{normal, GnssError};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;
use vehicle::Body;

/// GNSS solution quality.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FixQuality {
    RtkFixed,
    RtkFloat,
    Dgps,
    Single,
    None,
}

/// One GNSS measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssMeasurement {
    /// When the antenna was where it says, s.
    pub t_measured: f64,
    /// When it reaches the controller, s.
    pub t_delivered: f64,
    /// Antenna position with noise, local ENU, m.
    pub antenna: Vec2,
    /// Heading (dual antenna) with noise, rad CCW from East.
    pub heading: f64,
    /// Course over ground of the antenna with the same noise, rad CCW from East (differs from
    /// the heading while the vehicle slips, or turns with the antenna off the rear axle).
    pub course: f64,
    /// Speed with noise, m/s.
    pub speed: f64,
    pub fix: FixQuality,
}

/// A sensor output, in time order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SimOutput {
    Gnss(GnssMeasurement),
    /// Measured front-wheel angle (rad) at `t` (s).
    WheelAngle {
        t: f64,
        angle: f64,
    },
    /// Measured roll (rad, positive right side down) and pitch (rad, positive nose up) at `t`.
    Attitude {
        t: f64,
        roll: f64,
        pitch: f64,
    },
}

/// The simulator's true state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrueState {
    /// Rear-axle pose.
    pub pose: Pose,
    /// Longitudinal speed, m/s.
    pub speed: f64,
    /// Lateral velocity of the rear-axle centre in the body frame, m/s (positive left; 0
    /// without the dynamic lateral model unless a kinematic slip disturbance is on, which is
    /// not counted here).
    pub lateral_velocity: f64,
    /// Yaw rate, rad/s.
    pub yaw_rate: f64,
    /// Actual front-wheel angle, rad.
    pub wheel_angle: f64,
    /// Antenna position, local ENU, m.
    pub antenna: Vec2,
    /// Roll (rad, positive right side down) and pitch (rad, positive nose up).
    pub roll: f64,
    pub pitch: f64,
}

/// The simulator.
#[derive(Debug, Clone)]
pub struct Simulator {
    p: SimParams,
    k: u64,
    body: Body,
    actuator: Actuator,
    next_gnss: u64,
    gnss_every: u64,
    next_was: u64,
    was_every: u64,
    pending: VecDeque<GnssMeasurement>,
    rng: ChaCha8Rng,
    fix: FixQuality,
    /// Speed the driver (or the tractor's speed control) is heading for, m/s.
    speed_target: Option<f64>,
    /// Random stream of the disturbances.
    rng_dist: ChaCha8Rng,
    gnss_error: GnssError,
    next_imu: u64,
    imu_every: u64,
}

impl Simulator {
    /// Check parameters.
    pub fn validate(p: &SimParams) -> Result<(), SimError> {
        p.validate()
    }

    /// A vehicle at `initial` (rear axle) moving at `speed` (m/s).
    pub fn try_new(params: SimParams, initial: Pose, speed: f64) -> Result<Self, SimError> {
        params.validate()?;
        let every = |hz: f64| ((1.0 / hz / params.step).round() as u64).max(1);
        let mut rng_dist = ChaCha8Rng::seed_from_u64(params.seed);
        rng_dist.set_stream(1);
        let gnss_error = GnssError::new(&params.dist, &mut rng_dist);
        let imu = params.dist.imu_rate_hz > 0.0;
        Ok(Simulator {
            k: 0,
            body: Body::new(
                initial.pos.x,
                initial.pos.y,
                initial.heading,
                if speed.is_finite() { speed } else { 0.0 },
            ),
            actuator: Actuator::new(&params),
            next_gnss: 0,
            gnss_every: every(params.gnss_rate_hz),
            next_was: 0,
            was_every: every(params.was_rate_hz),
            pending: VecDeque::with_capacity(64),
            rng: ChaCha8Rng::seed_from_u64(params.seed),
            fix: FixQuality::RtkFixed,
            speed_target: None,
            rng_dist,
            gnss_error,
            next_imu: if imu { 0 } else { u64::MAX },
            imu_every: if imu {
                every(params.dist.imu_rate_hz)
            } else {
                u64::MAX
            },
            p: params,
        })
    }

    /// Like [`Simulator::try_new`]; invalid parameters fall back to the defaults (logged).
    pub fn new(params: SimParams, initial: Pose, speed: f64) -> Self {
        match Simulator::try_new(params, initial, speed) {
            Ok(s) => s,
            Err(e) => {
                tracing::error!("{e}; using default simulator parameters");
                Simulator::try_new(SimParams::default(), initial, speed)
                    .unwrap_or_else(|_| unreachable!("defaults are valid"))
            }
        }
    }

    pub fn params(&self) -> &SimParams {
        &self.p
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.k as f64 * self.p.step
    }

    /// The latest steering command (rad, in the wheel-angle sensor's terms: the steering
    /// controller servos the sensor's reading to it). Non-finite commands are ignored.
    pub fn set_command(&mut self, wheel_angle: f64) {
        if wheel_angle.is_finite() {
            self.actuator.set_command(wheel_angle);
        }
    }

    /// Change the steering actuator's lag (s, ≥ 0) from now on: a steering whose behaviour
    /// changes (hydraulic oil warming, a fault), for the calibration's consistency checks.
    pub fn set_actuator_tau(&mut self, tau: f64) {
        if tau.is_finite() && tau >= 0.0 {
            self.p.tau = tau;
        }
    }

    /// The driver holds the wheels: the actuator stays where it is.
    pub fn hold_wheels(&mut self) {
        self.actuator.hold(&self.p);
    }

    /// The driver has been steering along a path of curvature `curvature` (1/m, positive
    /// left; non-finite ignored) at the present speed and holds the wheels there until a
    /// command comes: a job started on an arc starts with the arc's steering, not with the
    /// wheels straight. The true vehicle's steady angle: atan(L·κ), plus K·u²·κ with the
    /// dynamic lateral model's understeer gradient K.
    pub fn hold_curvature(&mut self, curvature: f64) {
        if !curvature.is_finite() {
            return;
        }
        let understeer = self
            .p
            .lateral
            .as_ref()
            .map_or(0.0, |l| l.understeer_gradient(self.p.wheelbase));
        let u = self.body.speed;
        let angle = (self.p.wheelbase * curvature).atan() + understeer * u * u * curvature;
        self.actuator.set_wheel(&self.p, angle);
    }

    /// The driver centres the wheels and keeps straight: the actuator goes, at its rate, to
    /// where the sensor reads a true angle of zero.
    pub fn centre_wheels(&mut self) {
        self.actuator.set_command(self.p.dist.was_bias);
    }

    /// Set the speed (m/s, negative reverses).
    pub fn set_speed(&mut self, speed: f64) {
        if speed.is_finite() {
            self.body.speed = speed;
        }
    }

    /// Head for `speed` (m/s, negative reverses) at the acceleration `accel`, through zero
    /// when the direction changes (as a tractor obeying a direction request).
    pub fn set_speed_target(&mut self, speed: f64) {
        if speed.is_finite() {
            self.speed_target = Some(speed);
        }
    }

    /// Set the GNSS solution quality reported from now on.
    pub fn set_fix(&mut self, fix: FixQuality) {
        self.fix = fix;
    }

    /// Roll (rad, positive right side down) and pitch (rad, positive nose up) of the vehicle
    /// on the terrain where it stands.
    pub fn attitude(&self) -> (f64, f64) {
        self.body.attitude(&self.p.dist)
    }

    fn in_float_window(&self, t: f64) -> bool {
        self.p
            .dist
            .float_windows
            .iter()
            .any(|&(start, duration)| t >= start && t < start + duration)
    }

    /// The true state now.
    pub fn true_state(&self) -> TrueState {
        let (roll, pitch) = self.attitude();
        TrueState {
            pose: Pose::new(self.body.x, self.body.y, self.body.heading),
            speed: self.body.speed,
            lateral_velocity: self.body.v_lat,
            yaw_rate: self.body.yaw_rate,
            wheel_angle: self.actuator.wheel(),
            antenna: self.body.antenna(&self.p),
            roll,
            pitch,
        }
    }

    fn step_once(&mut self) {
        self.actuator.step(&self.p);
        if let Some(target) = self.speed_target {
            let dv = self.p.accel * self.p.step;
            self.body.speed += (target - self.body.speed).clamp(-dv, dv);
        }
        self.body.step(&self.p, self.actuator.wheel());
        self.k += 1;
    }

    /// Advance to absolute time `t` (s), appending every sensor output available by then, in
    /// time order.
    pub fn advance_to(&mut self, t: f64, out: &mut Vec<SimOutput>) {
        let target = if t.is_finite() {
            (t / self.p.step + 1e-9).floor().max(0.0) as u64
        } else {
            self.k
        };
        loop {
            let now = self.time();
            if self.k >= self.next_was {
                // (In this order: the same arithmetic as before the gain existed.)
                let noise = normal(&mut self.rng, self.p.was_noise);
                let angle = self.p.was_gain * self.actuator.wheel() + noise + self.p.dist.was_bias;
                out.push(SimOutput::WheelAngle { t: now, angle });
                self.next_was += self.was_every;
            }
            if self.k >= self.next_imu {
                let (roll, pitch) = self.attitude();
                let sd = self.p.dist.imu_noise;
                let roll = roll + normal(&mut self.rng_dist, sd);
                let pitch = pitch + normal(&mut self.rng_dist, sd);
                out.push(SimOutput::Attitude {
                    t: now,
                    roll,
                    pitch,
                });
                self.next_imu = self.next_imu.saturating_add(self.imu_every);
            }
            if self.k >= self.next_gnss {
                self.measure_gnss(now);
                self.next_gnss += self.gnss_every;
            }
            while self
                .pending
                .front()
                .is_some_and(|m| m.t_delivered <= now + 1e-9)
            {
                if let Some(m) = self.pending.pop_front() {
                    out.push(SimOutput::Gnss(m));
                }
            }
            if self.k >= target {
                break;
            }
            self.step_once();
        }
    }

    /// A GNSS measurement of now, queued for delivery after the latency.
    fn measure_gnss(&mut self, now: f64) {
        let ant = self.body.antenna(&self.p);
        let sigma = self.p.gnss_sigma;
        let mut antenna = Vec2::new(
            ant.x + normal(&mut self.rng, sigma),
            ant.y + normal(&mut self.rng, sigma),
        );
        let heading_noise = normal(&mut self.rng, self.p.heading_sigma);
        let bias = if now >= self.p.dist.heading_bias_at {
            self.p.dist.heading_bias
        } else {
            0.0
        };
        let heading = wrap_angle(self.body.heading + heading_noise + bias);
        let course = wrap_angle(self.body.antenna_course(&self.p) + heading_noise);
        let speed = self.body.speed + normal(&mut self.rng, self.p.speed_sigma);
        let in_float = self.in_float_window(now);
        if self.p.dist.gnss_error_on() {
            let dt = self.gnss_every as f64 * self.p.step;
            antenna += self
                .gnss_error
                .next(&self.p.dist, now, dt, in_float, &mut self.rng_dist);
        }
        self.pending.push_back(GnssMeasurement {
            t_measured: now,
            t_delivered: now + self.p.gnss_latency,
            antenna,
            heading,
            course,
            speed,
            fix: if in_float {
                FixQuality::RtkFloat
            } else {
                self.fix
            },
        });
    }
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_disturbances;
