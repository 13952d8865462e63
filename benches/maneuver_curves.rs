//! Manoeuvre curves (docs/METHODS.md, Curves): one plain Reeds-Shepp query, one CC Reeds-Shepp
//! query (length only and full path) and one CC turn, averaged over a fixed set of 256 random pose
//! pairs in ±20 m (κ_max 0.2 /m, σ_max 0.1 /m²). Targets: RS < 2 µs, CC < 10 µs per query.
//!
//! Run: cargo bench --bench maneuver_curves -- --warm-up-time 1 --measurement-time 3

use agsteer::geo::Direction;
use agsteer::plan::maneuver::cc_reeds_shepp::{cc_reeds_shepp_length, cc_reeds_shepp_shortest};
use agsteer::plan::maneuver::cc_turn::cc_turn;
use agsteer::plan::maneuver::path::CurveParams;
use agsteer::plan::maneuver::reeds_shepp::{reeds_shepp_length, reeds_shepp_shortest};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::f64::consts::PI;
use std::hint::black_box;

#[path = "../tests/common/mod.rs"]
mod common;

fn bench(c: &mut Criterion) {
    let pairs = common::random_pose_pairs(256, 7);
    let params = CurveParams {
        kappa_max: 0.2,
        sigma_max: 0.1,
    };
    let mut g = c.benchmark_group("maneuver_curves");
    g.throughput(Throughput::Elements(pairs.len() as u64));
    g.bench_function("rs_length_x256", |b| {
        b.iter(|| {
            for (a, z) in &pairs {
                black_box(reeds_shepp_length(black_box(a), black_box(z), 5.0));
            }
        })
    });
    g.bench_function("rs_path_x256", |b| {
        b.iter(|| {
            for (a, z) in &pairs {
                black_box(reeds_shepp_shortest(black_box(a), black_box(z), 5.0));
            }
        })
    });
    g.bench_function("cc_length_x256", |b| {
        b.iter(|| {
            for (a, z) in &pairs {
                black_box(cc_reeds_shepp_length(black_box(a), black_box(z), &params));
            }
        })
    });
    g.bench_function("cc_path_x256", |b| {
        b.iter(|| {
            for (a, z) in &pairs {
                black_box(cc_reeds_shepp_shortest(black_box(a), black_box(z), &params));
            }
        })
    });
    g.bench_function("cc_turn_x256", |b| {
        b.iter(|| {
            for i in 0..256 {
                let d = (i as f64 / 128.0 - 1.0) * PI;
                black_box(cc_turn(black_box(d), Direction::Reverse, &params));
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
