//! `agsteer calibrate`: the steering calibration (issue 15 point 4) against the simulated
//! tractor of the configuration's `[sim]`, over the in-memory bus. Against a live `agsteerd`
//! on a real interface and as a daemon mode: not built yet (README, "Calibration").

use agsteer::calibrate::{Calibration, Estimate};
use agsteer::config::Config;
use agsteer::demo::calibrate::{params_for, run, Operator};
use anyhow::{Context, Result};
use std::path::Path;

/// Exit status when calibration refuses.
pub const REFUSED: u8 = agsteer::exit::Exit::CalibrationRefused.code();

fn show(e: &Estimate, scale: f64, unit: &str, digits: usize) -> String {
    match e.sd {
        Some(s) => format!(
            "{:.*} ± {:.*} {unit}",
            digits,
            e.value * scale,
            digits,
            s * scale
        ),
        None => format!("{:.*} {unit} (not determined)", digits, e.value * scale),
    }
}

pub fn calibrate(cfg: &Config, out: Option<&Path>) -> Result<u8> {
    let params = params_for(cfg);
    let result = run(
        params,
        cfg.sim_params(),
        cfg.control.dt_s,
        &Operator::default(),
        &mut |t, phase| eprintln!("{t:7.1} s  {phase}"),
    );
    let c: Calibration = match result {
        Ok(c) => c,
        Err(e) => {
            eprintln!("calibration refused: {e}");
            return Ok(REFUSED);
        }
    };
    let deg = 1f64.to_degrees();
    println!("dead time      {}", show(&c.dead_time, 1000.0, "ms", 1));
    println!("lag            {}", show(&c.tau, 1000.0, "ms", 1));
    if c.rate_reached {
        println!("rate limit     {}", show(&c.rate, deg, "°/s", 1));
    } else {
        println!(
            "rate limit     ≥ {:.1} °/s (not reached by the tests)",
            c.rate.value * deg
        );
    }
    println!("deadband       {}", show(&c.deadband, deg, "°", 2));
    println!("backlash       {}", show(&c.backlash, deg, "°", 2));
    println!(
        "lost motion    {:.2} ° (deadband + half the backlash)",
        (c.deadband.value + 0.5 * c.backlash.value) * deg
    );
    println!("WAS gain       {}", show(&c.was_gain, 1.0, "", 4));
    println!("WAS offset     {}", show(&c.was_offset, deg, "°", 2));
    println!("fit residual   {:.3} ° RMS", c.steering_rms.to_degrees());
    let frag = c.toml_fragment();
    println!("\n{frag}");
    if let Some(p) = out {
        std::fs::write(p, &frag).with_context(|| format!("writing {}", p.display()))?;
        eprintln!("wrote {}", p.display());
    }
    Ok(0)
}
