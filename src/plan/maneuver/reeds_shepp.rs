//! Plain Reeds-Shepp shortest paths (curvature jumps allowed): all 48 words of Reeds & Shepp,
//! "Optimal paths for a car that goes both forwards and backwards", Pacific J. Math. 1990,
//! with the formula numbering of that paper (8.1–8.11) and the usual time-flip / reflection /
//! backwards symmetries (as organised in OMPL's `ReedsSheppStateSpace`; own code).
//!
//! Computed in units of the turning radius in the start's frame; lengths are exact.
//! Letters: L = steering left (κ = +1/r), R = right, S = straight; a negative length means
//! driven in reverse.

use super::path::{CurvePath, CurveSegment};
use crate::geo::{Direction, Pose};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

const ZERO: f64 = 1e-10;

/// Segment letter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RsLetter {
    L,
    S,
    R,
}

use RsLetter::{L, R, S};

/// A Reeds-Shepp word with signed lengths in units of the turning radius (arcs in radians).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RsWord {
    pub letters: [RsLetter; 5],
    pub lengths: [f64; 5],
    pub n: usize,
}

impl RsWord {
    /// Total length in units of the radius.
    pub fn length(&self) -> f64 {
        self.lengths[..self.n].iter().map(|l| l.abs()).sum()
    }
}

/// Wraps to (−π, π] (inputs here are within a few turns, so subtraction loops are cheap).
#[inline]
fn mod2pi(x: f64) -> f64 {
    if !x.is_finite() {
        return x;
    }
    let mut v = x;
    while v > PI {
        v -= TAU;
    }
    while v <= -PI {
        v += TAU;
    }
    v
}

#[inline]
fn polar(x: f64, y: f64) -> (f64, f64) {
    ((x * x + y * y).sqrt(), y.atan2(x))
}

fn tau_omega(u: f64, v: f64, xi: f64, eta: f64, phi: f64) -> (f64, f64) {
    let delta = mod2pi(u - v);
    let a = u.sin() - delta.sin();
    let b = u.cos() - delta.cos() - 1.0;
    let t1 = (eta * a - xi * b).atan2(xi * a + eta * b);
    let t2 = 2.0 * (delta.cos() - v.cos() - u.cos()) + 3.0;
    let tau = if t2 < 0.0 {
        mod2pi(t1 + PI)
    } else {
        mod2pi(t1)
    };
    let omega = mod2pi(tau - u + v - phi);
    (tau, omega)
}

// 8.1
fn lp_sp_lp(x: f64, y: f64, phi: f64, sp: f64, cp: f64) -> Option<(f64, f64, f64)> {
    let (u, t) = polar(x - sp, y - 1.0 + cp);
    if t >= -ZERO {
        let v = mod2pi(phi - t);
        if v >= -ZERO {
            return Some((t, u, v));
        }
    }
    None
}

// 8.2
fn lp_sp_rp(x: f64, y: f64, phi: f64, sp: f64, cp: f64) -> Option<(f64, f64, f64)> {
    let (u1, t1) = polar(x + sp, y - 1.0 - cp);
    let u1 = u1 * u1;
    if u1 >= 4.0 {
        let u = (u1 - 4.0).sqrt();
        let theta = 2.0f64.atan2(u);
        let t = mod2pi(t1 + theta);
        let v = mod2pi(t - phi);
        if t >= -ZERO && v >= -ZERO {
            return Some((t, u, v));
        }
    }
    None
}

// 8.3 / 8.4
fn lp_rm_l(x: f64, y: f64, phi: f64, sp: f64, cp: f64) -> Option<(f64, f64, f64)> {
    let xi = x - sp;
    let eta = y - 1.0 + cp;
    let (u1, theta) = polar(xi, eta);
    if u1 <= 4.0 {
        let u = -2.0 * (0.25 * u1).asin();
        let t = mod2pi(theta + 0.5 * u + PI);
        let v = mod2pi(phi - t + u);
        if t >= -ZERO && u <= ZERO {
            return Some((t, u, v));
        }
    }
    None
}

// 8.7
fn lp_rup_lum_rm(x: f64, y: f64, phi: f64, sp: f64, cp: f64) -> Option<(f64, f64, f64)> {
    let xi = x + sp;
    let eta = y - 1.0 - cp;
    let rho = 0.25 * (2.0 + (xi * xi + eta * eta).sqrt());
    if rho <= 1.0 {
        let u = rho.acos();
        let (t, v) = tau_omega(u, -u, xi, eta, phi);
        if t >= -ZERO && v <= ZERO {
            return Some((t, u, v));
        }
    }
    None
}

// 8.8
fn lp_rum_lum_rp(x: f64, y: f64, phi: f64, sp: f64, cp: f64) -> Option<(f64, f64, f64)> {
    let xi = x + sp;
    let eta = y - 1.0 - cp;
    let rho = (20.0 - xi * xi - eta * eta) / 16.0;
    if (0.0..=1.0).contains(&rho) {
        let u = -rho.acos();
        if u >= -FRAC_PI_2 {
            let (t, v) = tau_omega(u, u, xi, eta, phi);
            if t >= -ZERO && v >= -ZERO {
                return Some((t, u, v));
            }
        }
    }
    None
}

// 8.9
fn lp_rm_sm_lm(x: f64, y: f64, phi: f64, sp: f64, cp: f64) -> Option<(f64, f64, f64)> {
    let xi = x - sp;
    let eta = y - 1.0 + cp;
    let (rho, theta) = polar(xi, eta);
    if rho >= 2.0 {
        let r = (rho * rho - 4.0).sqrt();
        let u = 2.0 - r;
        let t = mod2pi(theta + r.atan2(-2.0));
        let v = mod2pi(phi - FRAC_PI_2 - t);
        if t >= -ZERO && u <= ZERO && v <= ZERO {
            return Some((t, u, v));
        }
    }
    None
}

// 8.10
fn lp_rm_sm_rm(x: f64, y: f64, phi: f64, sp: f64, cp: f64) -> Option<(f64, f64, f64)> {
    let xi = x + sp;
    let eta = y - 1.0 - cp;
    let (rho, theta) = polar(-eta, xi);
    if rho >= 2.0 {
        let t = theta;
        let u = 2.0 - rho;
        let v = mod2pi(t + FRAC_PI_2 - phi);
        if t >= -ZERO && u <= ZERO && v <= ZERO {
            return Some((t, u, v));
        }
    }
    None
}

// 8.11
fn lp_rm_s_lm_rp(x: f64, y: f64, phi: f64, sp: f64, cp: f64) -> Option<(f64, f64, f64)> {
    let xi = x + sp;
    let eta = y - 1.0 - cp;
    let (rho, _) = polar(xi, eta);
    if rho >= 2.0 {
        let u = 4.0 - (rho * rho - 4.0).sqrt();
        if u <= ZERO {
            let t = mod2pi(((4.0 - u) * xi - 2.0 * eta).atan2(-2.0 * xi + (u - 4.0) * eta));
            let v = mod2pi(t - phi);
            if t >= -ZERO && v >= -ZERO {
                return Some((t, u, v));
            }
        }
    }
    None
}

struct Best {
    word: Option<RsWord>,
    len: f64,
    /// Every word offered, when asked for ([`reeds_shepp_paths`]).
    all: Option<Vec<RsWord>>,
}

impl Best {
    #[inline]
    fn offer(&mut self, letters: &[RsLetter], lengths: &[f64]) {
        let len: f64 = lengths.iter().map(|l| l.abs()).sum();
        if len < self.len || self.all.is_some() {
            let mut w = RsWord {
                letters: [S; 5],
                lengths: [0.0; 5],
                n: letters.len(),
            };
            w.letters[..letters.len()].copy_from_slice(letters);
            w.lengths[..lengths.len()].copy_from_slice(lengths);
            if let Some(all) = &mut self.all {
                all.push(w);
            }
            if len < self.len {
                self.len = len;
                self.word = Some(w);
            }
        }
    }
}

/// Offers `formula`'s solution under the four symmetries of the Reeds-Shepp formulas, in this
/// order: as is; time-flipped (x → −x, φ → −φ: every length negated); reflected (y → −y,
/// φ → −φ: L and R swapped); both. `lengths` lays a solution `(t, u, v)` out along `word`.
/// (Generic in `formula` so that each call site is compiled with its formula inlined.)
#[inline(always)]
fn offer_symmetric<const N: usize>(
    (x, y, phi, sp, cp): (f64, f64, f64, f64, f64),
    formula: impl Fn(f64, f64, f64, f64, f64) -> Option<(f64, f64, f64)>,
    word: [RsLetter; N],
    lengths: impl Fn(f64, f64, f64) -> [f64; N],
    b: &mut Best,
) {
    let mut offer = |x: f64, y: f64, phi: f64, sp: f64, w: &[RsLetter; N], negate: bool| {
        if let Some((t, u, v)) = formula(x, y, phi, sp, cp) {
            let mut l = lengths(t, u, v);
            if negate {
                l = l.map(|x| -x);
            }
            b.offer(w, &l);
        }
    };
    let reflected = word.map(|l| match l {
        L => R,
        R => L,
        S => S,
    });
    offer(x, y, phi, sp, &word, false);
    offer(-x, y, -phi, -sp, &word, true);
    offer(x, -y, -phi, -sp, &reflected, false);
    offer(-x, -y, phi, sp, &reflected, true);
}

/// The goal seen from the start driven backwards (x, y of the "backwards" formulas, §8).
fn backwards(x: f64, y: f64, phi: f64, sp: f64, cp: f64) -> (f64, f64, f64, f64, f64) {
    (x * cp + y * sp, x * sp - y * cp, phi, sp, cp)
}

fn csc(x: f64, y: f64, phi: f64, sp: f64, cp: f64, b: &mut Best) {
    let a = (x, y, phi, sp, cp);
    offer_symmetric(a, lp_sp_lp, [L, S, L], |t, u, v| [t, u, v], b);
    offer_symmetric(a, lp_sp_rp, [L, S, R], |t, u, v| [t, u, v], b);
}

fn ccc(x: f64, y: f64, phi: f64, sp: f64, cp: f64, b: &mut Best) {
    offer_symmetric(
        (x, y, phi, sp, cp),
        lp_rm_l,
        [L, R, L],
        |t, u, v| [t, u, v],
        b,
    );
    let back = backwards(x, y, phi, sp, cp);
    offer_symmetric(back, lp_rm_l, [L, R, L], |t, u, v| [v, u, t], b);
}

fn cccc(x: f64, y: f64, phi: f64, sp: f64, cp: f64, b: &mut Best) {
    let a = (x, y, phi, sp, cp);
    offer_symmetric(a, lp_rup_lum_rm, [L, R, L, R], |t, u, v| [t, u, -u, v], b);
    offer_symmetric(a, lp_rum_lum_rp, [L, R, L, R], |t, u, v| [t, u, u, v], b);
}

fn ccsc(x: f64, y: f64, phi: f64, sp: f64, cp: f64, b: &mut Best) {
    let h = FRAC_PI_2;
    let a = (x, y, phi, sp, cp);
    offer_symmetric(a, lp_rm_sm_lm, [L, R, S, L], |t, u, v| [t, -h, u, v], b);
    offer_symmetric(a, lp_rm_sm_rm, [L, R, S, R], |t, u, v| [t, -h, u, v], b);
    let back = backwards(x, y, phi, sp, cp);
    offer_symmetric(back, lp_rm_sm_lm, [L, S, R, L], |t, u, v| [v, u, -h, t], b);
    offer_symmetric(back, lp_rm_sm_rm, [R, S, R, L], |t, u, v| [v, u, -h, t], b);
}

fn ccscc(x: f64, y: f64, phi: f64, sp: f64, cp: f64, b: &mut Best) {
    let h = FRAC_PI_2;
    let a = (x, y, phi, sp, cp);
    offer_symmetric(
        a,
        lp_rm_s_lm_rp,
        [L, R, S, L, R],
        |t, u, v| [t, -h, u, -h, v],
        b,
    );
}

/// Shortest word from `start` to `goal` for turning radius `r_min_m` (None if r ≤ 0 or the
/// inputs are not finite).
pub fn reeds_shepp_word(start: &Pose, goal: &Pose, r_min_m: f64) -> Option<RsWord> {
    words(start, goal, r_min_m, false)?.word
}

/// Every Reeds-Shepp path from `start` to `goal` for turning radius `r_min_m` that the formulas
/// give (up to 48 words, a few of them alike), shortest first: where the shortest leaves the
/// free space, a longer one may not.
pub fn reeds_shepp_paths(start: &Pose, goal: &Pose, r_min_m: f64) -> Vec<CurvePath> {
    let mut all = words(start, goal, r_min_m, true)
        .and_then(|b| b.all)
        .unwrap_or_default();
    all.sort_by(|a, b| a.length().total_cmp(&b.length()));
    all.iter().map(|w| path_of(start, w, r_min_m)).collect()
}

/// The formulas' words (the shortest, and every one when `collect`).
fn words(start: &Pose, goal: &Pose, r_min_m: f64, collect: bool) -> Option<Best> {
    if !(r_min_m > 0.0 && r_min_m.is_finite()) {
        return None;
    }
    let d = goal.pos - start.pos;
    let (sn, cs) = start.heading.sin_cos();
    let x = (cs * d.x + sn * d.y) / r_min_m;
    let y = (-sn * d.x + cs * d.y) / r_min_m;
    let phi = goal.heading - start.heading;
    if !(x.is_finite() && y.is_finite() && phi.is_finite()) {
        return None;
    }
    let (sp, cp) = phi.sin_cos();
    let mut best = Best {
        word: None,
        len: f64::INFINITY,
        all: collect.then(Vec::new),
    };
    csc(x, y, phi, sp, cp, &mut best);
    ccc(x, y, phi, sp, cp, &mut best);
    cccc(x, y, phi, sp, cp, &mut best);
    ccsc(x, y, phi, sp, cp, &mut best);
    ccscc(x, y, phi, sp, cp, &mut best);
    Some(best)
}

/// Length (m) of the shortest Reeds-Shepp path.
pub fn reeds_shepp_length(start: &Pose, goal: &Pose, r_min_m: f64) -> Option<f64> {
    reeds_shepp_word(start, goal, r_min_m).map(|w| w.length() * r_min_m)
}

/// Shortest Reeds-Shepp path as arcs of curvature ±1/r and lines (zero-length parts omitted).
pub fn reeds_shepp_shortest(start: &Pose, goal: &Pose, r_min_m: f64) -> Option<CurvePath> {
    let w = reeds_shepp_word(start, goal, r_min_m)?;
    Some(path_of(start, &w, r_min_m))
}

/// Word `w` from `start` as arcs and lines (zero-length parts omitted).
fn path_of(start: &Pose, w: &RsWord, r_min_m: f64) -> CurvePath {
    let mut segments = Vec::with_capacity(w.n);
    for i in 0..w.n {
        let l = w.lengths[i];
        if l.abs() < 1e-12 {
            continue;
        }
        let dir = if l >= 0.0 {
            Direction::Forward
        } else {
            Direction::Reverse
        };
        let len = l.abs() * r_min_m;
        segments.push(match w.letters[i] {
            L => CurveSegment::arc(dir, len, 1.0 / r_min_m),
            R => CurveSegment::arc(dir, len, -1.0 / r_min_m),
            S => CurveSegment::line(dir, len),
        });
    }
    CurvePath {
        start: *start,
        segments,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geo::wrap_angle;
    use rand::{Rng, SeedableRng};

    #[derive(serde::Deserialize)]
    struct Table {
        turn_radius_m: f64,
        pairs: Vec<[f64; 7]>,
    }

    /// Lengths equal an independent implementation (rsplan) on 1200 random pairs.
    #[test]
    fn lengths_match_reference_table() {
        let text = include_str!("../../../tools/maneuvers/reference/rs_table.json");
        let table: Table = serde_json::from_str(text).expect("table parses");
        assert!(table.pairs.len() >= 1000);
        let mut worst: f64 = 0.0;
        for p in &table.pairs {
            let a = Pose::new(p[0], p[1], p[2]);
            let b = Pose::new(p[3], p[4], p[5]);
            let len = reeds_shepp_length(&a, &b, table.turn_radius_m).expect("path");
            worst = worst.max((len - p[6]).abs());
            assert!(
                (len - p[6]).abs() < 1e-6,
                "{p:?}: ours {len}, reference {}",
                p[6]
            );
        }
        eprintln!("worst RS length difference {worst:.3e} m");
    }

    /// Every path reaches the goal; lengths scale with the radius.
    #[test]
    fn paths_reach_goal_and_scale() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(6);
        for _ in 0..2000 {
            let a = Pose::new(
                rng.gen_range(-20.0..20.0),
                rng.gen_range(-20.0..20.0),
                rng.gen_range(-PI..PI),
            );
            let b = Pose::new(
                rng.gen_range(-20.0..20.0),
                rng.gen_range(-20.0..20.0),
                rng.gen_range(-PI..PI),
            );
            let r = rng.gen_range(2.0..8.0);
            let path = reeds_shepp_shortest(&a, &b, r).expect("path");
            let end = path.end_pose();
            assert!((end.pos - b.pos).norm() < 1e-6, "{a:?} → {b:?}: {end:?}");
            assert!(wrap_angle(end.heading - b.heading).abs() < 1e-8);
            assert!((path.max_curvature() - 1.0 / r).abs() < 1e-12 || path.max_curvature() == 0.0);
            let len = reeds_shepp_length(&a, &b, r).expect("length");
            assert!((path.length() - len).abs() < 1e-9);
            // Scaling the scene scales the length.
            let k = 2.5;
            let a2 = Pose::new(a.pos.x * k, a.pos.y * k, a.heading);
            let b2 = Pose::new(b.pos.x * k, b.pos.y * k, b.heading);
            let len2 = reeds_shepp_length(&a2, &b2, r * k).expect("length");
            assert!((len2 - k * len).abs() < 1e-6 * len2.max(1.0));
            // Never shorter than the straight distance.
            assert!(len >= (b.pos - a.pos).norm() - 1e-9);
        }
    }

    #[test]
    fn rejects_bad_radius() {
        let a = Pose::new(0.0, 0.0, 0.0);
        assert!(reeds_shepp_shortest(&a, &a, 0.0).is_none());
        assert!(reeds_shepp_length(&a, &a, f64::NAN).is_none());
    }
}
