//! The observer in a job's first seconds: what it learns from the receiver's noise alone,
//! what of that the tracker steers for, and how soon a true drift is steered for
//! ([`super::significance`]).

use super::tests::antenna_of;
use super::tests_noise::robust_params;
use super::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::f64::consts::FRAC_PI_2;

/// What the observer made of a job's first `seconds` at 15 km/h driving north on a straight,
/// the vehicle drifting `drift_east` m/s while its wheels read 0, fixes at 10 Hz with 1 cm
/// position and 0.1° heading noise, over `seeds` runs.
struct StartUp {
    /// RMS of the offset estimate, rad, and of the offset steered for
    /// (`wheel_offset_for_steering`).
    offset: f64,
    offset_steered: f64,
    /// RMS error of the drift across the heading as learnt, and as the tracker steers for it
    /// (`drift_velocity`), m/s.
    learnt: f64,
    steered: f64,
    /// The largest error of the steered drift at the end of a run, m/s.
    steered_at_end: f64,
}

fn start_up(seeds: u64, seconds: f64, drift_east: f64) -> StartUp {
    use rand_distr::Distribution;
    let normal = rand_distr::Normal::new(0.0, 1.0).expect("σ");
    let (v, th) = (15.0 / 3.6, FRAC_PI_2);
    // Across the heading (north) is west.
    let truth_across = -drift_east;
    let (mut bias_sq, mut learnt_sq, mut steered_sq, mut n) = (0.0, 0.0, 0.0, 0.0);
    let mut offset_steered_sq = 0.0;
    let mut steered_at_end: f64 = 0.0;
    for seed in 0..seeds {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut e = Estimator::new(robust_params(0.0));
        let steps = (seconds / 0.02).round() as usize;
        for k in 1..=steps {
            let t = k as f64 * 0.02;
            e.on_wheel_angle(t, 0.0);
            if k % 5 == 0 {
                let truth = Pose::new(drift_east * t, v * t, th);
                let noise = v2(normal.sample(&mut rng), normal.sample(&mut rng)) * 0.01;
                let heading = th + normal.sample(&mut rng) * 0.1f64.to_radians();
                e.on_fix(&GnssFix {
                    t_received: t + e.params().gnss_latency,
                    antenna: antenna_of(&e, &truth) + noise,
                    heading: Some(heading),
                    speed: v,
                    roll: None,
                    latency: None,
                });
                let steered = -e.drift_velocity(th).x - truth_across;
                bias_sq += e.wheel_offset().powi(2);
                offset_steered_sq += e.wheel_offset_for_steering().powi(2);
                learnt_sq += (-e.drift().x - truth_across).powi(2);
                steered_sq += steered.powi(2);
                n += 1.0;
                if k == steps {
                    steered_at_end = steered_at_end.max(steered.abs());
                }
            }
        }
    }
    StartUp {
        offset: (bias_sq / n).sqrt(),
        offset_steered: (offset_steered_sq / n).sqrt(),
        learnt: (learnt_sq / n).sqrt(),
        steered: (steered_sq / n).sqrt(),
        steered_at_end,
    }
}

#[test]
fn a_job_s_first_seconds_do_not_learn_an_offset_from_the_noise() {
    // With a 1 s prior (session 16): 0.042°; with 3 s: 0.022°. (The drift, 0.50 cm/s from
    // its 1 s prior, was 0.33 with 2 s, which was not kept: it cost every seed's side slope
    // 10–13 %.)
    let bias = start_up(20, 6.0, 0.0).offset;
    assert!(bias < 0.03f64.to_radians(), "offset {}°", bias.to_degrees());
}

#[test]
fn a_drift_or_an_offset_within_its_own_noise_does_not_steer() {
    // Before session 19 all of it was steered for: a learnt drift of 0.50 cm/s RMS over
    // the first 6 s, and an offset of 0.022°; now 0.17 cm/s and 0.006° of them.
    let s = start_up(20, 6.0, 0.0);
    // (what, learnt RMS, steered RMS, the least learnt noise that makes the check mean it)
    for (what, learnt, steered, noise) in [
        ("drift, m/s", s.learnt, s.steered, 0.003),
        (
            "offset, rad",
            s.offset,
            s.offset_steered,
            0.01f64.to_radians(),
        ),
    ] {
        assert!(
            learnt > noise,
            "{what}: learnt {learnt}, no noise to test with"
        );
        assert!(
            steered < 0.4 * learnt,
            "{what}: steered {steered} of {learnt}"
        );
    }
}

#[test]
fn a_true_drift_steers_once_it_stands_out_of_the_noise() {
    // A 3 cm/s slip from the start is steered for within 0.5 cm/s after 20 s in every run
    // (0.26 cm/s measured). The filter's own variance taken as the estimate's error
    // (σ_rate·√P, blind to the telescoping) would hold back 1 cm/s then.
    let s = start_up(10, 20.0, 0.03);
    assert!(
        s.steered_at_end < 0.005,
        "{} m/s off at 20 s",
        s.steered_at_end
    );
}
