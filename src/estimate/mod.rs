//! Pose estimation (docs/METHODS.md, Estimation; docs/CONVENTIONS.md, Reference point): GNSS
//! antenna → rear-axle reference point, latency compensation and dead reckoning between fixes.
//!
//! A fix describes the antenna `gnss_latency` before it arrived, or the latency its own time
//! stamp gives ([`GnssFix::latency`], NMEA 0183 and UBX with a disciplined host clock). With
//! `predict` on, the estimator moves the rear-axle pose from that moment to `now + lead_time`
//! with the kinematic bicycle model (ẋ = v·cosθ, ẏ = v·sinθ, θ̇ = v·tanδ/L), using the measured
//! wheel angles of that interval: the latency compensation and the dead reckoning between
//! fixes. With `predict` off it returns the latest fix as it is: the seed's plain reference.
//! Allocation-free: the wheel-angle history is a fixed ring.

use crate::geo::{
    heading_vec, left_normal, rotate, small_sin_cos, v2, vec_heading, wrap_angle, Pose, Vec2,
};
use nalgebra::Vector4;

mod drift_memory;
mod lateral_filter;
mod noise;
mod significance;
mod wheel_history;
mod yaw_lag;
use drift_memory::DriftMemory;
use lateral_filter::LateralFilter;
use noise::{Noise, HEADING_NOISE_START, NOISE_START};

/// GNSS antenna position relative to the rear-axle centre, m.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AntennaOffset {
    pub forward: f64,
    pub left: f64,
    pub up: f64,
}

/// One GNSS solution as the controller received it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssFix {
    /// Arrival time on the controller clock, s.
    pub t_received: f64,
    /// Antenna position, local ENU, m.
    pub antenna: Vec2,
    /// Heading (rad, CCW from East) from a dual-antenna receiver, if any.
    pub heading: Option<f64>,
    /// Speed over ground, m/s (negative when reversing).
    pub speed: f64,
    /// Roll, rad, positive when the right side is down, if a roll signal is present.
    pub roll: Option<f64>,
    /// Time from the fix's time of validity to its arrival, s, when the sender's time stamp
    /// gives it (see [`crate::input::PositionInput::latency_s`]); `None` (NMEA 2000, or an
    /// undisciplined host clock): the configured [`EstimatorParams::gnss_latency`]. Used by
    /// the predicting estimator only.
    pub latency: Option<f64>,
}

/// Estimator parameters, SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct EstimatorParams {
    /// Wheelbase, m.
    pub wheelbase: f64,
    pub antenna: AntennaOffset,
    /// The fix describes the vehicle this long before it arrived, s (unless the fix carries
    /// its own latency).
    pub gnss_latency: f64,
    /// Compensate latency and dead-reckon between fixes.
    pub predict: bool,
    /// Extra prediction horizon past now (about the actuator dead time), s.
    pub lead_time: f64,
    /// Correct the antenna's lean with the fix's roll (lateral − up·sin roll); the plain
    /// pure-pursuit reference leaves it out.
    pub roll_compensation: bool,
    /// The disturbance observer (off by default).
    pub observer: ObserverParams,
}

/// The disturbance observer: Kalman-type filters on the innovation of each fix against the
/// pose predicted from the previous fix. Four slowly varying disturbances are estimated:
///
/// * a wheel-angle offset `b` (vehicle frame, rad: measured − true angle), from the heading
///   innovation: the predicted yaw rate uses v·tan(δ_measured − b)/L, so
///   Δθ ≈ −v·Δt/(L·cos²δ)·(b − b̂);
/// * a drift velocity `d` (world frame, m/s, e.g. slip on a slope without a roll signal), from
///   the lateral innovation Δl ≈ (d − d̂)·n·Δt, n the vehicle's left normal. Only the component
///   along n is observable on a straight pass; kept as a world vector, a drift that is fixed on
///   the ground (downhill) keeps its sign when the direction of travel flips, and per direction
///   of straight driving where a large one flips with it (a side draft's crab, [`drift_memory`]),
///   turning with the heading on curves where it is known to be the vehicle's;
/// * a side-slope slip coefficient `c` (vehicle frame, m/s per rad of roll), see
///   [`ObserverParams::slip_tau`], from the same lateral innovation;
/// * the tyres' cornering slip (rad per m/s² of lateral acceleration), see
///   [`ObserverParams::corner_slip_tau`], from the same lateral innovation in turns.
///
/// The offset's estimate moves by Δt/τ of the innovation's measurement of its error, a
/// first-order filter with time constant τ; τ starts at 3 s and grows with the time learnt up
/// to the configured value, as a Kalman filter's gain falls from its initial covariance to the
/// steady state. The drift and the two slips share one measurement and are estimated together
/// by a four-state Kalman filter ([`LateralFilter`]) tuned to the same time constants. Innovations
/// beyond a gate (5 cm lateral, 0.02 rad heading) are jumps, not drift: they are not learnt
/// from, and the estimator dead-reckons through them and through RTK-float periods
/// ([`ObserverParams::coast_max`]). The estimates enter the prediction, and the controller
/// steers the velocity (course) rather than the heading onto the path, which cancels the drift.
/// The innovation of two consecutive fixes telescopes: white position noise σ leaves about
/// σ/τ_drift of noise on the drift, heading noise σθ about σθ·L/(v·τ_bias) on the offset.
/// Reference: the disturbance-observer form of a Kalman filter on the path-relative error model,
/// e.g. Åström & Murray, *Feedback Systems*, ch. 7 (state estimation with integral
/// disturbance states).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObserverParams {
    /// Time constant of the wheel-angle offset estimate, s; 0 = off.
    pub bias_tau: f64,
    /// Time constant of the drift estimate, s; 0 = off.
    pub drift_tau: f64,
    /// Learns only above this speed, m/s.
    pub min_speed: f64,
    /// Learns the wheel-angle offset only above this speed, m/s (at least `min_speed`): its
    /// innovation is a heading change of v·δ/L, so its gain L/(v·τ) multiplies the heading's
    /// noise as the speed falls.
    pub offset_min_speed: f64,
    /// Largest wheel-angle offset, rad.
    pub bias_limit: f64,
    /// Largest drift speed, m/s.
    pub drift_limit: f64,
    /// Time constant of the slope-slip coefficient estimate at a roll of 2°, s; 0 = off.
    /// Side-slope slip is about proportional to the slope: a vehicle-frame lateral velocity
    /// −c·sin(roll) (to the right, downhill, for positive roll). The regressor of a fix
    /// interval is the mean of the rolls at its two ends: the antenna's lean makes roll noise
    /// a position error, which the latest roll alone would correlate with the innovation. The
    /// slip follows a slope that varies along the pass, which a drift estimate can only chase,
    /// and it keeps doing so while coasting.
    pub slip_tau: f64,
    /// Largest slip coefficient, m/s per rad of roll.
    pub slip_limit: f64,
    /// Time constant of the cornering-slip estimate, s; 0 = off. Dynamic tyres slip sideways
    /// as they carry a turn's lateral acceleration a_y = v·ω: the rear axle's slip angle is
    /// about proportional to it (its tyres' share of the centripetal force over their
    /// cornering stiffness), so the rear axle moves at c·v·a_y to the outside of the turn.
    /// The kinematic model leaves that out: an RTK float that began half-way round a turn on
    /// soft tyres was dead-reckoned 16 cm off the next line (docs/envelope.md, Session 32: the
    /// tyres' cornering slip learnt and steered about).
    /// Learnt from the lateral innovation wherever the vehicle turns (regressor −v·a_y, with
    /// the model's yaw rate) jointly with the drift, which it is told apart from by turning
    /// with the vehicle and scaling with v·a_y; every prediction moves the rear axle by it.
    /// Its time constant holds at v·a_y = 3 m²/s³ (10 km/h round r 7 m).
    pub corner_slip_tau: f64,
    /// While the fix is RTK float, dead-reckon the position from the last fixed one (with the
    /// measured heading, the measured wheel angles less the offset, and the drift) instead of
    /// taking the float positions, for at most this long, s; 0 = off.
    pub coast_max: f64,
    /// Robust to the receiver: estimate the fixes' noise from the innovations and widen the
    /// gates with it (3.5 σ of the innovation, never below the fixed ones), and coast through a
    /// jump only while it is a step (a lateral offset from the dead reckoning that stays put):
    /// an offset that keeps growing is the dead reckoning going wrong (a model error), and the
    /// fixes are taken again. Off: the fixed gates and a jump coasts until the fixes agree.
    pub robust: bool,
    /// Smooth the position: the pose handed out is the dead reckoning corrected by a Kalman
    /// gain towards each fix, for a dead-reckoning error that grows by this much per 0.1 s
    /// (m) against the estimated noise of the fixes (needs `robust`); 0 = each fix is taken
    /// as it is. The observer learns from the raw fixes either way.
    pub position_process: f64,
}

impl Default for ObserverParams {
    fn default() -> Self {
        ObserverParams {
            bias_tau: 0.0,
            drift_tau: 0.0,
            min_speed: 1.0,
            offset_min_speed: 1.0,
            bias_limit: 3f64.to_radians(),
            drift_limit: 0.3,
            slip_tau: 0.0,
            slip_limit: 3.0,
            corner_slip_tau: 0.0,
            coast_max: 0.0,
            robust: false,
            position_process: 0.0,
        }
    }
}

/// Innovations larger than these are not learnt from: lateral m (3.5 σ of the innovation of two
/// fixes with 1 cm noise each), heading rad. A lateral one while moving is a jump (multipath,
/// a float solution's onset): while RTK fixed, the estimator dead-reckons through it until the
/// fixes agree with it again, for at most [`ObserverParams::coast_max`].
const GATE_LATERAL: f64 = 0.05;
const GATE_HEADING: f64 = 0.02;
/// With [`ObserverParams::robust`]: the lateral gate is this many standard deviations of the
/// innovation (σ·√2 for two fixes of noise σ each).
const GATE_SIGMAS: f64 = 3.5;
/// Why the estimator is dead-reckoning instead of taking the fix positions.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Coast {
    Off,
    /// Since this time (s): the fix is RTK float.
    Float(f64),
    /// Since this time (s): the fixes jumped away from the dead reckoning.
    Jump(f64),
    /// Coasted for `coast_max`: fix positions are taken until the cause clears.
    Expired,
}

/// A fix against the pose predicted from the previous one.
#[derive(Debug, Clone, Copy)]
struct Innovation {
    predicted: Pose,
    /// Measurement times of the previous and the new fix, s.
    t_prev: f64,
    dt: f64,
    heading: f64,
    lateral: f64,
    normal: Vec2,
}
/// The offset is learnt only below this wheel angle, rad (the linearisation holds and the
/// actuator is not slewing through a turn).
const BIAS_MAX_WHEEL: f64 = 0.2;
/// Shortest effective time constant at the start of learning, s: the slip coefficient's.
const MIN_TAU: f64 = 1.0;
/// The offset's prior: its first estimate weighs an offset of zero as this many seconds of
/// fixes, s. The innovations of consecutive fixes telescope, so an estimate learnt over t s
/// carries the noise of two fixes over t (heading noise σθ: σθ·√2·L/(v·t) on the offset), and
/// with a 1 s prior a job's first seconds steered by an offset that was not there. Swept over
/// the envelope (docs/envelope.md, Session 17: the observer's priors): 2–5 s gain cells and lose
/// none. The drift keeps a 1 s prior: a 2 s one gained cells on the envelope's seed only and
/// put every seed's side slope 10–13 % worse.
const BIAS_PRIOR_S: f64 = 3.0;
/// The roll at which the slip coefficient's estimate has the time constant
/// [`ObserverParams::slip_tau`], rad (2°): at a steeper slope it learns faster, on flat ground
/// it is left alone.
const SLIP_REFERENCE_ROLL: f64 = 0.035;
/// The regressor v·a_y at which the cornering slip's estimate has the time constant
/// [`ObserverParams::corner_slip_tau`], m²/s³ (10 km/h at 1.1 m/s², a headland turn of
/// r 7 m): in gentler curves it learns slower, on a straight not at all.
const CORNER_REFERENCE: f64 = 3.0;
/// The cornering slip's prior: its first estimate weighs a slip of zero as this many seconds
/// of turning at [`CORNER_REFERENCE`], s.
const CORNER_PRIOR_S: f64 = 5.0;
/// Largest cornering slip, rad per m/s² (2.9°: soft tyres at 15 km/h learnt 1.8°).
const CORNER_SLIP_LIMIT: f64 = 0.05;

/// The estimate handed to guidance and tracking.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VehicleEstimate {
    /// Rear-axle pose.
    pub pose: Pose,
    /// Speed, m/s.
    pub speed: f64,
    /// Time since the fix was received, s.
    pub fix_age: f64,
}

/// The wheel-angle history: 2.56 s at 100 Hz, as long as [`Estimator::estimate`] predicts
/// over (a fix's age and latency, at most 2 s), so a 1 Hz receiver's dead reckoning is made
/// of measured angles, not the oldest one held.
const RING: usize = 256;
/// The longest interval between two fixes that the innovation is taken over (the observer's
/// learning, the jumps and coasting), s: a 1 Hz receiver's with its jitter. Longer (a lost
/// fix of a 1 Hz receiver) the dead reckoning's model error would be learnt as drift; the
/// estimator takes the fix as it is. (It was 0.5 s for learning: a 1 Hz receiver's drift and
/// offset were never learnt, and a 2° slope stood every pass 8 cm downhill.)
const LONGEST_FIX_INTERVAL: f64 = 1.5;
/// Integration step of the prediction, s.
const PREDICT_STEP: f64 = 0.005;
/// Course from successive fixes is used only after this much movement, m.
const COURSE_MIN_MOVE: f64 = 0.2;

/// The estimator.
#[derive(Debug, Clone)]
pub struct Estimator {
    params: EstimatorParams,
    fix_time: f64,
    /// The current fix's own latency, s (`None`: the configured one).
    fix_latency: Option<f64>,
    fix_pose: Option<Pose>,
    fix_speed: f64,
    last_course_pos: Option<Vec2>,
    course: Option<f64>,
    wheel: [(f64, f64); RING],
    wheel_head: usize,
    wheel_len: usize,
    /// Estimated wheel-angle offset (measured − true), rad.
    bias: f64,
    /// Estimated world-frame drift velocity, m/s.
    drift: Vec2,
    /// Estimated slope-slip coefficient, m/s per rad of roll (lateral, to the right).
    slip: f64,
    /// Estimated cornering slip, rad per m/s² ([`ObserverParams::corner_slip_tau`]).
    corner_slip: f64,
    /// The drift per direction of straight driving, and whether the path is straight.
    drift_memory: DriftMemory,
    /// The vehicle's lag behind the wheels ([`yaw_lag`]).
    yaw_lag: yaw_lag::YawLag,
    straight: bool,
    /// The drift on curves: work path or not, and what a headland turn carries.
    curve: drift_memory::CurveDrift,
    /// The joint filter of the drift and the slip.
    lateral: LateralFilter,
    /// Roll of the latest fix, rad (0 without a roll signal).
    roll: f64,
    /// Roll of the fix before, rad.
    roll_prev: f64,
    /// Time the observer has learnt for, s: the offset's effective time constant grows with it
    /// up to the configured one (as a Kalman filter's gain falls from a large initial
    /// covariance; the drift and the slip have [`LateralFilter`]'s covariance for that).
    learnt: f64,
    /// The observer learns from the next fixes (the fix quality vouches for them).
    learn: bool,
    /// The next fixes are RTK float: coast (see [`ObserverParams::coast_max`]).
    coast: bool,
    /// Dead reckoning through an RTK float or a position jump.
    coast_state: Coast,
    /// Estimated noise of a fix's position per axis, m ([`ObserverParams::robust`]).
    noise: Noise,
    /// Estimated noise of a fix's heading, rad, from the heading innovations the
    /// offset learns from (half their mean square: each is the difference of two fixes' noise).
    heading_noise: Noise,
    /// The offset estimate's error from the heading noise, rad, as of its latest update
    /// ([`significance`]).
    offset_noise: f64,
    /// The previous fix's lateral innovation, m.
    prev_lateral: Option<f64>,
    /// The lateral offset of the fixes from the dead reckoning when the current jump began, m.
    jump_onset: f64,
    /// The smoothed pose's offset from the fix-based one (world, m;
    /// [`ObserverParams::position_process`]).
    smooth: Vec2,
}

impl Estimator {
    pub fn new(params: EstimatorParams) -> Self {
        Estimator {
            params,
            fix_time: 0.0,
            fix_latency: None,
            fix_pose: None,
            fix_speed: 0.0,
            last_course_pos: None,
            course: None,
            wheel: [(0.0, 0.0); RING],
            wheel_head: 0,
            wheel_len: 0,
            bias: 0.0,
            drift: Vec2::zeros(),
            slip: 0.0,
            corner_slip: 0.0,
            drift_memory: DriftMemory::default(),
            yaw_lag: Default::default(),
            straight: false,
            curve: Default::default(),
            lateral: LateralFilter::new(),
            roll: 0.0,
            roll_prev: 0.0,
            learnt: 0.0,
            learn: true,
            coast: false,
            coast_state: Coast::Off,
            noise: Noise::new(NOISE_START),
            heading_noise: Noise::new(HEADING_NOISE_START),
            offset_noise: 0.0,
            prev_lateral: None,
            jump_onset: 0.0,
            smooth: Vec2::zeros(),
        }
    }

    /// The lateral gate for innovations, m: fixed, or widened with the estimated noise.
    fn gate_lateral(&self) -> f64 {
        if self.params.observer.robust {
            GATE_LATERAL.max(GATE_SIGMAS * std::f64::consts::SQRT_2 * self.noise.sigma())
        } else {
            GATE_LATERAL
        }
    }

    /// The estimated noise of the fixes' position, σ per axis, m.
    pub fn position_noise(&self) -> f64 {
        self.noise.sigma()
    }

    /// Learn the fixes' noise from a lateral innovation `lateral` (m). Against a pose taken
    /// from the previous fix the innovation is the difference of two fixes' noise (variance
    /// 2σ²); while coasting it is measured against the dead reckoning, so a jump is in all of
    /// them and the difference of two consecutive ones is used instead (variance 2σ² again).
    /// Each sample is clipped at 4 σ, so a jump's onset barely moves it.
    fn learn_noise(&mut self, lateral: f64, coasting: bool) {
        let sample = if coasting {
            match self.prev_lateral {
                Some(p) => lateral - p,
                None => return,
            }
        } else {
            lateral
        };
        self.noise.learn(sample);
    }

    /// Whether the next fixes are RTK float (coast through them, see
    /// [`ObserverParams::coast_max`]).
    pub fn set_coasting(&mut self, coast: bool) {
        self.coast = coast;
    }

    /// Whether the position is being dead-reckoned through an RTK-float period.
    pub fn is_coasting(&self) -> bool {
        matches!(self.coast_state, Coast::Float(_) | Coast::Jump(_))
    }

    /// Whether the observer may learn from the following fixes (off while the fix is not RTK
    /// fixed: a float solution wanders by decimetres and would read as drift).
    pub fn set_learning(&mut self, learn: bool) {
        self.learn = learn;
    }

    /// The estimated wheel-angle offset (measured − true), rad.
    pub fn wheel_offset(&self) -> f64 {
        self.bias
    }

    /// The wheel-angle offset as the tracker steers for it: only as far as it stands out of
    /// its own noise ([`significance`]; about 0.03° in a job's first seconds at 15 km/h with
    /// a heading noise of 0.1°).
    pub fn wheel_offset_for_steering(&self) -> f64 {
        significance::steered(self.bias, self.offset_noise)
    }

    /// How far ahead of the rear axle, along the vehicle, the point lies that turns without
    /// the cornering slip at `speed` (m/s), m: ℓ = c·v² with the estimated cornering slip c
    /// ([`ObserverParams::corner_slip_tau`]), within [0, L/2]. The rear axle moves outwards at
    /// c·v·a_y = c·v²·ω, a point ℓ ahead of it inwards at ℓ·ω relative to it, so that point
    /// moves along the vehicle: the kinematic bicycle model holds there, not at the rear axle
    /// (as a neutral-steer point). A tracker steering the rear axle on soft tyres at 15 km/h
    /// (ℓ ≈ 0.5 m) steered a response that first moves the wrong way, and overshot a line
    /// start 1.1 m off by 18 cm; steering this point, 5 cm (docs/envelope.md, Session 32: the
    /// tyres' cornering slip learnt and steered about).
    pub fn slip_free_lead(&self, speed: f64) -> f64 {
        let v = speed.max(0.0);
        (self.corner_slip * v * v).clamp(0.0, 0.5 * self.params.wheelbase)
    }

    /// The estimated world-frame drift velocity, m/s (without the slope slip).
    pub fn drift(&self) -> Vec2 {
        self.drift
    }

    /// The estimated drift velocity (world frame, m/s) of a vehicle heading `heading` (rad) at
    /// the latest roll, the world drift plus the slope slip, as the tracker steers for it: its
    /// part across the heading only as far as it stands out of its own noise
    /// ([`significance`]: the error from the fixes' noise and the lateral filter's variance
    /// along h = (n, −sin roll)), the part along as it is.
    pub fn drift_velocity(&self, heading: f64) -> Vec2 {
        let n = left_normal(&heading_vec(heading));
        let sin_roll = self.roll.sin();
        let whole = self.drift - n * (self.slip * sin_roll);
        let across = whole.dot(&n);
        let h = Vector4::new(n.x, n.y, -sin_roll, 0.0);
        let error = significance::drift_error(self.noise.sigma(), h.dot(&(self.lateral.p * h)));
        whole + n * (significance::steered(across, error) - across)
    }

    /// Integrate the bicycle model from `pose` at `t0` over `span` s at speed `v`, with the
    /// measured wheel angles less the estimated offset, the estimated drift and the cornering
    /// slip of the model's yaw rate.
    fn propagate(&self, pose: Pose, v: f64, t0: f64, span: f64) -> Pose {
        let (steps, h, mut yaw_rate) = self.model_yaw_rates(v, t0, span);
        let (mut x, mut y, mut th) = (pose.pos.x, pose.pos.y, pose.heading);
        // The slope slip's speed to the left is fixed over the span (the latest roll), so it
        // is worked out once, not per step (see [`Estimator::drift_velocity`]).
        let slip_left = self.slip * self.roll.sin();
        // The cornering slip's speed to the right per unit yaw rate (forward only): c·v·a_y
        // with a_y = v·ω.
        let corner = self.corner_slip * v.max(0.0) * v.max(0.0);
        if steps > 0 {
            // The heading's sine and cosine are carried from step to step by rotations through
            // each half step's small angle, not taken afresh: a sin/cos per step is most of
            // this loop's cost, and it runs at every fix and every control period.
            let (mut sin, mut cos) = th.sin_cos();
            for i in 0..steps {
                // Midpoint rule for the heading keeps the arc accurate at this step.
                let rate = yaw_rate(i);
                let half = small_sin_cos(0.5 * h * rate);
                (sin, cos) = rotate((sin, cos), half);
                // At the midpoint: the motion and the slip's direction.
                let drift = self.drift - left_normal(&v2(cos, sin)) * (slip_left + corner * rate);
                x += (v * cos + drift.x) * h;
                y += (v * sin + drift.y) * h;
                (sin, cos) = rotate((sin, cos), half);
                th += rate * h;
            }
        }
        Pose::new(x, y, th)
    }

    /// The fix `new` (measured at `t_new`) against the pose predicted from the previous fix.
    fn innovation(&self, new: &Pose, t_new: f64) -> Option<Innovation> {
        let prev = self.fix_pose?;
        let t_prev = self.fix_time - self.latency(self.fix_latency);
        let dt = t_new - t_prev;
        if !(dt > 0.0 && dt <= LONGEST_FIX_INTERVAL) {
            return None;
        }
        let predicted = self.propagate(prev, self.fix_speed, t_prev, dt);
        let normal = left_normal(&heading_vec(new.heading));
        Some(Innovation {
            predicted,
            t_prev,
            dt,
            heading: wrap_angle(new.heading - predicted.heading),
            lateral: (new.pos - predicted.pos).dot(&normal),
            normal,
        })
    }

    /// Learn the disturbances from an innovation within the gates.
    fn observe(&mut self, i: &Innovation, v_new: f64) {
        let o = self.params.observer;
        let v = self.fix_speed;
        if !self.learn
            || i.dt > LONGEST_FIX_INTERVAL
            || v.abs() < o.min_speed
            || v_new.abs() < o.min_speed
            || i.heading.abs() > GATE_HEADING
            || i.lateral.abs() > self.gate_lateral()
        {
            return;
        }
        let (dt, t_prev, d_heading, d_lateral, n) =
            (i.dt, i.t_prev, i.heading, i.lateral, i.normal);
        self.learnt += dt;
        let tau = |configured: f64| configured.min(self.learnt.max(BIAS_PRIOR_S));
        // The wheel angle over the interval, less the offset.
        let delta = self.wheel_angle_at(t_prev + 0.5 * dt) - self.bias;
        let offset_observable = v.abs().min(v_new.abs()) >= o.offset_min_speed;
        if o.bias_tau > 0.0 && delta.abs() < BIAS_MAX_WHEEL && offset_observable {
            let c = delta.cos();
            let gain = self.params.wheelbase * c * c / (v * tau(o.bias_tau));
            self.bias = (self.bias - d_heading * gain).clamp(-o.bias_limit, o.bias_limit);
            // The heading innovations telescope like the lateral ones: the estimate carries
            // the noise of two headings through its gain.
            self.heading_noise.learn(d_heading);
            self.offset_noise = significance::offset_error(self.heading_noise.sigma(), gain);
        }
        // The lateral rate error e = Δl/Δt measures h·(θ − θ̂) with θ = (drift, slip) and
        // h = (n, −sin roll): one Kalman update of the three together.
        let drift_on = o.drift_tau > 0.0 && !self.turn_keeps_drift();
        let slip_on = o.slip_tau > 0.0;
        let corner_on = o.corner_slip_tau > 0.0;
        if drift_on || slip_on || corner_on {
            // The cornering slip's regressor −v·a_y, a_y = v·ω with the model's mean yaw rate
            // over the interval (as the prediction turned).
            let corner = match self.fix_pose {
                Some(prev) if corner_on => {
                    -v.max(0.0) * v.max(0.0) * wrap_angle(i.predicted.heading - prev.heading) / dt
                }
                _ => 0.0,
            };
            let h = Vector4::new(
                if drift_on { n.x } else { 0.0 },
                if drift_on { n.y } else { 0.0 },
                if slip_on {
                    -(0.5 * (self.roll_prev + self.roll)).sin()
                } else {
                    0.0
                },
                corner,
            );
            let step = self.lateral.update(&h, d_lateral / dt, dt, &o);
            if drift_on {
                self.add_drift(v2(step.x, step.y));
                self.drift_memory.learnt(dt, self.straight);
                self.curve.learnt(dt, self.straight);
            }
            self.slip = (self.slip + step.z).clamp(-o.slip_limit, o.slip_limit);
            self.corner_slip =
                (self.corner_slip + step.w).clamp(-CORNER_SLIP_LIMIT, CORNER_SLIP_LIMIT);
        }
    }

    pub fn params(&self) -> &EstimatorParams {
        &self.params
    }

    /// A fix's latency: its own, or the configured one, s.
    fn latency(&self, own: Option<f64>) -> f64 {
        own.unwrap_or(self.params.gnss_latency)
    }

    /// New tuning; the fix and the wheel-angle history are kept.
    pub fn set_params(&mut self, params: EstimatorParams) {
        self.params = params;
    }

    /// Rear-axle position from the antenna position, heading and roll.
    pub fn antenna_to_rear_axle(&self, antenna: &Vec2, heading: f64, roll: Option<f64>) -> Vec2 {
        let a = &self.params.antenna;
        let lateral = a.left - a.up * roll.unwrap_or(0.0).sin();
        let h = heading_vec(heading);
        antenna - h * a.forward - left_normal(&h) * lateral
    }

    /// A new fix. Non-finite fixes are ignored.
    pub fn on_fix(&mut self, fix: &GnssFix) {
        if !(fix.t_received.is_finite()
            && fix.antenna.x.is_finite()
            && fix.antenna.y.is_finite()
            && fix.speed.is_finite())
        {
            return;
        }
        let heading = match fix.heading.filter(|h| h.is_finite()) {
            Some(h) => Some(h),
            None => {
                if let Some(prev) = self.last_course_pos {
                    let d = fix.antenna - prev;
                    if d.norm() >= COURSE_MIN_MOVE {
                        let mut c = vec_heading(&d);
                        if fix.speed < 0.0 {
                            c = wrap_angle(c + std::f64::consts::PI);
                        }
                        self.course = Some(c);
                        self.last_course_pos = Some(fix.antenna);
                    }
                } else {
                    self.last_course_pos = Some(fix.antenna);
                }
                self.course
            }
        };
        let Some(heading) = heading else {
            return;
        };
        let roll = fix
            .roll
            .filter(|r| r.is_finite() && self.params.roll_compensation);
        self.roll_prev = self.roll;
        self.roll = roll.unwrap_or(0.0);
        let pos = self.antenna_to_rear_axle(&fix.antenna, heading, roll);
        let mut pose = Pose::new(pos.x, pos.y, heading);
        let fix_latency = fix
            .latency
            .filter(|l| self.params.predict && l.is_finite() && *l >= 0.0);
        let t_meas = fix.t_received - self.latency(fix_latency);
        let o = self.params.observer;
        let innovation = if self.params.predict
            && (o.bias_tau > 0.0 || o.drift_tau > 0.0 || o.coast_max > 0.0)
        {
            self.innovation(&pose, t_meas)
        } else {
            None
        };
        // A jump is a lateral step of the position while moving: a heading that jumps (course
        // from successive fixes at low speed) is not a reason to distrust the position.
        let moving = self.fix_speed.abs() >= o.min_speed && fix.speed.abs() >= o.min_speed;
        let gate = self.gate_lateral();
        let jump = moving && innovation.is_some_and(|i| i.lateral.abs() > gate);
        // Robust: a jump is a step; an offset from the dead reckoning that moves on by more
        // than the gate since the jump began is the dead reckoning drifting, not the fixes.
        let ramp = o.robust
            && matches!(self.coast_state, Coast::Jump(_))
            && innovation.is_some_and(|i| (i.lateral - self.jump_onset).abs() > gate);
        let jump = jump && !ramp;
        if let (true, Some(i)) = (o.robust && moving, innovation) {
            if !self.coast {
                let coasting = matches!(self.coast_state, Coast::Jump(_));
                self.learn_noise(i.lateral, coasting);
            }
            self.prev_lateral = Some(i.lateral);
        }
        let t = fix.t_received;
        let expired = |since: f64| t - since > o.coast_max;
        let was_off = !matches!(self.coast_state, Coast::Jump(_));
        self.coast_state = match (innovation.is_some() && o.coast_max > 0.0, self.coast_state) {
            (false, _) => Coast::Off,
            (true, Coast::Off) if self.coast => Coast::Float(t),
            (true, Coast::Off) if jump && self.learn => Coast::Jump(t),
            (true, Coast::Off) => Coast::Off,
            (true, Coast::Float(_)) if !self.coast => Coast::Off,
            (true, Coast::Float(s)) if expired(s) => Coast::Expired,
            (true, Coast::Float(s)) => Coast::Float(s),
            (true, Coast::Jump(s)) if self.coast => Coast::Float(s),
            (true, Coast::Jump(_)) if !jump => Coast::Off,
            (true, Coast::Jump(s)) if expired(s) => Coast::Expired,
            (true, Coast::Jump(s)) => Coast::Jump(s),
            (true, Coast::Expired) if !self.coast && !jump => Coast::Off,
            (true, Coast::Expired) => Coast::Expired,
        };
        if let (Coast::Jump(_), true, Some(i)) = (self.coast_state, was_off, innovation) {
            self.jump_onset = i.lateral;
        }
        match (self.coast_state, innovation) {
            (Coast::Float(_) | Coast::Jump(_), Some(i)) => {
                // Dead reckoning from the previous (coasted or fixed) position; the heading is
                // measured.
                pose = Pose::new(i.predicted.pos.x, i.predicted.pos.y, heading);
            }
            (_, Some(i)) => {
                self.learn_yaw_lag(&i, fix.speed);
                self.observe(&i, fix.speed);
                self.smooth_towards(&i, &pose);
            }
            _ => self.smooth = Vec2::zeros(),
        }
        if o.drift_tau > 0.0 {
            if let Some(previous) = self.fix_pose {
                self.drift_with_speed(previous.heading, self.fix_speed, fix.speed);
                self.drift_through_curve(previous.heading, heading);
            }
            self.drift_by_direction(heading, fix.speed);
        }
        self.fix_pose = Some(pose);
        self.fix_time = fix.t_received;
        self.fix_latency = fix_latency;
        self.fix_speed = fix.speed;
    }

    /// The smoothed pose's correction after the fix `pose` with innovation `i`
    /// ([`ObserverParams::position_process`]): the smoothed pose is the dead reckoning of the
    /// previous smoothed one moved by a steady-state Kalman gain K towards the fix, so its
    /// offset from the fix-based pose becomes (1 − K)·(offset − innovation).
    fn smooth_towards(&mut self, i: &Innovation, pose: &Pose) {
        let o = &self.params.observer;
        if !(o.robust && o.position_process > 0.0) {
            self.smooth = Vec2::zeros();
            return;
        }
        // Random walk of q per step against a noise of r: P⁻ = (q + √(q² + 4qr)) / 2,
        // K = P⁻ / (P⁻ + r).
        let q = o.position_process * o.position_process * (i.dt / 0.1);
        let r = self.noise.var;
        let p = 0.5 * (q + (q * q + 4.0 * q * r).sqrt());
        let k = if p + r > 0.0 { p / (p + r) } else { 1.0 };
        let innovation = pose.pos - i.predicted.pos;
        self.smooth = (self.smooth - innovation) * (1.0 - k);
        // Never further than the gate from the fixes.
        let cap = self.gate_lateral();
        if self.smooth.norm() > cap {
            self.smooth *= cap / self.smooth.norm();
        }
    }

    /// The estimate at `t_now` (s), or `None` before the first usable fix.
    pub fn estimate(&self, t_now: f64) -> Option<VehicleEstimate> {
        let pose = self.fix_pose?;
        let fix_age = t_now - self.fix_time;
        if !self.params.predict {
            return Some(VehicleEstimate {
                pose,
                speed: self.fix_speed,
                fix_age,
            });
        }
        let t0 = self.fix_time - self.latency(self.fix_latency);
        let t1 = t_now + self.params.lead_time;
        let span = (t1 - t0).clamp(0.0, 2.0);
        let v = self.fix_speed;
        let start = Pose::new(
            pose.pos.x + self.smooth.x,
            pose.pos.y + self.smooth.y,
            pose.heading,
        );
        let pose = self.propagate(start, v, t0, span);
        Some(VehicleEstimate {
            pose,
            speed: v,
            fix_age,
        })
    }
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_corner;
#[cfg(test)]
mod tests_noise;
#[cfg(test)]
mod tests_start_up;
