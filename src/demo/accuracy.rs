//! The accuracy report (`agsteer accuracy`): the scenario suite in `tools/scenarios/` run
//! closed-loop for each tracker, scored in the style of ISO 12188-2 against the simulator's
//! ground truth.
//!
//! Figures per scenario and tracker:
//!
//! * XTE: RMS, 95th percentile and maximum of |XTE| of the true rear-axle centre on work passes,
//!   past the first [`ACQUISITION_SKIP_M`] of each pass (as `agsteer demo` reports them), and
//!   the 95 % error class: the smallest whole centimetre covering 95 % of the samples.
//! * Pass-to-pass, after ISO 12188-2 (straight and level travel; its "relative XTE" between
//!   adjacent passes): for every pair of adjacent passes (nominal lines about one line width
//!   apart), at stations every [`STATION_M`] along the first pass's nominal line, the driven
//!   lateral position of each pass is interpolated along that line (path interpolation rather
//!   than the nearest point, as Rhodes et al., *Transactions of the ASABE* 59(6), 2016,
//!   recommend for the standard's calculations), and the error is |actual distance − line
//!   width|. The figure is its 95th percentile over all stations of all pairs. Stations within
//!   the acquisition skip of either pass's start are left out, as in the XTE figures. On the
//!   arcs jobs the nominal distance of concentric arcs along the normal is the line width too.
//! * Acquisition after turns: the largest |XTE| in the first [`ACQUISITION_END_M`] of each pass
//!   that follows a turn, and the distance along the pass from which |XTE| stays within
//!   [`SETTLE_M`] for [`SETTLE_HOLD_M`] (worst pass).
//! * RTK float: the safety supervisor's configured behaviour (`safety.rtk_float_tolerance_s`:
//!   0 refuses a float fix at once, otherwise steering goes on for that long and then stops)
//!   and what happened: disengagements and the largest |XTE| while the float lasted.

use super::{run, DemoOptions, WorkPass, XteStats, ACQUISITION_END_M, ACQUISITION_SKIP_M};
use crate::config::{Config, TrackerChoice};
use crate::geo::Vec2;
use serde::Serialize;
use std::collections::BTreeMap;

/// Pass-to-pass stations are this far apart along the nominal line, m.
pub const STATION_M: f64 = 1.0;
/// A pass has settled once |XTE| stays within this, m ...
pub const SETTLE_M: f64 = 0.025;
/// ... for this distance, m.
pub const SETTLE_HOLD_M: f64 = 10.0;

/// The trackers of the report, in table order.
pub const TRACKERS: [TrackerChoice; 3] = [
    TrackerChoice::Predictive,
    TrackerChoice::PurePursuit,
    TrackerChoice::Stanley,
];

pub use super::tracker_name;

/// What the RTK-float part of a scenario did.
#[derive(Debug, Clone, Serialize)]
pub struct FloatReport {
    /// `safety.rtk_float_tolerance_s`.
    pub tolerance_s: f64,
    /// "refuse" (tolerance 0: disengage at the first float fix) or "degrade" (steer on for the
    /// tolerance, then disengage).
    pub behaviour: &'static str,
    /// Float windows `[start, duration]`, s.
    pub windows_s: Vec<[f64; 2]>,
    /// Disengagements for the fix quality.
    pub fix_disengagements: u64,
    /// Largest true |XTE| on work passes (past the acquisition skip) while the float lasted, m
    /// (`None`: no work samples).
    pub xte_max_during_float_m: Option<f64>,
}

/// One scenario run with one tracker.
#[derive(Debug, Clone, Serialize)]
pub struct ScenarioResult {
    pub scenario: String,
    pub tracker: String,
    pub finished: bool,
    pub xte_rms_m: f64,
    pub xte_p95_m: f64,
    pub xte_max_m: f64,
    /// Smallest whole cm bound covering 95 % of |XTE|.
    pub error_class_cm: u32,
    /// 95th percentile of |distance between adjacent passes − line width|, m (`None`: no
    /// adjacent passes).
    pub pass_to_pass_p95_m: Option<f64>,
    /// Stations compared for pass-to-pass.
    pub pass_to_pass_stations: usize,
    /// Largest |XTE| in the first `ACQUISITION_END_M` of a pass after a turn, m.
    pub acquisition_max_m: f64,
    /// Worst distance along a pass before |XTE| stays within `SETTLE_M` for `SETTLE_HOLD_M`, m
    /// (`None`: a pass never settled).
    pub settle_max_m: Option<f64>,
    pub engaged_fraction: f64,
    pub disengagements: BTreeMap<String, u64>,
    /// Engages refused for the line (`line_unfollowable`), see [`super::Report::refusals`].
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub refusals: BTreeMap<String, u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rtk_float: Option<FloatReport>,
}

/// Signed XTE over cumulative work distance, for the SVG: one polyline per tracker.
#[derive(Debug, Clone, Default)]
pub struct XteSeries {
    /// (cumulative work distance m, signed XTE m), every ~0.5 m.
    pub points: Vec<(f64, f64)>,
}

/// The error class: the smallest whole centimetre covering `p95_m`.
pub fn error_class_cm(p95_m: f64) -> u32 {
    let cm = (p95_m * 100.0 - 1e-9).ceil();
    if cm.is_finite() && cm > 0.0 {
        cm as u32
    } else {
        0
    }
}

/// The nearest point of `line` to `p`: (distance along, signed offset, positive left).
fn project(line: &[Vec2], cumulative: &[f64], p: &Vec2) -> Option<(f64, f64)> {
    let last = line.len().checked_sub(2)?;
    super::nearest_on_polyline(line, cumulative, p, 0..=last, false)
}

fn cumulative(line: &[Vec2]) -> Vec<f64> {
    let mut c = Vec::with_capacity(line.len());
    super::cumulative_lengths(line, &mut c);
    c
}

/// Linear interpolation of sorted (x, y) at `x`; `None` outside or across a gap wider than
/// `max_gap`.
fn interpolate(xy: &[(f64, f64)], x: f64, max_gap: f64) -> Option<f64> {
    let i = xy.partition_point(|p| p.0 < x);
    if i == 0 || i >= xy.len() {
        return None;
    }
    let (x0, y0) = xy[i - 1];
    let (x1, y1) = xy[i];
    if x1 - x0 > max_gap || x1 <= x0 {
        return None;
    }
    Some(y0 + (y1 - y0) * (x - x0) / (x1 - x0))
}

/// Pass-to-pass errors |actual distance − width| (m) at every station of every pair of
/// adjacent passes (see the module documentation).
pub fn pass_to_pass_errors(passes: &[WorkPass], width: f64) -> Vec<f64> {
    let mut errors = Vec::new();
    for (i, p) in passes.iter().enumerate() {
        if p.nominal.len() < 2 {
            continue;
        }
        let cum = cumulative(&p.nominal);
        let length = cum.last().copied().unwrap_or(0.0);
        // P's own driven offsets along its nominal line, past the acquisition skip.
        let own: Vec<(f64, f64)> = p
            .samples
            .iter()
            .filter(|s| s.along_m >= ACQUISITION_SKIP_M)
            .map(|s| (s.along_m, s.xte_m))
            .collect();
        for q in passes.iter().skip(i + 1) {
            // Adjacent: Q's nominal line lies about one width from P's, beside it.
            let q_length = crate::geo::polygon::polyline_length(&q.nominal);
            let mid = crate::track::point_along(&q.nominal, 0, 0.5 * q_length);
            let Some((along_mid, off_mid)) = project(&p.nominal, &cum, &mid) else {
                continue;
            };
            if !(0.5 * width..=1.5 * width).contains(&off_mid.abs())
                || along_mid <= 0.0
                || along_mid >= length
            {
                continue;
            }
            let side = off_mid.signum();
            let mut other: Vec<(f64, f64)> = q
                .samples
                .iter()
                .filter(|s| s.along_m >= ACQUISITION_SKIP_M)
                .filter_map(|s| project(&p.nominal, &cum, &s.pos))
                .filter(|(a, _)| *a > 0.0 && *a < length)
                .collect();
            other.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut s = 0.0;
            while s <= length {
                if let (Some(a), Some(b)) = (interpolate(&own, s, 1.0), interpolate(&other, s, 1.0))
                {
                    errors.push(((b - a) * side - width).abs());
                }
                s += STATION_M;
            }
        }
    }
    errors
}

fn quantile(values: &mut [f64], q: f64) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(|a, b| a.total_cmp(b));
    let k = ((q * values.len() as f64).ceil() as usize).clamp(1, values.len());
    Some(values[k - 1])
}

/// Acquisition after turns: (largest |XTE| in the first `ACQUISITION_END_M`, worst settle
/// distance).
fn acquisition(passes: &[WorkPass]) -> (f64, Option<f64>) {
    let mut max: f64 = 0.0;
    let mut settle: Option<f64> = Some(0.0);
    for p in passes
        .iter()
        .filter(|p| p.after_turn && !p.samples.is_empty())
    {
        for s in p.samples.iter().filter(|s| s.along_m <= ACQUISITION_END_M) {
            max = max.max(s.xte_m.abs());
        }
        // The first distance from which |XTE| stays within the band for SETTLE_HOLD_M (or to
        // the end of the pass, if that is shorter).
        let n = p.samples.len();
        let mut d = None;
        let mut run_start: Option<usize> = None;
        for (k, smp) in p.samples.iter().enumerate() {
            if smp.xte_m.abs() > SETTLE_M {
                run_start = None;
                continue;
            }
            let start = *run_start.get_or_insert(k);
            let held = smp.along_m - p.samples[start].along_m;
            if held >= SETTLE_HOLD_M || k + 1 == n {
                d = Some(p.samples[start].along_m.max(0.0));
                break;
            }
        }
        settle = match (settle, d) {
            (Some(a), Some(b)) => Some(a.max(b)),
            _ => None,
        };
    }
    (max, settle)
}

/// Run `cfg` (a scenario) with `tracker`: the result and its XTE series.
pub fn evaluate(
    name: &str,
    cfg: &Config,
    tracker: TrackerChoice,
) -> Result<(ScenarioResult, XteSeries), crate::job::JobError> {
    let mut cfg = cfg.clone();
    cfg.track.kind = tracker;
    let opts = DemoOptions {
        record_work: true,
        ..DemoOptions::default()
    };
    let run = run(&cfg, &opts, &mut |_| {}, &mut |_, _| {})?;
    let r = &run.report;
    let mut stats = XteStats::default();
    let mut series = XteSeries::default();
    let mut offset = 0.0;
    let windows = &cfg.sim.gnss_float_windows_s;
    let in_float = |t: f64| windows.iter().any(|w| t >= w[0] && t <= w[0] + w[1]);
    let mut float_max: Option<f64> = None;
    for p in &run.work {
        let mut next = f64::NEG_INFINITY;
        let mut end: f64 = 0.0;
        for s in &p.samples {
            if s.along_m >= ACQUISITION_SKIP_M {
                stats.add(s.xte_m);
            }
            if s.along_m >= next {
                series.points.push((offset + s.along_m.max(0.0), s.xte_m));
                next = s.along_m + 0.5;
            }
            end = end.max(s.along_m);
            if in_float(s.t) && s.along_m >= ACQUISITION_SKIP_M {
                float_max = Some(float_max.unwrap_or(0.0).max(s.xte_m.abs()));
            }
        }
        offset += end.max(0.0);
    }
    let mut p2p = pass_to_pass_errors(&run.work, cfg.job.line_width_m);
    let stations = p2p.len();
    let (acq, settle) = acquisition(&run.work);
    let p95 = stats.quantile(0.95);
    let rtk_float = (!windows.is_empty()).then(|| FloatReport {
        tolerance_s: cfg.safety.rtk_float_tolerance_s,
        behaviour: if cfg.safety.rtk_float_tolerance_s > 0.0 {
            "degrade"
        } else {
            "refuse"
        },
        windows_s: windows.clone(),
        fix_disengagements: r.disengagements.get("fix_quality").copied().unwrap_or(0),
        xte_max_during_float_m: float_max,
    });
    Ok((
        ScenarioResult {
            scenario: name.to_string(),
            tracker: tracker_name(tracker).to_string(),
            finished: r.finished,
            xte_rms_m: stats.rms(),
            xte_p95_m: p95,
            xte_max_m: stats.max(),
            error_class_cm: error_class_cm(p95),
            pass_to_pass_p95_m: quantile(&mut p2p, 0.95),
            pass_to_pass_stations: stations,
            acquisition_max_m: acq,
            settle_max_m: settle,
            engaged_fraction: r.engaged_fraction,
            disengagements: r.disengagements.clone(),
            refusals: r.refusals.clone(),
            rtk_float,
        },
        series,
    ))
}

/// The SVG of XTE over work distance, one polyline per tracker.
pub fn xte_svg(title: &str, series: &[(&str, &XteSeries)]) -> String {
    use std::fmt::Write;
    const W: f64 = 1000.0;
    const H: f64 = 400.0;
    const M: f64 = 50.0;
    let colours = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd"];
    let x_max = series
        .iter()
        .flat_map(|(_, s)| s.points.iter().map(|p| p.0))
        .fold(1.0f64, f64::max);
    // ±10 cm unless something is larger (then the largest, to 1 m), in whole cm.
    let y_abs = series
        .iter()
        .flat_map(|(_, s)| s.points.iter().map(|p| p.1.abs()))
        .fold(0.1f64, f64::max)
        .min(1.0);
    let y_cm = (y_abs * 100.0).ceil();
    let px = |x: f64| M + (W - 2.0 * M) * x / x_max;
    let py = |y: f64| H / 2.0 - (H / 2.0 - M) * (y * 100.0).clamp(-y_cm, y_cm) / y_cm;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="{W}" height="{H}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{M}" y="20">{title}: signed XTE (cm) over work distance (m)</text>"#
    );
    for (y, dash) in [(0.0, ""), (2.5, "4 4"), (-2.5, "4 4")] {
        let _ = writeln!(
            s,
            r##"<line x1="{M}" x2="{0}" y1="{1:.1}" y2="{1:.1}" stroke="#999" stroke-dasharray="{dash}"/>"##,
            W - M,
            py(y / 100.0)
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="5" y="{:.1}">+{y_cm}</text><text x="5" y="{:.1}">-{y_cm}</text><text x="{:.1}" y="{:.1}">±2.5 cm</text><text x="{:.1}" y="{}">{x_max:.0} m</text>"#,
        py(y_cm / 100.0) + 4.0,
        py(-y_cm / 100.0) + 4.0,
        W - M - 60.0,
        py(0.025) - 3.0,
        W - M - 40.0,
        H - 10.0
    );
    for (k, (name, ser)) in series.iter().enumerate() {
        let c = colours[k % colours.len()];
        let mut d = String::new();
        let mut last_x = f64::NEG_INFINITY;
        for &(x, y) in &ser.points {
            // A new sub-path at each pass (the distance jumps back to a pass start).
            let cmd = if x < last_x + 2.0 && !d.is_empty() {
                'L'
            } else {
                'M'
            };
            let _ = write!(d, "{cmd}{:.1},{:.1} ", px(x), py(y));
            last_x = x;
        }
        let _ = writeln!(
            s,
            r#"<path d="{d}" fill="none" stroke="{c}" stroke-width="1"/>"#
        );
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{}" fill="{c}">{name}</text>"#,
            M + 150.0 * k as f64 + 400.0,
            20
        );
    }
    s.push_str("</svg>\n");
    s
}

/// The Markdown table of `results`.
pub fn markdown_table(results: &[ScenarioResult]) -> String {
    use std::fmt::Write;
    let cm = |m: f64| format!("{:.2}", 100.0 * m);
    let mut s = String::from(
        "| scenario | tracker | XTE rms cm | p95 cm | max cm | 95 % class cm | pass-to-pass 95 % cm | acquisition max cm | settled after m | finished | disengagements |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in results {
        let d: Vec<String> = r
            .disengagements
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect();
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.scenario,
            r.tracker,
            cm(r.xte_rms_m),
            cm(r.xte_p95_m),
            cm(r.xte_max_m),
            r.error_class_cm,
            r.pass_to_pass_p95_m.map_or("-".into(), cm),
            cm(r.acquisition_max_m),
            r.settle_max_m.map_or("never".into(), |d| format!("{d:.1}")),
            r.finished,
            if d.is_empty() {
                "-".into()
            } else {
                d.join(", ")
            },
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::demo::WorkSample;
    use crate::geo::v2;

    fn pass(x: f64, reverse: bool, offset: impl Fn(f64) -> f64) -> WorkPass {
        let (a, b) = if reverse { (100.0, 0.0) } else { (0.0, 100.0) };
        let nominal = vec![v2(x, a), v2(x, b)];
        let samples = (0..=200)
            .map(|k| {
                let along = k as f64 * 0.5;
                let y = if reverse { 100.0 - along } else { along };
                // Positive XTE is left: −x going north, +x going south.
                let xte = offset(along);
                let dx = if reverse { xte } else { -xte };
                WorkSample {
                    t: along,
                    along_m: along,
                    xte_m: xte,
                    pos: v2(x + dx, y),
                }
            })
            .collect();
        WorkPass {
            nominal,
            after_turn: true,
            samples,
        }
    }

    #[test]
    fn pass_to_pass_measures_the_actual_spacing_against_the_width() {
        // Line 0 driven 2 cm right of its line (x + 0.02), line 1 (3 m East, driven south) 1 cm
        // left of its line (x + 0.01): 2.99 m apart, 1 cm short of the width.
        let passes = [pass(0.0, false, |_| -0.02), pass(3.0, true, |_| 0.01)];
        let e = pass_to_pass_errors(&passes, 3.0);
        // Stations 10..=90 m: each pass skips its own first 10 m.
        assert!((75..=81).contains(&e.len()), "{} stations", e.len());
        for v in &e {
            assert!((v - 0.01).abs() < 1e-9, "{v}");
        }
        // A pass 6 m away is not adjacent.
        let far = [pass(0.0, false, |_| 0.0), pass(6.0, true, |_| 0.0)];
        assert!(pass_to_pass_errors(&far, 3.0).is_empty());
    }

    #[test]
    fn acquisition_and_settling() {
        // 20 cm off at the start, decaying to 0 by 40 m.
        let p = pass(0.0, false, |a| (0.2 * (1.0 - a / 40.0)).max(0.0));
        let (max, settle) = acquisition(std::slice::from_ref(&p));
        assert!((max - 0.2).abs() < 1e-9);
        let d = settle.expect("settles");
        // |xte| ≤ 2.5 cm from along = 35 m.
        assert!((d - 35.0).abs() < 0.6, "{d}");
        // A later excursion does not undo it.
        let late = pass(0.0, false, |a| {
            if a < 5.0 || (60.0..61.0).contains(&a) {
                0.1
            } else {
                0.0
            }
        });
        assert_eq!(acquisition(&[late]).1, Some(5.0));
        let never = pass(0.0, false, |_| 0.05);
        assert_eq!(acquisition(&[never]).1, None);
    }

    #[test]
    fn error_class_is_the_smallest_whole_cm_covering_p95() {
        assert_eq!(error_class_cm(0.0041), 1);
        assert_eq!(error_class_cm(0.01), 1);
        assert_eq!(error_class_cm(0.0101), 2);
        assert_eq!(error_class_cm(0.0), 0);
    }

    #[test]
    fn the_svg_has_a_path_per_tracker() {
        let a = XteSeries {
            points: vec![(0.0, 0.01), (1.0, -0.02)],
        };
        let svg = xte_svg("t", &[("predictive", &a), ("stanley", &a)]);
        assert_eq!(svg.matches("<path").count(), 2);
        assert!(svg.contains("predictive") && svg.ends_with("</svg>\n"));
    }
}
