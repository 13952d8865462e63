//! The antenna's lateral offset from a two-way pass over the same ground line.
//!
//! The receiver reports the antenna, which sits `l` left of the vehicle's centre line; the
//! controller needs the centre (the rear axle, [`crate::estimate`]). Driving along a line on
//! the ground, then turning round and driving back over the same line with the wheels in the
//! same tracks, the centre runs along the same ground line both ways, but the antenna is `l`
//! to one side of it going out and `l` to the other side coming back: with `n` the left normal
//! of the out direction, the out pass reads the line at c + l along `n` and the back pass at
//! c − l. So l = (c_out − c_back) / 2, whatever the configuration says, and no ground
//! survey is needed: only that both passes follow the same line.
//!
//! Each pass is fitted with a straight line (across-track position against along-track
//! station, in a frame along the mean direction of the two passes), and both lines are read
//! at the middle of the stretch both passes cover. The standard deviation is the lines'
//! (the receiver's scatter over the pass); what it cannot see is how well the two passes
//! share the ground line: an error e between the passes' tracks adds e / 2. On a side slope
//! the antenna's lean changes sign with the direction too, so the passes must be on level
//! ground.

use super::was::line;
use crate::geo::{left_normal, Vec2};

/// Shortest stretch both passes must cover, m.
pub const MIN_OVERLAP_M: f64 = 5.0;

/// The fitted offset.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AntennaFit {
    /// Lateral offset of the antenna, m (positive left), and its standard deviation.
    pub left: f64,
    pub sd: f64,
    /// Length of the stretch both passes cover, m.
    pub overlap: f64,
    /// Largest residual RMS of the two lines, m (how straight the passes were).
    pub rms: f64,
}

/// Direction of travel over a pass: the principal axis of its points, pointing from the
/// first to the last.
fn direction(points: &[(f64, Vec2)]) -> Option<Vec2> {
    let n = points.len() as f64;
    let mean = points.iter().fold(Vec2::zeros(), |a, p| a + p.1) / n;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for (_, p) in points {
        let d = p - mean;
        sxx += d.x * d.x;
        sxy += d.x * d.y;
        syy += d.y * d.y;
    }
    let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let u = Vec2::new(angle.cos(), angle.sin());
    let travel = points.last()?.1 - points.first()?.1;
    Some(if travel.dot(&u) >= 0.0 { u } else { -u })
}

/// The antenna's lateral offset from the antenna positions (time s, local ENU m) of the out
/// pass and the back pass. Refused with the reason when a pass is too short, the passes are
/// not opposite (within 10°) or do not cover a common stretch of `MIN_OVERLAP_M`.
pub fn fit_antenna_left(out: &[(f64, Vec2)], back: &[(f64, Vec2)]) -> Result<AntennaFit, String> {
    if out.len() < 20 || back.len() < 20 {
        return Err(format!(
            "{} and {} positions on the two passes (at least 20 each)",
            out.len(),
            back.len()
        ));
    }
    let (Some(u_out), Some(u_back)) = (direction(out), direction(back)) else {
        return Err("no direction of travel".into());
    };
    if u_out.dot(&u_back) > -(10f64.to_radians().cos()) {
        return Err(format!(
            "the passes are {:.0}° apart, not opposite",
            u_out.dot(&u_back).clamp(-1.0, 1.0).acos().to_degrees()
        ));
    }
    let u = (u_out - u_back).normalize();
    let n = left_normal(&u);
    let origin = out.iter().fold(Vec2::zeros(), |a, p| a + p.1) / out.len() as f64;
    let frame = |pts: &[(f64, Vec2)]| -> Vec<(f64, f64)> {
        pts.iter()
            .map(|(_, p)| ((p - origin).dot(&u), (p - origin).dot(&n)))
            .collect()
    };
    let (a, b) = (frame(out), frame(back));
    let range = |v: &[(f64, f64)]| {
        v.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.0), hi.max(p.0))
            })
    };
    let ((lo_a, hi_a), (lo_b, hi_b)) = (range(&a), range(&b));
    let (lo, hi) = (lo_a.max(lo_b), hi_a.min(hi_b));
    if (hi - lo).is_nan() || hi - lo < MIN_OVERLAP_M {
        return Err(format!(
            "the passes share {:.1} m of the line (at least {MIN_OVERLAP_M} m)",
            (hi - lo).max(0.0)
        ));
    }
    let mid = 0.5 * (lo + hi);
    let at_mid = |v: &[(f64, f64)]| {
        let xy: Vec<(f64, f64)> = v
            .iter()
            .filter(|p| p.0 >= lo && p.0 <= hi)
            .map(|p| (p.0 - mid, p.1))
            .collect();
        line(&xy).map(|(c, _, sc, _, rms)| (c, sc, rms))
    };
    let (Some((c_out, s_out, r_out)), Some((c_back, s_back, r_back))) = (at_mid(&a), at_mid(&b))
    else {
        return Err("too few positions on the common stretch".into());
    };
    Ok(AntennaFit {
        left: 0.5 * (c_out - c_back),
        sd: 0.5 * s_out.hypot(s_back),
        overlap: hi - lo,
        rms: r_out.max(r_back),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pass along the line through `p0` in direction `heading` (the centre on the line),
    /// the antenna `left` of the centre, with deterministic noise of ±`noise` m.
    fn pass(p0: Vec2, heading: f64, left: f64, from: f64, to: f64, noise: f64) -> Vec<(f64, Vec2)> {
        let u = Vec2::new(heading.cos(), heading.sin());
        let n = left_normal(&u);
        (0..200)
            .map(|i| {
                let s = from + (to - from) * i as f64 / 199.0;
                let e = noise * ((i * 7919 % 13) as f64 - 6.0) / 6.0;
                (i as f64 * 0.1, p0 + u * s + n * (left + e))
            })
            .collect()
    }

    #[test]
    fn the_offset_changes_sign_with_the_direction() {
        let p0 = Vec2::new(10.0, -4.0);
        let h = 0.7;
        for left in [-0.3, 0.0, 0.12, 0.3] {
            let out = pass(p0, h, left, 0.0, 20.0, 0.01);
            // Back over the same line (direction h + π), from further along to before the
            // start: the back pass's left is the out pass's right.
            let back = pass(
                p0 + Vec2::new(h.cos(), h.sin()) * 25.0,
                h + std::f64::consts::PI,
                left,
                0.0,
                28.0,
                0.01,
            );
            let fit = fit_antenna_left(&out, &back).expect("fits");
            assert!((fit.left - left).abs() < 0.002, "{left}: {fit:?}");
            assert!(fit.overlap > 19.0 && fit.sd < 0.002, "{fit:?}");
        }
        // Not opposite: refused.
        let out = pass(p0, h, 0.1, 0.0, 20.0, 0.01);
        let again = pass(p0, h, 0.1, 0.0, 20.0, 0.01);
        assert!(fit_antenna_left(&out, &again).is_err());
    }
}
