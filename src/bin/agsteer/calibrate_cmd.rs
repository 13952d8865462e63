//! `agsteer calibrate`: the steering calibration (issue 15 point 4), either against the
//! simulated tractor of the configuration's `[sim]` over the in-memory bus, or (`--interface`)
//! by a running agsteerd on a real interface, in its calibration mode ([`crate::calibrate_live`]).

use agsteer::calibrate::Calibration;
use agsteer::config::Config;
use agsteer::demo::calibrate::{params_for, run, Operator};
use anyhow::{Context, Result};
use std::path::Path;

/// Exit status when calibration refuses.
pub const REFUSED: u8 = agsteer::exit::Exit::CalibrationRefused.code();

/// Print the figures and the fragment; write the fragment to `out` when asked.
pub fn report(
    figures: &agsteer::calibrate::Figures,
    fragment: &str,
    out: Option<&Path>,
) -> Result<()> {
    print!("{}", figures.report());
    println!("\n{fragment}");
    if let Some(p) = out {
        std::fs::write(p, fragment).with_context(|| format!("writing {}", p.display()))?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
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
    report(&c.figures(), &c.toml_fragment(), out)?;
    Ok(0)
}
