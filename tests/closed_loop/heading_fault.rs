//! A wrong GNSS heading, closed-loop (issue 15): the simulator's receiver reports a heading
//! 90° off from mid-line on (`sim.heading_bias_deg`, the course over ground stays right), the
//! controller node steers by it, and the supervisor's heading check
//! (`safety::heading`) gives the steering back, `heading_mismatch`. Asserts the time from the
//! onset to the first disengaged command, and that without the check the same run stays
//! engaged longer and leaves the line further (so the test fails without the detector).

use agsteer::config::Config;
use agsteer::demo::{run, DemoOptions, DemoRun};

const ONSET_S: f64 = 30.0;

fn drive(set: &[&str]) -> DemoRun {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tools/scenarios/straight_10kmh.toml"
    );
    let mut set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    set.extend([
        "job.line_num=2".to_string(),
        "sim.heading_bias_deg=90".to_string(),
        format!("sim.heading_bias_at_s={ONSET_S}"),
    ]);
    let cfg = Config::load(std::path::Path::new(path), &set).expect("valid configuration");
    let opts = DemoOptions {
        record_work: true,
        no_reengage: true,
        ..Default::default()
    };
    run(&cfg, &opts, &mut |_| {}, &mut |_, _| {}).expect("the run")
}

/// The first disengagement at or after the onset, and the largest true |XTE| from the onset
/// up to it (or to 10 s after the onset).
fn after_onset(r: &DemoRun) -> (Option<(f64, String)>, f64) {
    let first = r
        .disengage_events
        .iter()
        .find(|(t, _)| *t >= ONSET_S)
        .cloned();
    let until = first.as_ref().map_or(ONSET_S + 10.0, |f| f.0);
    let max_xte = r
        .work
        .iter()
        .flat_map(|w| w.samples.iter())
        .filter(|s| s.t >= ONSET_S && s.t <= until)
        .map(|s| s.xte_m.abs())
        .fold(0.0, f64::max);
    (first, max_xte)
}

#[test]
fn a_heading_90_degrees_off_disengages_heading_mismatch() {
    let r = drive(&[]);
    let before: Vec<_> = r
        .disengage_events
        .iter()
        .filter(|e| e.0 < ONSET_S)
        .collect();
    assert!(before.is_empty(), "disengaged before the onset: {before:?}");
    let (first, max_xte) = after_onset(&r);
    let (t, code) = first.unwrap_or_else(|| panic!("never disengaged: {:?}", r.report));
    println!(
        "HEADING-FAULT heading 90° off: {code} {:.3} s after the onset (true |XTE| up to {:.3} m)",
        t - ONSET_S,
        max_xte
    );
    assert_eq!(code, "heading_mismatch");
    // The check's time (1 s) plus a fix period and a control period.
    assert!(t - ONSET_S <= 1.2, "{:.3} s", t - ONSET_S);

    // Without the check: engaged for longer, further off the line.
    let r = drive(&["safety.heading_mismatch_deg=0"]);
    let (first, max_xte_off) = after_onset(&r);
    println!("HEADING-FAULT without the check: {first:?}, true |XTE| up to {max_xte_off:.3} m");
    assert!(first.is_none_or(|(t_off, _)| t_off - ONSET_S > 2.0 * (t - ONSET_S)));
    assert!(
        max_xte_off > 2.0 * max_xte.max(0.05),
        "{max_xte_off} vs {max_xte}"
    );
}
