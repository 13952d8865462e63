//! A small SVG canvas in local ENU metres (north up), shared by the demo trace, the accuracy
//! report and the field plan pictures.
//!
//! Contract: text in, text out; no I/O. Callers write the finished document where they like.

use crate::geo::{v2, Vec2};
use std::fmt::Write;

/// A drawing surface mapping local ENU metres onto an SVG with north up.
pub struct SvgCanvas {
    min: Vec2,
    scale: f64,
    width: f64,
    height: f64,
    margin: f64,
    footer: f64,
    body: String,
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

impl SvgCanvas {
    /// A canvas fitting every point of `extent` into `width` pixels (height follows).
    pub fn fit<'a>(extent: impl IntoIterator<Item = &'a Vec2>, width: f64) -> SvgCanvas {
        let mut min = v2(f64::INFINITY, f64::INFINITY);
        let mut max = v2(f64::NEG_INFINITY, f64::NEG_INFINITY);
        for p in extent {
            if p.x.is_finite() && p.y.is_finite() {
                min = min.inf(p);
                max = max.sup(p);
            }
        }
        if !min.x.is_finite() {
            min = v2(0.0, 0.0);
            max = v2(1.0, 1.0);
        }
        let span = (max - min).sup(&v2(1.0, 1.0));
        let margin = 40.0;
        let inner = width - 2.0 * margin;
        // Keep very tall drawings readable: cap the height at 2.5× the width.
        let scale = (inner / span.x).min(2.5 * inner / span.y);
        let footer = 90.0;
        SvgCanvas {
            min,
            scale,
            width,
            height: span.y * scale + 2.0 * margin + footer,
            margin,
            footer,
            body: String::new(),
        }
    }

    /// The canvas with its footer `extra_px` taller (for more lines of text).
    pub fn with_taller_footer(mut self, extra_px: f64) -> SvgCanvas {
        let extra = extra_px.max(0.0);
        self.footer += extra;
        self.height += extra;
        self
    }

    /// Raw SVG (for example `<defs>` with a fill pattern), added as is.
    pub fn raw(&mut self, svg: &str) {
        self.body.push_str(svg);
        self.body.push('\n');
    }

    /// An area of several rings in metres (an outer ring and its holes, or several polygons),
    /// filled by the even-odd rule so holes stay open.
    pub fn area<'a, R>(&mut self, rings: impl IntoIterator<Item = R>, style: &str)
    where
        R: IntoIterator<Item = &'a Vec2>,
    {
        let mut d = String::new();
        for ring in rings {
            let mut first = true;
            for p in ring {
                let (x, y) = self.px(p);
                let _ = write!(d, "{}{x:.1},{y:.1} ", if first { "M" } else { "L" });
                first = false;
            }
            if !first {
                d.push_str("Z ");
            }
        }
        if !d.is_empty() {
            let _ = writeln!(
                self.body,
                r#"<path fill-rule="evenodd" {style} d="{}"/>"#,
                d.trim_end()
            );
        }
    }

    /// Pixels per metre.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    fn px(&self, p: &Vec2) -> (f64, f64) {
        (
            self.margin + (p.x - self.min.x) * self.scale,
            self.height - self.footer - self.margin - (p.y - self.min.y) * self.scale,
        )
    }

    /// A polyline in metres; `style` is raw SVG attributes.
    pub fn polyline<'a>(&mut self, pts: impl IntoIterator<Item = &'a Vec2>, style: &str) {
        let mut d = String::new();
        for p in pts {
            let (x, y) = self.px(p);
            let _ = write!(d, "{x:.1},{y:.1} ");
        }
        if !d.is_empty() {
            let _ = writeln!(self.body, r#"<polyline fill="none" {style} points="{d}"/>"#);
        }
    }

    /// A closed polygon in metres.
    pub fn polygon<'a>(&mut self, pts: impl IntoIterator<Item = &'a Vec2>, style: &str) {
        let mut d = String::new();
        for p in pts {
            let (x, y) = self.px(p);
            let _ = write!(d, "{x:.1},{y:.1} ");
        }
        if !d.is_empty() {
            let _ = writeln!(self.body, r#"<polygon {style} points="{d}"/>"#);
        }
    }

    /// A small circle at a point in metres.
    pub fn dot(&mut self, p: &Vec2, r_px: f64, fill: &str) {
        let (x, y) = self.px(p);
        let _ = writeln!(
            self.body,
            r#"<circle cx="{x:.1}" cy="{y:.1}" r="{r_px}" fill="{fill}"/>"#
        );
    }

    /// Text at a point in metres.
    pub fn label(&mut self, p: &Vec2, text: &str, size: f64) {
        let (x, y) = self.px(p);
        let _ = writeln!(
            self.body,
            r#"<text x="{x:.1}" y="{y:.1}" font-size="{size}" font-family="sans-serif">{}</text>"#,
            esc(text)
        );
    }

    /// Text in pixel coordinates of the footer (y from the footer's top).
    pub fn footer_text(&mut self, x: f64, y: f64, text: &str, size: f64, fill: &str) {
        let top = self.height - self.footer;
        let _ = writeln!(
            self.body,
            r#"<text x="{x:.1}" y="{:.1}" font-size="{size}" fill="{fill}" font-family="sans-serif">{}</text>"#,
            top + y,
            esc(text)
        );
    }

    /// A legend swatch in the footer.
    pub fn footer_swatch(&mut self, x: f64, y: f64, colour: &str, text: &str) {
        let top = self.height - self.footer;
        let _ = writeln!(
            self.body,
            r#"<rect x="{x:.1}" y="{:.1}" width="18" height="8" fill="{colour}"/>"#,
            top + y - 8.0
        );
        self.footer_text(x + 24.0, y, text, 12.0, "#222");
    }

    /// A scale bar with a round length and a north arrow, bottom right.
    pub fn scale_bar_and_north(&mut self) {
        let target_px = (self.width - 2.0 * self.margin) / 5.0;
        let raw = target_px / self.scale;
        let mag = 10f64.powf(raw.log10().floor());
        let len_m = [1.0, 2.0, 5.0, 10.0]
            .iter()
            .map(|f| f * mag)
            .rfind(|l| *l <= raw)
            .unwrap_or(mag);
        let len_px = len_m * self.scale;
        let x1 = self.width - self.margin - len_px;
        let y = self.height - 20.0;
        let _ = writeln!(
            self.body,
            r##"<g stroke="#222" stroke-width="2"><line x1="{x1:.1}" y1="{y}" x2="{:.1}" y2="{y}"/><line x1="{x1:.1}" y1="{}" x2="{x1:.1}" y2="{}"/><line x1="{:.1}" y1="{}" x2="{:.1}" y2="{}"/></g>"##,
            x1 + len_px,
            y - 5.0,
            y + 5.0,
            x1 + len_px,
            y - 5.0,
            x1 + len_px,
            y + 5.0
        );
        let _ = writeln!(
            self.body,
            r#"<text x="{:.1}" y="{:.1}" font-size="12" text-anchor="middle" font-family="sans-serif">{} m</text>"#,
            x1 + len_px / 2.0,
            y - 8.0,
            len_m
        );
        let nx = self.width - self.margin / 2.0 - 4.0;
        let ny = self.margin;
        let _ = writeln!(
            self.body,
            r##"<g><polygon points="{nx},{} {},{} {nx},{} {},{}" fill="#222"/><text x="{nx}" y="{}" font-size="12" text-anchor="middle" font-family="sans-serif">N</text></g>"##,
            ny - 14.0,
            nx + 6.0,
            ny + 6.0,
            ny,
            nx - 6.0,
            ny + 6.0,
            ny - 18.0
        );
    }

    /// The finished SVG document.
    pub fn finish(self, title: &str) -> String {
        format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.0}\" height=\"{h:.0}\" viewBox=\"0 0 {w:.0} {h:.0}\">\n<title>{t}</title>\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n{b}</svg>\n",
            w = self.width,
            h = self.height,
            t = esc(title),
            b = self.body
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn canvas_is_north_up() {
        let pts = [v2(0.0, 0.0), v2(10.0, 100.0)];
        let c = SvgCanvas::fit(pts.iter(), 500.0);
        let (_, y_low) = c.px(&v2(0.0, 0.0));
        let (_, y_high) = c.px(&v2(0.0, 100.0));
        assert!(y_high < y_low, "north must be up");
    }
}
