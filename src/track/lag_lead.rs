//! Lag lead: the part of the steering's first-order lag beyond [`RESIDUAL_LAG`] cancelled by
//! a lead-lag filter on the command.
//!
//! The wheels follow the command through a lag (`safety.actuator_tau_s`, which
//! `agsteer calibrate` measures), and the vehicle's heading follows its wheels through a lag
//! of its own (tyres, yaw inertia) that the estimator learns while driving
//! (`estimate::yaw_lag`); τ is their sum. Pure pursuit's loop can only be made as fast as that lag
//! allows ([`super::TrackerParams::response_time`] lengthens the look-ahead to keep the lag's
//! phase in budget): at τ = 0.6 s and 15 km/h the look-ahead grew to 7 m and a line start's
//! 10 cm entry error took 20 m to go (the envelope's lag_0.6 row, docs/envelope.md). The
//! filter C(s) = (τ·s + 1)/(τ_r·s + 1) in front of a lag 1/(τ·s + 1) leaves the lag τ_r, so
//! the look-ahead is scheduled on τ_r and the wheels turn when pure pursuit asks:
//!
//! ```text
//! u = x + (τ/τ_r)·(δ − x),   ẋ = (δ − x)/τ_r
//! ```
//!
//! (x the demand δ low-passed over τ_r). In steady state u = δ: nothing changes on a held
//! line or arc, and a steering no slower than τ_r (the nominal steering the tuning was done
//! on) is not touched. The filter's high-frequency gain τ/τ_r also amplifies what changes
//! fast in the demand (a fix's correction of the pose), by as much as the lag then
//! attenuates it. Used by laws whose [`super::law::LawNeeds`] ask for it (the default).
//!
//! Contract: one state per controller, updated every control period; no allocation.

/// The lag left to the look-ahead schedule, s: the nominal steering's (the suite's tuning).
pub const RESIDUAL_LAG: f64 = 0.15;

/// The filter's state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LagLead {
    /// The law asks for the lead: without it the demand always passes through, whatever the
    /// lags.
    on: bool,
    /// The steering's lag, s.
    lag: f64,
    /// The vehicle's own lag behind its wheels (tyres, yaw inertia; `estimate::yaw_lag`),
    /// s: led on with the steering's, τ their sum (≤ [`RESIDUAL_LAG`]: the filter passes the
    /// demand through).
    vehicle: f64,
    /// The demand low-passed over [`RESIDUAL_LAG`], rad (NaN before the first demand).
    filtered: f64,
}

impl LagLead {
    /// The filter for a steering lag `lag` (s); a non-finite or small one leaves it off until
    /// a vehicle lag makes the sum exceed [`RESIDUAL_LAG`].
    pub fn new(lag: f64) -> Self {
        LagLead {
            on: true,
            lag: if lag.is_finite() { lag } else { 0.0 },
            vehicle: 0.0,
            filtered: f64::NAN,
        }
    }

    /// No lead, whatever the lags (a law that does not ask for it).
    pub fn off() -> Self {
        LagLead {
            on: false,
            ..LagLead::new(0.0)
        }
    }

    /// Whether the filter changes anything (on, and the lags exceed [`RESIDUAL_LAG`]).
    pub fn active(&self) -> bool {
        self.on && self.lag + self.vehicle > RESIDUAL_LAG
    }

    /// The vehicle's lag as learnt now, s (a non-finite or negative one counts as none).
    pub fn set_vehicle_lag(&mut self, lag: f64) {
        self.vehicle = if lag.is_finite() { lag.max(0.0) } else { 0.0 };
    }

    /// The command (rad) for the `demand`ed wheel angle (rad), one control period `dt` (s)
    /// on. A non-finite demand or period passes through and restarts the filter.
    pub fn command(&mut self, demand: f64, dt: f64) -> f64 {
        if !self.active() {
            return demand;
        }
        if !(demand.is_finite() && dt.is_finite() && dt >= 0.0) {
            self.filtered = f64::NAN;
            return demand;
        }
        if !self.filtered.is_finite() {
            self.filtered = demand;
        }
        // Backward Euler: stable for any period.
        self.filtered += (demand - self.filtered) * dt / (RESIDUAL_LAG + dt);
        self.filtered + (self.lag + self.vehicle) / RESIDUAL_LAG * (demand - self.filtered)
    }

    /// Forget the demand's history (the next command is the demand).
    pub fn reset(&mut self) {
        self.filtered = f64::NAN;
    }
}

/// The lag the look-ahead must cover when the lead runs, s.
pub fn residual(lag: f64) -> f64 {
    lag.min(RESIDUAL_LAG)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_vehicles_lag_is_led_on_with_the_steerings() {
        // A quick steering on a vehicle that lags 0.3 s: the filter leads their sum.
        let mut lead = LagLead::new(0.1);
        assert!(!lead.active());
        lead.set_vehicle_lag(0.3);
        assert!(lead.active());
        let _ = lead.command(0.0, 0.01);
        let first = lead.command(0.1, 0.01);
        // u = x + (τ/τ_r)·(δ − x) with τ = 0.4 s: the step led by about 0.4/0.15.
        assert!(first > 0.25 && first < 0.27, "{first}");
        lead.set_vehicle_lag(f64::NAN);
        assert!(!lead.active());
        // A law without the lead: nothing, whatever the vehicle's lag.
        let mut off = LagLead::off();
        off.set_vehicle_lag(0.5);
        assert!(!off.active());
        assert_eq!(off.command(0.3, 0.01), 0.3);
    }

    /// The wheels of a first-order lag `tau` (s) driven by `command` from rest, sampled every
    /// `dt` for `n` periods (exact discretisation of the lag under a held command).
    fn wheels(tau: f64, dt: f64, n: usize, mut command: impl FnMut(usize) -> f64) -> Vec<f64> {
        let a = (-dt / tau).exp();
        let mut wheel = 0.0;
        (0..n)
            .map(|k| {
                wheel = a * wheel + (1.0 - a) * command(k);
                wheel
            })
            .collect()
    }

    #[test]
    fn a_slow_steering_led_follows_a_step_as_the_residual_lag_does() {
        let dt = 0.01;
        let lag = 0.6;
        let mut lead = LagLead::new(lag);
        // The demand steps from 0 (its first value, where the filter starts) to 0.1 rad.
        let step = |k: usize| if k == 0 { 0.0 } else { 0.1 };
        let led = wheels(lag, dt, 300, |k| lead.command(step(k), dt));
        let residual = wheels(RESIDUAL_LAG, dt, 300, step);
        let unled = wheels(lag, dt, 300, step);
        // After one residual time constant the led wheels are where a τ_r steering would be
        // (63 %), the unled ones far behind (22 %).
        let k = (RESIDUAL_LAG / dt) as usize + 1;
        assert!(
            (led[k] - residual[k]).abs() < 0.006,
            "{} {}",
            led[k],
            residual[k]
        );
        assert!(unled[k] < 0.03, "{}", unled[k]);
        // And all settle on the demand: in steady state the command is the demand.
        assert!((led[299] - 0.1).abs() < 1e-4);
        assert!((lead.command(0.1, dt) - 0.1).abs() < 1e-6);
    }

    #[test]
    fn a_steering_no_slower_than_the_residual_is_not_touched() {
        let mut lead = LagLead::new(RESIDUAL_LAG);
        assert!(!lead.active());
        for demand in [0.0, 0.2, -0.1] {
            assert_eq!(lead.command(demand, 0.01), demand);
        }
        assert_eq!(LagLead::new(f64::NAN).command(0.3, 0.01), 0.3);
        assert_eq!(residual(0.6), RESIDUAL_LAG);
        assert_eq!(residual(0.1), 0.1);
    }

    #[test]
    fn bad_input_passes_the_demand_and_restarts() {
        let mut lead = LagLead::new(0.6);
        assert!((lead.command(0.1, 0.01) - 0.1).abs() < 1e-12);
        assert!(lead.command(0.2, 0.01) > 0.2);
        assert!(lead.command(f64::NAN, 0.01).is_nan());
        // Restarted: the first demand after is passed as it is.
        assert!((lead.command(0.05, 0.01) - 0.05).abs() < 1e-12);
        lead.reset();
        assert!((lead.command(-0.05, 0.01) + 0.05).abs() < 1e-12);
        assert_eq!(lead.command(0.1, f64::INFINITY), 0.1);
    }
}
