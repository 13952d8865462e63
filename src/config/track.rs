//! `[track]`: the local path, the steering law and its helpers (observer, integral action,
//! lost-motion compensation).
//!
//! Owns the section's keys, their defaults and their range checks.

use super::check::Checker;
use serde::{Deserialize, Serialize};

/// Which tracker steers (the tracker registry's type).
pub use crate::track::registry::TrackerKind as TrackerChoice;

/// Default of `track.predictive_ld_max_m`, m. Pure pursuit's loop about a line is second
/// order with ωn = √2·v/Ld, so it settles a line start over a distance proportional to Ld,
/// whatever the speed. With `ld_gain_s` 1.2 s (the plain reference's growth, which steers the
/// latest fix as it is) the default law settled the 20 and 25 km/h line starts over 30 m:
/// 0.63 / 1.22 cm RMS against Stanley's 0.37 / 0.41 cm (envelope rows speed_20, speed_25).
/// The predicted pose needs no look-ahead for the fix's age, and the steering's lag and slew
/// lengthen the look-ahead on their own (the response-time schedule), so the growth with
/// speed stops at this distance, reached at about 13.5 km/h: 4.5 m.
pub const PREDICTIVE_LD_MAX_M: f64 = 4.5;

/// `[track]`: local path and tracker.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrackConfig {
    /// "predictive" (default) or "pure_pursuit" (plain reference).
    pub kind: TrackerChoice,
    /// Minimum look-ahead distance, m.
    pub ld_min_m: f64,
    /// Look-ahead growth with speed, s: Ld = max(ld_min_m, ld_gain_s · v).
    pub ld_gain_s: f64,
    /// The default (`predictive`) tracker's longest look-ahead from `ld_gain_s`, m: Ld =
    /// max(ld_min_m, min(ld_gain_s · v, predictive_ld_max_m), the steering's response time · v).
    pub predictive_ld_max_m: f64,
    /// The default (`predictive`) tracker feeds the path's curvature forward, a steering
    /// response ahead ([`FeedForward`](crate::track::pure_pursuit::FeedForward)): turns and
    /// curves entered and left on the path, not a look-ahead early.
    pub curvature_feed_forward: bool,
    /// Global points before the nearest one used as local-path nodes.
    pub local_nodes_before: usize,
    /// Global points after the nearest one used as local-path nodes.
    pub local_nodes_after: usize,
    /// B-spline tangent length at each node, m.
    pub tangent_length_m: f64,
    /// Local path sample spacing, m.
    pub local_spacing_m: f64,
    /// Known GNSS latency (fix measured this long before it arrives), s. Predictive only.
    pub gnss_latency_s: f64,
    /// Extra prediction horizon (about the actuator dead time), s. Predictive only.
    pub lead_time_s: f64,
    /// Stanley cross-track gain k, 1/s: δ = ψ + atan(k·e / (v + stanley_soft_speed_mps)).
    pub stanley_gain_per_s: f64,
    /// Stanley softening speed, m/s.
    pub stanley_soft_speed_mps: f64,
    /// LQR tracker (`kind = "lqr"`, see [`crate::track::lqr`]): the cross-track error its
    /// cost counts as much as the other terms' scales (Bryson's rule), m.
    pub lqr_xte_m: f64,
    /// The LQR's heading-error scale, degrees.
    pub lqr_heading_deg: f64,
    /// The LQR's wheel-angle rate scale, as a fraction of the calibrated rate limit
    /// (`safety.actuator_rate_deg_s`).
    pub lqr_rate_fraction: f64,
    /// Integral action on the XTE, rad of wheel angle per (m · s); 0 = off.
    pub integral_gain_rad_per_m_s: f64,
    /// Largest wheel-angle offset the integral action may learn, degrees.
    pub integral_limit_deg: f64,
    /// The integral action learns only while |XTE| is below this, m.
    pub integral_capture_m: f64,
    /// The integral action learns only above this speed, m/s.
    pub integral_min_speed_mps: f64,
    /// Curvature scale (the default tracker; `track::CurvatureScale`): how fast the wheel
    /// angle curves need beyond the kinematic model's (wheelbase error, understeer, antenna
    /// along the vehicle) is learnt on curved work paths, 1/(m · s); 0 = off, else ≤ 5. It
    /// learns within `integral_capture_m` and above `integral_min_speed_mps`.
    pub curvature_gain_per_m_s: f64,
    /// Largest curvature scale learnt (a fraction of the curve's wheel angle), 0..=0.5.
    pub curvature_scale_limit: f64,
    /// Disturbance observer (predictive tracker only; see
    /// [`ObserverParams`](crate::estimate::ObserverParams)): time constant of the wheel-angle
    /// offset estimate, s (0 = off, else 1..=600).
    pub observer_bias_tau_s: f64,
    /// Time constant of the world-frame drift (slip) estimate, s (0 = off, else 1..=600).
    pub observer_drift_tau_s: f64,
    /// The observer learns its drift and slip only above this speed, m/s.
    pub observer_min_speed_mps: f64,
    /// The observer learns the wheel-angle offset only above this speed, m/s: the offset shows
    /// as a heading change of v·δ/L, so at a crawl it is lost in the heading's noise.
    pub observer_offset_min_speed_mps: f64,
    /// Largest wheel-angle offset the observer may estimate, degrees. The offset it learns is
    /// the sensor's zero error (calibration leaves ≤ 0.1°) plus the steady steer a side force
    /// needs: a 5 kN implement side draft at 1.5 m behind the axle learns −2.97°, and with the
    /// former 3° limit 6.5 kN put the straights 3 cm off, 8 kN 6 cm; at 6°, 10 kN holds
    /// (0.79 cm) and the envelope is unchanged (docs/envelope.md, Session 17: the observer's
    /// priors).
    pub observer_bias_limit_deg: f64,
    /// Largest drift speed the observer may estimate, m/s.
    pub observer_drift_limit_mps: f64,
    /// Time constant of the slope-slip coefficient (lateral slip per degree of IMU roll) at 2°
    /// of roll, s (0 = off, else 1..=600).
    pub observer_slip_tau_s: f64,
    /// Largest slope-slip coefficient, m/s per degree of roll.
    pub observer_slip_limit_mps_per_deg: f64,
    /// Time constant of the cornering-slip estimate (the rear axle's slip angle per m/s² of
    /// lateral acceleration, learnt in turns and curves) at 10 km/h and 1.1 m/s², s (0 = off,
    /// else 1..=600). See `estimate::ObserverParams::corner_slip_tau`.
    pub observer_corner_slip_tau_s: f64,
    /// Through an RTK-float period, dead-reckon from the last fixed position for at most this
    /// long instead of following the float positions, s (0 = off).
    pub observer_coast_max_s: f64,
    /// The observer estimates the fixes' noise and widens its gates with it; it coasts through
    /// a jump only while the jump is a step (see
    /// [`ObserverParams::robust`](crate::estimate::ObserverParams::robust)).
    pub observer_robust: bool,
    /// Position smoothing: dead-reckoning error growth per 0.1 s, m, against the estimated
    /// noise of the fixes (0 = off; needs `observer_robust`).
    pub position_process_m: f64,
    /// Lost-motion compensation (predictive tracker only; see
    /// [`LostMotion`](crate::track::lost_motion::LostMotion)): time constant of the steering's
    /// lost-motion (backlash + actuator deadband) estimate, s (0 = off).
    pub lost_motion_tau_s: f64,
    /// The command is pushed the other way only when the measured wheel angle is past the
    /// demand by this much, degrees (above the wheel-angle sensor's noise).
    pub lost_motion_threshold_deg: f64,
    /// Largest lost motion the compensation may learn, degrees.
    pub lost_motion_limit_deg: f64,
    /// The lost motion the compensation starts from, degrees (`agsteer calibrate` measures it:
    /// the deadband plus half the backlash); it learns on from there.
    pub lost_motion_initial_deg: f64,
    /// The estimate learns only this long after the push direction changed, with a steady
    /// demand, s (about the actuator's settling time).
    pub lost_motion_settle_s: f64,
}

impl Default for TrackConfig {
    fn default() -> Self {
        TrackConfig {
            kind: TrackerChoice::Predictive,
            ld_min_m: 3.0,
            ld_gain_s: 1.2,
            predictive_ld_max_m: PREDICTIVE_LD_MAX_M,
            curvature_feed_forward: true,
            local_nodes_before: 2,
            local_nodes_after: 10,
            tangent_length_m: 0.25,
            local_spacing_m: 0.1,
            gnss_latency_s: 0.05,
            lead_time_s: 0.05,
            stanley_gain_per_s: 2.5,
            stanley_soft_speed_mps: 1.0,
            lqr_xte_m: 0.1,
            lqr_heading_deg: 6.0,
            lqr_rate_fraction: 0.5,
            integral_gain_rad_per_m_s: 0.0,
            integral_limit_deg: 3.0,
            integral_capture_m: 0.3,
            integral_min_speed_mps: 0.5,
            curvature_gain_per_m_s: 0.5,
            curvature_scale_limit: 0.3,
            observer_bias_tau_s: 20.0,
            observer_drift_tau_s: 30.0,
            observer_min_speed_mps: 0.2,
            observer_offset_min_speed_mps: 1.0,
            observer_bias_limit_deg: 6.0,
            observer_drift_limit_mps: 0.3,
            observer_slip_tau_s: 30.0,
            observer_slip_limit_mps_per_deg: 0.05,
            observer_corner_slip_tau_s: 30.0,
            observer_coast_max_s: 30.0,
            observer_robust: true,
            position_process_m: 0.005,
            lost_motion_tau_s: 5.0,
            lost_motion_threshold_deg: 0.1,
            lost_motion_limit_deg: 1.0,
            lost_motion_initial_deg: 0.0,
            lost_motion_settle_s: 0.5,
        }
    }
}

impl TrackConfig {
    /// Range checks of `[track]`. The tuning keys that can make tracking unstable are held to
    /// ranges measured stable (`agsteer demo` and the `all_disturbances` scenario across each
    /// key's former range, issue 20): the observer's time constants 0 (off) or ≥ 1 s (0.1 s
    /// drift or 0.05 s bias: the demo weaves until tracking_unstable), the B-spline tangent
    /// ≤ 0.3 m (0.5 m: off_line on the R = 15 m curve, 1 m: tracking_unstable in the demo), the
    /// look-ahead ≤ 6 m + 2 s (12 m: off_line in the demo; 3 s: off_line at 15 km/h), the GNSS latency compensated ≤ 0.5 s (0.7 s against the
    /// true 0.05 s: tracking_unstable), the integral gain ≤ 0.2 (0.5: tracking_unstable).
    pub(crate) fn validate(&self, c: &mut Checker) {
        let t = self;
        c.range("track.ld_min_m", t.ld_min_m, 0.2, 6.0);
        c.range("track.ld_gain_s", t.ld_gain_s, 0.0, 2.0);
        c.range(
            "track.predictive_ld_max_m",
            t.predictive_ld_max_m,
            0.2,
            20.0,
        );
        if t.local_nodes_after < 1 {
            c.push(
                "track.local_nodes_after",
                t.local_nodes_after.to_string(),
                "must be an integer >= 1",
            );
        }
        if t.local_nodes_before + t.local_nodes_after > 64 {
            c.push(
                "track.local_nodes_after",
                t.local_nodes_after.to_string(),
                "local_nodes_before + local_nodes_after must be <= 64",
            );
        }
        c.range("track.tangent_length_m", t.tangent_length_m, 0.01, 0.3);
        c.range("track.local_spacing_m", t.local_spacing_m, 0.01, 1.0);
        c.range("track.gnss_latency_s", t.gnss_latency_s, 0.0, 0.5);
        c.range("track.lead_time_s", t.lead_time_s, 0.0, 1.0);
        c.range("track.stanley_gain_per_s", t.stanley_gain_per_s, 0.0, 50.0);
        c.range(
            "track.stanley_soft_speed_mps",
            t.stanley_soft_speed_mps,
            0.01,
            10.0,
        );
        c.range("track.lqr_xte_m", t.lqr_xte_m, 0.005, 2.0);
        c.range("track.lqr_heading_deg", t.lqr_heading_deg, 0.1, 45.0);
        c.range("track.lqr_rate_fraction", t.lqr_rate_fraction, 0.05, 2.0);
        c.range(
            "track.integral_gain_rad_per_m_s",
            t.integral_gain_rad_per_m_s,
            0.0,
            0.2,
        );
        c.range("track.integral_limit_deg", t.integral_limit_deg, 0.0, 10.0);
        c.range("track.integral_capture_m", t.integral_capture_m, 0.01, 5.0);
        c.range(
            "track.curvature_gain_per_m_s",
            t.curvature_gain_per_m_s,
            0.0,
            5.0,
        );
        c.range(
            "track.curvature_scale_limit",
            t.curvature_scale_limit,
            0.0,
            0.5,
        );
        c.range(
            "track.integral_min_speed_mps",
            t.integral_min_speed_mps,
            0.0,
            10.0,
        );
        c.off_or_range(
            "track.observer_bias_tau_s",
            t.observer_bias_tau_s,
            1.0,
            600.0,
        );
        c.off_or_range(
            "track.observer_drift_tau_s",
            t.observer_drift_tau_s,
            1.0,
            600.0,
        );
        c.range(
            "track.observer_min_speed_mps",
            t.observer_min_speed_mps,
            0.1,
            10.0,
        );
        c.range(
            "track.observer_offset_min_speed_mps",
            t.observer_offset_min_speed_mps,
            0.1,
            10.0,
        );
        c.range(
            "track.observer_bias_limit_deg",
            t.observer_bias_limit_deg,
            0.0,
            10.0,
        );
        c.range(
            "track.observer_drift_limit_mps",
            t.observer_drift_limit_mps,
            0.0,
            2.0,
        );
        c.off_or_range(
            "track.observer_slip_tau_s",
            t.observer_slip_tau_s,
            1.0,
            600.0,
        );
        c.off_or_range(
            "track.observer_corner_slip_tau_s",
            t.observer_corner_slip_tau_s,
            1.0,
            600.0,
        );
        c.range(
            "track.observer_slip_limit_mps_per_deg",
            t.observer_slip_limit_mps_per_deg,
            0.0,
            1.0,
        );
        c.range(
            "track.observer_coast_max_s",
            t.observer_coast_max_s,
            0.0,
            600.0,
        );
        c.range("track.position_process_m", t.position_process_m, 0.0, 1.0);
        c.range("track.lost_motion_tau_s", t.lost_motion_tau_s, 0.0, 600.0);
        c.range(
            "track.lost_motion_threshold_deg",
            t.lost_motion_threshold_deg,
            0.0,
            2.0,
        );
        c.range(
            "track.lost_motion_limit_deg",
            t.lost_motion_limit_deg,
            0.0,
            5.0,
        );
        c.range(
            "track.lost_motion_initial_deg",
            t.lost_motion_initial_deg,
            0.0,
            5.0,
        );
        c.range(
            "track.lost_motion_settle_s",
            t.lost_motion_settle_s,
            0.0,
            10.0,
        );
    }
}
