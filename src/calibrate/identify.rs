//! Identification of the steering from commanded and sensed angles (standstill tests): a
//! coarse grid over dead time and lag for a start, then the simplex search over all five
//! parameters of [`SteeringModel`], and their standard deviations.

use super::fit::{nelder_mead, std_devs};
use super::model::{simulate, SteeringModel};

/// Commands sent and angles sensed during the steering tests, sensor terms (rad), times s.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SteeringRecord {
    /// (time sent, commanded angle), in time order.
    pub commands: Vec<(f64, f64)>,
    /// (time measured, sensed angle), in time order.
    pub samples: Vec<(f64, f64)>,
    /// How the wheels came to the first sample: +1 from below, −1 from above, 0 unknown.
    pub approach: f64,
}

impl SteeringRecord {
    /// The part from `t0` to `t1` (the command in force at `t0` kept as its first), with the
    /// wheels having come to `t0` from `approach`.
    pub fn window(&self, t0: f64, t1: f64, approach: f64) -> SteeringRecord {
        let mut commands: Vec<(f64, f64)> = Vec::new();
        if let Some(&(_, c)) = self.commands.iter().rev().find(|(t, _)| *t <= t0) {
            commands.push((t0, c));
        }
        commands.extend(
            self.commands
                .iter()
                .filter(|(t, _)| *t > t0 && *t < t1)
                .copied(),
        );
        SteeringRecord {
            commands,
            samples: self
                .samples
                .iter()
                .filter(|(t, _)| *t >= t0 && *t < t1)
                .copied()
                .collect(),
            approach,
        }
    }
}

/// The fitted steering (sensor terms) and what the data says of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteeringFit {
    pub model: SteeringModel,
    /// Standard deviations of dead time, lag, rate, deadband, backlash (`None`: not
    /// determined by the data).
    pub sigma: [Option<f64>; 5],
    /// RMS of the residuals, rad.
    pub rms: f64,
    /// Time the rate limit bound the fitted response, s (0: the tests never reached it, and
    /// the rate is only known to be at least [`SteeringFit::fastest`]).
    pub rate_bound_s: f64,
    /// Fastest motion of the fitted response, rad/s (over 50 ms).
    pub fastest: f64,
}

/// Highest rate the fit considers, rad/s (beyond it a steering is rate-unlimited here).
const RATE_CEILING: f64 = 3.5;

fn model_of(x: &[f64; 5]) -> SteeringModel {
    SteeringModel {
        dead_time: x[0].abs(),
        tau: x[1].exp(),
        rate: x[2].exp().min(RATE_CEILING),
        deadband: x[3].abs(),
        backlash: x[4].abs(),
    }
}

/// Fit the steering to `rec`. `None` when the record is too short to say anything (fewer
/// than 50 samples or no command).
pub fn fit_steering(rec: &SteeringRecord) -> Option<SteeringFit> {
    fit_steering_from(rec, None)
}

/// [`fit_steering`] starting from `near` (a fit of more of the same data: no grid, one
/// shorter search) when given.
pub fn fit_steering_from(
    rec: &SteeringRecord,
    near: Option<&SteeringModel>,
) -> Option<SteeringFit> {
    let n = rec.samples.len();
    if n < 50 || rec.commands.is_empty() {
        return None;
    }
    let times: Vec<f64> = rec.samples.iter().map(|s| s.0).collect();
    let meas: Vec<f64> = rec.samples.iter().map(|s| s.1).collect();
    let start = meas.iter().take(5).sum::<f64>() / meas.len().min(5) as f64;
    // Fastest sensed motion over ~100 ms windows (a start for the rate).
    let mut fastest: f64 = 0.0;
    for i in 0..n {
        if let Some(j) = (i + 1..n).find(|&j| times[j] - times[i] >= 0.1) {
            fastest = fastest.max((meas[j] - meas[i]).abs() / (times[j] - times[i]));
        }
    }
    let mut pred = vec![0.0; n];
    let cost = |m: &SteeringModel, pred: &mut [f64]| -> f64 {
        simulate(m, &rec.commands, &times, start, rec.approach, pred);
        pred.iter().zip(&meas).map(|(p, y)| (p - y) * (p - y)).sum()
    };
    // Start: the best of a grid over dead time and lag, with the rate at the fastest sensed
    // motion (a steering that ran at its limit) or half as fast again (one that did not).
    let rates = [fastest, 1.5 * fastest].map(|r| r.clamp(0.05, RATE_CEILING));
    let mut best = (f64::INFINITY, [0.0; 5]);
    if let Some(m) = near {
        let x = [
            m.dead_time,
            m.tau.max(1e-3).ln(),
            m.rate.max(1e-3).ln(),
            m.deadband,
            m.backlash,
        ];
        best = (cost(&model_of(&x), &mut pred), x);
    }
    for di in 0..=15 {
        if near.is_some() {
            break;
        }
        for &tau in &[0.03, 0.06, 0.1, 0.15, 0.22, 0.32, 0.45, 0.65, 0.9] {
            for rate in rates {
                let x = [di as f64 * 0.02, f64::ln(tau), rate.ln(), 0.0, 0.0];
                let c = cost(&model_of(&x), &mut pred);
                if c < best.0 {
                    best = (c, x);
                }
            }
        }
    }
    let mut f = |x: &[f64; 5]| cost(&model_of(x), &mut pred);
    let step = [0.015, 0.25, 0.3, 0.003, 0.005];
    let first = if near.is_some() { 0.3 } else { 1.0 };
    let (mut x, mut v) = nelder_mead(&mut f, best.1, step.map(|s| first * s), 600, 1e-10);
    // Restart from the result (the simplex may have collapsed early in the long valley of
    // dead time against lag).
    let restarts: &[f64] = if near.is_some() { &[0.1] } else { &[0.5, 0.2] };
    for &scale in restarts {
        let (x2, v2) = nelder_mead(&mut f, x, step.map(|s| scale * s), 400, 1e-12);
        if v2 < v {
            (x, v) = (x2, v2);
        }
    }
    let model = model_of(&x);
    let rate_bound_s = simulate(
        &model,
        &rec.commands,
        &times,
        start,
        rec.approach,
        &mut pred,
    );
    // The fastest motion of the fitted response (the sensed one carries the noise).
    let mut fastest: f64 = 0.0;
    for i in 0..n {
        if let Some(j) = (i + 1..n).find(|&j| times[j] - times[i] >= 0.05) {
            fastest = fastest.max((pred[j] - pred[i]).abs() / (times[j] - times[i]));
        }
    }
    // Standard deviations in the physical parameters.
    let phys = [
        model.dead_time,
        model.tau,
        model.rate,
        model.deadband,
        model.backlash,
    ];
    let mut res = |p: &[f64; 5], out: &mut [f64]| {
        let m = SteeringModel {
            dead_time: p[0].max(0.0),
            tau: p[1].max(1e-4),
            rate: p[2].max(1e-4),
            deadband: p[3].max(0.0),
            backlash: p[4].max(0.0),
        };
        simulate(&m, &rec.commands, &times, start, rec.approach, out);
        for (o, y) in out.iter_mut().zip(&meas) {
            *o = y - *o;
        }
    };
    let h = [
        0.002,
        (0.02 * model.tau).max(1e-3),
        (0.02 * model.rate).max(1e-3),
        2e-4,
        2e-4,
    ];
    // Central differences need the parameters away from their bound at zero.
    let at = [
        phys[0].max(h[0]),
        phys[1],
        phys[2],
        phys[3].max(h[3]),
        phys[4].max(h[4]),
    ];
    let mut sigma = std_devs(&mut res, &at, &h, n);
    if rate_bound_s <= 0.0 {
        sigma[2] = None;
    }
    Some(SteeringFit {
        model,
        sigma,
        rms: (v / n as f64).sqrt(),
        rate_bound_s,
        fastest,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record of the model itself with a little deterministic noise.
    fn record(m: &SteeringModel) -> SteeringRecord {
        let script = [
            0.25, -0.25, 0.25, 0.0, 0.05, 0.07, 0.045, 0.025, 0.05, 0.01, 0.0,
        ];
        let mut commands = Vec::new();
        let mut t = 0.5;
        for c in script {
            commands.push((t, c));
            t += 3.0;
        }
        let times: Vec<f64> = (0..(t * 100.0) as usize).map(|i| i as f64 * 0.01).collect();
        let mut out = vec![0.0; times.len()];
        simulate(m, &commands, &times, 0.0, 0.0, &mut out);
        let samples = times
            .iter()
            .zip(&out)
            .enumerate()
            .map(|(i, (t, y))| (*t, y + 0.0005 * ((i * 7919 % 13) as f64 - 6.0) / 6.0))
            .collect();
        SteeringRecord {
            commands,
            samples,
            approach: 0.0,
        }
    }

    #[test]
    fn the_fit_recovers_a_model_from_its_own_response() {
        let truth = SteeringModel {
            dead_time: 0.12,
            tau: 0.3,
            rate: 20f64.to_radians(),
            deadband: 0.3f64.to_radians(),
            backlash: 0.6f64.to_radians(),
        };
        let fit = fit_steering(&record(&truth)).expect("fits");
        let m = fit.model;
        assert!((m.dead_time - truth.dead_time).abs() < 0.01, "{m:?}");
        assert!((m.tau / truth.tau - 1.0).abs() < 0.1, "{m:?}");
        assert!((m.rate / truth.rate - 1.0).abs() < 0.1, "{m:?}");
        assert!(
            (m.deadband - truth.deadband).abs() < 0.1f64.to_radians(),
            "{m:?}"
        );
        assert!(
            (m.backlash - truth.backlash).abs() < 0.1f64.to_radians(),
            "{m:?}"
        );
        assert!(fit.rate_bound_s > 0.5 && fit.sigma.iter().all(Option::is_some));
    }
}
