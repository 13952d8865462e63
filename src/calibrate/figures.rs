//! What calibration identified, in the units a technician reads (ms, degrees), each with its
//! standard deviation: printed by `agsteer calibrate`, shown by `agsteer status` and kept in
//! the daemon's state directory (`calibration.json`).

use super::{Calibration, Estimate};
use serde::{Deserialize, Serialize};

/// A value and its standard deviation (`None`: not determined by the tests).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Figure {
    pub value: f64,
    pub sd: Option<f64>,
}

impl Figure {
    fn of(e: &Estimate, scale: f64) -> Figure {
        Figure {
            value: e.value * scale,
            sd: e.sd.map(|s| s * scale),
        }
    }

    /// `value ± sd unit` with `digits` decimals, or `value unit (not determined)`.
    pub fn show(&self, unit: &str, digits: usize) -> String {
        match self.sd {
            Some(s) => format!("{:.*} ± {:.*} {unit}", digits, self.value, digits, s),
            None => format!("{:.*} {unit} (not determined)", digits, self.value),
        }
    }
}

/// The identified steering and sensor, edge units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Figures {
    pub dead_time_ms: Figure,
    pub lag_ms: Figure,
    /// The rate limit, °/s; when `rate_reached` is false the fastest motion seen (a lower
    /// bound, `sd` none).
    pub rate_deg_s: Figure,
    pub rate_reached: bool,
    pub deadband_deg: Figure,
    pub backlash_deg: Figure,
    /// Deadband + half the backlash, degrees.
    pub lost_motion_deg: f64,
    pub was_gain: Figure,
    pub was_offset_deg: Figure,
    /// RMS of the steering fit's residuals, degrees.
    pub fit_rms_deg: f64,
    /// GNSS latency, ms (`None`: not measured).
    #[serde(default)]
    pub gnss_latency_ms: Option<Figure>,
    /// The receiver's fix interval, ms (`None`: not measured).
    #[serde(default)]
    pub gnss_interval_ms: Option<f64>,
    /// Antenna lateral offset, m, positive left (`None`: no two-way pass).
    #[serde(default)]
    pub antenna_left_m: Option<Figure>,
    /// Antenna forward offset from the rear axle, m (`None`: not measured).
    #[serde(default)]
    pub antenna_forward_m: Option<Figure>,
}

impl Calibration {
    /// The figures in edge units.
    pub fn figures(&self) -> Figures {
        let deg = 1f64.to_degrees();
        Figures {
            dead_time_ms: Figure::of(&self.dead_time, 1000.0),
            lag_ms: Figure::of(&self.tau, 1000.0),
            rate_deg_s: Figure::of(&self.rate, deg),
            rate_reached: self.rate_reached,
            deadband_deg: Figure::of(&self.deadband, deg),
            backlash_deg: Figure::of(&self.backlash, deg),
            lost_motion_deg: (self.deadband.value + 0.5 * self.backlash.value) * deg,
            was_gain: Figure::of(&self.was_gain, 1.0),
            was_offset_deg: Figure::of(&self.was_offset, deg),
            fit_rms_deg: self.steering_rms * deg,
            gnss_latency_ms: self.gnss_latency.as_ref().map(|e| Figure::of(e, 1000.0)),
            gnss_interval_ms: self.gnss_interval.map(|i| i * 1000.0),
            antenna_left_m: self.antenna_left.as_ref().map(|e| Figure::of(e, 1.0)),
            antenna_forward_m: self.antenna_forward.as_ref().map(|e| Figure::of(e, 1.0)),
        }
    }
}

impl Figures {
    /// One line a figure, as `agsteer calibrate` prints them.
    pub fn report(&self) -> String {
        let rate = if self.rate_reached {
            self.rate_deg_s.show("°/s", 1)
        } else {
            format!(
                "≥ {:.1} °/s (not reached by the tests)",
                self.rate_deg_s.value
            )
        };
        let latency = self
            .gnss_latency_ms
            .map_or("not measured".to_string(), |f| f.show("ms", 1));
        let interval = self
            .gnss_interval_ms
            .map_or("not measured".to_string(), |i| format!("{i:.0} ms"));
        let antenna = self
            .antenna_left_m
            .map_or("not measured (no two-way pass)".to_string(), |f| {
                f.show("m (left of the centre line)", 3)
            });
        let forward = self.antenna_forward_m.map_or(
            "not measured (no heading receiver, or too little turning)".to_string(),
            |f| f.show("m (ahead of the rear axle)", 3),
        );
        format!(
            "dead time      {}\n\
             lag            {}\n\
             rate limit     {rate}\n\
             deadband       {}\n\
             backlash       {}\n\
             lost motion    {:.2} ° (deadband + half the backlash)\n\
             WAS gain       {}\n\
             WAS offset     {}\n\
             fit residual   {:.3} ° RMS\n\
             GNSS latency   {latency}\n\
             GNSS interval  {interval}\n\
             antenna left   {antenna}\n\
             antenna ahead  {forward}\n",
            self.dead_time_ms.show("ms", 1),
            self.lag_ms.show("ms", 1),
            self.deadband_deg.show("°", 2),
            self.backlash_deg.show("°", 2),
            self.lost_motion_deg,
            self.was_gain.show("", 4),
            self.was_offset_deg.show("°", 2),
            self.fit_rms_deg,
        )
    }
}
