//! What the waypoint searches of [`super::transit::route_graph`] on one grid keep for the
//! later ones: the edges whose points were checked ([`CheckedEdges`]), and the searches that
//! failed by exhausting what they could reach ([`ClosedSets`]).
//!
//! A search that empties its queue without reaching the goal has expanded every state it could
//! reach: its set of expanded states is closed (every clear edge from one of them to a node the
//! search could use ends at one of them). A later search on the same grid, with the same radius
//! and point spacing, whose usable nodes are among that search's and whose goal no curve
//! reaches from those of the states near it, cannot reach its goal through them: it may leave
//! them out (the same way found, with fewer states expanded toward the search's limit). A
//! search from inside such a pocket (a neck that the coarse grid says is passable but no curve
//! of radius r_min gets through) then fails at once instead of expanding the pocket again.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// Edges of the waypoint search whose points were checked: (parent, state) → the first clear
/// word and its length, `None` when none is clear; and the number of the last search on the
/// grid that checked or used it.
pub(super) type CheckedEdges =
    HashMap<(u32, u32), (Option<(u8, f64)>, u32), BuildHasherDefault<EdgeHasher>>;

/// Hasher of the search's edge keys (two state indices): one multiply-rotate per word, where
/// the standard SipHash cost as much as the lookups it served.
#[derive(Default)]
pub(super) struct EdgeHasher(u64);

impl Hasher for EdgeHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_u32(&mut self, n: u32) {
        self.write_u64(u64::from(n));
    }
    fn write_u64(&mut self, n: u64) {
        self.0 = (self.0.rotate_left(5) ^ n).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

/// One closed set of states: the states a failed search expanded (with the closed sets it
/// left out), the nodes holding them, and the nodes that search could use.
#[derive(Debug, Clone)]
struct ClosedSet {
    /// Bit per state (node × headings + heading index).
    states: Vec<u64>,
    /// Bit per node: a state of `states` is at it.
    nodes: Vec<u64>,
    /// Bit per node: the search could use it (a finite distance to its goal).
    open: Vec<u64>,
}

/// At most this many closed sets kept per grid (each a few kB to a few tens of kB).
const MAX_SETS: usize = 32;

/// The closed sets of one waypoint grid, for one radius and point spacing.
#[derive(Debug, Clone, Default)]
pub(super) struct ClosedSets {
    /// (r_min, point spacing) of the searches, as bits.
    key: (u64, u64),
    sets: Vec<ClosedSet>,
}

fn bit(bits: &[u64], k: usize) -> bool {
    bits.get(k / 64).is_some_and(|w| w >> (k % 64) & 1 == 1)
}

fn set_bit(bits: &mut [u64], k: usize) {
    if let Some(w) = bits.get_mut(k / 64) {
        *w |= 1 << (k % 64);
    }
}

/// A bit vector of `n` bits, set where `f` holds.
fn bits_of(n: usize, f: impl Fn(usize) -> bool) -> Vec<u64> {
    let mut bits = vec![0u64; n.div_ceil(64)];
    for k in (0..n).filter(|&k| f(k)) {
        set_bit(&mut bits, k);
    }
    bits
}

/// States a search may leave out: a bit per state.
#[derive(Debug, Clone)]
pub(super) struct Dead(Vec<u64>);

impl Dead {
    /// Is state `s` left out?
    pub(super) fn has(&self, s: usize) -> bool {
        bit(&self.0, s)
    }
}

impl ClosedSets {
    /// The states a search with radius and spacing `key` may leave out: those of every closed
    /// set whose open nodes include each node with a finite `to_goal` (distance to the goal, m,
    /// per node) and none of whose states at a node of `near_goal` (the nodes from which the
    /// search tries the goal, `headings` states per node) `finishes` (reaches the goal).
    /// `None` when no set qualifies.
    pub(super) fn dead(
        &self,
        key: (u64, u64),
        to_goal: &[f64],
        near_goal: &[usize],
        headings: usize,
        finishes: &dyn Fn(usize) -> bool,
    ) -> Option<Dead> {
        if self.key != key {
            return None;
        }
        let mut out: Option<Vec<u64>> = None;
        for set in &self.sets {
            let fits = to_goal
                .iter()
                .enumerate()
                .all(|(k, d)| !d.is_finite() || bit(&set.open, k))
                && near_goal.iter().all(|&k| {
                    !bit(&set.nodes, k)
                        || (0..headings)
                            .map(|h| k * headings + h)
                            .all(|s| !bit(&set.states, s) || !finishes(s))
                });
            if fits {
                let acc = out.get_or_insert_with(|| vec![0; set.states.len()]);
                for (a, b) in acc.iter_mut().zip(&set.states) {
                    *a |= b;
                }
            }
        }
        out.map(Dead)
    }

    /// Keep the closed set of a search with radius and spacing `key` that failed with its queue
    /// empty: the states it expanded (`expanded`, per state) and those it left out (`dead`),
    /// `headings` states per node, over the nodes with a finite `to_goal`.
    pub(super) fn record(
        &mut self,
        key: (u64, u64),
        expanded: &[bool],
        dead: Option<&Dead>,
        headings: usize,
        to_goal: &[f64],
    ) {
        if self.key != key {
            self.key = key;
            self.sets.clear();
        }
        if self.sets.len() >= MAX_SETS {
            return;
        }
        let in_set = |s: usize| expanded[s] || dead.is_some_and(|d| d.has(s));
        let states = bits_of(expanded.len(), in_set);
        let nodes = bits_of(to_goal.len(), |k| {
            (0..headings).any(|h| in_set(k * headings + h))
        });
        let open = bits_of(to_goal.len(), |k| to_goal[k].is_finite());
        self.sets.push(ClosedSet {
            states,
            nodes,
            open,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed set is left out only by a search whose usable nodes are among its own and
    /// whose goal no curve reaches from its states near the goal; it carries over (with the
    /// states a later failed search expanded) into that search's set.
    #[test]
    fn a_closed_set_is_left_out_only_where_it_cannot_reach_the_goal() {
        let key = (1, 2);
        let inf = f64::INFINITY;
        // Four nodes, two headings each: the search used nodes 0–2 and expanded states 0, 3.
        let to_goal = [1.0, 2.0, 3.0, inf];
        let mut expanded = vec![false; 8];
        expanded[0] = true;
        expanded[3] = true;
        let mut sets = ClosedSets::default();
        sets.record(key, &expanded, None, 2, &to_goal);
        let never = |_: usize| false;
        let dead = sets.dead(key, &to_goal, &[2], 2, &never).unwrap();
        assert!(dead.has(0) && dead.has(3) && !dead.has(1) && !dead.has(2));
        // Another radius or spacing: nothing known.
        assert!(sets.dead((1, 3), &to_goal, &[2], 2, &never).is_none());
        // A search that may use node 3 as well: the set proves nothing for it.
        assert!(sets.dead(key, &[1.0; 4], &[2], 2, &never).is_none());
        // A goal near node 1 (state 3 there): left out only when state 3 cannot finish.
        assert!(sets.dead(key, &to_goal, &[1], 2, &|s| s == 3).is_none());
        assert!(sets.dead(key, &to_goal, &[1], 2, &|s| s == 2).is_some());
        // A later failed search that expanded state 4 and left out the first set's states.
        let mut later = vec![false; 8];
        later[4] = true;
        sets.record(key, &later, Some(&dead), 2, &to_goal);
        let both = sets.dead(key, &to_goal, &[], 2, &never).unwrap();
        assert!(both.has(0) && both.has(3) && both.has(4));
    }
}
