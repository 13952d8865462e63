//! The robustness envelope (`agsteer accuracy --envelope`): every scenario of the accuracy
//! suite across a matrix of plant variations — the simulated tractor differing from the
//! controller's model, one way at a time and a few all at once — scored for every tracker.
//!
//! A variation is a list of `--set` overrides of `[sim]` keys (the true vehicle, its sensors
//! and actuator) and of `control.speed_kmh` (with the supervisor's speed limit where the speed
//! reaches it), applied on top of each scenario file, so any cell
//! is reproduced with `agsteer accuracy --config tools/scenarios/S.toml --set …`. The
//! controller keeps its nominal configuration except the keys that calibration owns
//! ([`Calibration`]).
//!
//! Targets (issue 15 point 3), per cell, for the default tracker: the job finishes; straight
//! lines and single disturbances XTE RMS ≤ 2.5 cm and max ≤ 15 cm; curves (R ≥ 15 m) and all
//! disturbances at once RMS ≤ 5 cm; and never more than 20 % worse than the better of the two
//! references (pure pursuit and Stanley).

use super::accuracy::{evaluate, tracker_name, ScenarioResult};
use crate::config::{Config, TrackerChoice};
use serde::Serialize;

/// One row of the envelope: a way the plant differs from the model.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Variation {
    pub name: &'static str,
    /// What it is, for the table.
    pub what: &'static str,
    /// `KEY=VALUE` overrides, applied after the scenario file.
    pub set: &'static [&'static str],
}

const fn v(name: &'static str, what: &'static str, set: &'static [&'static str]) -> Variation {
    Variation { name, what, set }
}

/// The matrix: each range of issue 15 point 2 at its ends (and the middle where the response
/// is not monotonic), then the tyre models and two whole tractors that differ in everything at
/// once.
pub const MATRIX: &[Variation] = &[
    v("nominal", "the model is exact", &[]),
    v(
        "gnss_white_0.5cm",
        "GNSS white noise σ 0.5 cm",
        &["sim.gnss_sigma_m=0.005"],
    ),
    v(
        "gnss_white_3cm",
        "GNSS white noise σ 3 cm",
        &["sim.gnss_sigma_m=0.03"],
    ),
    v(
        "gnss_white_5cm",
        "GNSS white noise σ 5 cm",
        &["sim.gnss_sigma_m=0.05"],
    ),
    v(
        "gnss_markov_3cm",
        "GNSS Gauss-Markov σ 3 cm, τ 60 s",
        &["sim.gnss_markov_sigma_m=0.03", "sim.gnss_markov_tau_s=60"],
    ),
    v("gnss_1hz", "GNSS at 1 Hz", &["sim.gnss_rate_hz=1"]),
    v("gnss_5hz", "GNSS at 5 Hz", &["sim.gnss_rate_hz=5"]),
    v("gnss_20hz", "GNSS at 20 Hz", &["sim.gnss_rate_hz=20"]),
    v(
        "gnss_latency_0",
        "GNSS latency 0 s (the controller assumes 0.05 s)",
        &["sim.gnss_latency_s=0"],
    ),
    v(
        "gnss_latency_0.3",
        "GNSS latency 0.3 s (the controller assumes 0.05 s)",
        &["sim.gnss_latency_s=0.3"],
    ),
    v(
        "rate_10",
        "steering rate limit 10°/s",
        &["sim.actuator_rate_deg_s=10"],
    ),
    v(
        "rate_20",
        "steering rate limit 20°/s",
        &["sim.actuator_rate_deg_s=20"],
    ),
    v(
        "rate_90",
        "steering rate limit 90°/s",
        &["sim.actuator_rate_deg_s=90"],
    ),
    v(
        "dead_time_0",
        "steering dead time 0 s",
        &["sim.actuator_dead_time_s=0"],
    ),
    v(
        "dead_time_0.25",
        "steering dead time 0.25 s",
        &["sim.actuator_dead_time_s=0.25"],
    ),
    v(
        "lag_0.05",
        "steering lag 0.05 s",
        &["sim.actuator_tau_s=0.05"],
    ),
    v("lag_0.6", "steering lag 0.6 s", &["sim.actuator_tau_s=0.6"]),
    v(
        "deadband_1",
        "actuator deadband 1°",
        &["sim.actuator_deadband_deg=1"],
    ),
    v(
        "backlash_1",
        "steering backlash 1°",
        &["sim.actuator_backlash_deg=1"],
    ),
    v(
        "was_noise_0.5",
        "wheel-angle sensor noise σ 0.5°",
        &["sim.was_noise_deg=0.5"],
    ),
    v(
        "was_gain_0.9",
        "wheel-angle sensor gain 0.9",
        &["sim.was_gain=0.9"],
    ),
    v(
        "was_gain_1.1",
        "wheel-angle sensor gain 1.1",
        &["sim.was_gain=1.1"],
    ),
    v(
        "was_offset_+2",
        "wheel-angle sensor offset +2°",
        &["sim.was_bias_deg=2"],
    ),
    v(
        "was_offset_-2",
        "wheel-angle sensor offset −2°",
        &["sim.was_bias_deg=-2"],
    ),
    v(
        "wheelbase_-10%",
        "true wheelbase 10 % shorter (2.7 m)",
        &["sim.wheelbase_error_m=-0.3"],
    ),
    v(
        "wheelbase_+10%",
        "true wheelbase 10 % longer (3.3 m)",
        &["sim.wheelbase_error_m=0.3"],
    ),
    v(
        "antenna_fwd_-0.3",
        "antenna 0.3 m further back than configured",
        &["sim.antenna_error_forward_m=-0.3"],
    ),
    v(
        "antenna_fwd_+0.3",
        "antenna 0.3 m further forward than configured",
        &["sim.antenna_error_forward_m=0.3"],
    ),
    v(
        "antenna_left_-0.3",
        "antenna 0.3 m right of where configured",
        &["sim.antenna_error_left_m=-0.3"],
    ),
    v(
        "antenna_left_+0.3",
        "antenna 0.3 m left of where configured",
        &["sim.antenna_error_left_m=0.3"],
    ),
    v(
        "antenna_up_-0.3",
        "antenna 0.3 m lower than configured",
        &["sim.antenna_error_up_m=-0.3"],
    ),
    v(
        "antenna_up_+0.3",
        "antenna 0.3 m higher than configured",
        &["sim.antenna_error_up_m=0.3"],
    ),
    v(
        "tyre_slip_firm",
        "dynamic tyres, firm soil (K 0.38°/(m/s²))",
        &["sim.tyre_slip=true"],
    ),
    v(
        "tyre_slip_soft",
        "dynamic tyres, soft soil (half the cornering stiffness)",
        &[
            "sim.tyre_slip=true",
            "sim.cornering_stiffness_front_n_per_deg=1050",
            "sim.cornering_stiffness_rear_n_per_deg=2100",
        ],
    ),
    v(
        "side_draft_5kN",
        "dynamic tyres and a 5 kN implement side draft",
        &[
            "sim.tyre_slip=true",
            "sim.implement_side_force_n=5000",
            "sim.implement_hitch_m=1.5",
        ],
    ),
    v("speed_1", "1 km/h", &["control.speed_kmh=1"]),
    v("speed_20", "20 km/h", &["control.speed_kmh=20"]),
    v(
        "speed_25",
        "25 km/h (the supervisor's speed limit raised from its 25 km/h default to 30)",
        &["control.speed_kmh=25", "safety.max_speed_kmh=30"],
    ),
    v(
        "tractor_a",
        "all at once: firm tyres, slow steering (20°/s, 0.1 s dead, 0.3 s lag, 0.5° play), \
         WAS gain 1.05 offset 1°, wheelbase +5 %, antenna 0.1 m off, GNSS σ 2 cm",
        &[
            "sim.tyre_slip=true",
            "sim.actuator_rate_deg_s=20",
            "sim.actuator_dead_time_s=0.1",
            "sim.actuator_tau_s=0.3",
            "sim.actuator_backlash_deg=0.5",
            "sim.was_gain=1.05",
            "sim.was_bias_deg=1",
            "sim.wheelbase_error_m=0.15",
            "sim.antenna_error_forward_m=0.1",
            "sim.antenna_error_left_m=-0.1",
            "sim.gnss_sigma_m=0.02",
        ],
    ),
    v(
        "tractor_b",
        "all at once: soft tyres, fast steering (60°/s, 0.03 s dead, 0.08 s lag, 0.3° deadband), \
         WAS gain 0.93 offset −1.5°, wheelbase −7 %, antenna 0.2 m off, GNSS at 5 Hz, 0.15 s late",
        &[
            "sim.tyre_slip=true",
            "sim.cornering_stiffness_front_n_per_deg=1200",
            "sim.cornering_stiffness_rear_n_per_deg=2500",
            "sim.actuator_rate_deg_s=60",
            "sim.actuator_dead_time_s=0.03",
            "sim.actuator_tau_s=0.08",
            "sim.actuator_deadband_deg=0.3",
            "sim.was_gain=0.93",
            "sim.was_bias_deg=-1.5",
            "sim.wheelbase_error_m=-0.2",
            "sim.antenna_error_forward_m=-0.2",
            "sim.antenna_error_up_m=0.2",
            "sim.gnss_rate_hz=5",
            "sim.gnss_latency_s=0.15",
        ],
    ),
];

/// What the controller is told about the steering that calibration measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Calibration {
    /// Nothing: the controller keeps its nominal configuration throughout.
    Nominal,
    /// The plant's true values of what calibration measures (an ideal calibration).
    Truth,
}

/// Set the controller's calibration-owned keys of `cfg` (a scenario with a variation) as
/// `calibration` says.
pub fn apply_calibration(cfg: &mut Config, calibration: Calibration) {
    match calibration {
        Calibration::Nominal => {}
        Calibration::Truth => {
            let s = cfg.sim.clone();
            cfg.safety.actuator_dead_time_s = s.actuator_dead_time_s.min(0.5);
            cfg.safety.actuator_tau_s = s.actuator_tau_s;
            cfg.safety.actuator_rate_deg_s = s.actuator_rate_deg_s;
            // The receiver's fix interval (calibration measures it from the slalom's fixes;
            // the loaded configuration's rate is at least 0.5 Hz).
            cfg.safety.gnss_timeout_s =
                crate::calibrate::gnss_timeout_for_interval(1.0 / s.gnss_rate_hz);
            cfg.track.lead_time_s = s.actuator_dead_time_s.min(1.0);
            // The sensor's gain as calibration measures it: the drive's yaw rates give the true
            // angle through the configured wheelbase, so a wheelbase error reads as a gain
            // error, L_true / L_configured (`agsteer calibrate` on a tractor 10 % longer than
            // configured: 1.097), which is the gain the controller needs with its wheelbase.
            // (The loaded configuration's wheelbase is at least 0.5 m.)
            let configured = cfg.vehicle.wheelbase_m;
            cfg.vehicle.was_gain = s.was_gain * (configured + s.wheelbase_error_m) / configured;
            cfg.vehicle.was_offset_deg = s.was_bias_deg;
            cfg.track.lost_motion_initial_deg = (s.actuator_deadband_deg
                + 0.5 * s.actuator_backlash_deg)
                .min(cfg.track.lost_motion_limit_deg);
            // The GNSS latency, the antenna's lateral offset and its forward offset (the
            // slalom, the two-way pass and the drive's turns); the true antenna stays where
            // it is.
            cfg.track.gnss_latency_s = s.gnss_latency_s.min(0.5);
            cfg.vehicle.antenna_left_m += s.antenna_error_left_m;
            cfg.sim.antenna_error_left_m = 0.0;
            cfg.vehicle.antenna_forward_m += s.antenna_error_forward_m;
            cfg.sim.antenna_error_forward_m = 0.0;
        }
    }
}

/// The target class of a scenario.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TargetClass {
    /// Straight lines and single disturbances: RMS ≤ 2.5 cm, max ≤ 15 cm.
    Straight,
    /// Curves (R ≥ 15 m) and every disturbance at once: RMS ≤ 5 cm.
    CurveOrAll,
}

impl TargetClass {
    pub fn of(cfg: &Config, scenario: &str) -> TargetClass {
        if cfg.job.kind == crate::config::JobKind::Arcs || scenario.starts_with("all_") {
            TargetClass::CurveOrAll
        } else {
            TargetClass::Straight
        }
    }
    /// (RMS, max) bounds, m.
    pub fn bounds(self) -> (f64, f64) {
        match self {
            TargetClass::Straight => (0.025, 0.15),
            TargetClass::CurveOrAll => (0.05, f64::INFINITY),
        }
    }
}

/// One cell: a scenario under a variation, every tracker.
#[derive(Debug, Clone, Serialize)]
pub struct Cell {
    pub variation: String,
    pub scenario: String,
    pub class: TargetClass,
    /// Per tracker, default first.
    pub results: Vec<ScenarioResult>,
    /// Why a run failed to start (configuration), if it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// How a cell stands against the targets.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Verdict {
    /// The default tracker finished and met the RMS and max bounds of its class.
    pub meets_bounds: bool,
    /// Better of the references' RMS, m (`None` when they were not run).
    pub best_reference_rms_m: Option<f64>,
    /// A reference tracker did better than the default.
    pub reference_better: bool,
    /// The default is more than 20 % worse than the better reference.
    pub worse_than_reference: bool,
    /// The default did not finish because the supervisor refused the line as unfollowable
    /// (`line_unfollowable`: the engage gate, or the line given back as it started), and for
    /// no other fault: physics, not the tracker (issue 15 point 3's named impossible cells).
    pub refused_by_design: bool,
}

impl Cell {
    pub fn default_result(&self) -> Option<&ScenarioResult> {
        self.results.first()
    }

    pub fn verdict(&self) -> Verdict {
        let (rms_max, max_max) = self.class.bounds();
        let d = self.default_result();
        let meets_bounds =
            d.is_some_and(|r| r.finished && r.xte_rms_m <= rms_max && r.xte_max_m <= max_max);
        let score = |r: &ScenarioResult| {
            if r.finished {
                r.xte_rms_m
            } else {
                f64::INFINITY
            }
        };
        let best = self
            .results
            .iter()
            .skip(1)
            .map(score)
            .fold(None, |b: Option<f64>, x| Some(b.map_or(x, |b| b.min(x))));
        let own = d.map_or(f64::INFINITY, score);
        let refused_by_design = d.is_some_and(|r| {
            const REFUSED: &str = "line_unfollowable";
            !r.finished
                && (r.refusals.contains_key(REFUSED) || r.disengagements.contains_key(REFUSED))
                && r.disengagements
                    .keys()
                    .all(|k| k == REFUSED || k == "no_guidance")
        });
        Verdict {
            meets_bounds,
            best_reference_rms_m: best,
            reference_better: best.is_some_and(|b| b < own),
            worse_than_reference: best.is_some_and(|b| own > 1.2 * b),
            refused_by_design,
        }
    }

    /// Every target of the cell holds.
    pub fn meets_targets(&self) -> bool {
        let v = self.verdict();
        v.meets_bounds && !v.worse_than_reference
    }
}

/// The scenario configurations of one variation (`KEY=VALUE` overrides in order: the
/// variation's, then `extra`), with the calibration applied.
pub fn cell_config(
    scenario: &std::path::Path,
    variation: &Variation,
    extra: &[String],
    calibration: Calibration,
) -> Result<Config, crate::config::ConfigError> {
    let mut set: Vec<String> = variation.set.iter().map(|s| s.to_string()).collect();
    set.extend_from_slice(extra);
    let mut cfg = Config::load(scenario, &set)?;
    apply_calibration(&mut cfg, calibration);
    Ok(cfg)
}

/// Run one cell for `trackers` (the default first).
pub fn run_cell(variation: &str, scenario: &str, cfg: &Config, trackers: &[TrackerChoice]) -> Cell {
    let mut results = Vec::with_capacity(trackers.len());
    let mut error = None;
    for &k in trackers {
        match evaluate(scenario, cfg, k) {
            Ok((r, _)) => results.push(r),
            Err(e) => {
                error = Some(format!("{}: {e}", tracker_name(k)));
                break;
            }
        }
    }
    Cell {
        variation: variation.to_string(),
        scenario: scenario.to_string(),
        class: TargetClass::of(cfg, scenario),
        results,
        error,
    }
}

/// The envelope's Markdown table: rows variations, columns scenarios, each cell the default
/// tracker's XTE RMS in cm; `*` where a reference tracker did better, `**` where the default
/// is more than 20 % worse than it, `!` where a bound of the cell's class is not met, `✗`
/// where the job did not finish, `⊘` where the supervisor refused the line as unfollowable
/// (refused by design, [`Verdict::refused_by_design`]).
pub fn markdown(cells: &[Cell], variations: &[&str], scenarios: &[&str]) -> String {
    use std::fmt::Write;
    let mut s = String::from("| variation |");
    for sc in scenarios {
        let _ = write!(s, " {sc} |");
    }
    s.push_str("\n|---|");
    for _ in scenarios {
        s.push_str("---|");
    }
    s.push('\n');
    for var in variations {
        let _ = write!(s, "| {var} |");
        for sc in scenarios {
            let cell = cells
                .iter()
                .find(|c| c.variation == *var && c.scenario == *sc);
            let text = match cell {
                None => "".to_string(),
                Some(c) => cell_text(c),
            };
            let _ = write!(s, " {text} |");
        }
        s.push('\n');
    }
    s
}

fn cell_text(c: &Cell) -> String {
    let Some(r) = c.default_result() else {
        return "error".into();
    };
    let v = c.verdict();
    if v.refused_by_design {
        return "⊘".into();
    }
    let mut t = format!("{:.2}", 100.0 * r.xte_rms_m);
    if !r.finished {
        t.push_str(" ✗");
    } else if !v.meets_bounds {
        t.push_str(" !");
    }
    if v.worse_than_reference {
        t.push_str(" **");
    } else if v.reference_better {
        t.push_str(" *");
    }
    t
}

/// Colour of an RMS on the heat map: green at ≤ 0.5 cm through yellow (2.5 cm) to red at
/// ≥ 25 cm, on a log scale.
fn heat(rms_m: f64) -> String {
    let cm = (rms_m * 100.0).max(1e-3);
    // 0 at 0.5 cm, 0.5 at 2.5 cm, 1 at 25 cm (piecewise log).
    let x = if cm <= 2.5 {
        0.5 * ((cm / 0.5).ln() / 5f64.ln()).clamp(0.0, 1.0)
    } else {
        0.5 + 0.5 * ((cm / 2.5).ln() / 10f64.ln()).clamp(0.0, 1.0)
    };
    let (r, g) = if x < 0.5 {
        ((510.0 * x) as u8, 190u8)
    } else {
        (255u8, (190.0 * (2.0 - 2.0 * x)) as u8)
    };
    format!("rgb({r},{g},60)")
}

/// The heat map (SVG): rows variations, columns scenarios, colour = the default tracker's XTE
/// RMS (value printed in cm), a black corner where a reference tracker did better, a red frame
/// where a target of the cell is missed, grey with ✗ where the job did not finish.
pub fn heat_map_svg(cells: &[Cell], variations: &[&str], scenarios: &[&str]) -> String {
    use std::fmt::Write;
    const CW: f64 = 74.0;
    const CH: f64 = 20.0;
    const LEFT: f64 = 140.0;
    const TOP: f64 = 130.0;
    let w = LEFT + CW * scenarios.len() as f64 + 10.0;
    let h = TOP + CH * variations.len() as f64 + 60.0;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="11">"#
    );
    let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="10" y="18" font-size="13">Envelope: default tracker XTE RMS (cm) per plant variation (rows) and scenario (columns)</text>"#
    );
    for (j, sc) in scenarios.iter().enumerate() {
        let x = LEFT + CW * (j as f64 + 0.5);
        let _ = writeln!(
            s,
            r#"<text transform="translate({x:.1},{:.1}) rotate(-50)">{sc}</text>"#,
            TOP - 6.0
        );
    }
    for (i, var) in variations.iter().enumerate() {
        let y = TOP + CH * i as f64;
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{var}</text>"#,
            LEFT - 6.0,
            y + 14.0
        );
        for (j, sc) in scenarios.iter().enumerate() {
            let x = LEFT + CW * j as f64;
            let Some(c) = cells
                .iter()
                .find(|c| c.variation == *var && c.scenario == *sc)
            else {
                continue;
            };
            let Some(r) = c.default_result() else {
                continue;
            };
            let v = c.verdict();
            let fill = if v.refused_by_design {
                "rgb(200,200,230)".into()
            } else if r.finished {
                heat(r.xte_rms_m)
            } else {
                "rgb(150,150,150)".into()
            };
            let _ = writeln!(
                s,
                r#"<rect x="{x:.1}" y="{y:.1}" width="{CW}" height="{CH}" fill="{fill}" stroke="white"/>"#
            );
            if !c.meets_targets() && !v.refused_by_design {
                let _ = writeln!(
                    s,
                    r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="#c00000" stroke-width="2"/>"##,
                    x + 1.5,
                    y + 1.5,
                    CW - 3.0,
                    CH - 3.0
                );
            }
            if v.reference_better {
                let _ = writeln!(
                    s,
                    r#"<path d="M{:.1},{y:.1} L{:.1},{y:.1} L{:.1},{:.1} Z" fill="black"/>"#,
                    x + CW - 9.0,
                    x + CW,
                    x + CW,
                    y + 9.0
                );
            }
            let text = if v.refused_by_design {
                "⊘".into()
            } else if r.finished {
                format!("{:.2}", 100.0 * r.xte_rms_m)
            } else {
                "✗".into()
            };
            let _ = writeln!(
                s,
                r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{text}</text>"#,
                x + CW / 2.0,
                y + 14.0
            );
        }
    }
    let y = TOP + CH * variations.len() as f64 + 20.0;
    let _ = writeln!(
        s,
        r#"<text x="10" y="{y:.1}">Colour: green ≤ 0.5 cm, yellow 2.5 cm, red ≥ 25 cm (log). Black corner: a reference tracker (pure pursuit or Stanley) did better. Red frame: a target missed. Grey ✗: unfinished. Blue-grey ⊘: refused as unfollowable (by design).</text>"#
    );
    s.push_str("</svg>\n");
    s
}

/// Run `f` over `items` on up to `threads` threads, calling `progress(done, total)` after
/// each; results in the items' order.
pub fn parallel_map<T: Sync, R: Send>(
    items: &[T],
    threads: usize,
    f: &(dyn Fn(&T) -> R + Sync),
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Vec<R> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let threads = threads.clamp(1, items.len().max(1));
    let mut out: Vec<(usize, R)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                s.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(item) = items.get(i) else {
                            break;
                        };
                        mine.push((i, f(item)));
                        let d = done.fetch_add(1, Ordering::Relaxed) + 1;
                        progress(d, items.len());
                    }
                    mine
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_default())
            .collect()
    });
    out.sort_by_key(|(i, _)| *i);
    out.into_iter().map(|(_, r)| r).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_variation_is_a_valid_configuration() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let scenario = root.join("tools/scenarios/straight_10kmh.toml");
        let mut names = std::collections::HashSet::new();
        for var in MATRIX {
            assert!(names.insert(var.name), "duplicate {}", var.name);
            let cfg = cell_config(&scenario, var, &[], Calibration::Truth);
            assert!(cfg.is_ok(), "{}: {:?}", var.name, cfg.err());
        }
    }

    #[test]
    fn the_heat_scale_runs_green_to_red() {
        assert_eq!(heat(0.001), "rgb(0,190,60)");
        assert_eq!(heat(0.025), "rgb(255,190,60)");
        assert_eq!(heat(1.0), "rgb(255,0,60)");
    }

    #[test]
    fn parallel_map_keeps_the_order() {
        let items: Vec<u32> = (0..50).collect();
        let out = parallel_map(&items, 3, &|x| x * 2, &|_, _| {});
        assert_eq!(out, items.iter().map(|x| x * 2).collect::<Vec<_>>());
    }
}
