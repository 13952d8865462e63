//! The true vehicle's body: a kinematic bicycle about the rear-axle centre, or with
//! [`LateralDynamics`] a dynamic single-track model with tyre slip; the terrain's roll and
//! pitch under it and where its antenna is.

use super::{Disturbances, LateralDynamics, SimParams};
use crate::geo::{heading_vec, left_normal, wrap_angle, Vec2};

/// Standard gravity, m/s².
const GRAVITY: f64 = 9.80665;

/// Below this rolling speed the tyres get a viscous lateral damping that fades out linearly
/// as the speed rises to it, m/s. With the relaxation-length model alone a tyre is an undamped
/// lateral spring at standstill (the force builds with distance rolled, not with time), and the
/// vehicle would rock on it; real tyres damp that by hysteresis. Above this speed the model is
/// the plain linear one (Pacejka, *Tyre and Vehicle Dynamics*, treats low-speed tyre transients
/// the same way: a damping term switched off as speed rises).
const LOW_SPEED: f64 = 1.0;

/// A lateral force `f` (N) limited to `max` (N): unchanged up to 70 % of it, then bending
/// smoothly (continuous slope) towards the limit.
fn saturate(f: f64, max: f64) -> f64 {
    let knee = 0.7 * max;
    if f.abs() <= knee {
        return f;
    }
    let span = max - knee;
    f.signum() * (knee + span * ((f.abs() - knee) / span).tanh())
}

/// The body's state.
#[derive(Debug, Clone)]
pub(super) struct Body {
    /// Rear-axle centre, local ENU, m.
    pub x: f64,
    pub y: f64,
    /// Yaw, rad CCW from East.
    pub heading: f64,
    /// Longitudinal speed (the driver's), m/s; negative reverses.
    pub speed: f64,
    /// Lateral velocity of the rear-axle centre in the body frame, m/s (positive left); 0 for
    /// the kinematic model.
    pub v_lat: f64,
    /// Yaw rate, rad/s (of the last step).
    pub yaw_rate: f64,
    /// Lateral forces of the front and rear axle's tyres in the tyre frame, N (positive left).
    f_front: f64,
    f_rear: f64,
}

impl Body {
    pub(super) fn new(x: f64, y: f64, heading: f64, speed: f64) -> Self {
        Body {
            x,
            y,
            heading,
            speed,
            v_lat: 0.0,
            yaw_rate: 0.0,
            f_front: 0.0,
            f_rear: 0.0,
        }
    }

    /// Roll (rad, positive right side down) and pitch (rad, positive nose up) of the vehicle
    /// on the terrain where it stands.
    pub(super) fn attitude(&self, d: &Disturbances) -> (f64, f64) {
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

    /// The antenna's position, local ENU, m.
    pub(super) fn antenna(&self, p: &SimParams) -> Vec2 {
        let h = heading_vec(self.heading);
        let base =
            Vec2::new(self.x, self.y) + h * p.antenna_forward + left_normal(&h) * p.antenna_left;
        if !p.dist.terrain_on() {
            return base;
        }
        // The antenna mast leans with the vehicle: roll (right side down) moves it right,
        // pitch (nose up) moves it back.
        let (roll, pitch) = self.attitude(&p.dist);
        base - left_normal(&h) * (p.antenna_up * roll.sin()) - h * (p.antenna_up * pitch.sin())
    }

    /// The direction of the antenna's velocity over ground, rad CCW from East (the heading
    /// when standing still).
    pub(super) fn antenna_course(&self, p: &SimParams) -> f64 {
        // Body-frame velocity of a point (f, l) from the rear axle: (u − r·l, v + r·f).
        let vx = self.speed - self.yaw_rate * p.antenna_left;
        let vy = self.v_lat + self.yaw_rate * p.antenna_forward;
        if vx.hypot(vy) < 1e-3 {
            return self.heading;
        }
        wrap_angle(self.heading + vy.atan2(vx))
    }

    /// One integration step of `p.step` s with the front wheels at `wheel` (rad).
    pub(super) fn step(&mut self, p: &SimParams, wheel: f64) {
        let h = p.step;
        let mid = match &p.lateral {
            None => {
                // Kinematic bicycle, midpoint heading.
                let yaw_rate = self.speed * wheel.tan() / p.wheelbase;
                let mid = self.heading + 0.5 * h * yaw_rate;
                self.x += self.speed * mid.cos() * h;
                self.y += self.speed * mid.sin() * h;
                self.heading = wrap_angle(self.heading + yaw_rate * h);
                self.yaw_rate = yaw_rate;
                mid
            }
            Some(l) => self.dynamic_step(p, l, wheel),
        };
        let d = &p.dist;
        if d.slip != 0.0 || d.slip_per_roll != 0.0 {
            let (roll, _) = self.attitude(d);
            let v_right = (d.slip + d.slip_per_roll * roll) * (self.speed.abs() / 0.5).min(1.0);
            let right = -left_normal(&heading_vec(mid));
            self.x += right.x * v_right * h;
            self.y += right.y * v_right * h;
        }
    }

    /// The dynamic single-track model (see [`LateralDynamics`]); returns the step's midpoint
    /// heading.
    ///
    /// With u the longitudinal speed, v the rear axle's lateral velocity and r the yaw rate,
    /// the front axle moves at (u, v + L·r) in the body frame. Each axle's tyres slide sideways
    /// (in the tyre frame) at s and roll at w; their lateral force F relaxes towards the
    /// steady −C·s/|w| (= C·α) over the relaxation length σ: σ·Ḟ = −C·s − |w|·F, written
    /// without a division by the speed so that it holds down to standstill. The forces, gravity
    /// on a side slope (at the centre of gravity) and the implement's side draft (at the hitch)
    /// drive m·(v̇_cg + u·r) = ΣF_y and I_z·ṙ = ΣM_z about the centre of gravity, b ahead of the
    /// rear axle (v_cg = v + b·r). The longitudinal speed is the driver's.
    fn dynamic_step(&mut self, p: &SimParams, l: &LateralDynamics, wheel: f64) -> f64 {
        let h = p.step;
        let wb = p.wheelbase;
        let b = l.cg_ahead_of_rear;
        let a = wb - b;
        let (u, v, r) = (self.speed, self.v_lat, self.yaw_rate);
        let (sin_d, cos_d) = wheel.sin_cos();
        let v_front = v + wb * r;
        let roll_front = u * cos_d + v_front * sin_d;
        let slide_front = -u * sin_d + v_front * cos_d;
        let (roll_rear, slide_rear) = (u, v);
        let sigma = l.relaxation_length;
        // Exact over the step for the slide held constant.
        let relax = |f: f64, c: f64, slide: f64, rolling: f64| {
            let w = rolling.abs();
            let x = w * h / sigma;
            let decay = (-x).exp();
            let gain = if x > 1e-12 {
                -(-x).exp_m1() / w
            } else {
                h / sigma
            };
            f * decay - c * slide * gain
        };
        self.f_front = relax(
            self.f_front,
            l.cornering_stiffness_front,
            slide_front,
            roll_front,
        );
        self.f_rear = relax(
            self.f_rear,
            l.cornering_stiffness_rear,
            slide_rear,
            roll_rear,
        );
        let damping = |c: f64, slide: f64, rolling: f64| {
            let fade = (1.0 - rolling.abs() / LOW_SPEED).max(0.0);
            -c / LOW_SPEED * fade * slide
        };
        // Each axle's force saturates at μ times its load.
        let load_front = l.mass * GRAVITY * b / wb;
        let load_rear = l.mass * GRAVITY * a / wb;
        let front = saturate(
            self.f_front + damping(l.cornering_stiffness_front, slide_front, roll_front),
            l.friction * load_front,
        );
        let rear = saturate(
            self.f_rear + damping(l.cornering_stiffness_rear, slide_rear, roll_rear),
            l.friction * load_rear,
        );
        // The tyre's deflection (the relaxed force) cannot build far past sliding either.
        self.f_front = self.f_front.clamp(
            -2.0 * l.friction * load_front,
            2.0 * l.friction * load_front,
        );
        self.f_rear = self
            .f_rear
            .clamp(-2.0 * l.friction * load_rear, 2.0 * l.friction * load_rear);
        let (roll, _) = self.attitude(&p.dist);
        // Positive roll is right side down: gravity pulls to the right (negative lateral).
        let gravity = -l.mass * GRAVITY * roll.sin();
        let side = -l.side_force;
        let force = front * cos_d + rear + gravity + side;
        // Moments about the centre of gravity: the front axle a ahead, the rear b behind, the
        // hitch b + hitch behind.
        let moment = a * front * cos_d - b * rear - (b + l.hitch_behind_rear) * side;
        let r_dot = moment / l.yaw_inertia;
        let v_cg_dot = force / l.mass - u * r;
        let v_dot = v_cg_dot - b * r_dot;
        let r_new = r + r_dot * h;
        let v_new = v + v_dot * h;
        let r_mid = 0.5 * (r + r_new);
        let v_mid = 0.5 * (v + v_new);
        let mid = self.heading + 0.5 * h * r_mid;
        let f = heading_vec(mid);
        let left = left_normal(&f);
        self.x += (f.x * u + left.x * v_mid) * h;
        self.y += (f.y * u + left.y * v_mid) * h;
        self.heading = wrap_angle(self.heading + r_mid * h);
        self.yaw_rate = r_new;
        self.v_lat = v_new;
        mid
    }
}
