//! The edges of the waypoint graph of [`super::transit::route_graph`]: the CSC words between
//! a grid node and the nodes up to [`EDGE_REACH`] steps away, solved once per grid in its
//! frame, with the checks of their points kept for the grid's later searches.

use super::closed::CheckedEdges;
use super::transit::{csc_length, Csc};
use crate::geo::{wrap_angle, Vec2};
use std::f64::consts::TAU;
use std::rc::Rc;

/// One CSC word of an edge between grid nodes: its length (m) and its points relative to the
/// edge's first node.
#[derive(Debug, Clone)]
pub(super) struct EdgeWord {
    pub(super) length: f64,
    pub(super) pts: Vec<Vec2>,
}

impl EdgeWord {
    /// The word of `curve`, points about `step` m apart.
    pub(super) fn of(curve: &Csc, step: f64) -> Option<Self> {
        Some(EdgeWord {
            length: curve.length,
            pts: curve.points(step, &|_| true)?,
        })
    }
}

/// Nodes an edge of the waypoint graph may join: up to this many grid steps apart each way.
pub(super) const EDGE_REACH: i64 = 2;
pub(super) const EDGE_SPAN: usize = (2 * EDGE_REACH + 1) as usize;

/// The CSC words of every edge of the waypoint graph, solved once in the grid's frame: the
/// curve from a node with heading index `ha` to the node (`di`, `dj`) steps away with heading
/// index `hb` has the same shape wherever the node lies (Fields2Cover solves its turns once in
/// a canonical frame the same way), so the search only translates the points and checks them.
#[derive(Debug, Clone, Default)]
pub(super) struct EdgeTable {
    /// (r_min, point spacing) the table was solved for, as bits.
    pub(super) key: (u64, u64),
    /// Words shortest first per (di, dj, ha, hb); `None` until first needed.
    pub(super) slots: Vec<Option<Rc<[EdgeWord]>>>,
    /// Length of each edge's shortest word, m; infinite where the edge arrives against its
    /// direction (see [`arrival_headings`]) or has no word.
    pub(super) shortest: Vec<f64>,
    /// Per (di, dj, ha): the heading indices hb (bit hb) of the edges with a word.
    pub(super) to_mask: Vec<u8>,
    /// Per (di, dj, hb): the heading indices ha (bit ha) of the edges with a word.
    pub(super) from_mask: Vec<u8>,
    /// Searches made on the grid: the number of the current one (see `checked`).
    pub(super) searches: u32,
    /// Edges between nodes whose points were checked, by every search on the grid (they are
    /// the same curves checked by the same test): (state, state) → the first clear word and
    /// its length, `None` when none is clear, and the number of the last search that checked
    /// or used it (one map serves the search's own record and the grid's). (Plans of many transits search the same ground
    /// again: a third to half of the edges a search checks were checked before.)
    pub(super) checked: CheckedEdges,
}

impl EdgeTable {
    /// The table's slot of the edge from heading index `ha` to the node `d` steps away with
    /// heading index `hb`.
    pub(super) fn slot(d: (i64, i64), ha: usize, hb: usize) -> usize {
        let cell = (d.0 + EDGE_REACH) as usize * EDGE_SPAN + (d.1 + EDGE_REACH) as usize;
        (cell * GRAPH_HEADINGS + ha) * GRAPH_HEADINGS + hb
    }

    /// Ready for radius `r`, point spacing `step` and grid spacing `grid_step`: the shortest
    /// lengths solved, the words emptied.
    pub(super) fn prepare(&mut self, r: f64, step: f64, grid_step: f64) {
        let key = (r.to_bits(), step.to_bits());
        if self.key == key && !self.slots.is_empty() {
            return;
        }
        let n = EDGE_SPAN * EDGE_SPAN * GRAPH_HEADINGS * GRAPH_HEADINGS;
        self.key = key;
        self.checked.clear();
        self.slots = vec![None; n];
        self.shortest = vec![f64::INFINITY; n];
        self.to_mask = vec![0; EDGE_SPAN * EDGE_SPAN * GRAPH_HEADINGS];
        self.from_mask = vec![0; EDGE_SPAN * EDGE_SPAN * GRAPH_HEADINGS];
        for di in -EDGE_REACH..=EDGE_REACH {
            for dj in -EDGE_REACH..=EDGE_REACH {
                let to = Vec2::new(di as f64 * grid_step, dj as f64 * grid_step);
                for ha in 0..GRAPH_HEADINGS {
                    let from = (di == 0 && dj == 0).then_some(ha);
                    for hb in arrival_headings(to, from) {
                        let (h1, h2) = (graph_heading(ha), graph_heading(hb));
                        if let Some(l) = csc_length(Vec2::new(0.0, 0.0), h1, to, h2, r) {
                            let slot = Self::slot((di, dj), ha, hb);
                            self.shortest[slot] = l;
                            let cell = slot / (GRAPH_HEADINGS * GRAPH_HEADINGS);
                            self.to_mask[cell * GRAPH_HEADINGS + ha] |= 1 << hb;
                            self.from_mask[cell * GRAPH_HEADINGS + hb] |= 1 << ha;
                        }
                    }
                }
            }
        }
    }
}

/// Headings tried at every waypoint.
pub(super) const GRAPH_HEADINGS: usize = 8;

/// Heading of heading index `k` of the waypoint graph, rad.
pub(super) fn graph_heading(k: usize) -> f64 {
    k as f64 * TAU / GRAPH_HEADINGS as f64
}

/// Heading indices an edge along `dir` may arrive with: roughly along the way there (all but
/// `from` when the edge starts and ends at one node).
pub(super) fn arrival_headings(dir: Vec2, from: Option<usize>) -> impl Iterator<Item = usize> {
    (0..GRAPH_HEADINGS).filter(move |&hk| {
        if dir.norm() > 1e-9 {
            wrap_angle(graph_heading(hk) - dir.y.atan2(dir.x)).abs() <= 0.8
        } else {
            Some(hk) != from
        }
    })
}
