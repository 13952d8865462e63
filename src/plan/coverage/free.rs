//! Waypoint-graph edges known clear without checking their points: a curve of length `l`
//! from a node lies within `l` of it (no point of a curve is farther from its start than the
//! length along it), so when every edge of the field is at least `half + l` from a usable
//! node, every point of the curve is at least `half` from every edge and on the node's side
//! of each, inside the field and off the obstacles: clear by the grid's test. (de_bb_concave
//! at r_min 8 m: the two searches that fail after expanding every state they can reach, some
//! 6 400 and 4 200, checked each edge's 30–70 points, though most of the field lies farther
//! than the edges are long from its boundary.)

use crate::geo::Vec2;
use crate::plan::coverage::Field;
use std::cell::RefCell;

/// Fields with more edges than this are not measured (a node's distance costs one distance
/// per edge; the fields this serves have tens).
const MAX_EDGES: usize = 512;

/// The distance from each node of a waypoint grid to the nearest edge of its field, found
/// when first asked.
#[derive(Clone)]
pub(super) struct Free<'a> {
    /// The field whose edges the grid's test keeps `half` m from (`None`: nothing known).
    field: Option<&'a Field>,
    half: f64,
    /// Per node: the distance, m; NaN until asked.
    dist: RefCell<Vec<f64>>,
}

impl<'a> Free<'a> {
    /// For a grid of `nodes` nodes whose test is [`super::super::implement_clear`] of `field`
    /// with `half` (the same answer at every point; `None`: unknown, nothing is known clear).
    pub(super) fn new(field: Option<&'a Field>, half: f64, nodes: usize) -> Self {
        let edges = field.map_or(0, |f| {
            f.boundary.len() + f.obstacles.iter().map(Vec::len).sum::<usize>()
        });
        Free {
            field: field.filter(|_| edges <= MAX_EDGES),
            half,
            dist: RefCell::new(vec![f64::NAN; nodes]),
        }
    }

    /// Is every point within `length` m of node `k` at `at` clear by the grid's test, so that
    /// every point of a curve of that length from the node is? Only for a node that is clear
    /// itself (usable): it says which side of every edge the disc lies on.
    pub(super) fn covers(&self, k: usize, at: &Vec2, length: f64) -> bool {
        let Some(field) = self.field else {
            return false;
        };
        let known = self.dist.borrow().get(k).copied().unwrap_or(f64::NAN);
        let d = if known.is_nan() {
            let d = field.distance_to_edges(at);
            if let Some(x) = self.dist.borrow_mut().get_mut(k) {
                *x = d;
            }
            d
        } else {
            known
        };
        // A millimetre to spare for the rounding of the curve's points.
        d >= self.half + length + 1e-3
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::v2;
    use crate::plan::coverage::implement_clear;
    use crate::plan::coverage::transit::words_by_length;
    use rand::{Rng, SeedableRng};

    /// Sound: every curve from a clear node that [`Free::covers`] passes is clear at every
    /// point by [`implement_clear`] (curves of every word, radius and length from random clear
    /// points of a concave field with an obstacle, checked point by point); and it passes many.
    #[test]
    fn covered_curves_are_clear_at_every_point() {
        let field = Field {
            boundary: vec![
                v2(0.0, 0.0),
                v2(300.0, 0.0),
                v2(300.0, 200.0),
                v2(170.0, 80.0),
                v2(100.0, 220.0),
                v2(0.0, 150.0),
            ],
            obstacles: vec![vec![
                v2(60.0, 50.0),
                v2(90.0, 55.0),
                v2(80.0, 85.0),
                v2(55.0, 75.0),
            ]],
        };
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
        let mut passed = 0;
        for half in [0.8, 1.6, 6.0] {
            let free = Free::new(Some(&field), half, 4000);
            for k in 0..4000 {
                let p = v2(rng.gen_range(-10.0..310.0), rng.gen_range(-10.0..230.0));
                if !implement_clear(&field, half, &p) {
                    continue;
                }
                for _ in 0..4 {
                    let to = p + v2(rng.gen_range(-60.0..60.0), rng.gen_range(-60.0..60.0));
                    let (h1, h2) = (rng.gen_range(-3.2..3.2), rng.gen_range(-3.2..3.2));
                    let r = rng.gen_range(4.0..10.0);
                    for c in words_by_length(p, h1, to, h2, r) {
                        if !free.covers(k, &p, c.length) {
                            continue;
                        }
                        passed += 1;
                        let pts = c.points(1.0, &|_| true).unwrap_or_default();
                        assert!(pts.len() >= 2);
                        for q in &pts {
                            assert!(implement_clear(&field, half, q), "half {half} at {q:?}");
                        }
                    }
                }
            }
        }
        assert!(passed > 500, "{passed} curves passed");
        // No field: nothing known.
        assert!(!Free::new(None, 1.0, 1).covers(0, &v2(150.0, 40.0), 0.0));
    }
}
