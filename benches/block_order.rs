//! Block order for N = 9, 12, 16, 20 lines (exact, Held–Karp over subsets), N = 41
//! (heuristic) and an infeasible remainder block (both DP passes). Target: < 10 ms at N = 16 in release.
//!
//! `cargo bench --bench block_order -- --warm-up-time 1 --measurement-time 3`

use agsteer::plan::skip_order::solve_block_order;
use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("block_order");
    g.sample_size(10);
    for n in [9usize, 12, 16, 20] {
        // N = 2·gap + 1 (a = 1) or 2·gap + 2 (a = 2): the tightest gap a full block has.
        let min_gap = (n - 1) / 2;
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, &n| {
            b.iter(|| solve_block_order(black_box(n), min_gap, true))
        });
    }
    // Beyond the exact solver: 41 lines with a gap of 10 (a = 21) and of 20 (a = 1).
    for min_gap in [10usize, 20] {
        g.bench_function(format!("41_gap{min_gap}"), |b| {
            b.iter(|| solve_block_order(black_box(41), min_gap, true))
        });
    }
    // A remainder block with no order free of short moves (N − 1 lines, gap 8): both DP
    // passes run.
    g.bench_function("16_infeasible", |b| {
        b.iter(|| solve_block_order(black_box(16), 8, false))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
