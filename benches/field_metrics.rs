//! Independent plan metrics (geo boolean ops) on synthetic boustrophedon plans of square
//! fields: 10 ha, 100 ha and 1000 ha at 6 m width, 1 m point spacing, semicircular turns.

use agsteer::geo::{v2, Direction, Vec2};
use agsteer::plan::coverage::metrics::plan_metrics;
use agsteer::plan::coverage::{Field, FieldPlan, PlanSegment, SegmentKind};
use criterion::{criterion_group, criterion_main, Criterion};

fn square_plan(side: f64, width: f64) -> (Field, FieldPlan) {
    let field = Field {
        boundary: vec![v2(0.0, 0.0), v2(side, 0.0), v2(side, side), v2(0.0, side)],
        obstacles: Vec::new(),
    };
    let n = (side / width).floor() as usize;
    let mut segments = Vec::new();
    for i in 0..n {
        let y = width * (i as f64 + 0.5);
        let forward = i % 2 == 0;
        let mut pts: Vec<Vec2> = (0..=side as usize).map(|k| v2(k as f64, y)).collect();
        if !forward {
            pts.reverse();
        }
        segments.push(PlanSegment {
            kind: SegmentKind::Work,
            direction: Direction::Forward,
            index: segments.len(),
            cell: 0,
            points: pts,
        });
        if i + 1 < n {
            let (cx, sign) = if forward { (side, 1.0) } else { (0.0, -1.0) };
            let arc = (0..=16)
                .map(|k| {
                    let a = -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * k as f64 / 16.0;
                    v2(
                        cx + sign * 0.5 * width * a.cos(),
                        y + 0.5 * width + 0.5 * width * a.sin(),
                    )
                })
                .collect();
            segments.push(PlanSegment {
                kind: SegmentKind::Turn,
                direction: Direction::Forward,
                index: segments.len(),
                cell: 0,
                points: arc,
            });
        }
    }
    let plan = FieldPlan {
        segments,
        working_area: vec![(field.boundary.clone(), Vec::new())],
        cells: 1,
        swath_angles: vec![0.0],
        swaths: n,
        ..FieldPlan::default()
    };
    (field, plan)
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("plan_metrics");
    g.sample_size(10);
    for (name, side) in [("10ha", 316.0), ("100ha", 1000.0), ("1000ha", 3162.0)] {
        let (field, plan) = square_plan(side, 6.0);
        g.bench_function(name, |b| b.iter(|| plan_metrics(&field, &plan, 6.0)));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
