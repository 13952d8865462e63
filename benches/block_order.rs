//! Exact block order (Held–Karp over subsets) for N = 9, 12, 16, 20 lines.
//! Target: < 10 ms at N = 16.

use agsteer::plan::abline::solve_block_order;
use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("block_order");
    g.sample_size(10);
    for n in [9usize, 12, 16, 20] {
        // N = 2k + 1: the tightest gap a block of N lines has.
        let min_gap = (n - 1) / 2;
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, &n| {
            b.iter(|| solve_block_order(black_box(n), min_gap, true))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
