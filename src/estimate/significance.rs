//! How far an observer estimate steers: only as far as it stands out of its own noise.
//!
//! The observer learns its drift and its wheel-angle offset from the innovations of
//! consecutive fixes, which telescope: an estimate averaged over T s carries the noise of two
//! fixes, σ·√2/T for the drift (σ the fixes' position noise; 1/T is the lateral filter's
//! variance along its regressor, in its units) and σθ·√2·L/(v·T) for the offset (σθ the
//! heading noise, L the wheelbase, v the speed). In a job's first seconds that is a drift of
//! about 1 cm/s at σ = 1 cm, and the tracker steered for it: at 15 km/h the first pass ran up
//! to 1.8 cm off its line where the references stayed within 0.8 cm (docs/envelope.md,
//! Session 19: estimates that steer once they stand out of their noise). So the tracker steers
//! for each estimate soft-thresholded at [`SIGNIFICANCE`] standard deviations of that error,
//! while learning and the dead reckoning keep the whole estimate. A true drift passes less the
//! threshold, which falls as the estimate settles (0.05 cm/s after a minute at 1 cm, 10 Hz).

use std::f64::consts::SQRT_2;

/// The threshold, in standard deviations of the estimate's error. Two gained the same cells of
/// the robustness envelope as one, but put the side slope (a drift real from the first metre,
/// with no IMU to tell it) 15–31 % worse.
const SIGNIFICANCE: f64 = 1.0;

/// The error of a drift estimate (m/s) from fixes of noise `position_noise` (m, per axis) and
/// the lateral filter's variance `variance_along` along the regressor (1/s in its units).
pub(super) fn drift_error(position_noise: f64, variance_along: f64) -> f64 {
    SQRT_2 * position_noise * variance_along.max(0.0)
}

/// The error of an offset estimate (rad) learnt with `gain` (rad of offset per rad of heading
/// innovation) from headings of noise `heading_noise` (rad).
pub(super) fn offset_error(heading_noise: f64, gain: f64) -> f64 {
    SQRT_2 * heading_noise * gain
}

/// The part of an estimate `x` to steer for, given its `error`: moved towards 0 by
/// [`SIGNIFICANCE`] times the error, never past it.
pub(super) fn steered(x: f64, error: f64) -> f64 {
    x.signum() * (x.abs() - SIGNIFICANCE * error.max(0.0)).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_estimate_within_its_error_steers_nothing_and_a_larger_one_less_the_threshold() {
        assert_eq!(steered(0.004, 0.005), 0.0);
        assert_eq!(steered(-0.004, 0.005), 0.0);
        assert!((steered(0.03, 0.005) - 0.025).abs() < 1e-12);
        assert!((steered(-0.03, 0.005) + 0.025).abs() < 1e-12);
        assert_eq!(steered(0.03, 0.0), 0.03);
    }
}
