//! The GNSS latency from a slalom at a crawl: the lag between the heading the receiver
//! reports and the heading the wheel-angle sensor predicts.
//!
//! At a crawl the tyres do not slip and the vehicle turns at ω = v·tan δ / L, δ the true
//! wheel angle ((sensed − offset) / gain, from the drive's sensor fit). Integrated over the
//! sensor's samples, that is a heading Θ(t) known up to a constant, with no GNSS delay in it:
//! the sensor's frames arrive at once. The receiver's heading at arrival time t describes the
//! vehicle at t − λ, λ the latency the estimator must compensate
//! ([`crate::estimate::EstimatorParams::gnss_latency`]). So the heading samples are fitted as
//!
//! ```text
//! θ(t) = a + b·t + k·Θ(t − λ)
//! ```
//!
//! linear in a, b, k (a straight-line drift absorbs a small sensor-offset error, the scale k a
//! gain or wheelbase error) and searched over λ (a grid, then a finer one about the best). A
//! slalom makes the yaw rate swing, and a latency shifts the whole swing in time: its standard
//! deviation is the Gauss–Newton one, σ_λ² = s² / Σ J⊥², J = ∂θ/∂λ = −k·ω(t − λ) with the
//! other regressors projected out.
//!
//! The drift b is the sensor's zero seen a second way: a sensed angle that reads e too low
//! makes Θ turn by v·e/(g·L) per second less than the vehicle does (as AgOpenGPS's "Smart
//! WAS" takes the zero from driving straight, here from the mean of the swing). Over half a
//! minute of 10 Hz headings it pins the offset to hundredths of a degree, finer than the
//! drive's holds; [`LatencyFit::offset_correction`] carries it.
//!
//! Without a heading receiver the course over ground stands in: the antenna then moves at
//! heading + atan2(ω·f, v − ω·l) (its crab in a turn, mounting f forward and l left as
//! configured), added to Θ. The crab is in phase with ω as the latency's effect is, so an
//! error δf in the configured forward offset reads as a latency error of about δf / v: that
//! term (for 2 cm) is added to the standard deviation.

use super::was::Geometry;
use super::{interp, unwrapped};

/// Largest latency searched, s.
pub const MAX_LATENCY: f64 = 0.5;
/// Uncertainty of a taped antenna forward offset, m (the course's crab; see the module).
const FORWARD_SD_M: f64 = 0.02;

/// What the slalom recorded, (time s, value) in time order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Slalom {
    /// Sensed wheel angles, rad.
    pub sensed: Vec<(f64, f64)>,
    /// GNSS headings, or courses over ground when `course`, rad.
    pub heading: Vec<(f64, f64)>,
    /// `heading` holds courses over ground (no heading receiver).
    pub course: bool,
    /// Speeds over ground, m/s.
    pub speed: Vec<(f64, f64)>,
}

/// The fitted latency.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatencyFit {
    /// Latency, s, and its standard deviation.
    pub latency: f64,
    pub sd: f64,
    /// The fitted scale of the sensor's heading swing (1: the sensor's gain and the wheelbase
    /// agree with the GNSS).
    pub scale: f64,
    /// Residual RMS of the heading fit, rad.
    pub rms: f64,
    /// RMS of the yaw-rate swing, rad/s (the excitation).
    pub yaw_rate_rms: f64,
    /// What the heading's drift says of the sensor's offset: the offset given is this much
    /// too small (rad, sensor terms), and its standard deviation (see [`fit_latency`]).
    pub offset_correction: f64,
    pub offset_correction_sd: f64,
}

/// Least squares of `y` on the columns `x` (3 of them): coefficients and residual sum of
/// squares; `None` when singular.
fn lsq3(cols: &[[f64; 3]], y: &[f64]) -> Option<([f64; 3], f64)> {
    lsq3_cov(cols, y).map(|(x, ssr, _)| (x, ssr))
}

/// [`lsq3`] and the diagonal of (XᵀX)⁻¹.
fn lsq3_cov(cols: &[[f64; 3]], y: &[f64]) -> Option<([f64; 3], f64, [f64; 3])> {
    let mut a = nalgebra::Matrix3::<f64>::zeros();
    let mut b = nalgebra::Vector3::<f64>::zeros();
    for (c, &yi) in cols.iter().zip(y) {
        let v = nalgebra::Vector3::from(*c);
        a += v * v.transpose();
        b += v * yi;
    }
    let inv = a.try_inverse()?;
    let x = inv * b;
    let ssr = cols
        .iter()
        .zip(y)
        .map(|(c, yi)| (yi - (x[0] * c[0] + x[1] * c[1] + x[2] * c[2])).powi(2))
        .sum();
    Some((
        [x[0], x[1], x[2]],
        ssr,
        [inv[(0, 0)], inv[(1, 1)], inv[(2, 2)]],
    ))
}

/// The sensor's heading and yaw rate at the sensor's sample times.
struct Predicted {
    ts: Vec<f64>,
    theta: Vec<f64>,
    omega: Vec<f64>,
}

impl Predicted {
    fn new(rec: &Slalom, geo: &Geometry, gain: f64, offset: f64, v: f64) -> Predicted {
        let ts: Vec<f64> = rec.sensed.iter().map(|s| s.0).collect();
        let omega: Vec<f64> = rec
            .sensed
            .iter()
            .map(|s| v * ((s.1 - offset) / gain).tan() / geo.wheelbase)
            .collect();
        let mut theta = Vec::with_capacity(ts.len());
        let mut acc = 0.0;
        for i in 0..ts.len() {
            if i > 0 {
                acc += 0.5 * (omega[i] + omega[i - 1]) * (ts[i] - ts[i - 1]);
            }
            theta.push(acc);
        }
        Predicted { ts, theta, omega }
    }

    /// The regressor of a heading (or course) sample at `t` for latency `lat`.
    fn regressor(&self, t: f64, lat: f64, course: Option<(&Geometry, f64)>) -> f64 {
        let th = interp(&self.ts, &self.theta, t - lat);
        match course {
            Some((g, v)) => {
                let w = interp(&self.ts, &self.omega, t - lat);
                th + (w * g.antenna_forward).atan2(v - w * g.antenna_left)
            }
            None => th,
        }
    }
}

/// Fit the latency to a slalom, with the sensor's `gain` and `offset` (sensed angle of
/// straight driving, rad) and the configured geometry. `None` without enough data (fewer than
/// 100 sensor samples or 30 headings, no speed) or no swing of the yaw rate to time.
pub fn fit_latency(rec: &Slalom, geo: &Geometry, gain: f64, offset: f64) -> Option<LatencyFit> {
    if rec.sensed.len() < 100 || rec.heading.len() < 30 || gain.is_nan() || gain <= 0.0 {
        return None;
    }
    let n_v = rec.speed.len();
    let v = rec.speed.iter().map(|s| s.1).sum::<f64>() / n_v.max(1) as f64;
    if n_v == 0 || v.is_nan() || v <= 0.1 {
        return None;
    }
    let pred = Predicted::new(rec, geo, gain, offset, v);
    let (t_first, t_last) = (pred.ts[0], pred.ts[pred.ts.len() - 1]);
    // Unwrapped headings, inside the span every latency searched can reach.
    let mut hs = unwrapped(&rec.heading);
    hs.retain(|&(t, _)| t - MAX_LATENCY >= t_first && t <= t_last);
    if hs.len() < 30 {
        return None;
    }
    let t_mean = hs.iter().map(|h| h.0).sum::<f64>() / hs.len() as f64;
    let y: Vec<f64> = hs.iter().map(|h| h.1).collect();
    let course = rec.course.then_some((geo, v));
    let mut cols = vec![[0.0; 3]; hs.len()];
    let ssr_at = |lat: f64, cols: &mut Vec<[f64; 3]>| -> Option<([f64; 3], f64)> {
        for (c, &(t, _)) in cols.iter_mut().zip(&hs) {
            *c = [1.0, t - t_mean, pred.regressor(t, lat, course)];
        }
        lsq3(cols, &y)
    };
    // Coarse grid, then a fine one about its best, then a parabola through the best three.
    let coarse = 0.005;
    let mut best = (f64::INFINITY, 0.0);
    for i in 0..=((MAX_LATENCY / coarse).round() as usize) {
        let lat = i as f64 * coarse;
        if let Some((_, ssr)) = ssr_at(lat, &mut cols) {
            if ssr < best.0 {
                best = (ssr, lat);
            }
        }
    }
    let fine = 0.0005;
    let centre = best.1;
    for i in -10i32..=10 {
        let lat = (centre + i as f64 * fine).clamp(0.0, MAX_LATENCY);
        if let Some((_, ssr)) = ssr_at(lat, &mut cols) {
            if ssr < best.0 {
                best = (ssr, lat);
            }
        }
    }
    let mut lat = best.1;
    if lat - fine >= 0.0 && lat + fine <= MAX_LATENCY {
        let f = |l: f64, c: &mut Vec<[f64; 3]>| ssr_at(l, c).map_or(f64::INFINITY, |r| r.1);
        let (fm, f0, fp) = (f(lat - fine, &mut cols), best.0, f(lat + fine, &mut cols));
        let curv = fm - 2.0 * f0 + fp;
        if curv > 0.0 {
            lat += 0.5 * fine * (fm - fp) / curv;
        }
    }
    let (_, ssr) = ssr_at(lat, &mut cols)?;
    let (coef, _, diag) = lsq3_cov(&cols, &y)?;
    let k = coef[2];
    // J = ∂θ/∂λ by central differences of the regressor, less its projection on the columns.
    let h = 1e-3;
    let jac: Vec<f64> = hs
        .iter()
        .map(|&(t, _)| {
            k * (pred.regressor(t, lat + h, course) - pred.regressor(t, lat - h, course))
                / (2.0 * h)
        })
        .collect();
    // The residual sum of squares of J on the columns: Σ J⊥².
    let (_, jj) = lsq3(&cols, &jac)?;
    let n = hs.len() as f64;
    let s2 = ssr / (n - 4.0).max(1.0);
    if jj.is_nan() || jj <= 0.0 {
        return None;
    }
    let mut sd = (s2 / jj).sqrt();
    if rec.course {
        sd = sd.hypot(FORWARD_SD_M / v);
    }
    let w_mean = pred.omega.iter().sum::<f64>() / pred.omega.len() as f64;
    let yaw_rate_rms = (pred.omega.iter().map(|w| (w - w_mean).powi(2)).sum::<f64>()
        / pred.omega.len() as f64)
        .sqrt();
    // The drift b: the vehicle turned on average at b less than the sensor says, which an
    // offset too small by e explains: dω/de = −v / (g·L·cos²δ) (mean over the swing).
    let sec2 = rec
        .sensed
        .iter()
        .map(|s| 1.0 / ((s.1 - offset) / gain).cos().powi(2))
        .sum::<f64>()
        / rec.sensed.len() as f64;
    let per_offset = v / (gain * geo.wheelbase) * sec2 * k;
    let offset_correction = -coef[1] / per_offset;
    let offset_correction_sd = (s2 * diag[1]).sqrt() / per_offset.abs();
    Some(LatencyFit {
        latency: lat,
        sd,
        scale: k,
        rms: (ssr / n).sqrt(),
        yaw_rate_rms,
        offset_correction,
        offset_correction_sd,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::wrap_angle;

    /// A slalom: the sensed angle a sine (period 4 s, ±12°) at 100 Hz, the heading integrated
    /// finely and reported at 10 Hz `latency` late, with a little deterministic noise.
    fn slalom(latency: f64, gain: f64, offset: f64, course_of: Option<&Geometry>) -> Slalom {
        let (l, v) = (3.0, 0.8);
        let mut rec = Slalom {
            course: course_of.is_some(),
            ..Default::default()
        };
        let true_angle = |t: f64| 12f64.to_radians() * (2.0 * std::f64::consts::PI * t / 4.0).sin();
        let h = 1e-4;
        let mut theta = 1.0;
        let mut k = 0usize;
        let mut history: Vec<(f64, f64, f64)> = Vec::new();
        while (k as f64) * h < 30.0 {
            let t = k as f64 * h;
            let w = v * true_angle(t).tan() / l;
            if k % 100 == 0 {
                let noise = 1e-4 * ((k / 100 * 7919 % 13) as f64 - 6.0) / 6.0;
                rec.sensed.push((t, gain * true_angle(t) + offset + noise));
            }
            if k % 1000 == 0 {
                history.push((t, theta, w));
            }
            theta += w * h;
            k += 1;
        }
        for &(t, th, w) in &history {
            let reported = match course_of {
                Some(g) => th + (w * g.antenna_forward).atan2(v - w * g.antenna_left),
                None => th,
            };
            rec.heading.push((t + latency, wrap_angle(reported)));
            rec.speed.push((t + latency, v));
        }
        rec
    }

    #[test]
    fn the_latency_of_a_heading_and_of_a_course() {
        let geo = Geometry {
            wheelbase: 3.0,
            antenna_forward: 1.2,
            antenna_left: 0.2,
        };
        for latency in [0.0, 0.05, 0.137, 0.3] {
            let rec = slalom(latency, 1.05, 0.02, None);
            let fit = fit_latency(&rec, &geo, 1.05, 0.02).expect("fits");
            assert!((fit.latency - latency).abs() < 0.002, "{latency}: {fit:?}");
            assert!((fit.scale - 1.0).abs() < 0.01, "{fit:?}");
            assert!(fit.offset_correction.abs() < 2e-4, "{fit:?}");
            // Told an offset 0.5° too small, the drift says by how much.
            let told = 0.02 - 0.5f64.to_radians();
            let fit = fit_latency(&rec, &geo, 1.05, told).expect("fits");
            let e = fit.offset_correction - 0.5f64.to_radians();
            assert!(e.abs() < 0.02f64.to_radians(), "{fit:?}");
            assert!((fit.latency - latency).abs() < 0.003, "{latency}: {fit:?}");
            let rec = slalom(latency, 1.05, 0.02, Some(&geo));
            let fit = fit_latency(&rec, &geo, 1.05, 0.02).expect("fits");
            assert!(
                (fit.latency - latency).abs() < 0.003,
                "course {latency}: {fit:?}"
            );
        }
    }
}
