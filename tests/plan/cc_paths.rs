//! Continuous-curvature Reeds-Shepp paths over seeded random pose pairs (docs/METHODS.md, Curves):
//! every path sampled at 1 cm reaches the goal, respects κ_max and σ_max, and has continuous
//! curvature, zero at the start, the goal and every cusp. Also reports the CC / RS length ratio.
//!
//! Run: cargo test --release --test plan cc_paths:: -- --nocapture

use agsteer::geo::wrap_angle;
use agsteer::plan::maneuver::cc_reeds_shepp::{cc_reeds_shepp_length, cc_reeds_shepp_shortest};
use agsteer::plan::maneuver::path::{CurveParams, PathSample};
use agsteer::plan::maneuver::reeds_shepp::reeds_shepp_length;
#[path = "../common/mod.rs"]
mod common;

use common::random_pose_pairs as pairs;

struct Stats {
    none: usize,
    ratios: Vec<f64>,
    /// (ratio, pair index, CC length, RS length) of the worst pair.
    worst: (f64, usize, f64, f64),
}

fn check_all(params: CurveParams) -> Stats {
    check_n(params, 1000)
}

fn check_n(params: CurveParams, n: usize) -> Stats {
    let mut samples: Vec<PathSample> = Vec::new();
    let mut stats = Stats {
        none: 0,
        ratios: Vec::new(),
        worst: (0.0, 0, 0.0, 0.0),
    };
    for (i, (a, b)) in pairs(n, 42).into_iter().enumerate() {
        let Some(path) = cc_reeds_shepp_shortest(&a, &b, &params) else {
            stats.none += 1;
            continue;
        };
        let ctx = format!("pair {i}: {a:?} → {b:?}");
        // Ends at the goal.
        let end = path.end_pose();
        assert!((end.pos - b.pos).norm() < 1e-3, "{ctx}: end {end:?}");
        assert!(
            wrap_angle(end.heading - b.heading).abs() < 0.01f64.to_radians(),
            "{ctx}"
        );
        // Length-only query agrees.
        let len = cc_reeds_shepp_length(&a, &b, &params).expect("length");
        assert!(
            (len - path.length()).abs() < 1e-9,
            "{ctx}: {len} vs {}",
            path.length()
        );
        // Sampled at 1 cm.
        path.sample(0.01, &mut samples);
        let first = samples.first().expect("samples");
        let last = samples.last().expect("samples");
        assert!(
            first.kappa.abs() < 1e-12,
            "{ctx}: κ at start {}",
            first.kappa
        );
        assert!(last.kappa.abs() < 1e-9, "{ctx}: κ at end {}", last.kappa);
        assert!((last.pose.pos - b.pos).norm() < 1e-3, "{ctx}");
        for w in samples.windows(2) {
            let (p, q) = (&w[0], &w[1]);
            assert!(
                q.kappa.abs() <= params.kappa_max + 1e-9,
                "{ctx}: κ {}",
                q.kappa
            );
            let ds = q.s - p.s;
            assert!(ds <= 0.01 + 1e-12 && ds > 0.0, "{ctx}: spacing {ds}");
            // Curvature rate, including across segment boundaries (continuity).
            let rate = (q.kappa - p.kappa).abs() / ds;
            assert!(
                rate <= params.sigma_max * (1.0 + 1e-6) + 1e-9,
                "{ctx}: dκ/ds {rate}"
            );
            // Positions move by at most the distance driven (no jumps).
            assert!((q.pose.pos - p.pose.pos).norm() <= ds + 1e-9, "{ctx}: jump");
            // Cusp: κ = 0 there (the boundary sample belongs to the earlier segment).
            if p.direction != q.direction {
                assert!(p.kappa.abs() < 1e-9, "{ctx}: κ {} at a cusp", p.kappa);
            }
        }
        assert!(path.max_curvature_jump() < 1e-9, "{ctx}");
        for seg in &path.segments {
            let k0 = seg.kappa_start;
            assert!(
                (seg.kappa_at(seg.length) - seg.kappa_end).abs() < 1e-9,
                "{ctx}: {k0}"
            );
        }
        let rs = reeds_shepp_length(&a, &b, 1.0 / params.kappa_max).expect("rs");
        let ratio = path.length() / rs;
        if ratio > stats.worst.0 {
            stats.worst = (ratio, i, path.length(), rs);
        }
        stats.ratios.push(ratio);
    }
    stats
}

fn report(name: &str, params: CurveParams, mut st: Stats) {
    st.ratios.sort_by(f64::total_cmp);
    let n = st.ratios.len();
    let mean = st.ratios.iter().sum::<f64>() / n as f64;
    let p95 = st.ratios[(0.95 * n as f64) as usize - 1];
    let min = st.ratios[0];
    let max = st.ratios[n - 1];
    println!(
        "{name}: κ_max {} /m, σ_max {} /m²: {n} paths, {} without; CC/RS length mean {mean:.4}, p95 {p95:.4}, min {min:.4}, max {max:.4}",
        params.kappa_max, params.sigma_max, st.none
    );
    println!(
        "  worst: pair {} CC {:.3} m vs RS {:.3} m",
        st.worst.1, st.worst.2, st.worst.3
    );
    assert_eq!(st.none, 0, "{name}: pairs without a path");
    // A CC path is an admissible path with curvature ≤ κ_max, so never shorter than RS.
    assert!(min >= 1.0 - 1e-9, "{name}: CC shorter than RS ({min})");
    assert!(
        mean < 1.5 && p95 < 2.0,
        "{name}: implausible ratio mean {mean}, p95 {p95}"
    );
}

#[test]
fn cc_paths_valid_sigma_0_1() {
    let p = CurveParams {
        kappa_max: 0.2,
        sigma_max: 0.1,
    };
    report("σ 0.1", p, check_all(p));
}

#[test]
fn cc_paths_valid_sigma_1() {
    let p = CurveParams {
        kappa_max: 0.2,
        sigma_max: 1.0,
    };
    report("σ 1", p, check_all(p));
}

/// With a very large σ_max the clothoids vanish and CC paths must approach plain RS paths
/// (same families with μ → 0): checks the circle geometry against the independent RS code.
#[test]
fn cc_tends_to_rs_for_large_sigma() {
    let p = CurveParams {
        kappa_max: 0.2,
        sigma_max: 1e4,
    };
    let mut worst: f64 = 0.0;
    let mut sum = 0.0;
    let all = pairs(500, 9);
    for (a, b) in &all {
        let cc = cc_reeds_shepp_length(a, b, &p).expect("cc");
        let rs = reeds_shepp_length(a, b, 1.0 / p.kappa_max).expect("rs");
        worst = worst.max(cc / rs);
        sum += cc / rs;
    }
    let mean = sum / all.len() as f64;
    println!("σ 1e4: CC/RS mean {mean:.6}, max {worst:.6}");
    assert!(mean < 1.0001 && worst < 1.001, "mean {mean}, worst {worst}");
}

/// Other vehicle limits, including δ_min = κ²/σ close to π (long clothoids): still valid.
#[test]
fn cc_paths_valid_other_limits() {
    for (k, s) in [
        (0.1, 0.02),
        (0.25, 0.05),
        (0.5, 0.1),
        (0.3, 0.03),
        (0.15, 5.0),
        (0.5, 0.05),
        (0.5, 0.04),
        (0.5, 0.03),
    ] {
        let p = CurveParams {
            kappa_max: k,
            sigma_max: s,
        };
        let st = check_n(p, 200);
        println!(
            "κ {k}, σ {s} (δ_min {:.2} rad): {} without a path",
            k * k / s,
            st.none
        );
        assert_eq!(st.none, 0);
        assert!(st.ratios.iter().all(|r| *r >= 1.0 - 1e-9));
    }
}
