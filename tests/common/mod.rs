//! Fixtures shared by the integration tests and the benches (a bench includes this file with
//! `#[path]`).

use agsteer::geo::Pose;
use rand::{Rng, SeedableRng};
use std::f64::consts::PI;

/// `n` seeded random pairs of poses in ±20 m with any heading.
pub fn random_pose_pairs(n: usize, seed: u64) -> Vec<(Pose, Pose)> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let mut p = || {
                Pose::new(
                    rng.gen_range(-20.0..20.0),
                    rng.gen_range(-20.0..20.0),
                    rng.gen_range(-PI..PI),
                )
            };
            (p(), p())
        })
        .collect()
}
