//! The antenna's forward offset from the drive: the holds' steady turns and the slalom.
//!
//! The receiver reports the antenna, `f` ahead of the rear axle and `l` left of it; the
//! estimator moves it back to the rear axle with the configured offsets
//! ([`crate::estimate::Estimator::antenna_to_rear_axle`]). An error in `f` does nothing on a
//! straight line but turns with the vehicle: after a headland turn the estimated rear axle is
//! off the line by the error times the heading error, so every line start is steered on a
//! wrong position (issue 15's envelope, antenna ±0.3 m along).
//!
//! At a crawl the tyres do not slip and the rear axle moves along the heading θ, so with the
//! receiver's heading and speed its track is known up to where it started:
//! D(t) = ∫ v·h(θ) dt, h(θ) = (cos θ, sin θ). The antenna is then
//!
//! ```text
//! p(t) = p₀ + p₁·t + s·D(t) + ε·D⊥(t) + f·h(θ) + l·n(θ)
//! ```
//!
//! (n the left normal), linear in the unknowns: the start p₀, a slow drift p₁ of the
//! receiver's position, a scale s and a small rotation ε of the dead-reckoned track (a speed
//! scale, a heading bias), and the offsets. On a turn the antenna's offset sweeps round with
//! the heading while the track moves along it, so `f` is seen as soon as the heading turns by
//! a few tenths of a radian: the drive's holds at ±12° sweep it through radians. (`l` is
//! fitted too but not reported: on a circle it moves along n(θ) as the track's scale does; the
//! two-way pass measures it, [`super::antenna`].) The standard deviation is the least-squares
//! one from the residual scatter: it sees the receiver's noise, not the tyres' slip at a crawl
//! nor a correlated receiver error (1–2 cm on such plants where it says 0.1–0.4 cm; README,
//! Calibration).

use crate::geo::{heading_vec, left_normal, Vec2};
use nalgebra::{SMatrix, SVector};

/// Fewest positions the fit needs.
const MIN_FIXES: usize = 100;
/// Least heading swept over the record, rad: less and the offset is not seen.
const MIN_SWEEP: f64 = 0.3;
/// Longest gap between positions integrated over, s.
const MAX_GAP_S: f64 = 1.0;

/// What the drive recorded, (time s, value) in time order: antenna positions (local ENU m),
/// receiver headings (rad) and speeds over ground (m/s).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DriveTrack {
    pub positions: Vec<(f64, Vec2)>,
    pub headings: Vec<(f64, f64)>,
    pub speeds: Vec<(f64, f64)>,
}

/// The fitted forward offset.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForwardFit {
    /// Forward offset of the antenna from the rear axle, m, and its standard deviation.
    pub forward: f64,
    pub sd: f64,
}

/// Finite samples (time s, value) as times and values, for [`super::interp`].
struct Series {
    ts: Vec<f64>,
    ys: Vec<f64>,
}

impl Series {
    fn of(samples: &[(f64, f64)]) -> Series {
        let (ts, ys) = samples
            .iter()
            .filter(|s| s.0.is_finite() && s.1.is_finite())
            .copied()
            .unzip();
        Series { ts, ys }
    }

    /// The value at `t`, linearly (`None` outside the samples).
    fn at(&self, t: f64) -> Option<f64> {
        let (first, last) = (self.ts.first()?, self.ts.last()?);
        (*first <= t && t <= *last).then(|| super::interp(&self.ts, &self.ys, t))
    }
}

/// The antenna's forward offset from a drive with turns. Refused with the reason when there
/// are too few positions, the heading does not turn enough or the fit is singular.
pub fn fit_antenna_forward(track: &DriveTrack) -> Result<ForwardFit, String> {
    let finite: Vec<(f64, f64)> = track
        .headings
        .iter()
        .copied()
        .filter(|s| s.0.is_finite() && s.1.is_finite())
        .collect();
    let headings = Series::of(&super::unwrapped(&finite));
    let speeds = Series::of(&track.speeds);
    // (t, antenna, heading, track so far) at each position the headings and speeds cover.
    let mut rows: Vec<(f64, Vec2, f64, Vec2)> = Vec::with_capacity(track.positions.len());
    let mut travelled = Vec2::zeros();
    for &(t, p) in &track.positions {
        let (Some(theta), Some(_)) = (headings.at(t), speeds.at(t)) else {
            continue;
        };
        if !(t.is_finite() && p.x.is_finite() && p.y.is_finite()) {
            continue;
        }
        if let Some(&(t_prev, _, _, _)) = rows.last() {
            let dt = t - t_prev;
            if !(dt > 0.0 && dt <= MAX_GAP_S) {
                // A gap (or time running back): start the record again.
                rows.clear();
                travelled = Vec2::zeros();
            } else {
                let mid = t_prev + 0.5 * dt;
                let (th, v) = (headings.at(mid), speeds.at(mid));
                if let (Some(th), Some(v)) = (th, v) {
                    travelled += heading_vec(th) * (v * dt);
                }
            }
        }
        rows.push((t, p, theta, travelled));
    }
    if rows.len() < MIN_FIXES {
        return Err(format!(
            "{} positions with headings on the drive, {MIN_FIXES} needed",
            rows.len()
        ));
    }
    let (lo, hi) = rows
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, r| {
            (a.0.min(r.2), a.1.max(r.2))
        });
    let sweep = hi - lo;
    if sweep < MIN_SWEEP {
        return Err(format!(
            "the heading turned through {:.1}° on the drive, {:.0}° needed",
            sweep.to_degrees(),
            MIN_SWEEP.to_degrees()
        ));
    }
    let t0 = rows[0].0;
    // Unknowns: p₀ (x, y), p₁ (x, y), s, ε, f, l; two rows (east, north) per position.
    let design = |r: &(f64, Vec2, f64, Vec2)| {
        let (t, _, theta, d) = *r;
        let (h, n, tt) = (heading_vec(theta), left_normal(&heading_vec(theta)), t - t0);
        [
            SVector::<f64, 8>::from([1.0, 0.0, tt, 0.0, d.x, -d.y, h.x, n.x]),
            SVector::<f64, 8>::from([0.0, 1.0, 0.0, tt, d.y, d.x, h.y, n.y]),
        ]
    };
    let mut ata = SMatrix::<f64, 8, 8>::zeros();
    let mut atb = SVector::<f64, 8>::zeros();
    for r in &rows {
        for (a, b) in design(r).iter().zip([r.1.x, r.1.y]) {
            ata += a * a.transpose();
            atb += a * b;
        }
    }
    let inverse = ata
        .try_inverse()
        .ok_or("the drive's positions do not determine the offset")?;
    let x = inverse * atb;
    let mut rss = 0.0;
    for r in &rows {
        for (a, b) in design(r).iter().zip([r.1.x, r.1.y]) {
            rss += (b - a.dot(&x)).powi(2);
        }
    }
    let dof = (2 * rows.len()).saturating_sub(8).max(1) as f64;
    let var = rss / dof;
    let sd = (var * inverse[(6, 6)]).max(0.0).sqrt();
    if !(x[6].is_finite() && sd.is_finite()) {
        return Err("the drive's positions do not determine the offset".to_string());
    }
    Ok(ForwardFit { forward: x[6], sd })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A crawl at 0.8 m/s: straight, a steady left turn, a slalom, a right turn; the antenna
    /// `forward` ahead and 0.2 m left, with deterministic noise of ±`noise` m on the positions
    /// and a speed that reads 2 % high.
    fn drive(forward: f64, noise: f64) -> DriveTrack {
        let (mut pos, mut heading, mut track) = (Vec2::new(5.0, -3.0), 0.4, DriveTrack::default());
        let dt = 0.1;
        for i in 0..900 {
            let t = i as f64 * dt;
            let yaw_rate = match i {
                0..=99 => 0.0,
                100..=399 => 0.06,
                400..=699 => 0.05 * (t * std::f64::consts::PI / 2.0).sin(),
                _ => -0.06,
            };
            let v = 0.8;
            let h = heading_vec(heading);
            let antenna = pos + h * forward + left_normal(&h) * 0.2;
            let wiggle = noise * ((i * 7919 % 1000) as f64 / 500.0 - 1.0);
            let wiggle2 = noise * ((i * 104_729 % 1000) as f64 / 500.0 - 1.0);
            track
                .positions
                .push((t, antenna + Vec2::new(wiggle, wiggle2)));
            track.headings.push((t, crate::geo::wrap_angle(heading)));
            track.speeds.push((t, v * 1.02));
            let mid = heading + 0.5 * yaw_rate * dt;
            pos += heading_vec(mid) * (v * dt);
            heading += yaw_rate * dt;
        }
        track
    }

    #[test]
    fn the_forward_offset_is_found_from_the_turns() {
        for forward in [0.0, 1.2, 2.5, -0.5] {
            let fit = fit_antenna_forward(&drive(forward, 0.02)).expect("fits");
            assert!((fit.forward - forward).abs() < 0.02, "{forward}: {fit:?}");
            assert!(fit.sd > 0.0 && fit.sd < 0.02, "{fit:?}");
        }
    }

    #[test]
    fn a_straight_drive_or_too_few_fixes_is_refused() {
        let mut straight = drive(1.2, 0.01);
        for h in &mut straight.headings {
            h.1 = 0.4;
        }
        assert!(fit_antenna_forward(&straight).is_err());
        let mut short = drive(1.2, 0.01);
        short.positions.truncate(50);
        assert!(fit_antenna_forward(&short).is_err());
        assert!(fit_antenna_forward(&DriveTrack::default()).is_err());
    }
}
