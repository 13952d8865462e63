//! The demo trace picture, drawn on the shared [`SvgCanvas`].

use super::{Report, Trace};
use crate::geo::svg::SvgCanvas;
use crate::geo::Vec2;

/// Colour classes for |XTE|: (upper bound m, colour, label).
pub const XTE_CLASSES: [(f64, &str, &str); 4] = [
    (0.02, "#1a9850", "< 2 cm"),
    (0.05, "#a6d96a", "2–5 cm"),
    (0.10, "#fdae61", "5–10 cm"),
    (f64::INFINITY, "#d73027", "≥ 10 cm"),
];

/// Colour of an |XTE| value.
pub fn xte_colour(xte_abs: f64) -> &'static str {
    XTE_CLASSES
        .iter()
        .find(|(ub, _, _)| xte_abs < *ub)
        .map(|c| c.1)
        .unwrap_or("#d73027")
}

/// The demo picture: planned lines (grey), turns (blue, dashed), and the driven trace
/// coloured by |XTE|, with a legend, the key figures, a scale bar and a north arrow.
pub fn demo_svg(trace: &Trace, report: &Report) -> String {
    let extent = trace
        .lines
        .iter()
        .flatten()
        .chain(trace.outlines.iter().flatten())
        .chain(trace.turns.iter().flatten())
        .chain(trace.points.iter().map(|p| &p.pos));
    let mut c = SvgCanvas::fit(extent, 900.0);
    for o in &trace.outlines {
        c.polygon(
            o,
            r##"fill="#f3efe0" stroke="#8c7b4f" stroke-width="1.5" fill-opacity="0.5""##,
        );
    }
    for l in &trace.lines {
        c.polyline(
            l,
            r##"stroke="#bbbbbb" stroke-width="5" stroke-linecap="round""##,
        );
    }
    for t in &trace.turns {
        c.polyline(
            t,
            r##"stroke="#4575b4" stroke-width="1.5" stroke-dasharray="4 3""##,
        );
    }
    // Driven trace: consecutive points of one colour form one polyline.
    let mut run: Vec<Vec2> = Vec::new();
    let mut run_colour = "";
    let colour_of = |x: Option<f64>| x.map(xte_colour).unwrap_or("#666666");
    for w in trace.points.windows(2) {
        let col = colour_of(w[1].xte_abs);
        if col != run_colour && !run.is_empty() {
            c.polyline(
                &run,
                &format!(r#"stroke="{run_colour}" stroke-width="1.5""#),
            );
            run.clear();
        }
        if run.is_empty() {
            run.push(w[0].pos);
        }
        run.push(w[1].pos);
        run_colour = col;
    }
    if !run.is_empty() {
        c.polyline(
            &run,
            &format!(r#"stroke="{run_colour}" stroke-width="1.5""#),
        );
    }
    if let Some(p) = trace.points.first() {
        c.dot(&p.pos, 4.0, "#000");
    }
    let status = if report.finished {
        "finished"
    } else {
        "NOT finished"
    };
    c.footer_text(
        10.0,
        20.0,
        &format!(
            "agsteer demo — {status}: {} lines, {} turns, {:.0} m, tracker {}",
            report.lines_completed, report.turns, report.distance_m, report.tracker
        ),
        14.0,
        "#000",
    );
    c.footer_text(
        10.0,
        40.0,
        &format!(
            "true |XTE| on work lines (after 10 m): RMS {:.1} cm, p95 {:.1} cm, max {:.1} cm; acquisition max {:.1} cm",
            report.xte_rms_m * 100.0,
            report.xte_p95_m * 100.0,
            report.xte_max_m * 100.0,
            report.acquisition_xte_max_m * 100.0
        ),
        12.0,
        "#222",
    );
    let mut x = 10.0;
    for (_, col, label) in XTE_CLASSES {
        c.footer_swatch(x, 64.0, col, label);
        x += 95.0;
    }
    c.footer_swatch(x, 64.0, "#666666", "turn");
    c.footer_swatch(x + 80.0, 64.0, "#bbbbbb", "work line");
    c.scale_bar_and_north();
    c.finish("agsteer demo trace")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_classes() {
        assert_eq!(xte_colour(0.0), "#1a9850");
        assert_eq!(xte_colour(0.03), "#a6d96a");
        assert_eq!(xte_colour(0.5), "#d73027");
    }
}
