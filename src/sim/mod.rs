//! The vehicle simulator (SPEC §6), in process: a kinematic bicycle at a fine internal step,
//! a steering actuator with dead time, first-order lag, rate and angle limits, GNSS with
//! noise, rate and latency, and a noisy wheel-angle sensor. Deterministic for a given seed.
//!
//! Disturbances, each off by default ([`Disturbances`]): correlated GNSS error (first-order
//! Gauss-Markov), multipath jumps, RTK-float windows (larger error, float fix status),
//! terrain roll and pitch (the antenna height moves the measured position, an IMU reports the
//! attitude), side-slope slip, wheel-angle sensor bias, actuator deadband and backlash. They
//! draw from their own random stream, so switching one on leaves the others' noise unchanged.
//!
//! Ground truth ([`Simulator::true_state`]) is the model's own state: scoring uses it, never an
//! estimate. The same model drives the simulator on CAN.

pub mod can_node;

use crate::geo::{heading_vec, left_normal, wrap_angle, Pose, Vec2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// Simulator parameters, SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct SimParams {
    /// Wheelbase, m.
    pub wheelbase: f64,
    /// Largest front-wheel angle, rad.
    pub max_wheel_angle: f64,
    /// Antenna position from the rear-axle centre: forward, left, up, m.
    pub antenna_forward: f64,
    pub antenna_left: f64,
    pub antenna_up: f64,
    /// Actuator dead time, s.
    pub dead_time: f64,
    /// Actuator first-order lag time constant, s.
    pub tau: f64,
    /// Actuator rate limit, rad/s.
    pub max_rate: f64,
    /// GNSS update rate, Hz.
    pub gnss_rate_hz: f64,
    /// GNSS latency from measurement to delivery, s.
    pub gnss_latency: f64,
    /// GNSS position white noise σ per axis, m.
    pub gnss_sigma: f64,
    /// Dual-antenna heading noise σ, rad.
    pub heading_sigma: f64,
    /// Speed noise σ, m/s.
    pub speed_sigma: f64,
    /// Wheel-angle sensor rate, Hz.
    pub was_rate_hz: f64,
    /// Wheel-angle sensor noise σ, rad.
    pub was_noise: f64,
    /// Internal integration step, s.
    pub step: f64,
    /// Random seed.
    pub seed: u64,
    /// Acceleration and braking towards a requested speed (direction requests), m/s².
    pub accel: f64,
    /// Disturbances, all off by default.
    pub dist: Disturbances,
}

/// Simulator disturbances, SI units. The default is none at all.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Disturbances {
    /// Correlated GNSS position error per axis: first-order Gauss-Markov, stationary σ (m) and
    /// time constant (s). Off when σ = 0.
    pub gnss_markov_sigma: f64,
    pub gnss_markov_tau: f64,
    /// Multipath jumps: mean rate, 1/s; magnitude (random direction), m; duration, s.
    pub multipath_rate: f64,
    pub multipath_magnitude: f64,
    pub multipath_duration: f64,
    /// RTK-float windows (start, duration), s of simulated time. Inside one the fix is
    /// reported as RTK float and a Gauss-Markov error (σ m, τ s) is added per axis.
    pub float_windows: Vec<(f64, f64)>,
    pub float_sigma: f64,
    pub float_tau: f64,
    /// Terrain: slope angle (rad) falling towards `terrain_downhill` (rad, CCW from East),
    /// varying by `terrain_slope_amp` (rad) sinusoidally with `terrain_wavelength` (m) along the
    /// contour direction (downhill turned 90° left).
    pub terrain_slope: f64,
    pub terrain_downhill: f64,
    pub terrain_slope_amp: f64,
    pub terrain_wavelength: f64,
    /// IMU attitude output rate, Hz (0 = no IMU), and its noise σ, rad.
    pub imu_rate_hz: f64,
    pub imu_noise: f64,
    /// Lateral slip to the right (downhill for positive roll), m/s per rad of roll, and a
    /// constant lateral slip to the right, m/s. Applied while moving (full above 0.5 m/s).
    pub slip_per_roll: f64,
    pub slip: f64,
    /// Wheel-angle sensor bias, rad: added to the reported angle, and the steering
    /// controller, which closes its position loop on that sensor, holds the wheels at the
    /// command minus the bias (so a tracker that trusts the sensor steers off by the bias).
    pub was_bias: f64,
    /// Actuator deadband: no motion while the delayed command is within this of the actuator
    /// position, rad (half-width).
    pub deadband: f64,
    /// Backlash (total play) between the actuator and the wheels, rad.
    pub backlash: f64,
}

impl Disturbances {
    fn terrain_on(&self) -> bool {
        self.terrain_slope != 0.0 || self.terrain_slope_amp != 0.0
    }
}

impl Default for SimParams {
    fn default() -> Self {
        SimParams {
            wheelbase: 3.0,
            max_wheel_angle: 35f64.to_radians(),
            antenna_forward: 0.0,
            antenna_left: 0.0,
            antenna_up: 0.0,
            dead_time: 0.05,
            tau: 0.15,
            max_rate: 30f64.to_radians(),
            gnss_rate_hz: 10.0,
            gnss_latency: 0.05,
            gnss_sigma: 0.01,
            heading_sigma: 0.1f64.to_radians(),
            speed_sigma: 0.01,
            was_rate_hz: 100.0,
            was_noise: 0.05f64.to_radians(),
            step: 0.001,
            seed: 1,
            accel: 0.5,
            dist: Disturbances::default(),
        }
    }
}

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
    /// Heading with noise, rad CCW from East.
    pub heading: f64,
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
    /// Speed, m/s.
    pub speed: f64,
    /// Actual front-wheel angle, rad.
    pub wheel_angle: f64,
    /// Antenna position, local ENU, m.
    pub antenna: Vec2,
    /// Roll (rad, positive right side down) and pitch (rad, positive nose up).
    pub roll: f64,
    pub pitch: f64,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SimError {
    #[error("sim parameter {name} = {value}: {rule}")]
    Invalid {
        name: &'static str,
        value: f64,
        rule: &'static str,
    },
}

/// The simulator.
#[derive(Debug, Clone)]
pub struct Simulator {
    p: SimParams,
    k: u64,
    x: f64,
    y: f64,
    heading: f64,
    speed: f64,
    wheel: f64,
    command: f64,
    delay: VecDeque<f64>,
    next_gnss: u64,
    gnss_every: u64,
    next_was: u64,
    was_every: u64,
    pending: VecDeque<GnssMeasurement>,
    rng: ChaCha8Rng,
    fix: FixQuality,
    /// Speed the driver (or the tractor's speed control) is heading for, m/s.
    speed_target: Option<f64>,
    /// Actuator position before the backlash, rad (equal to `wheel` without backlash).
    act: f64,
    /// Random stream of the disturbances.
    rng_dist: ChaCha8Rng,
    /// Gauss-Markov GNSS error (E, N), m.
    markov: Vec2,
    /// RTK-float Gauss-Markov error (E, N), m.
    float_err: Vec2,
    /// Current multipath jump and when it ends, s.
    multipath: Vec2,
    multipath_until: f64,
    next_imu: u64,
    imu_every: u64,
}

impl Simulator {
    /// Check parameters.
    pub fn validate(p: &SimParams) -> Result<(), SimError> {
        let check = |name: &'static str, v: f64, ok: bool, rule: &'static str| {
            if ok && v.is_finite() {
                Ok(())
            } else {
                Err(SimError::Invalid {
                    name,
                    value: v,
                    rule,
                })
            }
        };
        check(
            "step",
            p.step,
            p.step > 0.0 && p.step <= 0.1,
            "must be in (0, 0.1] s",
        )?;
        check("wheelbase", p.wheelbase, p.wheelbase > 0.0, "must be > 0")?;
        check(
            "gnss_rate_hz",
            p.gnss_rate_hz,
            p.gnss_rate_hz > 0.0,
            "must be > 0",
        )?;
        check(
            "was_rate_hz",
            p.was_rate_hz,
            p.was_rate_hz > 0.0,
            "must be > 0",
        )?;
        check("dead_time", p.dead_time, p.dead_time >= 0.0, "must be >= 0")?;
        check("tau", p.tau, p.tau >= 0.0, "must be >= 0")?;
        check("max_rate", p.max_rate, p.max_rate > 0.0, "must be > 0")?;
        check("accel", p.accel, p.accel > 0.0, "must be > 0")?;
        check(
            "gnss_latency",
            p.gnss_latency,
            p.gnss_latency >= 0.0,
            "must be >= 0",
        )?;
        for (n, v) in [
            ("gnss_sigma", p.gnss_sigma),
            ("heading_sigma", p.heading_sigma),
            ("speed_sigma", p.speed_sigma),
            ("was_noise", p.was_noise),
            ("gnss_markov_sigma", p.dist.gnss_markov_sigma),
            ("multipath_rate", p.dist.multipath_rate),
            ("multipath_magnitude", p.dist.multipath_magnitude),
            ("multipath_duration", p.dist.multipath_duration),
            ("float_sigma", p.dist.float_sigma),
            ("imu_rate_hz", p.dist.imu_rate_hz),
            ("imu_noise", p.dist.imu_noise),
            ("deadband", p.dist.deadband),
            ("backlash", p.dist.backlash),
        ] {
            check(n, v, v >= 0.0, "must be >= 0")?;
        }
        let d = &p.dist;
        if d.gnss_markov_sigma > 0.0 {
            check(
                "gnss_markov_tau",
                d.gnss_markov_tau,
                d.gnss_markov_tau > 0.0,
                "must be > 0",
            )?;
        }
        if !d.float_windows.is_empty() {
            check("float_tau", d.float_tau, d.float_tau > 0.0, "must be > 0")?;
        }
        for &(start, duration) in &d.float_windows {
            check("float_windows start", start, start >= 0.0, "must be >= 0")?;
            check(
                "float_windows duration",
                duration,
                duration > 0.0,
                "must be > 0",
            )?;
        }
        if d.terrain_on() {
            check(
                "terrain_wavelength",
                d.terrain_wavelength,
                d.terrain_wavelength > 0.0,
                "must be > 0",
            )?;
        }
        for (n, v) in [
            ("terrain_slope", d.terrain_slope),
            ("terrain_downhill", d.terrain_downhill),
            ("terrain_slope_amp", d.terrain_slope_amp),
            ("slip_per_roll", d.slip_per_roll),
            ("slip", d.slip),
            ("was_bias", d.was_bias),
        ] {
            check(n, v, true, "must be finite")?;
        }
        Ok(())
    }

    /// A vehicle at `initial` (rear axle) moving at `speed` (m/s).
    pub fn try_new(params: SimParams, initial: Pose, speed: f64) -> Result<Self, SimError> {
        Simulator::validate(&params)?;
        let delay_len = (params.dead_time / params.step).round() as usize;
        let every = |hz: f64| ((1.0 / hz / params.step).round() as u64).max(1);
        let mut sim = Simulator {
            k: 0,
            x: initial.pos.x,
            y: initial.pos.y,
            heading: initial.heading,
            speed: if speed.is_finite() { speed } else { 0.0 },
            wheel: 0.0,
            command: 0.0,
            delay: std::iter::repeat_n(0.0, delay_len).collect(),
            next_gnss: 0,
            gnss_every: every(params.gnss_rate_hz),
            next_was: 0,
            was_every: every(params.was_rate_hz),
            pending: VecDeque::with_capacity(64),
            rng: ChaCha8Rng::seed_from_u64(params.seed),
            fix: FixQuality::RtkFixed,
            speed_target: None,
            act: 0.0,
            rng_dist: {
                let mut r = ChaCha8Rng::seed_from_u64(params.seed);
                r.set_stream(1);
                r
            },
            markov: Vec2::zeros(),
            float_err: Vec2::zeros(),
            multipath: Vec2::zeros(),
            multipath_until: f64::NEG_INFINITY,
            next_imu: if params.dist.imu_rate_hz > 0.0 {
                0
            } else {
                u64::MAX
            },
            imu_every: if params.dist.imu_rate_hz > 0.0 {
                every(params.dist.imu_rate_hz)
            } else {
                u64::MAX
            },
            p: params,
        };
        // The correlated errors start from their stationary distributions.
        if sim.p.dist.gnss_markov_sigma > 0.0 {
            let sd = sim.p.dist.gnss_markov_sigma;
            sim.markov = Vec2::new(sim.dist_noise(sd), sim.dist_noise(sd));
        }
        if !sim.p.dist.float_windows.is_empty() {
            let sd = sim.p.dist.float_sigma;
            sim.float_err = Vec2::new(sim.dist_noise(sd), sim.dist_noise(sd));
        }
        Ok(sim)
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

    /// The latest steering command (rad). Non-finite commands are ignored.
    pub fn set_command(&mut self, wheel_angle: f64) {
        if wheel_angle.is_finite() {
            self.command = wheel_angle;
        }
    }

    /// Set the speed (m/s, negative reverses).
    pub fn set_speed(&mut self, speed: f64) {
        if speed.is_finite() {
            self.speed = speed;
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

    fn noise(&mut self, sigma: f64) -> f64 {
        if sigma == 0.0 {
            return 0.0;
        }
        let z: f64 = StandardNormal.sample(&mut self.rng);
        z * sigma
    }

    fn dist_noise(&mut self, sigma: f64) -> f64 {
        if sigma == 0.0 {
            return 0.0;
        }
        let z: f64 = StandardNormal.sample(&mut self.rng_dist);
        z * sigma
    }

    /// Roll (rad, positive right side down) and pitch (rad, positive nose up) of the vehicle
    /// on the terrain where it stands.
    pub fn attitude(&self) -> (f64, f64) {
        let d = &self.p.dist;
        if !d.terrain_on() {
            return (0.0, 0.0);
        }
        let down = heading_vec(d.terrain_downhill);
        let contour = left_normal(&down);
        let along = Vec2::new(self.x, self.y).dot(&contour);
        let slope = d.terrain_slope
            + d.terrain_slope_amp * (std::f64::consts::TAU * along / d.terrain_wavelength).sin();
        let grade = slope.tan();
        let f = heading_vec(self.heading);
        let right = -left_normal(&f);
        let roll = (grade * down.dot(&right)).atan();
        let pitch = (-grade * down.dot(&f)).atan();
        (roll, pitch)
    }

    fn antenna(&self) -> Vec2 {
        let h = heading_vec(self.heading);
        let base = Vec2::new(self.x, self.y)
            + h * self.p.antenna_forward
            + left_normal(&h) * self.p.antenna_left;
        if !self.p.dist.terrain_on() {
            return base;
        }
        // The antenna mast leans with the vehicle: roll (right side down) moves it right,
        // pitch (nose up) moves it back.
        let (roll, pitch) = self.attitude();
        base - left_normal(&h) * (self.p.antenna_up * roll.sin())
            - h * (self.p.antenna_up * pitch.sin())
    }

    fn in_float_window(&self, t: f64) -> bool {
        self.p
            .dist
            .float_windows
            .iter()
            .any(|&(start, duration)| t >= start && t < start + duration)
    }

    /// The disturbance part of the GNSS position error at a fix measured at `now`.
    fn gnss_disturbance(&mut self, now: f64) -> Vec2 {
        let dt = self.gnss_every as f64 * self.p.step;
        let mut e = Vec2::zeros();
        let d = self.p.dist.clone();
        if d.gnss_markov_sigma > 0.0 {
            // Exact discretisation of dx = -x/τ dt + σ·sqrt(2/τ) dW over one GNSS period.
            let phi = (-dt / d.gnss_markov_tau).exp();
            let q = d.gnss_markov_sigma * (1.0 - phi * phi).sqrt();
            self.markov = self.markov * phi + Vec2::new(self.dist_noise(q), self.dist_noise(q));
            e += self.markov;
        }
        if d.multipath_rate > 0.0 && d.multipath_magnitude > 0.0 {
            if now >= self.multipath_until {
                self.multipath = Vec2::zeros();
                let p = 1.0 - (-d.multipath_rate * dt).exp();
                let u: f64 = self.rng_dist.gen();
                let dir: f64 = self.rng_dist.gen::<f64>() * std::f64::consts::TAU;
                if u < p {
                    self.multipath = heading_vec(dir) * d.multipath_magnitude;
                    self.multipath_until = now + d.multipath_duration;
                }
            }
            if now < self.multipath_until {
                e += self.multipath;
            }
        }
        if !d.float_windows.is_empty() {
            let phi = (-dt / d.float_tau).exp();
            let q = d.float_sigma * (1.0 - phi * phi).sqrt();
            self.float_err =
                self.float_err * phi + Vec2::new(self.dist_noise(q), self.dist_noise(q));
            if self.in_float_window(now) {
                e += self.float_err;
            }
        }
        e
    }

    /// The true state now.
    pub fn true_state(&self) -> TrueState {
        let (roll, pitch) = self.attitude();
        TrueState {
            pose: Pose::new(self.x, self.y, self.heading),
            speed: self.speed,
            wheel_angle: self.wheel,
            antenna: self.antenna(),
            roll,
            pitch,
        }
    }

    fn step_once(&mut self) {
        let h = self.p.step;
        // Actuator: dead time, then first-order lag bounded by the rate, then the angle limit.
        let delayed = if self.delay.is_empty() {
            self.command
        } else {
            let d = self.delay.pop_front().unwrap_or(self.command);
            self.delay.push_back(self.command);
            d
        };
        // The steering controller servos the sensed angle (true + bias) to the command.
        let target =
            (delayed - self.p.dist.was_bias).clamp(-self.p.max_wheel_angle, self.p.max_wheel_angle);
        let mut err = target - self.act;
        let db = self.p.dist.deadband;
        if db > 0.0 {
            // The actuator does not act on errors inside its deadband.
            err = if err.abs() <= db {
                0.0
            } else {
                err - db * err.signum()
            };
        }
        let rate = if self.p.tau > 0.0 {
            err / self.p.tau
        } else {
            err / h
        };
        let rate = rate.clamp(-self.p.max_rate, self.p.max_rate);
        self.act = (self.act + rate * h).clamp(-self.p.max_wheel_angle, self.p.max_wheel_angle);
        let play = self.p.dist.backlash;
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
        if let Some(target) = self.speed_target {
            let dv = self.p.accel * h;
            self.speed += (target - self.speed).clamp(-dv, dv);
        }
        // Kinematic bicycle, midpoint heading.
        let yaw_rate = self.speed * self.wheel.tan() / self.p.wheelbase;
        let mid = self.heading + 0.5 * h * yaw_rate;
        self.x += self.speed * mid.cos() * h;
        self.y += self.speed * mid.sin() * h;
        self.heading = wrap_angle(self.heading + yaw_rate * h);
        let d = &self.p.dist;
        if d.slip != 0.0 || d.slip_per_roll != 0.0 {
            let (roll, _) = self.attitude();
            let v_right = (d.slip + d.slip_per_roll * roll) * (self.speed.abs() / 0.5).min(1.0);
            let right = -left_normal(&heading_vec(mid));
            self.x += right.x * v_right * h;
            self.y += right.y * v_right * h;
        }
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
                let angle = self.wheel + self.noise(self.p.was_noise) + self.p.dist.was_bias;
                out.push(SimOutput::WheelAngle { t: now, angle });
                self.next_was += self.was_every;
            }
            if self.k >= self.next_imu {
                let (roll, pitch) = self.attitude();
                let sd = self.p.dist.imu_noise;
                let roll = roll + self.dist_noise(sd);
                let pitch = pitch + self.dist_noise(sd);
                out.push(SimOutput::Attitude {
                    t: now,
                    roll,
                    pitch,
                });
                self.next_imu = self.next_imu.saturating_add(self.imu_every);
            }
            if self.k >= self.next_gnss {
                let ant = self.antenna();
                let mut antenna = Vec2::new(
                    ant.x + self.noise(self.p.gnss_sigma),
                    ant.y + self.noise(self.p.gnss_sigma),
                );
                let heading = wrap_angle(self.heading + self.noise(self.p.heading_sigma));
                let speed = self.speed + self.noise(self.p.speed_sigma);
                let d = &self.p.dist;
                if d.gnss_markov_sigma > 0.0
                    || d.multipath_rate > 0.0
                    || !d.float_windows.is_empty()
                {
                    antenna += self.gnss_disturbance(now);
                }
                let m = GnssMeasurement {
                    t_measured: now,
                    t_delivered: now + self.p.gnss_latency,
                    antenna,
                    heading,
                    speed,
                    fix: if self.in_float_window(now) {
                        FixQuality::RtkFloat
                    } else {
                        self.fix
                    },
                };
                self.pending.push_back(m);
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
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(sim: &mut Simulator, until: f64) -> Vec<SimOutput> {
        let mut out = Vec::new();
        sim.advance_to(until, &mut out);
        out
    }

    #[test]
    fn same_seed_same_outputs() {
        let mk = |seed| {
            let p = SimParams {
                seed,
                ..SimParams::default()
            };
            let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 3.0);
            s.set_command(0.1);
            run(&mut s, 5.0)
        };
        assert_eq!(mk(7), mk(7));
        assert_ne!(mk(7), mk(8));
    }

    #[test]
    fn constant_angle_drives_a_circle() {
        let p = SimParams::default();
        let delta: f64 = 0.2;
        let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, 0.0), 2.0);
        s.set_command(delta);
        run(&mut s, 3.0);
        // After the transient the yaw rate is v·tanδ/L: check the radius from the heading change.
        let a = s.true_state();
        run(&mut s, 6.0);
        let b = s.true_state();
        let dth = wrap_angle(b.pose.heading - a.pose.heading);
        let r = 2.0 * 3.0 / dth;
        let expect = p.wheelbase / delta.tan();
        assert!((r - expect).abs() / expect < 1e-3, "r {r} vs {expect}");
    }

    #[test]
    fn dead_time_and_rate_limit() {
        let p = SimParams {
            tau: 0.0,
            ..SimParams::default()
        };
        let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, 0.0), 1.0);
        s.set_command(0.5);
        let mut out = Vec::new();
        let mut prev = 0.0;
        let mut first_move = None;
        for k in 1..=1000 {
            let t = k as f64 * 0.001;
            s.advance_to(t, &mut out);
            let w = s.true_state().wheel_angle;
            assert!(
                (w - prev).abs() <= p.max_rate * p.step + 1e-12,
                "rate limit"
            );
            if w != 0.0 && first_move.is_none() {
                first_move = Some(t);
            }
            prev = w;
        }
        let t0 = first_move.unwrap();
        assert!((t0 - p.dead_time).abs() <= 2.0 * p.step, "moved at {t0}");
        assert!(prev <= p.max_wheel_angle);
    }

    #[test]
    fn gnss_rate_latency_and_noise() {
        let p = SimParams::default();
        let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, 0.0), 0.0);
        let out = run(&mut s, 1000.0);
        let fixes: Vec<GnssMeasurement> = out
            .iter()
            .filter_map(|o| match o {
                SimOutput::Gnss(m) => Some(*m),
                _ => None,
            })
            .collect();
        assert!((fixes.len() as i64 - 10_000).abs() <= 1, "{}", fixes.len());
        for w in fixes.windows(2) {
            assert!((w[1].t_measured - w[0].t_measured - 0.1).abs() < 1e-9);
        }
        assert!(fixes
            .iter()
            .all(|m| (m.t_delivered - m.t_measured - 0.05).abs() < 1e-12));
        let n = fixes.len() as f64;
        let var = fixes.iter().map(|m| m.antenna.x.powi(2)).sum::<f64>() / n;
        assert!((var.sqrt() - 0.01).abs() < 0.0005, "σ {}", var.sqrt());
        let was = out
            .iter()
            .filter(|o| matches!(o, SimOutput::WheelAngle { .. }))
            .count();
        assert!((was as i64 - 100_000).abs() <= 1);
    }

    #[test]
    fn antenna_forward_offset_is_ahead() {
        let p = SimParams {
            antenna_forward: 2.0,
            gnss_sigma: 0.0,
            ..SimParams::default()
        };
        let s = Simulator::new(p, Pose::new(1.0, 1.0, std::f64::consts::FRAC_PI_2), 0.0);
        let t = s.true_state();
        assert!((t.antenna - Vec2::new(1.0, 3.0)).norm() < 1e-12);
    }

    #[test]
    fn bad_parameters_are_errors() {
        let p = SimParams {
            step: 0.0,
            ..SimParams::default()
        };
        assert!(Simulator::try_new(p, Pose::new(0.0, 0.0, 0.0), 1.0).is_err());
        let mut s = Simulator::new(SimParams::default(), Pose::new(0.0, 0.0, 0.0), 1.0);
        s.set_command(f64::NAN);
        run(&mut s, 1.0);
        assert!(s.true_state().pose.pos.x.is_finite());
    }

    // ---- Disturbances -------------------------------------------------------------------

    fn quiet() -> SimParams {
        SimParams {
            gnss_sigma: 0.0,
            heading_sigma: 0.0,
            speed_sigma: 0.0,
            was_noise: 0.0,
            ..SimParams::default()
        }
    }

    fn fixes(out: &[SimOutput]) -> Vec<GnssMeasurement> {
        out.iter()
            .filter_map(|o| match o {
                SimOutput::Gnss(m) => Some(*m),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn disturbances_draw_from_their_own_stream() {
        // A correlated GNSS error leaves the white noise of every other output unchanged.
        let mut a = Simulator::new(SimParams::default(), Pose::new(0.0, 0.0, 0.0), 3.0);
        let mut b = Simulator::new(
            SimParams {
                dist: Disturbances {
                    gnss_markov_sigma: 0.02,
                    gnss_markov_tau: 10.0,
                    ..Disturbances::default()
                },
                ..SimParams::default()
            },
            Pose::new(0.0, 0.0, 0.0),
            3.0,
        );
        a.set_command(0.05);
        b.set_command(0.05);
        let (oa, ob) = (run(&mut a, 20.0), run(&mut b, 20.0));
        assert_eq!(oa.len(), ob.len());
        let mut moved = 0;
        for (x, y) in oa.iter().zip(&ob) {
            match (x, y) {
                (SimOutput::Gnss(p), SimOutput::Gnss(q)) => {
                    assert_eq!((p.heading, p.speed), (q.heading, q.speed));
                    moved += usize::from(p.antenna != q.antenna);
                }
                _ => assert_eq!(x, y),
            }
        }
        assert!(moved > 100);
    }

    #[test]
    fn gauss_markov_sigma_and_autocorrelation() {
        let (sigma, tau) = (0.015, 30.0);
        let p = SimParams {
            dist: Disturbances {
                gnss_markov_sigma: sigma,
                gnss_markov_tau: tau,
                ..Disturbances::default()
            },
            ..quiet()
        };
        let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 0.0);
        // 200 000 s at 10 Hz: about 6 700 time constants.
        let mut out = Vec::new();
        let mut xs = Vec::with_capacity(2_000_001);
        let mut t = 0.0;
        while t < 200_000.0 {
            t += 1000.0;
            out.clear();
            s.advance_to(t, &mut out);
            xs.extend(fixes(&out).iter().map(|m| m.antenna.x));
        }
        let n = xs.len() as f64;
        let mean = xs.iter().sum::<f64>() / n;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
        let sd = var.sqrt();
        assert!((sd - sigma).abs() < 0.05 * sigma, "σ {sd}");
        let lag1 = xs
            .windows(2)
            .map(|w| (w[0] - mean) * (w[1] - mean))
            .sum::<f64>()
            / (n - 1.0)
            / var;
        let expect = (-0.1f64 / tau).exp();
        assert!((lag1 - expect).abs() < 2e-4, "ρ1 {lag1} vs {expect}");
        // Correlated over τ: lag 300 (30 s) ≈ e^-1.
        let lag_tau = xs
            .windows(301)
            .map(|w| (w[0] - mean) * (w[300] - mean))
            .sum::<f64>()
            / (n - 300.0)
            / var;
        assert!((lag_tau - (-1f64).exp()).abs() < 0.05, "ρ(τ) {lag_tau}");
    }

    #[test]
    fn multipath_jumps_at_the_configured_rate_magnitude_and_duration() {
        let p = SimParams {
            dist: Disturbances {
                multipath_rate: 20.0 / 3600.0,
                multipath_magnitude: 0.3,
                multipath_duration: 5.0,
                ..Disturbances::default()
            },
            ..quiet()
        };
        let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 0.0);
        let f = fixes(&run(&mut s, 36_000.0));
        let jumped: Vec<&GnssMeasurement> = f.iter().filter(|m| m.antenna.norm() > 1e-9).collect();
        for m in &jumped {
            assert!((m.antenna.norm() - 0.3).abs() < 1e-9);
        }
        // Each jump lasts 5 s (50 fixes); 200 expected in 10 h.
        let starts = f
            .windows(2)
            .filter(|w| w[0].antenna.norm() < 1e-9 && w[1].antenna.norm() > 1e-9)
            .count();
        assert!((150..=250).contains(&starts), "{starts} jumps");
        let per_jump = jumped.len() as f64 / starts as f64;
        assert!((per_jump - 50.0).abs() <= 1.0, "{per_jump} fixes per jump");
    }

    #[test]
    fn rtk_float_window_reports_float_and_a_larger_error() {
        let p = SimParams {
            dist: Disturbances {
                float_windows: vec![(10.0, 20.0)],
                float_sigma: 0.2,
                float_tau: 5.0,
                ..Disturbances::default()
            },
            ..quiet()
        };
        let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 0.0);
        let f = fixes(&run(&mut s, 40.0));
        for m in &f {
            let inside = m.t_measured >= 10.0 - 1e-9 && m.t_measured < 30.0 - 1e-9;
            if inside {
                assert_eq!(m.fix, FixQuality::RtkFloat, "t {}", m.t_measured);
            } else {
                assert_eq!(m.fix, FixQuality::RtkFixed, "t {}", m.t_measured);
                assert!(m.antenna.norm() < 1e-12);
            }
        }
        let err: f64 = f
            .iter()
            .filter(|m| m.fix == FixQuality::RtkFloat)
            .map(|m| m.antenna.norm())
            .fold(0.0, f64::max);
        assert!(err > 0.05, "float error {err}");
    }

    fn on_slope(deg: f64, up: f64) -> SimParams {
        SimParams {
            antenna_up: up,
            dist: Disturbances {
                terrain_slope: deg.to_radians(),
                // Downhill to the East.
                terrain_downhill: 0.0,
                terrain_wavelength: 100.0,
                imu_rate_hz: 10.0,
                ..Disturbances::default()
            },
            ..quiet()
        }
    }

    #[test]
    fn roll_moves_the_antenna_sideways_by_height_times_sin_roll() {
        // Heading north across a slope falling East: right side down, roll +2°.
        let north = std::f64::consts::FRAC_PI_2;
        let mut s = Simulator::new(on_slope(2.0, 3.0), Pose::new(0.0, 0.0, north), 0.0);
        let out = run(&mut s, 1.0);
        let (roll, pitch) = s.attitude();
        assert!((roll - 2f64.to_radians()).abs() < 1e-3, "roll {roll}");
        assert!(pitch.abs() < 1e-12);
        let shift = 3.0 * 2f64.to_radians().sin();
        assert!((shift - 0.1047).abs() < 1e-3);
        for m in fixes(&out) {
            // Moved right (East), not along the track.
            assert!((m.antenna.x - shift).abs() < 1e-3, "{}", m.antenna.x);
            assert!(m.antenna.y.abs() < 1e-12);
        }
        // The IMU reports it, in degrees on the bus: here in rad.
        let att: Vec<(f64, f64)> = out
            .iter()
            .filter_map(|o| match o {
                SimOutput::Attitude { roll, pitch, .. } => Some((*roll, *pitch)),
                _ => None,
            })
            .collect();
        assert_eq!(att.len(), 11);
        assert!(att.iter().all(|(r, _)| (r - roll).abs() < 1e-12));
        // Coming back south the other side is down; the antenna still leans downhill (East).
        let s = Simulator::new(on_slope(2.0, 3.0), Pose::new(0.0, 0.0, -north), 0.0);
        assert!((s.attitude().0 + 2f64.to_radians()).abs() < 1e-3);
        assert!((s.true_state().antenna.x - shift).abs() < 1e-3);
        // Driving downhill (East) pitches the nose down.
        let s = Simulator::new(on_slope(2.0, 3.0), Pose::new(0.0, 0.0, 0.0), 0.0);
        let (r, p) = s.attitude();
        assert!(r.abs() < 1e-12 && (p + 2f64.to_radians()).abs() < 1e-3);
    }

    #[test]
    fn terrain_varies_with_the_wavelength() {
        let mut p = on_slope(0.0, 0.0);
        p.dist.terrain_slope_amp = 3f64.to_radians();
        p.dist.terrain_wavelength = 40.0;
        let north = std::f64::consts::FRAC_PI_2;
        // Contour direction (downhill East turned left) is North: quarter wavelength → peak.
        let roll_at = |y: f64| {
            Simulator::new(p.clone(), Pose::new(0.0, y, north), 0.0)
                .attitude()
                .0
        };
        assert!(roll_at(0.0).abs() < 1e-12);
        assert!((roll_at(10.0) - 3f64.to_radians()).abs() < 1e-3);
        assert!((roll_at(30.0) + 3f64.to_radians()).abs() < 1e-3);
        assert!((roll_at(50.0) - roll_at(10.0)).abs() < 1e-9);
    }

    #[test]
    fn slip_moves_the_vehicle_downhill_at_the_configured_rate() {
        // 2° roll, 0.015 m/s per degree → 3 cm/s to the right (East) while driving north.
        let mut p = on_slope(2.0, 0.0);
        p.dist.slip_per_roll = 0.015f64.to_degrees();
        let north = std::f64::consts::FRAC_PI_2;
        let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, north), 3.0);
        run(&mut s, 100.0);
        let t = s.true_state();
        let rate = t.pose.pos.x / 100.0;
        let roll_deg = 2f64.to_radians().tan().atan().to_degrees();
        assert!((rate - 0.015 * roll_deg).abs() < 1e-6, "slip {rate} m/s");
        // Heading unchanged: it crabs, it does not turn.
        assert!((t.pose.heading - north).abs() < 1e-12);
        // Southward the downhill side is the right too: still East.
        let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, -north), 3.0);
        run(&mut s, 100.0);
        assert!((s.true_state().pose.pos.x / 100.0 - rate).abs() < 1e-6);
        // Flat ground: no slip.
        p.dist.terrain_slope = 0.0;
        let mut s = Simulator::new(p, Pose::new(0.0, 0.0, north), 3.0);
        run(&mut s, 100.0);
        assert!(s.true_state().pose.pos.x.abs() < 1e-12);
        // A constant slip needs no slope, and none while standing still.
        let p = SimParams {
            dist: Disturbances {
                slip: 0.02,
                ..Disturbances::default()
            },
            ..quiet()
        };
        let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, 0.0), 2.0);
        run(&mut s, 50.0);
        assert!((s.true_state().pose.pos.y + 1.0).abs() < 1e-6);
        let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 0.0);
        run(&mut s, 50.0);
        assert!(s.true_state().pose.pos.norm() < 1e-12);
    }

    fn was_mean(out: &[SimOutput], from: f64) -> f64 {
        let v: Vec<f64> = out
            .iter()
            .filter_map(|o| match o {
                SimOutput::WheelAngle { t, angle } if *t >= from => Some(*angle),
                _ => None,
            })
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    }

    #[test]
    fn was_bias_appears_in_the_reported_angle_and_offsets_the_wheels() {
        let bias = 0.5f64.to_radians();
        let p = SimParams {
            dist: Disturbances {
                was_bias: bias,
                ..Disturbances::default()
            },
            ..SimParams::default()
        };
        let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 2.0);
        s.set_command(0.1);
        let out = run(&mut s, 20.0);
        // The steering controller servos the biased reading to the command: the wheels sit
        // at command − bias, the sensor reads the command.
        assert!((s.true_state().wheel_angle - (0.1 - bias)).abs() < 1e-9);
        let m = was_mean(&out, 5.0);
        assert!((m - 0.1).abs() < 2e-4, "mean {m}");
    }

    #[test]
    fn deadband_holds_small_commands() {
        let db = 0.5f64.to_radians();
        let p = SimParams {
            dist: Disturbances {
                deadband: db,
                ..Disturbances::default()
            },
            ..quiet()
        };
        let mut s = Simulator::new(p.clone(), Pose::new(0.0, 0.0, 0.0), 2.0);
        s.set_command(0.8 * db);
        run(&mut s, 5.0);
        assert_eq!(s.true_state().wheel_angle, 0.0);
        // A larger command moves the wheels, to within the deadband of it.
        s.set_command(5.0 * db);
        run(&mut s, 10.0);
        let w = s.true_state().wheel_angle;
        assert!((w - 4.0 * db).abs() < 1e-6, "{w}");
        // Without the deadband it gets there.
        let mut s = Simulator::new(quiet(), Pose::new(0.0, 0.0, 0.0), 2.0);
        s.set_command(0.8 * db);
        run(&mut s, 5.0);
        assert!((s.true_state().wheel_angle - 0.8 * db).abs() < 1e-9);
    }

    #[test]
    fn backlash_is_lost_at_a_reversal() {
        let play = 1f64.to_radians();
        let p = SimParams {
            dist: Disturbances {
                backlash: play,
                ..Disturbances::default()
            },
            ..quiet()
        };
        let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 2.0);
        s.set_command(0.1);
        run(&mut s, 5.0);
        // Moving left the wheels trail the actuator by half the play (the play is centred).
        let w1 = s.true_state().wheel_angle;
        assert!((w1 - (0.1 - 0.5 * play)).abs() < 1e-6, "{w1}");
        // Reverse by less than the play: the wheels don't move.
        s.set_command(0.1 - 0.9 * play);
        run(&mut s, 10.0);
        assert!((s.true_state().wheel_angle - w1).abs() < 1e-12);
        // Reverse further: the wheels move only by what is beyond the play.
        s.set_command(0.05);
        run(&mut s, 15.0);
        let w2 = s.true_state().wheel_angle;
        assert!((w2 - (0.05 + 0.5 * play)).abs() < 1e-6, "{w2}");
        // Actuator travel 0.05, wheel travel 0.05 - play.
        assert!(((w1 - w2) - (0.05 - play)).abs() < 1e-6);
    }

    #[test]
    fn disturbed_runs_are_deterministic_by_seed() {
        let mk = |seed| {
            let p = SimParams {
                seed,
                antenna_up: 3.0,
                dist: Disturbances {
                    gnss_markov_sigma: 0.015,
                    gnss_markov_tau: 30.0,
                    multipath_rate: 0.01,
                    multipath_magnitude: 0.1,
                    multipath_duration: 2.0,
                    float_windows: vec![(5.0, 5.0)],
                    float_sigma: 0.2,
                    float_tau: 10.0,
                    terrain_slope: 0.03,
                    terrain_downhill: 0.3,
                    terrain_slope_amp: 0.02,
                    terrain_wavelength: 30.0,
                    imu_rate_hz: 50.0,
                    imu_noise: 0.001,
                    slip_per_roll: 1.0,
                    slip: 0.01,
                    was_bias: 0.01,
                    deadband: 0.002,
                    backlash: 0.01,
                },
                ..SimParams::default()
            };
            let mut s = Simulator::new(p, Pose::new(0.0, 0.0, 0.0), 3.0);
            s.set_command(0.1);
            run(&mut s, 20.0)
        };
        assert_eq!(mk(3), mk(3));
        assert_ne!(mk(3), mk(4));
    }
}
