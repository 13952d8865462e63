//! Swaths (seed 003): scan lines across a cell in the frame rotated so the swaths run along x,
//! balanced so their w-wide footprints cover the whole cell, then grouped into runs that a
//! boustrophedon can sweep (a large obstacle splits the lines, and both sides are covered).

use super::geometry::{rotate_area, Area, Scanner};
use crate::geo::Vec2;

/// The swath lines of one cell, in the rotated frame (swaths along +x).
#[derive(Debug, Clone, PartialEq)]
pub struct SwathLines {
    /// Swath direction in the local frame, rad.
    pub angle: f64,
    /// Distance between adjacent lines, m (≤ the line width).
    pub spacing: f64,
    /// y of every line, rotated frame, m.
    pub ys: Vec<f64>,
    /// The x-intervals of every line, rotated frame, m.
    pub intervals: Vec<Vec<(f64, f64)>>,
    /// Overlap of adjacent footprints summed across the cell, m (n·w − span).
    pub overlap_m: f64,
}

/// Share of a swath's band (its spacing) within which the swath is run on to the cell's
/// extent. Where an edge crosses the band at θ to the swaths, widening over the middle share f
/// leaves (1 − f)²·w²·cot θ / 8 unworked at that end and lays (1 + f)²·w²·cot θ / 8 over the
/// headland pass: f = 1 (the whole band) worked every corner but ran swaths along shallow edges
/// over the pass for up to w·cot θ (125 m at w 12 m on nl_brp_concave); f = ½ lays 9/16 of that
/// overlap for 1/16 of the band's corner unworked.
pub const BAND_WIDENING: f64 = 0.5;

/// The share of a swath's band run on to the cell's extent for an implement of `sections`:
/// [`BAND_WIDENING`] without section control; the whole band with it (the sections that leave
/// the working area switch off, so running on lays nothing twice).
pub fn band_widening(sections: usize) -> f64 {
    if sections > 1 {
        1.0
    } else {
        BAND_WIDENING
    }
}

/// Lines across `cell` (local frame) along `angle` rad, `line_width` apart at most. The n =
/// ceil(span / w) lines cover the span, so no pass is dropped and the footprints overlap by
/// (n·w − span) in all. Spread (`exact` false), the lines are span / n apart, the first and
/// last half a spacing inside the cell, and the overlap is shared between every pair of
/// neighbours. Exact, they are w apart and the overlap lies beyond the cell's sides, where the
/// outer footprints run on over the headland pass: an implement in sections switches off
/// there what lies over the pass (strips at the sides, not a sliver between every pair of
/// swaths that no section fits in), and the lines are where a farmer's tramlines expect them.
/// The overlap goes beyond the high side, the low side or half to each, whichever keeps the
/// most swath length inside `safe` (a notched edge may leave an outer line's centre outside).
///
/// Each interval is widened to the cell's extent within the middle share `widening` of the
/// line's band ([`band_widening`]: slanted edges are covered nearly to the corner) and then cut
/// back to `safe` (where a centre line keeps the implement inside the field and off the
/// obstacles).
pub fn swath_lines(
    cell: &Area,
    safe: &[Area],
    angle: f64,
    line_width: f64,
    widening: f64,
    exact: bool,
) -> SwathLines {
    let rot = rotate_area(cell, -angle);
    let safe_rot: Vec<Area> = safe.iter().map(|a| rotate_area(a, -angle)).collect();
    let (lo, hi) = rot
        .0
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p.y), h.max(p.y))
        });
    let span = (hi - lo).max(0.0);
    let n = (span / line_width - 1e-9).ceil().max(1.0) as usize;
    let overlap_m = (n as f64 * line_width - span).max(0.0);
    let scan = Scanner::new(&rot);
    let safe_scans: Vec<Scanner> = safe_rot.iter().map(Scanner::new).collect();
    let lines_from = |base: f64, spacing: f64| {
        let ys: Vec<f64> = (0..n).map(|k| base + spacing * (k as f64 + 0.5)).collect();
        let intervals = ys
            .iter()
            .map(|&y| line_intervals(&scan, &safe_scans, y, spacing, (lo, hi), widening))
            .collect();
        SwathLines {
            angle,
            spacing,
            ys,
            intervals,
            overlap_m,
        }
    };
    if !exact {
        let spacing = span / n as f64;
        return lines_from(lo, spacing);
    }
    let length = |l: &SwathLines| -> f64 { l.intervals.iter().flatten().map(|(a, b)| b - a).sum() };
    // The overlap beyond the high side first; the low side or half each only if longer.
    let mut best = lines_from(lo, line_width);
    if overlap_m > 1e-9 {
        let mut best_length = length(&best);
        for shift in [overlap_m, overlap_m / 2.0] {
            let l = lines_from(lo - shift, line_width);
            let len = length(&l);
            if len > best_length + 1e-6 {
                (best, best_length) = (l, len);
            }
        }
    }
    best
}

/// The x-intervals of the line at `y`, `spacing` from its neighbours, across the rotated cell
/// of `scan` spanning `lo_hi` in y (see [`swath_lines`]), cut back to the areas of
/// `safe_scans`: the cell is scanned at the middle of the part of the line's band it
/// holds (an exact outer line's band runs on beyond the cell).
fn line_intervals(
    scan: &Scanner,
    safe_scans: &[Scanner],
    y: f64,
    spacing: f64,
    (lo, hi): (f64, f64),
    widening: f64,
) -> Vec<(f64, f64)> {
    let (b0, b1) = (y - spacing / 2.0, y + spacing / 2.0);
    let (at, half) = if b0 >= lo - 1e-9 && b1 <= hi + 1e-9 {
        (y, spacing / 2.0)
    } else {
        let (b0, b1) = (b0.max(lo), b1.min(hi));
        (0.5 * (b0 + b1), 0.5 * (b1 - b0).max(0.0))
    };
    let ivs = scan.intervals(at);
    if ivs.is_empty() {
        return ivs;
    }
    let band = band_extent(scan, at, widening * half);
    let safe: Vec<(f64, f64)> = safe_scans.iter().flat_map(|s| s.intervals(y)).collect();
    let ivs = ivs
        .into_iter()
        .filter_map(|(a, b)| {
            // Widen to the band's extent over this piece, then keep inside `safe`.
            let (mut x0, mut x1) = (a, b);
            for &(c, d) in &band {
                if c <= b && d >= a {
                    x0 = x0.min(c);
                    x1 = x1.max(d);
                }
            }
            let mid = 0.5 * (a + b);
            let s = *safe.iter().find(|&&(c, d)| c <= mid && mid <= d)?;
            let (x0, x1) = (x0.max(s.0), x1.min(s.1));
            (x1 - x0 > 1e-3).then_some((x0, x1))
        })
        .collect();
    merge_overlapping(ivs)
}

/// Intervals sorted and merged where they overlap or touch. Pieces of one line that the band's
/// extent widened over the same ground (a line crossing a notched edge in several pieces, each
/// widened to the whole band) are one swath: kept apart, each was driven over the same ground
/// (bg_arable_60ha at w 6 m drove its outermost swath four times).
pub(super) fn merge_overlapping(mut ivs: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    ivs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut merged: Vec<(f64, f64)> = Vec::with_capacity(ivs.len());
    for iv in ivs {
        match merged.last_mut() {
            Some(m) if iv.0 <= m.1 + 1e-6 => m.1 = m.1.max(iv.1),
            _ => merged.push(iv),
        }
    }
    merged
}

/// The x-extent of the area of `scan` within the band [y − half, y + half]: intervals at both
/// band edges and at every vertex inside the band, merged where they overlap.
fn band_extent(scan: &Scanner, y: f64, half: f64) -> Vec<(f64, f64)> {
    let mut ys = vec![y - half + 1e-6, y, y + half - 1e-6];
    ys.extend(scan.heights_within(y, half));
    merge_overlapping(ys.iter().flat_map(|&v| scan.intervals(v)).collect())
}

/// One swath of a run: line index and x-interval, rotated frame.
pub type RunSwath = (usize, (f64, f64));

/// Group the swaths into runs, each swept by one boustrophedon: consecutive lines whose
/// intervals overlap one to one. Where a line splits (an obstacle) or pieces join, new runs
/// start, so both sides of a large obstacle are covered.
pub fn runs(lines: &SwathLines) -> Vec<Vec<RunSwath>> {
    let mut done: Vec<Vec<RunSwath>> = Vec::new();
    let mut open: Vec<Vec<RunSwath>> = Vec::new();
    for (k, ivs) in lines.intervals.iter().enumerate() {
        let mut next_open: Vec<Vec<RunSwath>> = Vec::new();
        let mut used = vec![false; open.len()];
        for &iv in ivs {
            let overlaps =
                |r: &Vec<RunSwath>| r.last().is_some_and(|&(_, (a, b))| a < iv.1 && b > iv.0);
            let matches: Vec<usize> = (0..open.len()).filter(|&i| overlaps(&open[i])).collect();
            let back = ivs
                .iter()
                .filter(|o| {
                    matches.len() == 1 && {
                        let (a, b) = open[matches[0]].last().map(|s| s.1).unwrap_or((0.0, 0.0));
                        a < o.1 && b > o.0
                    }
                })
                .count();
            if matches.len() == 1 && back == 1 && !used[matches[0]] {
                used[matches[0]] = true;
                let mut r = std::mem::take(&mut open[matches[0]]);
                r.push((k, iv));
                next_open.push(r);
            } else {
                next_open.push(vec![(k, iv)]);
            }
        }
        for (i, r) in open.into_iter().enumerate() {
            if !used[i] && !r.is_empty() {
                done.push(r);
            }
        }
        open = next_open;
    }
    done.extend(open.into_iter().filter(|r| !r.is_empty()));
    done
}

/// A rotated-frame point back in the local frame.
pub fn unrotate(p: Vec2, angle: f64) -> Vec2 {
    super::geometry::rotate(&p, angle)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;

    fn rect(w: f64, h: f64) -> Area {
        (vec![v2(0.0, 0.0), v2(w, 0.0), v2(w, h), v2(0.0, h)], vec![])
    }

    #[test]
    fn balanced_lines_cover_the_cell_and_obstacles_split_runs() {
        let cell = rect(100.0, 50.0);
        let l = swath_lines(&cell, &[rect(100.0, 50.0)], 0.0, 6.0, BAND_WIDENING, false);
        assert_eq!(l.ys.len(), 9, "ceil(50/6)");
        assert!((l.ys[0] - l.spacing / 2.0).abs() < 1e-9);
        assert!((l.ys[8] - (50.0 - l.spacing / 2.0)).abs() < 1e-9);
        assert!((l.overlap_m - (54.0 - 50.0)).abs() < 1e-9);
        assert_eq!(runs(&l).len(), 1);
        // A hole across the middle lines splits them: runs below, left, right and above.
        let holed: Area = (
            cell.0.clone(),
            vec![vec![
                v2(40.0, 15.0),
                v2(60.0, 15.0),
                v2(60.0, 35.0),
                v2(40.0, 35.0),
            ]],
        );
        let l = swath_lines(
            &holed,
            std::slice::from_ref(&holed),
            0.0,
            6.0,
            BAND_WIDENING,
            false,
        );
        let r = runs(&l);
        assert_eq!(r.len(), 4, "{r:?}");
        let swaths: usize = r.iter().map(|x| x.len()).sum();
        assert_eq!(swaths, l.intervals.iter().map(|v| v.len()).sum::<usize>());
    }

    #[test]
    fn a_line_crossing_a_notched_edge_is_one_swath_not_one_per_piece() {
        // Two notches 4 m deep in the bottom edge: the first line (y 2.8) crosses the cell in
        // three pieces, and its band reaches above the notches, so each piece widens to the
        // whole width. They are one swath, driven once.
        let cell: Area = (
            vec![
                v2(0.0, 0.0),
                v2(20.0, 0.0),
                v2(25.0, 4.0),
                v2(30.0, 0.0),
                v2(60.0, 0.0),
                v2(65.0, 4.0),
                v2(70.0, 0.0),
                v2(100.0, 0.0),
                v2(100.0, 50.0),
                v2(0.0, 50.0),
            ],
            vec![],
        );
        // Where the implement is clear: here the rectangle without the notches.
        let l = swath_lines(&cell, &[rect(100.0, 50.0)], 0.0, 6.0, BAND_WIDENING, false);
        assert_eq!(
            crate::plan::coverage::geometry::scan_intervals(&cell, l.ys[0]).len(),
            3
        );
        assert_eq!(l.intervals[0].len(), 1, "{:?}", l.intervals[0]);
        let (a, b) = l.intervals[0][0];
        assert!(a.abs() < 1e-6 && (b - 100.0).abs() < 1e-6, "{a} {b}");
        for ivs in &l.intervals {
            assert!(ivs.windows(2).all(|p| p[0].1 < p[1].0), "{ivs:?}");
        }
    }

    #[test]
    fn exact_lines_are_w_apart_and_lay_the_overlap_where_the_safe_ground_reaches() {
        // 50 m at w 6 m: 9 lines, 4 m of overlap. Exact, the lines are 6 m apart and the
        // whole overlap lies beyond one side, not 0.44 m between every pair.
        let cell = rect(100.0, 50.0);
        let safe = |y0: f64, y1: f64| {
            let r = rect(100.0, y1 - y0);
            let ring = r.0.iter().map(|p| v2(p.x, p.y + y0)).collect();
            vec![(ring, vec![])]
        };
        let l = swath_lines(&cell, &safe(-10.0, 60.0), 0.0, 6.0, 1.0, true);
        assert_eq!(l.ys.len(), 9);
        assert!((l.spacing - 6.0).abs() < 1e-12);
        assert!(l.ys.windows(2).all(|p| (p[1] - p[0] - 6.0).abs() < 1e-9));
        // With room on both sides the overlap goes beyond the high side: the first footprint
        // starts at the low side, the last ends 4 m beyond the high side.
        assert!((l.ys[0] - 3.0).abs() < 1e-9, "{:?}", l.ys);
        assert!((l.ys[8] + 3.0 - 54.0).abs() < 1e-9, "{:?}", l.ys);
        // Every line, the outer ones too, spans the cell (the outer ones scanned inside it).
        for ivs in &l.intervals {
            assert_eq!(ivs.len(), 1, "{ivs:?}");
            assert!(
                ivs[0].0.abs() < 1e-6 && (ivs[0].1 - 100.0).abs() < 1e-6,
                "{ivs:?}"
            );
        }
        // Where the safe ground ends 0.5 m beyond the high side (a line there would lose its
        // swath), the overlap goes beyond the low side instead.
        let l = swath_lines(&cell, &safe(-10.0, 50.5), 0.0, 6.0, 1.0, true);
        assert!((l.ys[0] + 1.0).abs() < 1e-9, "{:?}", l.ys);
        assert_eq!(l.intervals.iter().flatten().count(), 9);
        // Room for neither outer line's centre 1 m beyond a side, but for both on it: half
        // the overlap to each side.
        let l = swath_lines(&cell, &safe(-0.5, 50.5), 0.0, 6.0, 1.0, true);
        assert!((l.ys[0] - 1.0).abs() < 1e-9, "{:?}", l.ys);
        assert_eq!(l.intervals.iter().flatten().count(), 9);
    }
}
