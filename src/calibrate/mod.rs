//! Steering calibration (issue 15 point 4): a guided identification of the steering and the
//! wheel-angle sensor, run against the simulator or a tractor on the bus.
//!
//! [`session::Session`] is the procedure (standstill steering tests, then a slow drive), fed the
//! bus's [`Input`](crate::input::Input)s and answering the command to send each period;
//! [`Session::finish`](session::Session) fits what it recorded:
//!
//! * the steering ([`identify`]): dead time, first-order lag, rate limit, deadband and backlash
//!   of the map from commanded to sensed angle ([`model::SteeringModel`]), by simulation least
//!   squares, with standard deviations; the two repetitions of the tests are fitted apart and
//!   must agree;
//! * the wheel-angle sensor ([`was`]): gain and zero offset against the GNSS yaw rate on the
//!   drive;
//! * the GNSS latency ([`latency`]): the delay of the GNSS heading's swing against the yaw
//!   rate the sensor predicts, on a slalom;
//! * the antenna's lateral offset ([`antenna`]): half the difference between the two ways of a
//!   pass over the same ground line.
//!
//! [`Calibration::toml_fragment`] writes the keys the controller and the supervisor read. Pure:
//! no I/O, no clock; the driving of a bus is the caller's (`agsteer calibrate`,
//! [`crate::demo::calibrate`]).

pub mod antenna;
pub mod antenna_forward;
pub mod figures;
pub mod fit;
pub mod identify;
pub mod latency;
pub mod model;
pub mod session;
pub mod was;

pub use figures::{Figure, Figures};
use identify::{fit_steering, fit_steering_from, SteeringFit};
use model::SteeringModel;
pub use session::{Instruction, Session, Tick};
use was::{fit_was, hold_result, Geometry, WasFit};

/// Limits and shape of the procedure, SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CalibrationParams {
    /// The steering tests need the tractor below this speed, m/s.
    pub standstill_speed: f64,
    /// The drive: asked speed and accepted range, m/s.
    pub drive_speed: f64,
    pub drive_speed_min: f64,
    pub drive_speed_max: f64,
    /// Big steering steps, either side of centre, rad.
    pub step: f64,
    /// Largest sensed angle held on the drive, rad.
    pub hold_angle: f64,
    /// No command beyond this, rad.
    pub max_angle: f64,
    /// While measuring on the drive the sensed angle must stay this close to the command, rad.
    pub follow_tolerance: f64,
    /// Longest wait for the operator to stop or reach the drive speed, s.
    pub wait_timeout: f64,
    /// Every hold of the steering tests and of the drive lasts this × its nominal time (1:
    /// about 85 s of steering tests and 80 s of drive). Shorter suits a fast steering and a
    /// quiet sensor only: a hold too short for the steering to settle shows as inconsistent
    /// responses and is refused.
    pub time_scale: f64,
    /// Run the two-way pass for the antenna's lateral offset (the operator steers it).
    pub antenna_pass: bool,
    pub geometry: Geometry,
}

impl Default for CalibrationParams {
    fn default() -> Self {
        CalibrationParams {
            standstill_speed: 0.5 / 3.6,
            drive_speed: 3.0 / 3.6,
            drive_speed_min: 1.5 / 3.6,
            drive_speed_max: 6.0 / 3.6,
            step: 20f64.to_radians(),
            hold_angle: 12f64.to_radians(),
            max_angle: 30f64.to_radians(),
            follow_tolerance: 3f64.to_radians(),
            wait_timeout: 60.0,
            time_scale: 1.0,
            antenna_pass: true,
            geometry: Geometry {
                wheelbase: 3.0,
                antenna_forward: 0.0,
                antenna_left: 0.0,
            },
        }
    }
}

/// Why calibration refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    #[error("moving at {speed_kmh:.1} km/h during {phase} (limit {limit_kmh:.1} km/h)")]
    TooFast {
        phase: &'static str,
        speed_kmh: f64,
        limit_kmh: f64,
    },
    #[error("the operator intervened at {t:.1} s: {how}")]
    OperatorIntervened { t: f64, how: String },
    #[error("inconsistent responses: {0}")]
    Inconsistent(String),
    #[error("no steering response: {0}")]
    NoResponse(String),
    #[error("not enough data: {0}")]
    NoData(String),
}

/// A value and its standard deviation (`None`: not determined by the tests).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    pub value: f64,
    pub sd: Option<f64>,
}

/// What calibration identified, in true wheel angles (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Calibration {
    pub dead_time: Estimate,
    pub tau: Estimate,
    /// Rate limit, rad/s. When the tests never reached it (`rate_reached` false) `value` is the
    /// fastest motion seen: a lower bound.
    pub rate: Estimate,
    pub rate_reached: bool,
    pub deadband: Estimate,
    pub backlash: Estimate,
    /// Sensor gain (sensed / true) and offset (sensed angle of straight driving, rad).
    pub was_gain: Estimate,
    pub was_offset: Estimate,
    /// GNSS latency, s (`None`: no slalom heading to time; the reason in `latency_note`).
    pub gnss_latency: Option<Estimate>,
    pub latency_note: Option<&'static str>,
    /// The receiver's fix interval, s: the median interval of the slalom's position fixes
    /// (`None` without ten of them).
    pub gnss_interval: Option<f64>,
    /// Antenna lateral offset, m, positive left (`None`: no two-way pass).
    pub antenna_left: Option<Estimate>,
    /// Antenna forward offset from the rear axle, m (`None`: no heading receiver, or the
    /// drive's turns did not pin it within [`FORWARD_MAX_SD_M`]).
    pub antenna_forward: Option<Estimate>,
    /// RMS of the steering fit's residuals, rad.
    pub steering_rms: f64,
    /// The fit in the sensor's terms and the sensor fit, as found.
    pub steering_fit: SteeringFit,
    pub was_fit: WasFit,
}

/// Linear interpolation of `ys` at `t` on increasing `ts` (clamped at the ends; `ts` and `ys`
/// of the same non-zero length).
pub(super) fn interp(ts: &[f64], ys: &[f64], t: f64) -> f64 {
    let i = ts.partition_point(|&x| x <= t);
    if i == 0 {
        return ys[0];
    }
    if i >= ts.len() {
        return ys[ys.len() - 1];
    }
    let (t0, t1) = (ts[i - 1], ts[i]);
    let w = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
    ys[i - 1] + w * (ys[i] - ys[i - 1])
}

/// Headings (time s, rad) unwrapped into a continuous angle from the first.
pub(super) fn unwrapped(headings: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut prev: Option<f64> = None;
    headings
        .iter()
        .map(|&(t, h)| {
            let u = prev.map_or(h, |p| p + crate::geo::wrap_angle(h - p));
            prev = Some(u);
            (t, u)
        })
        .collect()
}

/// Largest standard deviation of a measured antenna forward offset written, m: a less certain
/// one leaves the taped value.
pub const FORWARD_MAX_SD_M: f64 = 0.05;

/// The GNSS timeout for a receiver that sends a fix every `interval` s: one and a half
/// intervals and 0.1 s of jitter, at least the default 0.3 s (a 10 Hz receiver keeps it; a
/// 1 Hz one needs 1.6 s). What calibration writes as `safety.gnss_timeout_s` from the fix interval
/// it measured; a longer timeout is a longer dead-reckoned stretch before a lost
/// receiver stops the steering (1.6 s is 4.4 m at 10 km/h).
pub fn gnss_timeout_for_interval(interval: f64) -> f64 {
    // f64::max takes the other operand for a NaN: 0.3.
    (1.5 * interval + 0.1).max(0.3)
}

/// The median interval between consecutive times of `times` (s, in order), s; `None` with
/// fewer than ten or no positive interval.
fn median_interval(times: &[f64]) -> Option<f64> {
    if times.len() < 10 {
        return None;
    }
    let mut d: Vec<f64> = times
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| d.is_finite() && *d > 0.0)
        .collect();
    if d.is_empty() {
        return None;
    }
    let mid = d.len() / 2;
    let (_, m, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
    Some(*m)
}

/// Do two fits of the same steering agree? (Tolerances above the tests' own scatter: 3 σ plus
/// a floor.) Returns the first disagreement.
fn disagreement(a: &SteeringFit, b: &SteeringFit) -> Option<String> {
    let sd = |i: usize| {
        let s = |f: &SteeringFit| f.sigma[i].unwrap_or(0.0);
        (s(a).powi(2) + s(b).powi(2)).sqrt()
    };
    let (ma, mb) = (&a.model, &b.model);
    let check = |name: &str, x: f64, y: f64, floor: f64, i: usize, unit: f64, u: &str| {
        ((x - y).abs() > floor + 3.0 * sd(i)).then(|| {
            format!(
                "{name} {:.3} {u} in the first repetition, {:.3} {u} in the second",
                x * unit,
                y * unit
            )
        })
    };
    let deg = 1f64.to_degrees();
    check("dead time", ma.dead_time, mb.dead_time, 0.02, 0, 1.0, "s")
        .or_else(|| check("lag", ma.tau, mb.tau, 0.2 * ma.tau.max(mb.tau), 1, 1.0, "s"))
        .or_else(|| {
            (a.rate_bound_s > 0.3 && b.rate_bound_s > 0.3)
                .then(|| {
                    check(
                        "rate limit",
                        ma.rate,
                        mb.rate,
                        0.2 * ma.rate.max(mb.rate),
                        2,
                        deg,
                        "°/s",
                    )
                })
                .flatten()
        })
        .or_else(|| {
            let lost = |m: &SteeringModel| m.deadband + 0.5 * m.backlash;
            check(
                "lost motion",
                lost(ma),
                lost(mb),
                0.3f64.to_radians(),
                3,
                deg,
                "°",
            )
        })
}

impl Session {
    /// Fit what the procedure recorded. Refuses when the steering did not respond, the two
    /// repetitions disagree, the model does not explain the responses or the drive's holds do
    /// not lie on a line.
    pub fn finish(&self) -> Result<Calibration, CalibrationError> {
        if !self.is_done() {
            return Err(CalibrationError::NoData(
                "the procedure did not run to its end".into(),
            ));
        }
        let (Some(&(t0, t1a)), Some(&(t2, t1))) = (self.markers.first(), self.markers.last())
        else {
            return Err(CalibrationError::NoData(
                "no steering tests recorded".into(),
            ));
        };
        let rec = &self.steering;
        let whole = rec.window(t0, t1, 1.0);
        // Did the wheels move at all? The big steps span 2·step.
        let (lo, hi) = whole
            .samples
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
                (lo.min(s.1), hi.max(s.1))
            });
        let span = 2.0 * self.params.step.min(self.params.max_angle);
        if hi - lo < 0.3 * span || !(hi - lo).is_finite() {
            return Err(CalibrationError::NoResponse(format!(
                "the sensed angle moved {:.1}° for commands {:.1}° apart",
                (hi - lo).max(0.0).to_degrees(),
                span.to_degrees()
            )));
        }
        let fit = fit_steering(&whole)
            .ok_or_else(|| CalibrationError::NoData("too few wheel-angle samples".into()))?;
        let first = fit_steering_from(&rec.window(t0, t1a, 1.0), Some(&fit.model));
        let second = fit_steering_from(&rec.window(t2, t1, 1.0), Some(&fit.model));
        if let (Some(a), Some(b)) = (first, second) {
            if let Some(why) = disagreement(&a, &b) {
                return Err(CalibrationError::Inconsistent(why));
            }
        }
        // The sensor's own scatter, from the drive's holds (wheels still), against the fit.
        let noise = self
            .holds
            .iter()
            .filter_map(|h| {
                let n = h.sensed.len();
                (n > 10).then(|| {
                    let m = h.sensed.iter().map(|s| s.1).sum::<f64>() / n as f64;
                    (h.sensed.iter().map(|s| (s.1 - m).powi(2)).sum::<f64>() / n as f64).sqrt()
                })
            })
            .fold(0.0, f64::max);
        let allowed = 2.0 * noise + 0.15f64.to_radians();
        if fit.rms > allowed {
            return Err(CalibrationError::Inconsistent(format!(
                "the steering model leaves {:.2}° RMS unexplained (sensor noise {:.2}°)",
                fit.rms.to_degrees(),
                noise.to_degrees()
            )));
        }
        let results: Vec<_> = self
            .holds
            .iter()
            .filter_map(|h| hold_result(h, &self.params.geometry))
            .collect();
        let was = fit_was(&results).ok_or_else(|| {
            CalibrationError::NoData(format!(
                "{} of {} drive holds measured: the sensor's gain needs three",
                results.len(),
                self.holds.len()
            ))
        })?;
        if was.rms > 0.3f64.to_radians() {
            return Err(CalibrationError::Inconsistent(format!(
                "the drive's sensed angles lie {:.2}° RMS off a line through the yaw rates",
                was.rms.to_degrees()
            )));
        }
        let g = was.gain;
        let m = fit.model.to_true(g);
        let geo = &self.params.geometry;
        let lat = latency::fit_latency(&self.slalom, geo, g, was.offset);
        let (gnss_latency, latency_note) = match lat {
            Some(l) if (l.scale - 1.0).abs() > 0.3 => {
                return Err(CalibrationError::Inconsistent(format!(
                    "the GNSS heading turned {:.2} × as much as the wheel angles say on the                      slalom (tyres slipping, or the wheelbase wrong)",
                    l.scale
                )))
            }
            Some(l) => (
                Some(Estimate {
                    value: l.latency,
                    sd: Some(l.sd),
                }),
                None,
            ),
            None => (None, Some("no slalom with GNSS headings recorded")),
        };
        // The sensor's zero: the holds' line and the slalom's drift, weighted by their
        // variances.
        let was_offset = match lat {
            Some(l) if l.offset_correction_sd > 0.0 && was.offset_sd > 0.0 => {
                let (w1, w2) = (
                    1.0 / was.offset_sd.powi(2),
                    1.0 / l.offset_correction_sd.powi(2),
                );
                Estimate {
                    value: (w1 * was.offset + w2 * (was.offset + l.offset_correction)) / (w1 + w2),
                    sd: Some((1.0 / (w1 + w2)).sqrt()),
                }
            }
            _ => Estimate {
                value: was.offset,
                sd: Some(was.offset_sd),
            },
        };
        let antenna_left = if self.params.antenna_pass {
            let a = antenna::fit_antenna_left(&self.pass_out, &self.pass_back)
                .map_err(|e| CalibrationError::Inconsistent(format!("two-way pass: {e}")))?;
            if a.rms > 0.15 {
                return Err(CalibrationError::Inconsistent(format!(
                    "two-way pass: the passes wander {:.2} m RMS off a straight line",
                    a.rms
                )));
            }
            Some(Estimate {
                value: a.left,
                sd: Some(a.sd),
            })
        } else {
            None
        };
        let est = |value: f64, i: usize, scale: f64| Estimate {
            value,
            sd: fit.sigma[i].map(|s| s * scale),
        };
        // The rate is identified where the fitted response runs at it long enough for the
        // data to pin it (σ within 5 %); else only the fastest motion is known.
        let rate_reached =
            fit.rate_bound_s > 0.5 && fit.sigma[2].is_some_and(|s| s < 0.05 * fit.model.rate);
        Ok(Calibration {
            dead_time: est(m.dead_time, 0, 1.0),
            tau: est(m.tau, 1, 1.0),
            rate: if rate_reached {
                est(m.rate, 2, 1.0 / g)
            } else {
                Estimate {
                    value: fit.fastest / g,
                    sd: None,
                }
            },
            rate_reached,
            deadband: est(m.deadband, 3, 1.0 / g),
            backlash: est(m.backlash, 4, 1.0 / g),
            was_gain: Estimate {
                value: g,
                sd: Some(was.gain_sd),
            },
            was_offset,
            gnss_latency,
            latency_note,
            gnss_interval: median_interval(&self.slalom_fixes),
            antenna_left,
            antenna_forward: antenna_forward::fit_antenna_forward(&self.drive)
                .ok()
                .filter(|f| f.sd <= FORWARD_MAX_SD_M)
                .map(|f| Estimate {
                    value: f.forward,
                    sd: Some(f.sd),
                }),
            steering_rms: fit.rms,
            steering_fit: fit,
            was_fit: was,
        })
    }
}

impl Calibration {
    /// The calibration as the TOML the technician puts into the configuration (each key into
    /// its table), with the uncertainties as comments.
    pub fn toml_fragment(&self) -> String {
        let sd = |e: &Estimate, scale: f64, digits: usize| match e.sd {
            Some(s) => format!("± {:.*}", digits, s * scale),
            None => "not determined".to_string(),
        };
        let deg = 1f64.to_degrees();
        let lost = self.deadband.value + 0.5 * self.backlash.value;
        let rate_note = if self.rate_reached {
            sd(&self.rate, deg, 1)
        } else {
            "not reached by the tests: the fastest motion seen, a lower bound".to_string()
        };
        let latency = match &self.gnss_latency {
            Some(e) => format!(
                "# The GNSS latency (slalom); NMEA 0183 / UBX with a disciplined clock carry \
                 their own.\ngnss_latency_s = {:.3}  # {}\n",
                e.value.clamp(0.0, 0.5),
                sd(e, 1.0, 3)
            ),
            None => String::new(),
        };
        let gnss_timeout = match self.gnss_interval {
            Some(i) => format!(
                "# A fix every {i:.3} s (the slalom's receiver).\ngnss_timeout_s = {:.2}\n",
                gnss_timeout_for_interval(i)
            ),
            None => String::new(),
        };
        let mut antenna = match &self.antenna_left {
            Some(e) => format!(
                "antenna_left_m = {:.3}  # {} (two-way pass)\n",
                e.value,
                sd(e, 1.0, 3)
            ),
            None => String::new(),
        };
        if let Some(e) = &self.antenna_forward {
            antenna += &format!(
                "antenna_forward_m = {:.3}  # {} (the drive's turns)\n",
                e.value,
                sd(e, 1.0, 3)
            );
        }
        format!(
            "# Written by `agsteer calibrate`: copy each key into its table of the configuration.\n\
             [safety]\n\
             actuator_dead_time_s = {:.3}  # {}\n\
             actuator_tau_s = {:.3}  # {}\n\
             actuator_rate_deg_s = {:.1}  # {}\n\
             {gnss_timeout}\
             \n[track]\n\
             # The prediction horizon covers the steering's dead time.\n\
             lead_time_s = {:.3}\n\
             # Lost motion = deadband {:.2}° ({}) + half the backlash {:.2}° ({}).\n\
             lost_motion_initial_deg = {:.2}\n\
             {latency}\
             \n[vehicle]\n\
             was_gain = {:.4}  # {}\n\
             was_offset_deg = {:.2}  # {}\n\
             {antenna}",
            self.dead_time.value,
            sd(&self.dead_time, 1.0, 3),
            self.tau.value,
            sd(&self.tau, 1.0, 3),
            self.rate.value * deg,
            rate_note,
            self.dead_time.value.min(1.0),
            self.deadband.value * deg,
            sd(&self.deadband, deg, 2),
            self.backlash.value * deg,
            sd(&self.backlash, deg, 2),
            lost * deg,
            self.was_gain.value,
            sd(&self.was_gain, 1.0, 4),
            self.was_offset.value * deg,
            sd(&self.was_offset, deg, 2),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gnss_timeout_covers_the_fix_interval() {
        assert_eq!(
            gnss_timeout_for_interval(0.1),
            0.3,
            "10 Hz keeps the default"
        );
        assert!((gnss_timeout_for_interval(0.2) - 0.4).abs() < 1e-12);
        assert!((gnss_timeout_for_interval(1.0) - 1.6).abs() < 1e-12);
        assert_eq!(gnss_timeout_for_interval(f64::NAN), 0.3);
        // A 5 Hz receiver with one fix late by 0.3 s: still 0.2 s.
        let mut fixes: Vec<f64> = (0..20).map(|k| k as f64 * 0.2).collect();
        fixes[7] += 0.3;
        fixes[8] += 0.3;
        fixes[9] += 0.3;
        let interval = median_interval(&fixes).expect("twenty fixes");
        assert!((interval - 0.2).abs() < 1e-9, "{interval}");
        assert_eq!(median_interval(&fixes[..5]), None);
    }
}
