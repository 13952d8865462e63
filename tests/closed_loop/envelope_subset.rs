//! A sampled subset of the robustness envelope (issue 15 point 3, `agsteer accuracy
//! --envelope`): a few cells, default tracker only, each held to about twice the XTE RMS the
//! full run measured (docs/envelope.md), so a change that makes the tracker less robust fails
//! here without the hour the whole envelope takes. Simulated time only.

use agsteer::config::TrackerChoice;
use agsteer::demo::envelope::{cell_config, run_cell, Calibration, MATRIX};
use std::path::Path;

/// (variation, scenario, measured RMS cm in docs/envelope.md).
const CELLS: &[(&str, &str, f64)] = &[
    ("nominal", "straight_10kmh", 0.29),
    ("gnss_white_3cm", "straight_10kmh", 0.73),
    ("backlash_1", "straight_10kmh", 0.36),
    ("dead_time_0.25", "straight_10kmh", 0.31),
    ("deadband_1", "curve_r30", 0.63),
    // The look-ahead scheduled on the calibrated steering (a 20°/s motor, a 0.6 s lag: both
    // weaved until the supervisor disengaged before) and the position smoothing (GNSS σ 5 cm:
    // 3.5 m RMS before).
    ("rate_20", "straight_10kmh", 0.53),
    ("lag_0.6", "curve_r30", 0.32),
    ("gnss_white_5cm", "straight_10kmh", 0.99),
    // Turns planned within the steering's rate (a 10°/s motor: 11.2 cm RMS before, turns
    // planned steeper than it could follow), the look-ahead's growth capped at speed (25 km/h:
    // 2.39 cm before), and the all-at-once tractor_a (10.2 cm before).
    ("rate_10", "straight_10kmh", 0.29),
    ("speed_25", "straight_15kmh", 0.48),
    ("tractor_a", "straight_10kmh", 0.54),
    // The curvature scale (session 7): the wheel angle curves need beyond the model's is
    // learnt (firm tyres' understeer: 15.4 cm before; soft tyres, wheelbase −7 %, antenna
    // 0.2 m back: 10.15 cm before).
    ("tyre_slip_firm", "curve_r15", 4.17),
    ("tractor_b", "curve_r30", 2.72),
    // Session 13: the arcs' turns continuous-curvature (they fell back to arcs) and the
    // look-ahead kept within the steering's rate (a 10°/s motor on R 30 m arcs: 14.6 cm
    // before); the GNSS timeout that calibration sets from the receiver's fix interval (1 Hz:
    // no cell finished before).
    ("rate_10", "curve_r30", 0.41),
    ("gnss_1hz", "straight_10kmh", 0.82),
    // The ideal calibration's WAS gain as `agsteer calibrate` measures it, relative to the
    // configured wheelbase (0.63 cm with the sensor's own gain, `**` against Stanley's 0.29).
    ("wheelbase_+10%", "straight_15kmh", 0.35),
    // Session 14: the drift kept per direction of straight driving (a 5 kN side draft's crab
    // flipped with every pass: 12.08 cm RMS before).
    ("side_draft_5kN", "straight_10kmh", 0.63),
    // Session 16: on curves a drift known to be the vehicle's turns with the heading (the side
    // draft's crab on R 15 m arcs: 14.1 cm RMS before).
    ("side_draft_5kN", "curve_r15", 2.49),
    // Session 18: a job started on an arc starts with the arc's steering held (a slow
    // steering never caught the arc it had left with straight wheels: 7.57 cm before; 20 km/h
    // on R 30 m: 5.01 cm).
    ("rate_10", "curve_r15", 1.00),
    ("speed_20", "curve_r30", 0.45),
    // Session 18: turns no faster than a lagging steering can lead within the supervisor's
    // angle limit (a 0.6 s lag at 15 km/h left every line start 0.7-1.3 m off: 3.23 cm).
    ("lag_0.6", "straight_15kmh", 0.33),
    // Session 19: the drift learnt down to 0.2 m/s (a 2° slope's slip, a 6° crab at 1 km/h:
    // 18.5 cm RMS before; 0.55 since session 33's faster drift, 0.31 at its 60 s).
    ("speed_1", "slip_side_slope", 0.55),
    // Session 24: the observer learns over a 1 Hz receiver's 1 s fix intervals (it learnt
    // nothing beyond 0.5 s: a 2° slope stood every pass 8 cm downhill, 8.38 cm RMS).
    ("gnss_1hz", "slip_side_slope", 0.96),
    // Session 25: the lag beyond 0.15 s led on the command and the look-ahead scheduled on
    // what is left (a 0.6 s lag: a 7 m look-ahead took 20 m to remove a line start's 10 cm,
    // 0.64 cm on the 15 km/h straight and 1.42 on R 15 m before).
    ("lag_0.6", "curve_r15", 0.59),
];

/// The default tracker on one envelope cell with the ideal calibration: whether the job
/// finished, and the XTE RMS, cm.
fn default_on(var: &str, scenario: &str) -> (bool, f64) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let v = MATRIX
        .iter()
        .find(|v| v.name == var)
        .unwrap_or_else(|| panic!("variation {var}"));
    let path = root.join(format!("tools/scenarios/{scenario}.toml"));
    let cfg = cell_config(&path, v, &[], Calibration::Truth).expect("valid cell");
    let cell = run_cell(var, scenario, &cfg, &[TrackerChoice::Predictive]);
    let r = cell.default_result().expect("ran");
    (r.finished, 100.0 * r.xte_rms_m)
}

/// Every cell (variation, scenario, bound cm) finishes with the default tracker within its
/// bound.
fn each_within(cells: &[(&str, &str, f64)]) {
    for &(var, scenario, bound_cm) in cells {
        let (finished, got) = default_on(var, scenario);
        assert!(
            finished && got <= bound_cm,
            "{var}/{scenario}: {got:.2} cm, bound {bound_cm}"
        );
    }
}

#[test]
fn sampled_envelope_cells_stay_within_twice_their_figures() {
    let mut out = Vec::new();
    for &(var, scenario, rms_cm) in CELLS {
        let (finished, got) = default_on(var, scenario);
        out.push(format!(
            "{var}/{scenario}: {got:.2} cm (figure {rms_cm}, bound {:.2})",
            2.0 * rms_cm
        ));
        assert!(finished && got <= 2.0 * rms_cm, "{}", out.join("\n"));
    }
    eprintln!("{}", out.join("\n"));
}

/// Session 25: the turns learn their own share of the curvature scale. On straight lines the
/// work lines teach the scale nothing, so a 15 km/h turn (2 m/s²) on soft tyres ran wide and
/// started the next line up to 1.1 m off (2.43 cm RMS over the cell, max 29.8); on R 15 m at
/// 20 km/h the turns between the arcs did the same (5.08 cm, over its 5 cm bound).
#[test]
fn the_turns_learn_what_dynamic_tyres_need_beyond_the_model() {
    each_within(&[
        ("tyre_slip_soft", "straight_15kmh", 2.0),
        ("speed_20", "curve_r15", 5.0),
    ]);
}

/// A side draft's crab, as the vehicle kept it, on every line and at every speed:
/// - restored on each line as the vehicle kept it: a sector's drift was a world vector taken
///   across the heading where the turn's last straight restored it, a few degrees off the
///   line, with a share of the unobservable drift along the heading; at 15 km/h lines 3 to 7
///   started 0.02–0.03 m/s short of their crab and kept a 2–3 cm standing error (1.85 cm RMS,
///   against Stanley's uncompensated 1.16);
/// - following the speed (a slip angle: the crab's velocity is proportional to the speed):
///   a velocity learnt at 15 km/h and carried through the 4 km/h turns, or learnt there, was
///   wrong by the speed ratio until the observer relearnt it over most of a pass (speed
///   profile 2.55 cm, all disturbances 5.64 cm).
#[test]
fn a_side_draft_is_held_as_the_crab_the_vehicle_keeps_at_every_speed() {
    each_within(&[
        ("side_draft_5kN", "straight_15kmh", 1.4),
        // 1.47 after session 26 (2.55 before); 1.75 since session 32's slip-free point (a
        // slip learnt in the decelerating turns steered at 15 km/h), `**` against Stanley's
        // 1.37 (docs/envelope.md, Session 32: the tyres' cornering slip learnt and steered about).
        ("side_draft_5kN", "speed_profile_4_15", 1.9),
        ("side_draft_5kN", "all_disturbances", 5.0),
    ]);
}

/// The vehicle's own lag behind its wheels (tyres building their side force, the yaw inertia;
/// `estimate::yaw_lag`) learnt from the turns and led on with the steering's: at 15 km/h on
/// soft tyres the turns exited late and lines started 0.6–1 m off (tyre_slip_soft 1.69 cm RMS,
/// max 20.8 over its 15 cm bound; tractor_b 2.63 cm over its 2.5 cm bound); 1.10 and 1.40 now.
#[test]
fn the_vehicles_own_lag_behind_its_wheels_is_led_on() {
    each_within(&[
        ("tyre_slip_soft", "straight_15kmh", 1.4),
        ("tractor_b", "straight_15kmh", 2.0),
    ]);
}

/// Session 31: the path's curvature fed forward (`track.curvature_feed_forward`). Pure pursuit
/// alone turned into and out of a turn's arcs a look-ahead early and started the next line with
/// its swing: on firm tyres at 15 km/h the line starts kept 0.54 cm RMS over the cell (`**`
/// against Stanley's 0.39), and at 20 km/h on R 15 m arcs 4.70 cm (bound 5). Now 0.39 and 3.66.
#[test]
fn turns_fed_forward_start_the_lines_on_them() {
    each_within(&[
        ("tyre_slip_firm", "straight_15kmh", 0.47),
        ("speed_20", "curve_r15", 4.2),
    ]);
}

/// Session 32: the tyres' cornering slip (`track.observer_corner_slip_tau_s`) learnt in the
/// turns and steered about the point that turns without it. Soft tyres: an RTK float that
/// began half-way round a turn was dead-reckoned 16 cm off the next line (tractor_b 2.46 cm
/// RMS, max 18.7 over its 15 cm bound); steering the rear axle, 15 km/h line starts 1.1 m off
/// were overshot by 10–18 cm (1.44 cm RMS).
/// With the drift at 30 s (session 33) the float's cell is 1.53 cm, 3.01 with the slip off.
#[test]
fn the_turns_slip_is_learnt_and_steered_about() {
    each_within(&[
        ("tractor_b", "rtk_float_20s", 2.0),
        ("tractor_b", "straight_15kmh", 1.0),
    ]);
}

/// Session 33: the drift learnt in half the time (`track.observer_drift_tau_s` 60 → 30 s). A
/// 5 kN side draft's crab was still being learnt at the end of each 15 km/h pass, and the
/// default law held the shortfall as a steady 0.7–1.2 cm: 1.75 cm RMS over the speed profile,
/// more than 1.2 × Stanley's 1.37 (issue 15 point 3). Now 1.47.
#[test]
fn a_side_drafts_crab_is_learnt_within_the_pass() {
    each_within(&[("side_draft_5kN", "speed_profile_4_15", 1.64)]);
}
