//! Least squares by simulation: the Nelder–Mead simplex search (derivative-free: the model's
//! cost is only piecewise smooth in the dead time and the deadband) and the parameters'
//! standard deviations from the Gauss–Newton approximation of the covariance,
//! σ² (JᵀJ)⁻¹, with J the residuals' Jacobian by central differences.
//!
//! Hand-written rather than a crate (argmin and friends bring a framework of traits and
//! allocations for a 60-line routine on five parameters); the method is the textbook one
//! (Nelder & Mead 1965, with the standard coefficients 1, 2, ½, ½ of Lagarias et al. 1998).

/// Minimise `f` over `N` parameters from `x0` with initial steps `step`, for at most `iters`
/// iterations or until the simplex's values agree within `ftol` (relative). Returns the best
/// point and its value.
pub fn nelder_mead<const N: usize>(
    f: &mut dyn FnMut(&[f64; N]) -> f64,
    x0: [f64; N],
    step: [f64; N],
    iters: usize,
    ftol: f64,
) -> ([f64; N], f64) {
    // N + 1 vertices; N ≤ 8 in practice, kept on the stack as a Vec-free array of arrays is
    // not expressible for N + 1 in stable Rust: a small Vec, allocated once per fit.
    let mut pts: Vec<([f64; N], f64)> = Vec::with_capacity(N + 1);
    let v0 = f(&x0);
    pts.push((x0, v0));
    for i in 0..N {
        let mut x = x0;
        x[i] += step[i];
        let v = f(&x);
        pts.push((x, v));
    }
    let cmp = |a: &([f64; N], f64), b: &([f64; N], f64)| a.1.total_cmp(&b.1);
    for _ in 0..iters {
        pts.sort_by(cmp);
        let best = pts[0].1;
        let worst = pts[N].1;
        if (worst - best).abs() <= ftol * (best.abs() + worst.abs()) + 1e-300 {
            break;
        }
        let mut centroid = [0.0; N];
        for p in pts.iter().take(N) {
            for (c, x) in centroid.iter_mut().zip(p.0) {
                *c += x / N as f64;
            }
        }
        let along = |c: f64| {
            let mut x = [0.0; N];
            for j in 0..N {
                x[j] = centroid[j] + c * (pts[N].0[j] - centroid[j]);
            }
            x
        };
        let xr = along(-1.0);
        let fr = f(&xr);
        if fr < pts[0].1 {
            let xe = along(-2.0);
            let fe = f(&xe);
            pts[N] = if fe < fr { (xe, fe) } else { (xr, fr) };
            continue;
        }
        if fr < pts[N - 1].1 {
            pts[N] = (xr, fr);
            continue;
        }
        let (xc, fc) = if fr < pts[N].1 {
            let x = along(-0.5);
            (x, f(&x))
        } else {
            let x = along(0.5);
            (x, f(&x))
        };
        if fc < fr.min(pts[N].1) {
            pts[N] = (xc, fc);
            continue;
        }
        // Shrink towards the best.
        let b = pts[0].0;
        for p in pts.iter_mut().skip(1) {
            for (x, bj) in p.0.iter_mut().zip(b) {
                *x = bj + 0.5 * (*x - bj);
            }
            p.1 = f(&p.0);
        }
    }
    pts.sort_by(cmp);
    pts[0]
}

/// Standard deviations of the `N` parameters at `x` of a least-squares fit whose residuals
/// `residuals(x, out)` writes (`m` of them), from σ²(JᵀJ)⁻¹ with σ² = SSR / (m − N) and J by
/// central differences of half-width `h`. `None` for a parameter the data does not determine
/// (a singular or ill-conditioned JᵀJ in it).
pub fn std_devs<const N: usize>(
    residuals: &mut dyn FnMut(&[f64; N], &mut [f64]),
    x: &[f64; N],
    h: &[f64; N],
    m: usize,
) -> [Option<f64>; N] {
    let mut r0 = vec![0.0; m];
    residuals(x, &mut r0);
    let ssr: f64 = r0.iter().map(|r| r * r).sum();
    let dof = m.saturating_sub(N).max(1) as f64;
    let s2 = ssr / dof;
    let mut jac = vec![[0.0; N]; m];
    let mut rp = vec![0.0; m];
    let mut rm = vec![0.0; m];
    for j in 0..N {
        let mut xp = *x;
        let mut xm = *x;
        xp[j] += h[j];
        xm[j] -= h[j];
        residuals(&xp, &mut rp);
        residuals(&xm, &mut rm);
        for i in 0..m {
            jac[i][j] = (rp[i] - rm[i]) / (2.0 * h[j]);
        }
    }
    let mut a = nalgebra::DMatrix::<f64>::zeros(N, N);
    for row in &jac {
        for p in 0..N {
            for q in 0..N {
                a[(p, q)] += row[p] * row[q];
            }
        }
    }
    let mut out = [None; N];
    // A parameter whose column is (nearly) zero is not determined: leave it out and invert
    // the rest.
    let scale: f64 = (0..N).map(|k| a[(k, k)]).fold(0.0, f64::max);
    let keep: Vec<usize> = (0..N).filter(|&k| a[(k, k)] > 1e-12 * scale).collect();
    let mut sub = nalgebra::DMatrix::<f64>::zeros(keep.len(), keep.len());
    for (p, &kp) in keep.iter().enumerate() {
        for (q, &kq) in keep.iter().enumerate() {
            sub[(p, q)] = a[(kp, kq)];
        }
    }
    if let Some(inv) = sub.try_inverse() {
        for (p, &kp) in keep.iter().enumerate() {
            let v = s2 * inv[(p, p)];
            if v.is_finite() && v >= 0.0 {
                out[kp] = Some(v.sqrt());
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nelder_mead_finds_the_rosenbrock_minimum() {
        let mut f = |x: &[f64; 2]| (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2);
        let (x, v) = nelder_mead(&mut f, [-1.2, 1.0], [0.5, 0.5], 2000, 1e-14);
        assert!(
            (x[0] - 1.0).abs() < 1e-3 && (x[1] - 1.0).abs() < 1e-3,
            "{x:?}"
        );
        assert!(v < 1e-6);
    }

    #[test]
    fn std_devs_of_a_straight_line_fit_match_the_closed_form() {
        // y = a + b·t with alternating ±0.1 noise: σ_b = s / sqrt(Σ(t − t̄)²).
        let ts: Vec<f64> = (0..20).map(|i| i as f64).collect();
        let ys: Vec<f64> = ts
            .iter()
            .enumerate()
            .map(|(i, t)| 1.0 + 2.0 * t + if i % 2 == 0 { 0.1 } else { -0.1 })
            .collect();
        let mut res = |x: &[f64; 2], out: &mut [f64]| {
            for ((o, t), y) in out.iter_mut().zip(&ts).zip(&ys) {
                *o = y - (x[0] + x[1] * t);
            }
        };
        let mean = 9.5;
        let sxx: f64 = ts.iter().map(|t| (t - mean).powi(2)).sum();
        // The least-squares line through the alternating noise.
        let sxy: f64 = ts.iter().zip(&ys).map(|(t, y)| (t - mean) * y).sum();
        let b = sxy / sxx;
        let a = ys.iter().sum::<f64>() / 20.0 - b * mean;
        let mut r = vec![0.0; 20];
        res(&[a, b], &mut r);
        let s = (r.iter().map(|x| x * x).sum::<f64>() / 18.0).sqrt();
        let sd = std_devs(&mut res, &[a, b], &[1e-3, 1e-3], 20);
        let sb = sd[1].expect("determined");
        assert!((sb - s / sxx.sqrt()).abs() < 1e-9, "{sb}");
        // A parameter the residuals do not depend on is not determined.
        let mut res3 = |x: &[f64; 3], out: &mut [f64]| res(&[x[0], x[1]], out);
        let sd3 = std_devs(&mut res3, &[a, b, 0.0], &[1e-3, 1e-3, 1e-3], 20);
        assert!(sd3[2].is_none() && sd3[1].is_some());
    }
}
