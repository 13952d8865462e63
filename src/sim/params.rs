//! The simulator's parameters: the true vehicle (which need not be the controller's model),
//! its sensors and actuator, and the disturbances. SI units throughout.

/// Simulator parameters, SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct SimParams {
    /// Wheelbase of the true vehicle, m.
    pub wheelbase: f64,
    /// Largest front-wheel angle, rad.
    pub max_wheel_angle: f64,
    /// True antenna position from the rear-axle centre: forward, left, up, m.
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
    /// Wheel-angle sensor gain: it reads `was_gain` × the true angle (+ `dist.was_bias`, its
    /// offset). 1 = a correct scale. The steering controller servos that reading to the
    /// command, so the wheels sit at (command − offset) / gain.
    pub was_gain: f64,
    /// Internal integration step, s.
    pub step: f64,
    /// Random seed.
    pub seed: u64,
    /// Acceleration and braking towards a requested speed (direction requests), m/s².
    pub accel: f64,
    /// The dynamic lateral model (tyre slip); `None` = the kinematic bicycle (no slip).
    pub lateral: Option<LateralDynamics>,
    /// Disturbances, all off by default.
    pub dist: Disturbances,
}

/// The dynamic lateral model of the true vehicle: a linear single-track (bicycle) model with
/// cornering stiffness per axle, first-order tyre relaxation over a relaxation length, mass
/// and yaw inertia, and an optional lateral force of a trailed implement at the hitch. With it
/// the vehicle slips more the harder it turns and the faster it goes: in a steady turn the
/// rear axle slips by α_r = m·(a/L)·a_y / C_r and the front needs δ = L/R + K·a_y, K the
/// understeer gradient ([`LateralDynamics::understeer_gradient`]). On a side slope gravity
/// pulls the vehicle downhill through the same tyres.
///
/// The defaults are an 8 t two-wheel-drive tractor on firm soil (front axle 40 % of the
/// weight): linear-range cornering stiffness of a few kN per degree per axle, as in published
/// tractor yaw models (e.g. Bevly, Gerdes & Bernard, "A new yaw dynamic model for improved
/// high speed control of a farm tractor", J. Dyn. Sys. Meas. Control 124, 2002); softer soil
/// has about half of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LateralDynamics {
    /// Mass, kg.
    pub mass: f64,
    /// Yaw moment of inertia about the centre of gravity, kg·m².
    pub yaw_inertia: f64,
    /// Centre of gravity ahead of the rear axle, m (0 < b < wheelbase).
    pub cg_ahead_of_rear: f64,
    /// Cornering stiffness of the front axle (both tyres), N/rad.
    pub cornering_stiffness_front: f64,
    /// Cornering stiffness of the rear axle (both tyres), N/rad.
    pub cornering_stiffness_rear: f64,
    /// Tyre relaxation length: the distance rolled for the lateral force to build up, m.
    pub relaxation_length: f64,
    /// Tyre-soil friction coefficient μ: an axle's lateral force saturates at μ times its
    /// load (linear up to 70 % of it, then smoothly to the limit), so at large slip angles the
    /// tyres slide instead of pulling ever harder.
    pub friction: f64,
    /// Implement side draft: a lateral force at the hitch, N, positive pulling to the right.
    pub side_force: f64,
    /// The hitch point behind the rear axle, m.
    pub hitch_behind_rear: f64,
}

impl Default for LateralDynamics {
    fn default() -> Self {
        LateralDynamics {
            mass: 8000.0,
            yaw_inertia: 18_000.0,
            cg_ahead_of_rear: 1.2,
            cornering_stiffness_front: 120_000.0,
            cornering_stiffness_rear: 240_000.0,
            relaxation_length: 0.6,
            friction: 0.6,
            side_force: 0.0,
            hitch_behind_rear: 1.0,
        }
    }
}

impl LateralDynamics {
    /// The understeer gradient K of the linear model, rad per m/s² of lateral acceleration:
    /// K = m/L · (b/C_f − a/C_r), with a the centre of gravity's distance to the front axle
    /// and b to the rear one. A steady turn of radius R at lateral acceleration a_y needs the
    /// front wheels at δ = L/R + K·a_y (small angles).
    pub fn understeer_gradient(&self, wheelbase: f64) -> f64 {
        let b = self.cg_ahead_of_rear;
        let a = wheelbase - b;
        self.mass / wheelbase
            * (b / self.cornering_stiffness_front - a / self.cornering_stiffness_rear)
    }

    /// The steady-state slip angle of the rear axle at lateral acceleration `a_y` (m/s²,
    /// positive to the left), rad: the angle by which the rear axle's velocity points outward
    /// of its heading (to the right in a left turn), so its lateral velocity is
    /// −u·tan α_r. Linear model: α_r = m·(a/L)·a_y / C_r, a the centre of gravity's distance
    /// to the front axle.
    pub fn rear_slip_angle(&self, wheelbase: f64, a_y: f64) -> f64 {
        let a = wheelbase - self.cg_ahead_of_rear;
        self.mass * a / wheelbase * a_y / self.cornering_stiffness_rear
    }
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
    /// Wheel-angle sensor bias (offset), rad: added to the reported angle, and the steering
    /// controller, which closes its position loop on that sensor, holds the wheels at the
    /// command minus the bias (so a tracker that trusts the sensor steers off by the bias).
    pub was_bias: f64,
    /// A wrong heading: from `heading_bias_at` (s) on, the reported heading (not the course
    /// over ground) is `heading_bias` (rad) off.
    pub heading_bias: f64,
    pub heading_bias_at: f64,
    /// Actuator deadband: no motion while the delayed command is within this of the actuator
    /// position, rad (half-width).
    pub deadband: f64,
    /// Backlash (total play) between the actuator and the wheels, rad.
    pub backlash: f64,
}

impl Disturbances {
    pub(super) fn terrain_on(&self) -> bool {
        self.terrain_slope != 0.0 || self.terrain_slope_amp != 0.0
    }

    pub(super) fn gnss_error_on(&self) -> bool {
        self.gnss_markov_sigma > 0.0 || self.multipath_rate > 0.0 || !self.float_windows.is_empty()
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
            was_gain: 1.0,
            step: 0.001,
            seed: 1,
            accel: 0.5,
            lateral: None,
            dist: Disturbances::default(),
        }
    }
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

fn check(name: &'static str, v: f64, ok: bool, rule: &'static str) -> Result<(), SimError> {
    if ok && v.is_finite() {
        Ok(())
    } else {
        Err(SimError::Invalid {
            name,
            value: v,
            rule,
        })
    }
}

impl SimParams {
    /// Check the parameters (every float finite and in its range).
    pub fn validate(&self) -> Result<(), SimError> {
        let p = self;
        check(
            "step",
            p.step,
            p.step > 0.0 && p.step <= 0.1,
            "must be in (0, 0.1] s",
        )?;
        check("wheelbase", p.wheelbase, p.wheelbase > 0.0, "must be > 0")?;
        check(
            "max_wheel_angle",
            p.max_wheel_angle,
            p.max_wheel_angle > 0.0 && p.max_wheel_angle < 1.5,
            "must be in (0, 1.5) rad",
        )?;
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
        check(
            "was_gain",
            p.was_gain,
            (0.5..=2.0).contains(&p.was_gain),
            "must be in [0.5, 2]",
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
            ("antenna_forward", p.antenna_forward),
            ("antenna_left", p.antenna_left),
            ("antenna_up", p.antenna_up),
            ("heading_bias", p.dist.heading_bias),
        ] {
            check(n, v, true, "must be finite")?;
        }
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
            ("heading_bias_at", p.dist.heading_bias_at),
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
        if let Some(l) = &p.lateral {
            l.validate(p.wheelbase)?;
        }
        Ok(())
    }
}

impl LateralDynamics {
    fn validate(&self, wheelbase: f64) -> Result<(), SimError> {
        check("mass", self.mass, self.mass > 0.0, "must be > 0 kg")?;
        check(
            "yaw_inertia",
            self.yaw_inertia,
            self.yaw_inertia > 0.0,
            "must be > 0 kg·m²",
        )?;
        check(
            "cg_ahead_of_rear",
            self.cg_ahead_of_rear,
            self.cg_ahead_of_rear > 0.0 && self.cg_ahead_of_rear < wheelbase,
            "must be between the axles (0 < b < wheelbase)",
        )?;
        check(
            "cornering_stiffness_front",
            self.cornering_stiffness_front,
            self.cornering_stiffness_front > 0.0,
            "must be > 0 N/rad",
        )?;
        check(
            "cornering_stiffness_rear",
            self.cornering_stiffness_rear,
            self.cornering_stiffness_rear > 0.0,
            "must be > 0 N/rad",
        )?;
        // The tyre force is a state (no division by the speed), so the model is defined down
        // to standstill only with a relaxation length.
        check(
            "relaxation_length",
            self.relaxation_length,
            self.relaxation_length >= 0.01,
            "must be >= 0.01 m",
        )?;
        check(
            "friction",
            self.friction,
            self.friction > 0.0,
            "must be > 0",
        )?;
        check("side_force", self.side_force, true, "must be finite")?;
        check(
            "hitch_behind_rear",
            self.hitch_behind_rear,
            self.hitch_behind_rear >= 0.0,
            "must be >= 0",
        )?;
        Ok(())
    }
}
