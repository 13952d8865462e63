//! Scoring a run against the simulator's true pose: |XTE| statistics in constant memory, the
//! nearest point on a path, and the path being scored.

use crate::geo::{signed_offset, Vec2};

/// |XTE| statistics in constant memory: a histogram of 0.1 mm bins up to 2 m.
#[derive(Debug, Clone)]
pub struct XteStats {
    bins: Vec<u32>,
    overflow: u64,
    count: u64,
    sum_sq: f64,
    max: f64,
}

const BIN_M: f64 = 1e-4;
const BINS: usize = 20_000;

impl Default for XteStats {
    fn default() -> Self {
        XteStats {
            bins: vec![0; BINS],
            overflow: 0,
            count: 0,
            sum_sq: 0.0,
            max: 0.0,
        }
    }
}

impl XteStats {
    pub fn add(&mut self, xte: f64) {
        let a = xte.abs();
        if !a.is_finite() {
            return;
        }
        let i = (a / BIN_M) as usize;
        match self.bins.get_mut(i) {
            Some(b) => *b += 1,
            None => self.overflow += 1,
        }
        self.count += 1;
        self.sum_sq += a * a;
        self.max = self.max.max(a);
    }
    pub fn count(&self) -> u64 {
        self.count
    }
    pub fn rms(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            (self.sum_sq / self.count as f64).sqrt()
        }
    }
    pub fn max(&self) -> f64 {
        self.max
    }
    /// The `q` quantile (0..1), to the bin resolution (upper bin edge).
    pub fn quantile(&self, q: f64) -> f64 {
        if self.count == 0 {
            return 0.0;
        }
        let target = (q * self.count as f64).ceil().max(1.0) as u64;
        let mut seen = 0u64;
        for (i, &b) in self.bins.iter().enumerate() {
            seen += b as u64;
            if seen >= target {
                return ((i + 1) as f64 * BIN_M).min(self.max);
            }
        }
        self.max
    }
}

/// Running |XTE| of one segment.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct SegmentScore {
    pub(super) count: u64,
    pub(super) sum_sq: f64,
    pub(super) max: f64,
}

/// The cumulative lengths of the polyline `points` into `out` (cleared first), m: 0 at the
/// first point.
pub(crate) fn cumulative_lengths(points: &[Vec2], out: &mut Vec<f64>) {
    out.clear();
    let mut s = 0.0;
    out.push(0.0);
    for w in points.windows(2) {
        s += (w[1] - w[0]).norm();
        out.push(s);
    }
}

/// The nearest point to `p` on the segments `segments` (indices of their first points) of the
/// polyline `points` with cumulative lengths `cumulative`: (distance along m, signed offset m,
/// positive left). With `extend_ends`, beyond the polyline's ends the distance along keeps
/// counting along its end segments (negative before the start). `None` for fewer than two
/// points.
pub(crate) fn nearest_on_polyline(
    points: &[Vec2],
    cumulative: &[f64],
    p: &Vec2,
    segments: std::ops::RangeInclusive<usize>,
    extend_ends: bool,
) -> Option<(f64, f64)> {
    let n = points.len();
    if n < 2 {
        return None;
    }
    let mut best: Option<(f64, f64, f64)> = None;
    for i in segments {
        let a = points[i];
        let d = points[i + 1] - a;
        let len = d.norm();
        if len <= 0.0 {
            continue;
        }
        let dir = d / len;
        let t = (p - a).dot(&dir);
        let tc = t.clamp(0.0, len);
        let dist = (p - (a + dir * tc)).norm();
        if best.is_none_or(|b| dist < b.0) {
            let along_seg = if extend_ends && ((i == 0 && t < 0.0) || (i == n - 2 && t > len)) {
                t
            } else {
                tc
            };
            best = Some((dist, cumulative[i] + along_seg, signed_offset(p, &a, &dir)));
        }
    }
    best.map(|(_, along, offset)| (along, offset))
}

/// The work path being scored against the true pose, with its cumulative lengths.
#[derive(Debug, Default)]
pub(super) struct ScoredPath {
    /// (block, rank) of the guidance path this is.
    pub(super) key: Option<(u64, usize)>,
    pub(super) points: Vec<Vec2>,
    pub(super) cumulative: Vec<f64>,
}

impl ScoredPath {
    /// Whether this is the guidance's current path: the same (block, rank) and the same first
    /// point. The first point alone is not enough: a field plan's transit starts exactly where
    /// the closed headland pass before it started and ended.
    pub(super) fn is_current(&self, g: &crate::guidance::Guidance) -> bool {
        self.key == Some((g.index_block(), g.index_rank()))
            && self.points.first().copied() == g.global_path().first().map(|p| p.pos)
    }

    pub(super) fn set(&mut self, g: &crate::guidance::Guidance) {
        self.key = Some((g.index_block(), g.index_rank()));
        let path = g.global_path();
        self.points.clear();
        self.points.extend(path.iter().map(|p| p.pos));
        cumulative_lengths(&self.points, &mut self.cumulative);
    }

    pub(super) fn length(&self) -> f64 {
        self.cumulative.last().copied().unwrap_or(0.0)
    }

    /// Distance along the path and signed cross-track error (positive left) of `p`, from the
    /// nearest path segment within a few points of `hint`.
    pub(super) fn locate(&self, p: &Vec2, hint: usize) -> Option<(f64, f64)> {
        let n = self.points.len();
        if n < 2 {
            return None;
        }
        let lo = hint.saturating_sub(4).min(n - 2);
        let hi = (hint + 4).min(n - 2);
        nearest_on_polyline(&self.points, &self.cumulative, p, lo..=hi, true)
    }
}
