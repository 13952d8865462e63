//! The GNSS position error processes beyond white noise: correlated (Gauss-Markov) error,
//! multipath jumps and RTK-float windows. They draw from the disturbance stream only.

use super::Disturbances;
use crate::geo::{heading_vec, Vec2};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// A normal draw of σ `sigma` from `rng`; no draw at all when σ is 0 (so switching a process
/// off leaves the stream of the others unchanged).
pub(super) fn normal(rng: &mut ChaCha8Rng, sigma: f64) -> f64 {
    if sigma == 0.0 {
        return 0.0;
    }
    let z: f64 = StandardNormal.sample(rng);
    z * sigma
}

#[derive(Debug, Clone)]
pub(super) struct GnssError {
    /// Gauss-Markov GNSS error (E, N), m.
    markov: Vec2,
    /// RTK-float Gauss-Markov error (E, N), m.
    float_err: Vec2,
    /// Current multipath jump and when it ends, s.
    multipath: Vec2,
    multipath_until: f64,
}

impl GnssError {
    /// The correlated errors start from their stationary distributions.
    pub(super) fn new(d: &Disturbances, rng: &mut ChaCha8Rng) -> Self {
        let mut e = GnssError {
            markov: Vec2::zeros(),
            float_err: Vec2::zeros(),
            multipath: Vec2::zeros(),
            multipath_until: f64::NEG_INFINITY,
        };
        if d.gnss_markov_sigma > 0.0 {
            let sd = d.gnss_markov_sigma;
            e.markov = Vec2::new(normal(rng, sd), normal(rng, sd));
        }
        if !d.float_windows.is_empty() {
            let sd = d.float_sigma;
            e.float_err = Vec2::new(normal(rng, sd), normal(rng, sd));
        }
        e
    }

    /// The error at a fix measured at `now` (s), `dt` (s) after the previous one.
    pub(super) fn next(
        &mut self,
        d: &Disturbances,
        now: f64,
        dt: f64,
        in_float: bool,
        rng: &mut ChaCha8Rng,
    ) -> Vec2 {
        let mut e = Vec2::zeros();
        if d.gnss_markov_sigma > 0.0 {
            // Exact discretisation of dx = -x/τ dt + σ·sqrt(2/τ) dW over one GNSS period.
            let phi = (-dt / d.gnss_markov_tau).exp();
            let q = d.gnss_markov_sigma * (1.0 - phi * phi).sqrt();
            self.markov = self.markov * phi + Vec2::new(normal(rng, q), normal(rng, q));
            e += self.markov;
        }
        if d.multipath_rate > 0.0 && d.multipath_magnitude > 0.0 {
            if now >= self.multipath_until {
                self.multipath = Vec2::zeros();
                let p = 1.0 - (-d.multipath_rate * dt).exp();
                let u: f64 = rng.gen();
                let dir: f64 = rng.gen::<f64>() * std::f64::consts::TAU;
                if u < p {
                    self.multipath = heading_vec(dir) * d.multipath_magnitude;
                    self.multipath_until = now + d.multipath_duration;
                }
            }
            if now < self.multipath_until {
                e += self.multipath;
            }
        }
        if !d.float_windows.is_empty() {
            let phi = (-dt / d.float_tau).exp();
            let q = d.float_sigma * (1.0 - phi * phi).sqrt();
            self.float_err = self.float_err * phi + Vec2::new(normal(rng, q), normal(rng, q));
            if in_float {
                e += self.float_err;
            }
        }
        e
    }
}
