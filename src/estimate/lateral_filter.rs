//! The Kalman filter of the observer's lateral disturbances (world drift, slope slip and
//! cornering slip).

use super::{ObserverParams, CORNER_PRIOR_S, CORNER_REFERENCE, MIN_TAU, SLIP_REFERENCE_ROLL};
use crate::geo::Vec2;
use nalgebra::{Matrix4, Vector4};

/// The Kalman filter of the lateral disturbances θ = (world drift x, y in m/s; slip
/// coefficient in m/s per rad of roll; cornering slip in rad per m/s² of lateral
/// acceleration), each a random walk. The measurement is the lateral rate error of one fix
/// interval, e = Δl/Δt = h·(θ − θ̂) + noise, h = (n, −sin roll, −v·a_y).
///
/// Estimating them jointly matters on a side slope: the downhill drift and the slope slip push
/// the same way on every pass, so only the slope's variation along a pass tells them apart, and
/// two filters fed the same error would share it arbitrarily (then dead reckoning through RTK
/// float drifts wherever the slope differs from its mean). The noise densities are set so
/// that, alone, each state is a first-order filter with its configured time constant (the
/// slip at [`SLIP_REFERENCE_ROLL`]): process noise q = r/τ² against a measurement noise
/// density r (the scale cancels, r = 1). The covariance starts at the value of a 1 s time
/// constant ([`MIN_TAU`]) and is never let above it, so that a state that is not observed
/// (the drift along the pass, the slip on flat ground, the cornering slip on a straight) does
/// not gather an unbounded gain. The cornering slip starts and stays within the variance of
/// [`CORNER_PRIOR_S`] instead: a turn's few fixes are noisy against its slip of a few cm/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct LateralFilter {
    pub(super) p: Matrix4<f64>,
}

impl LateralFilter {
    /// The initial and largest variances: a time constant τ for a state seen through a
    /// regressor of size h has variance 1/(τ·h²); here τ = [`MIN_TAU`], h = 1 for the drift and
    /// the reference roll for the slip; τ = [`CORNER_PRIOR_S`], h = [`CORNER_REFERENCE`] for
    /// the cornering slip.
    const P0: [f64; 4] = [
        1.0 / MIN_TAU,
        1.0 / MIN_TAU,
        1.0 / (MIN_TAU * SLIP_REFERENCE_ROLL * SLIP_REFERENCE_ROLL),
        1.0 / (CORNER_PRIOR_S * CORNER_REFERENCE * CORNER_REFERENCE),
    ];

    pub(super) fn new() -> Self {
        LateralFilter {
            p: Matrix4::from_diagonal(&Vector4::from(Self::P0)),
        }
    }

    /// One fix interval `dt` (s) with regressor `h` and lateral rate error `e` (m/s): the
    /// correction of θ̂.
    pub(super) fn update(
        &mut self,
        h: &Vector4<f64>,
        e: f64,
        dt: f64,
        o: &ObserverParams,
    ) -> Vector4<f64> {
        // Process noise q = r/τ² (r = 1) for the slip in units of the reference roll.
        let q = |tau: f64, scale: f64| {
            if tau > 0.0 {
                1.0 / (tau * tau * scale * scale)
            } else {
                0.0
            }
        };
        let q_drift = q(o.drift_tau, 1.0);
        let q_slip = q(o.slip_tau, SLIP_REFERENCE_ROLL);
        let q_corner = q(o.corner_slip_tau, CORNER_REFERENCE);
        self.p += Matrix4::from_diagonal(&Vector4::new(q_drift, q_drift, q_slip, q_corner)) * dt;
        let ph = self.p * h;
        let s = h.dot(&ph) + 1.0 / dt;
        let k = ph / s;
        self.p -= k * ph.transpose();
        // Keep the covariance symmetric and each variance within its initial value (scaling
        // the row and column keeps it positive semi-definite).
        self.p = 0.5 * (self.p + self.p.transpose());
        for (i, cap) in Self::P0.into_iter().enumerate() {
            if self.p[(i, i)] > cap {
                let f = (cap / self.p[(i, i)]).sqrt();
                for j in 0..4 {
                    self.p[(i, j)] *= f;
                    self.p[(j, i)] *= f;
                }
            }
        }
        k * e
    }

    /// Learn the drift across `n` (a unit vector) afresh: its variance along `n` back to the
    /// initial one, the rest as it is.
    pub(super) fn relearn_across(&mut self, n: &Vec2) {
        let n4 = Vector4::new(n.x, n.y, 0.0, 0.0);
        let add = Self::P0[0] - n4.dot(&(self.p * n4));
        if add > 0.0 && add.is_finite() {
            self.p += n4 * n4.transpose() * add;
        }
    }

    /// Turn the drift's covariance by the angle of cosine `c` and sine `s`, as the drift
    /// ([`super::Estimator::rotate_drift`]).
    pub(super) fn rotate_drift(&mut self, c: f64, s: f64) {
        let mut r = Matrix4::identity();
        r[(0, 0)] = c;
        r[(0, 1)] = -s;
        r[(1, 0)] = s;
        r[(1, 1)] = c;
        self.p = r * self.p * r.transpose();
    }
}
