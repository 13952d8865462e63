//! The true XTE of one envelope cell, pass by pass and by distance along the passes: where a
//! cell's error is (a line start after a turn, the steady state, the job's first pass). A
//! diagnostic for the robustness envelope (docs/envelope.md); the figures are the scored ones
//! (`agsteer accuracy` skips the first 10 m of every pass).
//!
//!     cargo run --release --example xte_by_pass -- VARIATION tools/scenarios/S.toml [KEY=VALUE...]
//!
//! VARIATION is a row of `agsteer accuracy --envelope` (`nominal`, `lag_0.6`, …); KEY=VALUE
//! overrides apply to the default tracker and the LQR only, for A/B runs against the references.
//! With `XTE_TRACE=PASS` in the environment, each tracker's pass PASS is also printed every
//! metre (time, distance along, XTE): where in the pass an error grows.

use agsteer::config::TrackerChoice;
use agsteer::demo::envelope::{cell_config, Calibration, MATRIX};
use agsteer::demo::{run, DemoOptions, WorkPass, ACQUISITION_SKIP_M};
use anyhow::{anyhow, Context};

/// Upper ends of the distance bins along a pass, m.
const BINS: [f64; 6] = [15.0, 20.0, 30.0, 50.0, 100.0, f64::INFINITY];

fn rms(sum_sq: f64, n: usize) -> f64 {
    (sum_sq / n.max(1) as f64).sqrt()
}

fn report(tracker: &str, passes: &[WorkPass]) {
    let mut bins = [(0.0f64, 0usize, 0.0f64); BINS.len()];
    let (mut total, mut count) = (0.0, 0);
    for (i, pass) in passes.iter().enumerate() {
        let scored: Vec<f64> = pass
            .samples
            .iter()
            .filter(|s| s.along_m >= ACQUISITION_SKIP_M)
            .map(|s| s.xte_m)
            .collect();
        let start = pass.samples.first().map_or(0.0, |s| s.xte_m);
        let worst = scored.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let sum_sq: f64 = scored.iter().map(|x| x * x).sum();
        let mean = scored.iter().sum::<f64>() / scored.len().max(1) as f64;
        println!(
            "{tracker:<13} pass {i:>2}: starts {:>7.2} cm, scored RMS {:>6.2} max {:>6.2} mean {:>6.2} cm",
            100.0 * start,
            100.0 * rms(sum_sq, scored.len()),
            100.0 * worst,
            100.0 * mean
        );
        for s in pass
            .samples
            .iter()
            .filter(|s| s.along_m >= ACQUISITION_SKIP_M)
        {
            let b = BINS
                .iter()
                .position(|e| s.along_m < *e)
                .unwrap_or(BINS.len() - 1);
            bins[b].0 += s.xte_m * s.xte_m;
            bins[b].1 += 1;
            bins[b].2 = bins[b].2.max(s.xte_m.abs());
            total += s.xte_m * s.xte_m;
            count += 1;
        }
    }
    print!(
        "{tracker:<13} scored RMS {:.2} cm |",
        100.0 * rms(total, count)
    );
    let mut from = ACQUISITION_SKIP_M;
    for (edge, (sum_sq, n, worst)) in BINS.iter().zip(bins) {
        print!(
            " {from:.0}-{edge:.0} m: {:.2}/{:.2} ({:.0} %)",
            100.0 * rms(sum_sq, n),
            100.0 * worst,
            100.0 * sum_sq / total.max(f64::MIN_POSITIVE)
        );
        from = *edge;
    }
    println!();
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (name, scenario) = match args.as_slice() {
        [name, scenario, ..] => (name, scenario),
        _ => {
            return Err(anyhow!(
                "usage: xte_by_pass VARIATION SCENARIO.toml [KEY=VALUE...]"
            ))
        }
    };
    let variation = MATRIX
        .iter()
        .find(|v| v.name == name.as_str())
        .ok_or_else(|| anyhow!("no variation {name} in the envelope"))?;
    let path = std::path::Path::new(scenario);
    let extra = &args[2..];
    for tracker in [
        TrackerChoice::Predictive,
        TrackerChoice::PurePursuit,
        TrackerChoice::Stanley,
        TrackerChoice::Lqr,
    ] {
        let set = if matches!(tracker, TrackerChoice::Predictive | TrackerChoice::Lqr) {
            extra
        } else {
            &[]
        };
        let mut cfg = cell_config(path, variation, set, Calibration::Truth)
            .with_context(|| format!("{scenario} with {name}"))?;
        cfg.track.kind = tracker;
        let opts = DemoOptions {
            record_work: true,
            ..DemoOptions::default()
        };
        let done = run(&cfg, &opts, &mut |_| {}, &mut |_, _| {})
            .with_context(|| format!("{scenario} with {name}"))?;
        report(tracker.name(), &done.work);
        if let Some(pass) = std::env::var("XTE_TRACE")
            .ok()
            .and_then(|v| v.parse::<usize>().ok())
            .and_then(|i| done.work.get(i))
        {
            let mut next = 0.0;
            for s in &pass.samples {
                if s.along_m >= next {
                    println!(
                        "  t {:7.2} s  along {:6.1} m  xte {:7.2} cm",
                        s.t,
                        s.along_m,
                        100.0 * s.xte_m
                    );
                    next = s.along_m.floor() + 1.0;
                }
            }
        }
    }
    Ok(())
}
