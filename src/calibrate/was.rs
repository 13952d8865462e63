//! The wheel-angle sensor's gain and offset from a drive (the GNSS as the independent
//! reference, as AgOpenGPS's "Smart WAS" takes the zero from a straight drive).
//!
//! The sensor alone cannot tell its own scale error: the steering servos its reading, so every
//! standstill test sees only the sensor's terms. Driving slowly with the wheels held at a few
//! sensed angles, the vehicle turns at a yaw rate ω the GNSS heading measures; at a crawl the
//! tyres do not slip, so the rear axle follows the kinematic bicycle: its path curvature is
//! κ = ω / v and the true wheel angle δ = atan(κ·L). The rear axle's speed v follows from the
//! antenna's speed over ground and its mounting (forward f, left l): on a steady turn the
//! antenna moves at (v − ω·l) along the heading and ω·f across it. A straight line through
//! (δ, sensed) gives the gain (slope) and the offset (the sensed angle of a straight drive).
//!
//! The gain is relative to the configured wheelbase: a wheelbase 5 % long reads as a gain 5 %
//! small, which is what the controller needs (it maps a curvature to a sensed angle through
//! the same wheelbase).

/// One hold of the drive: the sensed angles, the headings (or courses over ground) and the
/// antenna's speeds over ground it recorded, (time s, value) in time order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Hold {
    pub sensed: Vec<(f64, f64)>,
    pub heading: Vec<(f64, f64)>,
    pub speed: Vec<(f64, f64)>,
}

/// What one hold measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HoldResult {
    /// Mean sensed angle, rad.
    pub sensed: f64,
    /// Yaw rate, rad/s, and its standard deviation.
    pub yaw_rate: f64,
    pub yaw_rate_sd: f64,
    /// Rear-axle speed, m/s.
    pub speed: f64,
    /// The true wheel angle atan(κ·L), rad.
    pub wheel: f64,
}

/// Mounting and geometry as configured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    pub wheelbase: f64,
    pub antenna_forward: f64,
    pub antenna_left: f64,
}

/// The sensor's gain and offset with standard deviations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WasFit {
    pub gain: f64,
    pub gain_sd: f64,
    /// Sensed angle of straight driving, rad.
    pub offset: f64,
    pub offset_sd: f64,
    /// RMS of the line's residuals, rad.
    pub rms: f64,
}

fn mean(xs: impl Iterator<Item = f64>) -> Option<f64> {
    let (s, n) = xs.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    (n > 0).then(|| s / n as f64)
}

/// Least-squares line y = a + b·x: (a, b, σ_a, σ_b, residual RMS).
pub(super) fn line(xy: &[(f64, f64)]) -> Option<(f64, f64, f64, f64, f64)> {
    let n = xy.len();
    if n < 3 {
        return None;
    }
    let mx = mean(xy.iter().map(|p| p.0))?;
    let my = mean(xy.iter().map(|p| p.1))?;
    let sxx: f64 = xy.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let b = xy.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / sxx;
    let a = my - b * mx;
    let ssr: f64 = xy.iter().map(|p| (p.1 - a - b * p.0).powi(2)).sum();
    let s2 = ssr / (n - 2) as f64;
    let sb = (s2 / sxx).sqrt();
    let sa = (s2 * (1.0 / n as f64 + mx * mx / sxx)).sqrt();
    Some((a, b, sa, sb, (ssr / n as f64).sqrt()))
}

/// What one hold measured; `None` without enough data (fewer than 10 headings or no speed).
pub fn hold_result(hold: &Hold, geo: &Geometry) -> Option<HoldResult> {
    let sensed = mean(hold.sensed.iter().map(|s| s.1))?;
    if hold.heading.len() < 10 {
        return None;
    }
    let (_, yaw_rate, _, yaw_rate_sd, _) = line(&super::unwrapped(&hold.heading))?;
    let v_ant = mean(hold.speed.iter().map(|s| s.1))?;
    let across = yaw_rate * geo.antenna_forward;
    let along = (v_ant * v_ant - across * across).max(0.0).sqrt();
    let speed = along + yaw_rate * geo.antenna_left;
    if speed <= 0.05 {
        return None;
    }
    let wheel = (yaw_rate / speed * geo.wheelbase).atan();
    Some(HoldResult {
        sensed,
        yaw_rate,
        yaw_rate_sd,
        speed,
        wheel,
    })
}

/// Gain and offset from the holds' results; `None` with fewer than three holds or no spread
/// of angles.
pub fn fit_was(holds: &[HoldResult]) -> Option<WasFit> {
    let xy: Vec<(f64, f64)> = holds.iter().map(|h| (h.wheel, h.sensed)).collect();
    let (a, b, sa, sb, rms) = line(&xy)?;
    (b.is_finite() && b > 0.0).then_some(WasFit {
        gain: b,
        gain_sd: sb,
        offset: a,
        offset_sd: sa,
        rms,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::wrap_angle;

    /// A hold on a circle: the rear axle at `v` with true angle `delta`, sensed through gain
    /// and offset, the antenna at (f, l).
    fn hold(delta: f64, gain: f64, offset: f64, geo: &Geometry) -> Hold {
        let v = 0.8;
        let w = v * delta.tan() / geo.wheelbase;
        let mut h = Hold::default();
        for i in 0..150 {
            let t = i as f64 * 0.1;
            h.heading.push((t, wrap_angle(3.0 + w * t)));
            let along = v - w * geo.antenna_left;
            let across = w * geo.antenna_forward;
            h.speed.push((t, (along * along + across * across).sqrt()));
            h.sensed.push((t, gain * delta + offset));
        }
        h
    }

    #[test]
    fn gain_and_offset_from_circles_with_an_offset_antenna() {
        let geo = Geometry {
            wheelbase: 3.0,
            antenna_forward: 1.5,
            antenna_left: 0.4,
        };
        let (gain, offset) = (1.07, 1.5f64.to_radians());
        let results: Vec<HoldResult> = [0.0, 12.0, -12.0, 6.0, -6.0]
            .iter()
            .map(|d: &f64| hold_result(&hold(d.to_radians(), gain, offset, &geo), &geo))
            .collect::<Option<_>>()
            .expect("every hold measured");
        let fit = fit_was(&results).expect("fits");
        assert!((fit.gain - gain).abs() < 1e-6, "{fit:?}");
        assert!((fit.offset - offset).abs() < 1e-6, "{fit:?}");
    }
}
